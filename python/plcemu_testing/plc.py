"""One PLC under test: devices by name, its tag export and its simulator unit (PlcApi), and
Plc, a plcemud process holding one PLC.

Plc needs no pytest: the `plcemud` fixture (plugin.py) creates them and stops them at teardown.
A `plcs:` config gives a Plcs instead (plcs.py), whose PLCs have the same PlcApi.
"""

import json
import re
import time
from collections.abc import Mapping
from pathlib import Path

from pymodbus.client import ModbusTcpClient
from pymodbus.exceptions import ModbusException
from pymodbus.pdu import ExceptionResponse

from .errors import DaemonError, DeviceError, ModbusError
from .fatek import Fatek
from .process import Process, free_port
from .tags import FUNCTIONS, WIDTH, from_registers, read_tags, to_registers
from .wire_map import BIT_TABLES, WORD_TABLES, WireMap, parse_device, width

# Largest quantities of one request (FC03/04 125, FC16 123, FC01/02 2000, FC15 1968 by the
# protocol), rounded down.
MAX_WORDS = 120
MAX_BITS = 1960
MAX_STEP = 60000  # scans per write of the step register
FAULT_BITS = {"sensor_broken": 0, "heater_open": 1, "heater_shorted": 2, "reading_frozen": 3}
# plant() keyword -> (simulator field, register counts per config unit, signed)
# comm_fault() keyword -> the simulator unit's register (docs/communication-faults.md); the
# block runs from comm.delay_min_ms to comm.count and is written in one request.
COMM_FIELDS = ("delay_min_ms", "delay_max_ms", "drop_every", "drop_probability", "seed",
               "exception", "offline", "refuse_connections", "disconnect", "disconnect_after",
               "garble", "stop", "unit", "function", "from_1", "from_2", "from_3", "from_4",
               "count")
COMM_KEYS = {"delay_ms", "drop_every", "drop_probability", "seed", "exception", "offline",
             "refuse_connections", "disconnect_after", "reset", "garble", "stop", "unit",
             "function", "from", "count"}
GARBLES = ("none", "crc", "short", "gap")
PLANT_PARAMS = {"ambient": ("ambient", 10, True), "k": ("k", 10, False),
                "tau": ("tau", 1, False), "dead_time": ("dead_time", 1, False),
                "noise": ("noise", 100, False), "lead_resistance": ("lead_resistance", 100, False)}


def _to_signed(value, bits):
    return value - (1 << bits) if value >> (bits - 1) & 1 else value


def connect(port):
    """A connected client of plcemud on 127.0.0.1:`port`."""
    client = ModbusTcpClient("127.0.0.1", port=port, timeout=5, retries=1)
    if not client.connect():
        raise DaemonError(f"cannot connect to plcemud on port {port}")
    return client


def _settings(config):
    """(scan_ms, station) of a config (one PLC, or an entry of `plcs:`) given as a dict or as
    YAML text."""
    if not isinstance(config, Mapping):
        try:
            import yaml  # optional: the top-level keys are also found without it
            loaded = yaml.safe_load(config)
            config = loaded if isinstance(loaded, Mapping) else {}
        except ImportError:
            config = {k: v for k, v in re.findall(r"(?m)^(scan_ms|station)\s*:\s*(\d+)",
                                                  config)}
        except yaml.YAMLError:
            config = {}  # plcemud says what is wrong
    return float(config.get("scan_ms", 10)), int(config.get("station", 1))


def config_text(config):
    """YAML text of a config: a dict (as JSON, which YAML reads; TCP bound to 127.0.0.1 unless
    it says otherwise), YAML text (a str with a newline), or the path of a YAML file."""
    if isinstance(config, Mapping):
        cfg = json.loads(json.dumps(config))  # a deep copy, with string keys
        modbus = cfg.setdefault("modbus", {}) or {}
        cfg["modbus"] = modbus
        tcp = modbus.setdefault("tcp", {}) or {}
        modbus["tcp"] = tcp
        tcp.setdefault("bind", "127.0.0.1")
        fatek_listener(cfg, given={})
        return json.dumps(cfg, indent=1) + "\n"
    if isinstance(config, str) and "\n" in config:
        return config
    path = Path(config)
    try:
        return path.read_text()
    except OSError as e:
        raise DaemonError(f"cannot read the config {path}: {e}") from e


def fatek_listener(cfg, given=None):
    """(transport, host, port) of the FATEK listener a client reaches a config (a dict: one PLC
    or a `plcs:` entry) on: its fatek.tcp, else its fatek.udp, else None. With `given` (a dict
    of listener as written -> port it got, shared by the entries that write the same one), each
    listener gets a free port, bound to 127.0.0.1 unless it says otherwise (as modbus.tcp)."""
    fatek = cfg.get("fatek") if isinstance(cfg, Mapping) else None
    found = None
    for transport in ("tcp", "udp") if isinstance(fatek, Mapping) else ():
        listener = fatek.get(transport)
        if not isinstance(listener, dict) or listener.get("enabled", True) is False:
            continue
        if given is not None:
            key = ("fatek", transport, listener.get("bind"), listener.get("port"))
            if key not in given:
                given[key] = free_port(taken=set(given.values()),
                                       kind="udp" if transport == "udp" else "tcp")
            listener["port"] = given[key]
            listener.setdefault("bind", "127.0.0.1")
        bind = listener.get("bind", "0.0.0.0")
        host = "127.0.0.1" if bind in ("0.0.0.0", "::") else bind
        found = found or (transport, host, int(listener.get("port", 500)))
    return found


def fatek_config(path):
    """The config file at `path` as a dict when it names `fatek` (JSON, else YAML: PyYAML
    needed then), else {}: what the FATEK client needs of it, without PyYAML for the others."""
    text = Path(path).read_text()
    if "fatek" not in text:
        return {}
    try:
        return json.loads(text)
    except ValueError:
        pass
    try:
        import yaml
    except ImportError as e:
        raise DaemonError(f"{path}: a YAML config with fatek: needs PyYAML (python3-yaml) for "
                          "plc.fatek; or pass it as a dict") from e
    try:
        loaded = yaml.safe_load(text)
    except yaml.YAMLError:
        return {}  # plcemud says what is wrong
    return loaded if isinstance(loaded, Mapping) else {}


class PlcApi:
    """What a test does with one PLC: device methods take names as the profile writes them
    (D100, R4005, M0, X17, TMR5, CN200, WM800) and translate them through the daemon's own
    --print-map; the tag export; the simulator unit.

    A subclass provides `client` (connected to the PLC's listener), `port`, `station`, `map`
    (its WireMap), `scan_ms`, `tags` (its rows of the export), `config_path` and `log`."""

    # --- Modbus requests ------------------------------------------------------------------

    def _call(self, operation, device, function, *args, unit=None):
        if self.client is None:
            raise DaemonError(f"{operation} {device}: plcemud is not running"
                              if self.port else f"{operation} {device}: the PLC has no TCP "
                              "listener (modbus.tcp.enabled: false)")
        try:
            r = function(*args, slave=self.station if unit is None else unit)
        except ModbusException as e:
            raise ModbusError(operation, device, detail=e) from e
        if isinstance(r, ExceptionResponse):
            raise ModbusError(operation, device, code=r.exception_code)
        if r.isError():
            raise ModbusError(operation, device, detail=r)
        return r

    # --- devices --------------------------------------------------------------------------

    def _elements(self, device, n, bits, write):
        """[(row, wire address, width)] of `n` devices from `device` on."""
        d = parse_device(device)
        if not d:
            raise DeviceError(device, "not a device name (e.g. D100, R4005, M0, X17, CN200)")
        packed, area, digits = d
        if packed:  # only here when the map packs the area in registers (read() and write())
            area = "W" + area
        step = 16 if packed else 1
        name = f"{area}{digits}"
        if n < 1:
            raise ValueError(f"{name}: n must be at least 1")
        tables = BIT_TABLES if bits else WORD_TABLES
        if write:
            tables = tables[:1]
        target = area if area in self.map.areas() else self.map.aliases.get(area, area)
        has = {r.table for r in self.map.rows if r.area == target}
        if has and not has & set(BIT_TABLES if bits else WORD_TABLES):
            use = "read()/write()" if bits else "read_bits()/write_bits()"
            raise DeviceError(name, f"a {'register' if bits else 'bit device'}: use {use}")
        if has and write and not has & set(tables):
            raise DeviceError(name, f"read-only over Modbus (only in {', '.join(sorted(has))})")
        out = []
        for k in range(n):
            row, wire = self.map.locate(area, digits, k * step, tables)
            index = int(digits, row.base) + k * step
            out.append((row, wire, 1 if bits else width(row.table, row.area, index)))
        return out

    @staticmethod
    def _runs(elements, limit):
        """Elements grouped into requests: one table, contiguous wires, at most `limit` wires."""
        runs = []
        for e in elements:
            row, wire, w = e
            last = runs[-1] if runs else None
            if (last and last[0] == row.table and last[1] + last[2] == wire
                    and last[2] + w <= limit):
                last[2] += w
                last[3].append(e)
            else:
                runs.append([row.table, wire, w, [e]])
        return runs

    def _label(self, device, n):
        return device.upper() if n == 1 else f"{device.upper()} (x{n})"

    def read(self, device, n=1, signed=False):
        """Values of `n` registers from `device` on (a 32-bit counter is one value, low word
        first on the wire); `signed`: as two's complement."""
        d = parse_device(device)
        if d and d[0] and not any(r.area == "W" + d[1] for r in self.map.rows):
            words = self._pack(self.read_bits(f"{d[1]}{d[2]}", 16 * n))
            return [_to_signed(v, 16) if signed else v for v in words]
        values = []
        for table, wire, count, elements in self._runs(self._elements(device, n, False, False),
                                                       MAX_WORDS):
            fn = (self.client.read_holding_registers if table == "holding registers"
                  else self.client.read_input_registers)
            regs = self._call("read", self._label(device, n), fn, wire, count).registers
            i = 0
            for _, _, w in elements:
                v = regs[i] | (regs[i + 1] << 16 if w == 2 else 0)
                values.append(_to_signed(v, 16 * w) if signed else v)
                i += w
        return values

    def write(self, device, values):
        """Writes one value or a list to registers from `device` on (a 32-bit counter takes one
        value); a Modbus exception raises ModbusError naming the device."""
        values = list(values) if isinstance(values, (list, tuple)) else [values]
        d = parse_device(device)
        if d and d[0] and not any(r.area == "W" + d[1] for r in self.map.rows):
            self.write_bits(f"{d[1]}{d[2]}", [(self._word(device, v, 1) >> b) & 1
                                              for v in values for b in range(16)])
            return
        elements = self._elements(device, len(values), False, True)
        words = []
        for (_, _, w), v in zip(elements, values):
            v = self._word(device, v, w)
            words += [v & 0xFFFF, v >> 16] if w == 2 else [v]
        i = 0
        for _, wire, count, _ in self._runs(elements, MAX_WORDS):
            self._call("write", self._label(device, len(values)), self.client.write_registers,
                       wire, words[i:i + count])
            i += count

    @staticmethod
    def _word(device, value, w):
        bits = 16 * w
        if not isinstance(value, int) or not -(1 << (bits - 1)) <= value < (1 << bits):
            raise ValueError(f"{device}: {value!r} does not fit {bits} bits")
        return value & ((1 << bits) - 1)

    @staticmethod
    def _pack(bits):
        return [sum(b << i for i, b in enumerate(bits[k:k + 16])) for k in range(0, len(bits), 16)]

    def read_bits(self, device, n=1):
        """States (0/1) of `n` bit devices from `device` on (coils, else discrete inputs)."""
        values = []
        for table, wire, count, _ in self._runs(self._elements(device, n, True, False), MAX_BITS):
            fn = self.client.read_coils if table == "coils" else self.client.read_discrete_inputs
            values += [int(b) for b in self._call("read", self._label(device, n), fn, wire,
                                                  count).bits[:count]]
        return values

    def write_bits(self, device, values):
        """Sets bit devices from `device` on to one value or a list of 0/1 (coils)."""
        values = list(values) if isinstance(values, (list, tuple)) else [values]
        i = 0
        for _, wire, count, _ in self._runs(self._elements(device, len(values), True, True),
                                            MAX_BITS):
            self._call("write", self._label(device, len(values)), self.client.write_coils, wire,
                       [bool(v) for v in values[i:i + count]])
            i += count

    # --- the FATEK protocol ------------------------------------------------------------------

    _fatek = None

    @property
    def fatek(self):
        """A FATEK protocol master (fatek.py) on the PLC's fatek.tcp listener, else its fatek.udp
        one, at its station: connected at first use, closed when the daemon stops."""
        if self._fatek is None:
            found = fatek_listener(self._own_config())
            if found is None:
                raise DaemonError(f"{self.config_path}: the PLC has no fatek.tcp or fatek.udp "
                                  "listener")
            transport, host, port = found
            connect_to = Fatek.tcp if transport == "tcp" else Fatek.udp
            self._fatek = connect_to(port, host, station=self.station)
        return self._fatek

    def _close_fatek(self):
        if self._fatek is not None:
            self._fatek.close()
            self._fatek = None

    # --- the tag export -------------------------------------------------------------------

    def tag(self, name):
        """The exported tag named `name` ("R100", "CN200", "sim.ch0.ambient"; a PLC of `plcs:`
        takes the name with or without its prefix, "kiln.R100" or "R100")."""
        for t in self.tags:
            if t["name"] in (name, f"{t.get('plc')}.{name}"):
                return t
        raise KeyError(f"{name}: no such tag in the export of {self.config_path}")

    def read_tag(self, tag):
        """A tag's value read at its exported unit, table and address with the function its
        table implies: 0/1 for a bool, a signed value for int16/int32 (one value for int32)."""
        tag = self.tag(tag) if isinstance(tag, str) else tag
        fn = getattr(self.client, FUNCTIONS[tag["table"]][0])
        n = WIDTH[tag["type"]]
        r = self._call("read", tag["name"], fn, tag["address"], n, unit=tag["unit"])
        if tag["type"] == "bool":
            return int(r.bits[0])
        return from_registers(tag, r.registers)

    def write_tag(self, tag, value):
        """Writes a tag's value at its exported address (coils with FC15, registers with FC16);
        a Modbus exception raises ModbusError naming the tag."""
        tag = self.tag(tag) if isinstance(tag, str) else tag
        name = FUNCTIONS[tag["table"]][1]
        if name is None:
            raise DaemonError(f"{tag['name']}: a {tag['table']} cannot be written")
        words = [bool(value)] if tag["type"] == "bool" else to_registers(tag, value)
        self._call("write", tag["name"], getattr(self.client, name), tag["address"], words,
                   unit=tag["unit"])

    # --- the simulator unit ---------------------------------------------------------------

    def _sim_wire(self, field, channel=None):
        if self.map.sim_unit is None:
            raise DaemonError("the config turns the simulator unit off (simulator.unit: 0)")
        if field not in self.map.sim:
            raise DaemonError(f"the simulator unit's map has no '{field}' register")
        first, stride = self.map.sim[field]
        if channel is None:
            return first
        if not 0 <= channel < self.map.channels:
            raise ValueError(f"channel {channel}: the plant has channels 0-{self.map.channels - 1}")
        return first + stride * channel

    _sim = None

    @property
    def _sim_client(self):
        # A connection of its own: a communication fault that closes the PLC's connections
        # (disconnect_after) counts only requests to the PLC, so this one stays to switch it off.
        if self._sim is None:
            if self.client is None:
                return None
            self._sim = connect(self.port)
        return self._sim

    def _close_sim(self):
        if self._sim is not None:
            self._sim.close()
            self._sim = None

    def _sim_call(self, operation, what, name, *args):
        client = self._sim_client
        return self._call(operation, what, getattr(client, name) if client else None, *args,
                          unit=self.map.sim_unit)

    def _sim_read(self, field, channel=None, n=1):
        wire = self._sim_wire(field, channel)
        what = f"simulator {field}" + ("" if channel is None else f" of channel {channel}")
        return self._sim_call("read", what, "read_holding_registers", wire, n).registers

    def _sim_write(self, field, value, channel=None):
        wire = self._sim_wire(field, channel)
        what = f"simulator {field}" + ("" if channel is None else f" of channel {channel}")
        self._sim_call("write", what, "write_register", wire, value & 0xFFFF)

    def freeze(self):
        """Stops the scans (requests are still served); run() steps them."""
        self._sim_write("freeze", 1)

    def resume(self):
        """Lets the scans run in (scaled) real time again."""
        self._sim_write("freeze", 0)

    @property
    def frozen(self):
        return bool(self._sim_read("freeze")[0])

    @property
    def time_scale(self):
        return self._sim_read("time_scale")[0]

    @time_scale.setter
    def time_scale(self, value):
        self._sim_write("time_scale", int(value))

    @property
    def sim_time(self):
        """Simulated seconds since the program started (a reload restarts it)."""
        lo, hi = self._sim_read("time_low", n=2)
        return lo | hi << 16

    def run(self, seconds=None, scans=None):
        """Runs `scans` scans, or `seconds` of simulated time in scans of the config's scan_ms,
        back to back, and returns when they are done (frozen or not). Returns sim_time."""
        if (seconds is None) == (scans is None):
            raise TypeError("run() takes seconds= or scans=")
        if scans is None:
            scans = round(seconds * 1000 / self.scan_ms)
        while scans > 0:
            chunk = min(scans, MAX_STEP)
            self._sim_write("step", chunk)
            scans -= chunk
            self._wait_steps()
        return self.sim_time

    def _wait_steps(self):
        last, since = None, time.monotonic()
        while True:
            queued = self._sim_read("step")[0]
            if queued == 0:
                return
            if queued != last:
                last, since = queued, time.monotonic()
            elif time.monotonic() - since > 10:
                raise DaemonError(f"the simulator's step queue stays at {queued} scans\n{self.log}")
            time.sleep(0.001)

    def fault(self, channel, **faults):
        """Sets (True) or clears (False) faults of a plant channel: sensor_broken, heater_open,
        heater_shorted, reading_frozen; the others stay. Returns the channel's faults."""
        unknown = set(faults) - set(FAULT_BITS)
        if unknown:
            raise TypeError(f"unknown faults {sorted(unknown)}; known: {sorted(FAULT_BITS)}")
        bits = self._sim_read("faults", channel)[0]
        for name, on in faults.items():
            bits = bits | 1 << FAULT_BITS[name] if on else bits & ~(1 << FAULT_BITS[name])
        self._sim_write("faults", bits, channel)
        return self.faults(channel)

    def faults(self, channel):
        bits = self._sim_read("faults", channel)[0]
        return {name: bool(bits >> b & 1) for name, b in FAULT_BITS.items()}

    def clear_faults(self, channel):
        self._sim_write("faults", 0, channel)

    def plant(self, channel, **params):
        """Sets plant parameters of a channel in the config's units (ambient and k in °C, tau and
        dead_time in s, noise in °C, lead_resistance in ohm); returns them all as the daemon
        holds them (clamped)."""
        unknown = set(params) - set(PLANT_PARAMS)
        if unknown:
            raise TypeError(f"unknown plant parameters {sorted(unknown)}; known: "
                            f"{sorted(PLANT_PARAMS)}")
        for name, value in params.items():
            field, scale, _ = PLANT_PARAMS[name]
            self._sim_write(field, round(value * scale), channel)
        out = {}
        for name, (field, scale, is_signed) in PLANT_PARAMS.items():
            v = self._sim_read(field, channel)[0]
            out[name] = (_to_signed(v, 16) if is_signed else v) / scale
        return out

    # --- communication faults (docs/communication-faults.md) ------------------------------

    def comm_fault(self, **fields):
        """Switches the PLC's communication faults to `fields` (the config's `faults:` names:
        delay_ms=300 or (100, 300), drop_every, drop_probability, seed, exception, offline,
        refuse_connections, disconnect_after, reset, garble="crc"|"short"|"gap", stop, and the
        scope unit, function, **{"from": "R100"}, count); a field left out is off. Returns a
        context manager that switches them all off on exit:

            with plc.comm_fault(delay_ms=300, **{"from": "R100", "count": 10}):
                ...
        """
        unknown = set(fields) - COMM_KEYS
        if unknown:
            raise TypeError(f"unknown communication faults {sorted(unknown)}; known: "
                            f"{sorted(COMM_KEYS)}")
        words = dict.fromkeys(COMM_FIELDS, 0)
        delay = fields.get("delay_ms", 0)
        lo, hi = (delay, delay) if isinstance(delay, (int, float)) else tuple(delay)
        words["delay_min_ms"], words["delay_max_ms"] = int(lo), int(hi)
        p = fields.get("drop_probability", 0)
        if not 0 <= p <= 1:
            raise ValueError(f"drop_probability {p}: expected 0 to 1")
        words["drop_probability"] = round(p * 10000)
        for k in ("drop_every", "seed", "exception", "unit", "function"):
            words[k] = int(fields.get(k, 0 if k != "seed" else 1))
        for k in ("offline", "refuse_connections", "stop"):
            words[k] = 1 if fields.get(k) else 0
        if fields.get("disconnect_after") is not None:
            words["disconnect"] = 2 if fields.get("reset") else 1
            words["disconnect_after"] = int(fields["disconnect_after"])
        elif fields.get("reset"):
            raise ValueError("reset: says how disconnect_after closes; give disconnect_after")
        garble = fields.get("garble") or "none"
        if garble not in GARBLES:
            raise ValueError(f"garble {garble!r}: expected one of {GARBLES}")
        words["garble"] = GARBLES.index(garble)
        name = str(fields.get("from") or "").upper().encode("ascii")
        if len(name) > 8:
            raise ValueError(f"from {fields['from']!r}: at most 8 characters")
        name = name.ljust(8, b"\0")
        for i in range(4):
            words[f"from_{i + 1}"] = name[2 * i] << 8 | name[2 * i + 1]
        if "count" in fields and not fields.get("from"):
            raise ValueError("count: counts devices from `from`; give from")
        words["count"] = int(fields.get("count", 1 if fields.get("from") else 0))
        for k in ("delay_min_ms", "delay_max_ms", "drop_every", "seed", "exception", "unit",
                  "function", "disconnect_after", "count"):
            if not 0 <= words[k] <= 0xFFFF:
                raise ValueError(f"{k} {words[k]}: expected 0 to 65535")
        first = self._sim_wire("comm.delay_min_ms")
        self._sim_call("write", "communication faults", "write_registers", first,
                       [words[k] for k in COMM_FIELDS])
        if self._sim_read("comm.status")[0] & 2:
            raise DeviceError("communication faults", f"refused {fields} (see the daemon's "
                              "log and docs/communication-faults.md)")
        return _CommFaults(self)

    def clear_comm_faults(self):
        """Switches every communication fault off."""
        self._sim_write("comm.clear", 1)

    @property
    def comm_faults_on(self):
        """True while a communication fault is on."""
        return bool(self._sim_read("comm.status")[0] & 1)

    def true_temperature(self, channel):
        """The process temperature of a plant channel, °C (what the sensor would read)."""
        return _to_signed(self._sim_read("true_temperature", channel)[0], 16) / 10

    def heater_power(self, channel):
        """The power the plant received on a channel, %, mean of the last 8 s."""
        return self._sim_read("heater_power", channel)[0] / 10


class _CommFaults:
    """What comm_fault() returns: with it, the faults are switched off on leaving the block."""

    def __init__(self, plc):
        self._plc = plc

    def __enter__(self):
        return self._plc

    def __exit__(self, *exc):
        self._plc.clear_comm_faults()
        return False


class Plc(Process, PlcApi):
    """A running plcemud holding one PLC, on 127.0.0.1:`port`, with its config, state file and
    log in `workdir`."""

    def __init__(self, binary, workdir, config, name="plc"):
        super().__init__(binary, workdir, name)
        self.client = None
        self._tags = None
        self.port = free_port()
        self.http_port = free_port(taken={self.port})
        self._set_config(config)
        self.map = WireMap(self.binary, self.config_path)
        self._start()

    def _set_config(self, config):
        text = config_text(config)
        self.config_path.write_text(text)
        self.scan_ms, self.station = _settings(config if isinstance(config, Mapping) else text)

    def _args(self):
        # Every PLC under test has its console, on a port of its own (docs/console.md).
        return ["--port", str(self.port), "--http-port", str(self.http_port)]

    def _ports(self):
        fatek = fatek_listener(self._own_config())
        return ([self.port, self.http_port] +
                ([fatek[2]] if fatek and fatek[0] == "tcp" else []))

    @property
    def console_url(self):
        """The base URL of the PLC's console and REST API: "http://127.0.0.1:PORT/" (its pages
        at plcs/0/devices..., its API at api/v1/...)."""
        return f"http://127.0.0.1:{self.http_port}/"

    def _own_config(self):
        return fatek_config(self.config_path)

    def _connect(self):
        self.client = connect(self.port)

    def _disconnect(self):
        self._close_fatek()
        self._close_sim()
        if self.client is not None:
            self.client.close()
            self.client = None

    def _new_ports(self):
        self.port = free_port()
        self.http_port = free_port(taken={self.port})

    def _snapshot(self):
        return self.scan_ms, self.station

    def _restore(self, snapshot):
        self.scan_ms, self.station = snapshot

    def _reloaded(self):
        self.map = WireMap(self.binary, self.config_path)
        self._tags = None

    def __repr__(self):
        return f"<Plc {self.config_path} on 127.0.0.1:{self.port}, station {self.station}>"

    @property
    def tags(self):
        """The config's tag export (`--export-tags json`): a list of dicts, one per device the
        configuration gives meaning to, and the simulator unit's registers."""
        if self._tags is None:
            self._tags = read_tags(self.binary, self.config_path)
        return self._tags
