"""Device names -> Modbus (table, wire address), from the daemon's own map.

`plcemud -c CONFIG --print-map --format csv` prints the map the configuration gives (the
profile's default or its `modbus.map`) and the simulator unit's registers; WireMap reads it, so
any profile and any map work without a table of addresses here.
"""

import csv
import re
import subprocess

from .errors import DaemonError, DeviceError

DEVICE = re.compile(r"^(W?)([A-Z]+)(\d+)$")

BIT_TABLES = ("coils", "discrete inputs")
WORD_TABLES = ("holding registers", "input registers")
WRITABLE = ("coils", "holding registers")

# Other names the profiles give an area the map prints under one name: the FBs' timer and
# counter registers (TMR5 is the current value of T5), the VB's contacts (TS5 is T5).
ALIASES = {"fatek": {"TMR": "T", "CTR": "C"}, "vigor": {"TS": "T", "CS": "C"}}
# Counter values from C200 (CN200) on are 32-bit: two registers, low word first.
COUNTER_VALUES = ("C", "CN")
FIRST_32BIT = 200

# The simulator unit's registers, by the start of their label after "simulator: " or
# "channel c: ".
SIM_FIELDS = (("time scale", "time_scale"), ("freeze", "freeze"), ("step", "step"),
              ("simulated time, s, low", "time_low"), ("simulated time, s, high", "time_high"),
              ("faults", "faults"), ("ambient", "ambient"), ("K full-power", "k"), ("tau", "tau"),
              ("dead time", "dead_time"), ("noise", "noise"),
              ("true temperature", "true_temperature"), ("heater power", "heater_power"),
              ("RTD lead resistance", "lead_resistance"))


def parse_device(text):
    """(16 bits from a bit device?, area, digits as written) of a device name, or None."""
    m = DEVICE.match(str(text).strip().upper())
    if not m:
        return None
    return m.group(1) == "W", m.group(2), m.group(3)


def width(table, area, index):
    """Wire addresses one element takes: 2 for a 32-bit counter value, else 1."""
    return 2 if table in WORD_TABLES and area in COUNTER_VALUES and index >= FIRST_32BIT else 1


class Row:
    """One row of the map: elements first..last of `area` (numbered in `base`) from `wire` on;
    `packed`: 16 bits per register (a W device of modbus.map)."""

    def __init__(self, table, area, first, last, wire, base, packed, access):
        self.table, self.area, self.first, self.last = table, area, first, last
        self.wire, self.base, self.packed, self.access = wire, base, packed, access

    def name(self, index):
        digits = format(index, "o") if self.base == 8 else str(index)
        return f"{self.area}{digits}"

    def offset(self, index):
        """Wire offset of element `index` from the row's first wire."""
        if self.packed:
            return (index - self.first) // 16
        wide = max(0, index - max(self.first, FIRST_32BIT)) if width(
            self.table, self.area, FIRST_32BIT) == 2 else 0
        return index - self.first + wide

    def describe(self):
        return f"{self.name(self.first)}-{self.name(self.last)} in {self.table}"


def _base_of(table, area, first, last, count, packed):
    """The radix (10 or 8) in which the row's names span `count` wire addresses, or None."""
    for base in (10, 8):
        try:
            lo, hi = int(first, base), int(last, base)
        except ValueError:
            continue
        if packed:
            spans = (hi - lo + 1 + 15) // 16
        else:
            spans = sum(width(table, area, i) for i in range(lo, hi + 1))
        if spans == count:
            return base
    return None


def _print_map(plcemud, config_path):
    """The rows of `plcemud -c CONFIG --print-map --format csv`."""
    try:
        r = subprocess.run([str(plcemud), "-c", str(config_path), "--print-map", "--format",
                            "csv"], capture_output=True, text=True, timeout=30)
    except OSError as e:
        raise DaemonError(f"cannot run {plcemud}: {e}") from e
    if r.returncode != 0:
        raise DaemonError(f"plcemud --print-map failed on {config_path}:\n{r.stderr}")
    return list(csv.reader(r.stdout.splitlines()))


class WireMap:
    """Device -> (table, wire address), and the simulator unit, from `plcemud --print-map
    --format csv` on the config: the daemon's own map, whatever the profile or modbus.map."""

    ROW = re.compile(r"^([A-Z]+)(\d+)-([A-Z]+)(\d+)\b")

    def __init__(self, plcemud, config_path, rows=None):
        """The map of a config holding one PLC; `rows`: its csv rows (header first) when
        already read."""
        if rows is None:
            rows = _print_map(plcemud, config_path)
        self.vendor = rows[0][4] if rows and len(rows[0]) > 4 else ""
        self.aliases = ALIASES.get(self.vendor, {})
        self.rows = []
        self.sim_unit = None
        self.sim = {}  # field -> (first wire, stride per channel)
        self.channels = 0
        for row in rows[1:]:
            self._add(row)
        self.power = self.sim.get("heater_power")  # (first wire, stride) of the heater power

    @classmethod
    def per_plc(cls, plcemud, config_path):
        """{plc: WireMap} of a `plcs:` config, by the `plc` column of --print-map --format csv
        ("kiln", "plcs[2]"): each PLC's rows follow a header of their own after that column."""
        maps, header = {}, None
        for row in _print_map(plcemud, config_path):
            if not row:
                continue
            if row[0] == "plc":
                header = row[1:]
                continue
            maps.setdefault(row[0], [header]).append(row[1:])
        return {plc: cls(plcemud, config_path, rows) for plc, rows in maps.items()}

    def _add(self, row):
        table, wire_text, label, access = row[0], row[3], row[4], row[-1]
        m = re.match(r"holding registers \(unit (\d+)\)$", table)
        if m:
            self.sim_unit = int(m.group(1))
            self._add_sim(wire_text, label)
            return
        if table not in BIT_TABLES + WORD_TABLES:
            return
        m = self.ROW.match(label)
        w = re.match(r"(\d+)-(\d+)$", wire_text)
        if not m or not w or m.group(1) != m.group(3):
            return
        first_w, last_w = int(w.group(1)), int(w.group(2))
        packed = table in WORD_TABLES and "16 per register" in label
        area = m.group(1)
        base = _base_of(table, area, m.group(2), m.group(4), last_w - first_w + 1, packed)
        if base is None:  # a layout this reader does not know: better no address than a wrong one
            return
        self.rows.append(Row(table, "W" + area if packed else area, int(m.group(2), base),
                             int(m.group(4), base), first_w, base, packed, access))

    def _add_sim(self, wire_text, label):
        m = re.match(r"(\d+)(?:\+(\d+)c)?$", wire_text)
        if not m:
            return
        c = re.search(r"channel c \(0-(\d+)\)", label)
        if c:
            self.channels = int(c.group(1)) + 1
        text = re.sub(r"^(simulator|channel c( \([^)]*\))?): ", "", label)
        comm = re.match(r"comm\.(\w+):", text)
        if comm:
            self.sim["comm." + comm.group(1)] = (int(m.group(1)), 0)
            return
        for prefix, field in SIM_FIELDS:
            if text.startswith(prefix):
                self.sim[field] = (int(m.group(1)), int(m.group(2) or 0))
                return

    def areas(self):
        return sorted({r.area for r in self.rows})

    def locate(self, area, digits, offset=0, tables=None):
        """(row, wire address) of device `area``digits` + offset in the first of `tables`
        (default: any, in map order) that maps it; DeviceError naming it otherwise."""
        name = f"{area}{digits}"
        if area not in self.areas():
            area = self.aliases.get(area, area)
        rows = [r for r in self.rows if r.area == area]
        if not rows:
            raise DeviceError(name, f"no {area} devices in this PLC's Modbus map (its areas: "
                                    f"{', '.join(self.areas())})")
        valid = False
        for table in tables or [None]:
            for r in rows:
                if table and r.table != table:
                    continue
                try:
                    index = int(digits, r.base) + offset
                except ValueError:
                    continue
                valid = True
                if r.first <= index <= r.last and (not r.packed or (index - r.first) % 16 == 0):
                    return r, r.wire + r.offset(index)
        if not valid:
            raise DeviceError(name, f"not a device name: {area} is numbered in octal "
                                    "(7 is followed by 10)")
        where = "; ".join(r.describe() for r in rows if not tables or r.table in tables)
        shown = f"{name} + {offset}" if offset else name
        raise DeviceError(shown, f"not reachable over Modbus (the map has {where or 'none'}"
                                 f"{' there' if tables else ''})")

    def wire(self, area, digits, offset=0, table=None):
        """(table, wire address) of device `area``digits` + offset."""
        r, w = self.locate(area, digits, offset, [table] if table else None)
        return r.table, w

    def reg(self, device, offset=0):
        """Holding register address of a register device (+ offset)."""
        d = parse_device(device)
        if not d or d[0]:
            raise DeviceError(device, "not a register")
        return self.wire(d[1], d[2], offset, "holding registers")[1]
