"""`plcemud -c FILE --export-tags csv|json` (docs/configuration.md, "Tag export") walked whole
against the live daemon: every exported address reads back with the function its table implies
and gives what the device holds by its name; read-write tags take a distinct value written by
name and show it at the exported address, read-only ones refuse a write there; csv and json
agree; bad usage exits with 2."""

import csv
import io
import json
import re

import pytest
import yaml

from conftest import REPO, run_plcemud
from plcemu_testing import ModbusError

KEYS = ["name", "device", "unit", "table", "address", "address_1based", "type", "access",
        "description"]
TABLES = {"coil", "discrete_input", "holding_register", "input_register"}
# Profiles fbs and fb add how FATEK's own protocol names each device, after `device`.
FATEK_KEYS = [*KEYS[:2], "fatek", *KEYS[2:]]
FATEK_NAME = re.compile(r"(X|Y|M|S|T|C|WX|WY|WM|WS|WT|WC)\d{4}|(R|D)\d{5}|(RT|RC|DRC)\d{4}")

# An FBs temperature setup other than config/default.yaml's: the table in D, readings and
# working registers in the ROR area, three modules (6 + 6 + 16 channels), two TPCTLs.
FBS_TEMPERATURE = {
    "profile": "fbs",
    "model": "FBs-44MC",
    "temperature": {"table": "D2000", "modules": ["TC6:K", "RTD6:PT100_DIN", "TC16:J"]},
    "init": {"D2000": [0xA556, 3, 15000, 15100, 0x0001, 0x0002, 0x0103],
             "R100": [1200] * 4},
    "program": [
        {"TPCTL": {"en": "M0", "hc": 1, "md": 0, "sn": 0, "zn": 4, "yn": "Y60", "sv": "R100",
                   "os": "R110", "pr": "R120", "ir": "R130", "dr": "R140", "or": "R200",
                   "wr": "R300", "err": "M100", "alm": "M101"}},
        {"TPCTL": {"en": "M1", "hc": 1, "md": 0, "sn": 12, "zn": 2, "yn": "Y70", "sv": "D100",
                   "os": "D110", "pr": "D120", "ir": "D130", "dr": "D140", "or": "D200",
                   "wr": "D300"}},
    ],
}

# A FATEK FB with one TP4: the raw readings and the FB temperature registers besides its operands.
FB_TP4 = {
    "profile": "fb",
    "program": [{"TP4": {"en": "M3", "tp": 0, "pl": 0, "sm": 0, "ym": "Y16", "ar": "R3842",
                         "tr": "R0", "wr": "R220", "err": "M110", "alm": "M111"}}],
}

CONFIGS = {
    "default": REPO / "config" / "default.yaml",
    "vb": REPO / "config" / "vb.yaml",
    "vb-pid": REPO / "config" / "vb-pid.yaml",
    "vb-mbus": REPO / "config" / "vb-mbus.yaml",
    "fbs-temperature": FBS_TEMPERATURE,
    "fb-tp4": FB_TP4,
    "fb-example": REPO / "config" / "fb-example.yaml",
}

# Rows each config must have (a sample of what its program, profile and presets describe).
EXPECTED = {
    "default": {"R100": "TPCTL sv", "R109": "TPCTL sv", "R308": "TPCTL WR+8", "Y39": "TPCTL yn",
                "R0": "temperature reading, channel 0", "R11": "channel 11",
                "D11": "temperature working register WR+11", "R5000": "SR+0",
                "M815": "MOV s", "M1926": "RUN", "R4136": "scan time",
                "sim.ch31.heater_power": "channel 31"},
    "vb": {"C1": "CNT c", "CN1": "CNT c value", "CN2": "CNT c value", "D100": "MOV d",
           "D7000": "HOUR d1", "M500": "HOUR d2", "D10": "FROM d", "D0": "preset by init",
           "Y10": "preset by init", "M9013": "1 s clock", "D9067": "operation error code"},
    "vb-pid": {"D200": "PID S3+0 sampling time", "D224": "PID S3+24 alarm bits",
               "D102": "drives plant channel 0", "TN0": "TMR t value", "TN200": "TMR t value",
               "M10": "FROM d", "M25": "FROM d", "Y1": "CMPOUT out"},
    "vb-mbus": {"D1000": "number of transfer sets", "D1021": "MBUS set 3",
                "D2000": "data read from station 5", "D2014": "data written to station 2",
                "D2015": "data written to station 3", "D103": "last exception code",
                "CN0": "CNT c value", "M9199": "MBUS pass complete"},
    "fbs-temperature": {"D2000": "SR+0", "D2006": "SR+6: module 3", "R5027": "channel 27",
                        "R5100": "WR+0", "R5115": "WR+15: module 3", "D100": "TPCTL sv",
                        "D308": "TPCTL WR+8", "Y71": "heater output of plant channel 13"},
}
# ...and rows it must not have (one past a block's end).
EXPECTED["fb-tp4"] = {"R3968": "raw reading of temperature point", "R3999": "[31]",
                      "R4016": "K thermocouple factor", "R4021": "compensation table",
                      "R227": "TP4 wr", "R3842": "TP4 ar", "Y23": "TP4 ym", "M1926": "RUN"}
EXPECTED["fb-example"] = {"R102": "TSTC sv", "R142": "TSTC pr", "Y51": "TSTC yh",
                          "R6": "TP4 tr", "R4014": "ms between points"}
ABSENT = {"fb-tp4": ["R228", "R4", "Y24"], "default": ["R12", "D12", "R309"], "fbs-temperature": ["R5028", "R5116", "D102"],
          "vb-mbus": ["D1022", "D2016"], "vb-pid": ["D225"]}

# The simulator unit's fields as the plugin's plant() takes them: (keyword, scale).
PLANT = {"ambient": ("ambient", 10), "k": ("k", 10), "tau": ("tau", 1),
         "dead_time": ("dead_time", 1), "noise": ("noise", 100)}


def export(path, fmt):
    r = run_plcemud("-c", path, "--export-tags", fmt)
    assert r.returncode == 0, r.stderr
    return r.stdout


def exported(config_path, keys):
    """The csv export of a config, its header `keys`, as dicts with numbers for numbers: the
    same as its json export."""
    text = export(config_path, "csv")
    assert text.splitlines()[0] == ",".join(keys)
    rows = list(csv.DictReader(io.StringIO(text)))
    for r in rows:
        for k in ("unit", "address", "address_1based"):
            r[k] = int(r[k])
    assert rows == json.loads(export(config_path, "json"))
    assert len({r["name"] for r in rows}) == len(rows)
    return rows


def by_name(plc, tag):
    """The device's value read by its name through the plugin's WireMap (--print-map)."""
    if tag["type"] == "bool":
        return plc.read_bits(tag["device"])[0]
    return plc.read(tag["device"], signed=tag["type"] in ("int16", "int32"))[0]


def sim_field(tag):
    """(field, channel) of a simulator unit tag: sim.time_scale, sim.ch3.ambient,
    sim.comm.offline (field "comm.offline", as the kit names it)."""
    name = tag["name"].removeprefix(f"{tag['plc']}.") if "plc" in tag else tag["name"]
    m = re.fullmatch(r"sim\.(?:ch(\d+)\.)?((?:comm\.)?\w+)", name)
    assert m, tag
    return m.group(2), None if m.group(1) is None else int(m.group(1))


def distinct(tag, i):
    """A value no other tag gets, of the tag's type (never A55Ah, which switches FBs maps)."""
    if tag["type"] == "int32":
        return -(100000 + 7 * i)
    if tag["type"] == "int16":
        return -(100 + i) if i % 2 else 100 + i
    return 100 + i


@pytest.mark.parametrize("name", list(CONFIGS))
def test_csv_and_json_agree(plcemud, name):
    plc = plcemud(CONFIGS[name])
    fatek = not name.startswith("vb")
    rows = exported(plc.config_path, FATEK_KEYS if fatek else KEYS)
    assert rows == plc.tags
    assert len({(r["unit"], r["table"], r["address"]) for r in rows}) == len(rows)
    for r in rows:
        assert r["table"] in TABLES and r["type"] in ("bool", "int16", "uint16", "int32"), r
        assert r["access"] in ("read", "read-write") and r["description"], r
        assert r["address_1based"] == r["address"] + 1
        assert (r["type"] == "bool") == (r["table"] in ("coil", "discrete_input")), r
    names = {r["name"]: r["description"] for r in rows}
    for device, text in EXPECTED[name].items():
        assert device in names, device
        assert text in names[device], (device, names[device])
    for device in ABSENT.get(name, []):
        assert device not in names
    # The simulator unit: 5 registers, 21 of communication faults and 8 per channel of 32.
    assert sum(r["unit"] == 247 for r in rows) == 5 + 21 + 8 * 32
    # Every device of a FATEK family has its FATEK name (a 32-bit counter's at its low word);
    # the simulator unit's registers have none.
    for r in rows if fatek else ():
        if r["unit"] == 247:
            assert r["fatek"] == "", r
        else:
            assert FATEK_NAME.fullmatch(r["fatek"]), r


def walk(plc, tags):
    """Walks a PLC's rows of the export against it (a Plc, or one PLC of a plcs: config): every
    address reads what the device holds by name; a distinct value written by name reads back at
    the exported address, and one written at the address reads back by name; read-only
    addresses refuse a write with exception 02. The PLC is frozen: no scan changes a value."""
    plc_rows = [t for t in tags if t["device"]]
    assert len(plc_rows) > 30
    # Every address reads with its table's function and shows what the device holds.
    for t in plc_rows:
        assert plc.read_tag(t) == by_name(plc, t), t
    for t in tags:
        if not t["device"]:
            field, channel = sim_field(t)
            assert plc.read_tag(t) & 0xFFFF == plc._sim_read(field, channel)[0], t
    # A distinct value written by the device's name reads back at the exported address; an
    # address exported read-only refuses the write with exception 02.
    written = {}
    for i, t in enumerate(plc_rows):
        if t["access"] == "read":
            if t["table"] in ("discrete_input", "input_register"):
                continue  # no function writes these tables
            with pytest.raises(ModbusError) as e:
                plc.write_tag(t, plc.read_tag(t))
            assert e.value.code == 2, t
            continue
        if t["type"] == "bool":
            v = 1 - plc.read_tag(t)
            plc.write_bits(t["device"], [v])
        else:
            v = distinct(t, i)
            plc.write(t["device"], v)
        written[t["name"]] = v
    assert written, "no read-write tag"
    for t in plc_rows:
        if t["name"] in written:
            assert plc.read_tag(t) == written[t["name"]], t
    # And the other way: written at the exported address, read by name.
    for i, t in enumerate(plc_rows):
        if t["access"] == "read-write" and t["type"] != "bool":
            plc.write_tag(t, distinct(t, i + 1000))
            assert plc.read(t["device"], signed=t["type"] != "uint16")[0] == distinct(t, i + 1000)


@pytest.mark.parametrize("name", list(CONFIGS))
def test_every_exported_address_reads_and_writes_as_exported(plcemud, name):
    plc = plcemud(CONFIGS[name])
    plc.freeze()  # no scan changes a value between the reads below
    walk(plc, plc.tags)


def plant_of_three():
    """kiln (config/default.yaml) and press (config/vb.yaml) behind one TCP listener as stations
    1 and 2 with simulator units 201 and 202, and an unnamed FB (config/fb-example.yaml) on a
    port of its own (docs/configuration.md, "Sharing a listener")."""
    def entry(path, **keys):
        cfg = yaml.safe_load(path.read_text())
        cfg.update(keys)
        return cfg
    return {"plcs": [
        entry(CONFIGS["default"], name="kiln", station=1, simulator={"unit": 201}),
        entry(CONFIGS["vb"], name="press", station=2, simulator={"unit": 202}),
        entry(CONFIGS["fb-example"], modbus={"tcp": {"bind": "127.0.0.1", "port": 5021}}),
    ]}


def test_a_plcs_config_exports_every_plc_each_row_reaching_its_own(plcemud):
    plcs = plcemud(plant_of_three())
    kiln, press, fb = plcs
    assert kiln.port == press.port != fb.port
    rows = exported(plcs.config_path, ["plc", "name", "device", "fatek", "endpoint", *KEYS[2:]])
    assert rows == plcs.tags
    assert len({(r["endpoint"], r["unit"], r["table"], r["address"]) for r in rows}) == len(rows)
    assert [r["plc"] for r in rows] == sorted((r["plc"] for r in rows),
                                              key=["kiln", "press", "plcs[2]"].index)
    for p, sim in ((kiln, 201), (press, 202), (fb, 247)):
        assert p.tags, p
        for t in p.tags:
            assert t["endpoint"] == f"tcp:127.0.0.1:{p.port}", t
            assert t["name"] == f"{p.name}.{t['device'] or t['name'].split('.', 1)[1]}", t
            assert t["unit"] == (p.station if t["device"] else sim), t
    assert plcs["kiln"].tag("R100")["name"] == "kiln.R100"
    assert plcs["plcs[2]"].tag("sim.ch0.ambient")["unit"] == 247

    # Walk each PLC through its rows: each row reaches its PLC, and no other PLC changes.
    for p in plcs:
        p.freeze()
    for p in plcs:
        others = [o for o in plcs if o is not p]
        before = [[o.read_tag(t) for t in o.tags] for o in others]
        walk(p, p.tags)
        assert [[o.read_tag(t) for t in o.tags] for o in others] == before, p.name


def test_simulator_unit_tags_write_and_read_as_exported(plcemud):
    plc = plcemud(CONFIGS["default"])
    plc.freeze()
    tags = {t["name"]: t for t in plc.tags if t["unit"] == 247}
    assert plc.read_tag(tags["sim.freeze"]) == 1
    plc.time_scale = 7
    assert plc.read_tag(tags["sim.time_scale"]) == 7
    plc.fault(3, heater_open=True)
    assert plc.read_tag(tags["sim.ch3.faults"]) == 2
    for i, (keyword, (field, scale)) in enumerate(PLANT.items()):
        t = tags[f"sim.ch5.{field}"]
        assert t["access"] == "read-write"
        value = -(20 + i) if t["type"] == "int16" else 20 + i
        plc.plant(5, **{keyword: value / scale})
        assert plc.read_tag(t) == value, t
    for field in ("true_temperature", "heater_power", "time_low", "time_high"):
        t = tags[f"sim.ch0.{field}" if field in ("true_temperature", "heater_power")
                 else f"sim.{field}"]
        assert t["access"] == "read"
        with pytest.raises(ModbusError) as e:
            plc.write_tag(t, 1)
        assert e.value.code == 2
    # 25.0 °C at the start: the signed true temperature in 0.1 °C.
    assert plc.read_tag(tags["sim.ch0.true_temperature"]) == 250


def test_presets_show_at_their_exported_addresses(plcemud):
    plc = plcemud(CONFIGS["fbs-temperature"])
    plc.freeze()
    assert plc.tag("D2000")["type"] == "uint16"
    assert plc.read_tag("D2000") == 0xA556
    assert plc.read_tag("D2002") == 15000
    assert [plc.read_tag(f"R10{i}") for i in range(4)] == [1200] * 4
    assert plc.tag("R100")["address"] == 100 and plc.tag("D2000")["address"] == 6000 + 2000


def test_thirty_two_bit_counter_is_one_int32_low_word_first(plcemud):
    plc = plcemud({"profile": "vb", "program": [{"CNT": {"en": "M9013", "c": "C235", "k": 5}}]})
    plc.freeze()
    t = plc.tag("CN235")
    assert t["type"] == "int32" and t["table"] == "holding_register"
    assert "low word at address, high word at address+1" in t["description"]
    plc.write("CN235", 0x12345678)
    r = plc.client.read_holding_registers(t["address"], 2, slave=t["unit"]).registers
    assert r == [0x5678, 0x1234]
    assert plc.read_tag(t) == 0x12345678
    plc.write_tag(t, -2)
    assert plc.read("CN235", signed=True) == [-2]


def test_devices_off_the_map_are_said_on_stderr_not_exported(tmp_path):
    p = tmp_path / "c.yaml"
    p.write_text("profile: fbs\nmodbus:\n  map:\n    - {table: holding, start: 0, device: R0, "
                 "count: 10}\nprogram:\n  - MOV: {en: M0, s: R1, d: R100}\n")
    r = run_plcemud("-c", p, "--export-tags", "csv")
    assert r.returncode == 0, r.stderr
    names = [row["name"] for row in csv.DictReader(io.StringIO(r.stdout))]
    assert "R1" in names and "R100" not in names and "M0" not in names
    assert "no Modbus address for R100: MOV d, program entry 1" in r.stderr
    assert "no Modbus address for M0: MOV en" in r.stderr


@pytest.mark.parametrize("args,needle", [
    (["--export-tags", "xml", "-c", "CONFIG"],
     "--export-tags takes csv, json, kepware, ignition or weintek"),
    (["-c", "CONFIG", "--export-tags"],
     "--export-tags takes csv, json, kepware, ignition or weintek"),
    (["--export-tags", "csv"], "--export-tags needs a configuration file (-c FILE)"),
])
def test_bad_usage_exits_2(args, needle):
    args = [str(CONFIGS["default"]) if a == "CONFIG" else a for a in args]
    r = run_plcemud(*args)
    assert r.returncode == 2
    assert needle in r.stderr
    assert r.stdout == ""


def test_config_error_names_file_line_and_column(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("profile: fbs\nprogram:\n  - MOV: {en: M0, s: R1, d: Q7}\n")
    r = run_plcemud("-c", p, "--export-tags", "json")
    assert r.returncode == 2
    assert f"{p}:3:" in r.stderr and "MOV.d" in r.stderr
    assert r.stdout == ""
