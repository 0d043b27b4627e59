"""`plcemud -c FILE --export-tags kepware|ignition|weintek` (docs/configuration.md, "Tag export"):
each file checked against the import format its tool publishes (the header, and the row of R100
of config/default.yaml, field by field), every PLC row against the csv export, and the address
each tool would use read back through Modbus from the running daemon. Then a `plcs:` config:
each entry's tags under its own device."""

import csv
import io
import json
import re
import subprocess

import yaml

from conftest import PLCEMUD, REPO

DEFAULT = REPO / "config" / "default.yaml"

# Kepware KEPServerEX, "CSV Import/Export": the server's tag CSV columns, in order.
KEPWARE_HEADER = ["Tag Name", "Address", "Data Type", "Respect Data Type", "Client Access",
                  "Scan Rate", "Scaling", "Raw Low", "Raw High", "Scaled Low", "Scaled High",
                  "Scaled Data Type", "Clamp Low", "Clamp High", "Eng Units", "Description",
                  "Negate Value"]
# The digit of a table in a 6-digit Modbus number (Kepware, Weintek's "4x").
DIGIT = {"coil": "0", "discrete_input": "1", "input_register": "3", "holding_register": "4"}
TABLE_OF_DIGIT = {v: k for k, v in DIGIT.items()}
KEPWARE_TYPE = {"bool": "Boolean", "int16": "Short", "uint16": "Word", "int32": "Long"}
# Ignition's Modbus designators and data types.
IGNITION_TABLE = {"C": "coil", "DI": "discrete_input", "HR": "holding_register",
                  "IR": "input_register"}
IGNITION_TYPE = {"bool": "Boolean", "int16": "Int2", "uint16": "Int4", "int32": "Int4"}
WEINTEK_TYPE = {"bool": "", "int16": "16-bit Signed", "uint16": "16-bit Unsigned",
                "int32": "32-bit Signed"}


def export(path, fmt):
    """The export as written: lines end as the format says (no newline translation)."""
    r = subprocess.run([PLCEMUD, "-c", str(path), "--export-tags", fmt], capture_output=True,
                       timeout=20)
    assert r.returncode == 0, r.stderr.decode()
    return r.stdout.decode()


def plc_rows(path):
    """The csv export's rows of the PLCs' own devices (not the simulator unit's)."""
    rows = list(csv.DictReader(io.StringIO(export(path, "csv"))))
    return [r for r in rows if r["device"]]


def kepware(path):
    text = export(path, "kepware")
    assert text.endswith("\r\n") and "\n" not in text.replace("\r\n", "")
    lines = list(csv.reader(io.StringIO(text, newline="")))
    return lines[0], [dict(zip(lines[0], line)) for line in lines[1:]]


def ignition(path):
    return json.loads(export(path, "ignition"))


def weintek(path):
    text = export(path, "weintek")
    assert text.endswith("\r\n") and "\n" not in text.replace("\r\n", "")
    return list(csv.reader(io.StringIO(text, newline="")))


def parse_ignition_path(item):
    """ns=1;s=[plcemu]1.HR101 -> (device, unit, table, designator, 0-based address)."""
    m = re.fullmatch(r"ns=1;s=\[([\w-]+)\](\d+)\.([A-Z]+)(\d+)", item)
    assert m, item
    designator = m.group(3)
    base = next(k for k in ("HR", "IR", "DI", "C") if designator.startswith(k))
    return m.group(1), int(m.group(2)), IGNITION_TABLE[base], designator, int(m.group(4)) - 1


def read_at(plc, unit, table, address, type_):
    """A value read at a tool's address, as the csv export's type reads it."""
    fn = {"coil": plc.client.read_coils, "discrete_input": plc.client.read_discrete_inputs,
          "holding_register": plc.client.read_holding_registers,
          "input_register": plc.client.read_input_registers}[table]
    r = fn(address, 2 if type_ == "int32" else 1, slave=unit)
    assert not r.isError(), r
    if type_ == "bool":
        return int(r.bits[0])
    v = r.registers[0] | (r.registers[1] << 16 if type_ == "int32" else 0)
    bits = 32 if type_ == "int32" else 16
    if type_ != "uint16" and v >= 1 << (bits - 1):
        v -= 1 << bits
    return v


def test_kepware_csv_has_the_servers_columns_and_modbus_ethernet_addresses(plcemud):
    header, rows = kepware(DEFAULT)
    assert header == KEPWARE_HEADER
    by_name = {r["Tag Name"]: r for r in rows}
    r100 = by_name["R100"]
    assert (r100["Address"], r100["Data Type"], r100["Respect Data Type"],
            r100["Client Access"], r100["Scan Rate"]) == ("400101", "Short", "1", "R/W", "100")
    assert "TPCTL sv" in r100["Description"]
    assert [r100[k] for k in KEPWARE_HEADER[6:15]] == [""] * 9 and r100["Negate Value"] == ""
    assert (by_name["Y30"]["Address"], by_name["Y30"]["Data Type"]) == ("000031", "Boolean")
    assert by_name["M1926"]["Client Access"] == "RO"
    assert by_name["R300"]["Data Type"] == "Word"
    assert all(len(r["Description"]) <= 255 for r in rows)
    # Every PLC row of the csv export, none of the simulator unit's, each at its Modbus number.
    expected = plc_rows(DEFAULT)
    assert [r["Tag Name"] for r in rows] == [e["name"] for e in expected]
    for r, e in zip(rows, expected):
        assert r["Address"] == DIGIT[e["table"]] + "%05d" % int(e["address_1based"]), e
        assert r["Data Type"] == KEPWARE_TYPE[e["type"]]
        assert r["Client Access"] == ("R/W" if e["access"] == "read-write" else "RO")

    # The address Kepware reads (400101: holding register 101, 1-based) is R100 on the wire.
    plc = plcemud(DEFAULT)
    plc.freeze()
    plc.write("R100", 1234)
    digit, number = r100["Address"][0], int(r100["Address"][1:])
    assert read_at(plc, 1, TABLE_OF_DIGIT[digit], number - 1, "int16") == 1234


def test_ignition_json_is_opc_tags_on_modbus_addresses(plcemud):
    doc = ignition(DEFAULT)
    assert list(doc) == ["tags"]
    tags = {t["name"]: t for t in doc["tags"]}
    r100 = tags["R100"]
    assert r100 == {"name": "R100", "tagType": "AtomicTag", "valueSource": "opc",
                    "opcServer": "Ignition OPC UA Server",
                    "opcItemPath": "ns=1;s=[plcemu]1.HR101", "dataType": "Int2",
                    "documentation": r100["documentation"]}
    assert "TPCTL sv" in r100["documentation"]
    assert tags["R300"]["opcItemPath"] == "ns=1;s=[plcemu]1.HRUS301"
    assert tags["R300"]["dataType"] == "Int4"
    assert tags["M1926"]["opcItemPath"] == "ns=1;s=[plcemu]1.C3927"
    assert tags["M1926"]["readOnly"] is True and tags["M1926"]["dataType"] == "Boolean"
    expected = plc_rows(DEFAULT)
    assert [t["name"] for t in doc["tags"]] == [e["device"] for e in expected]

    # Every item path, read through Modbus, gives what the device holds by its name.
    plc = plcemud(DEFAULT)
    plc.freeze()
    plc.write("R100", -321)
    for t, e in zip(doc["tags"], expected):
        device, unit, table, designator, address = parse_ignition_path(t["opcItemPath"])
        assert (device, unit, table, address) == ("plcemu", 1, e["table"], int(e["address"]))
        assert t["dataType"] == IGNITION_TYPE[e["type"]]
        assert designator.endswith("US") == (e["type"] == "uint16"), t
        assert t.get("readOnly", False) == (e["access"] == "read"), t
        value = read_at(plc, unit, table, address, e["type"])
        if e["type"] == "bool":
            assert value == plc.read_bits(e["device"])[0], t
        else:
            assert value == plc.read(e["device"], signed=e["type"] != "uint16")[0], t
    _, unit, table, _, address = parse_ignition_path(r100["opcItemPath"])
    assert read_at(plc, unit, table, address, "int16") == -321


def test_weintek_csv_is_an_address_tag_library(plcemud):
    lines = weintek(DEFAULT)
    # No header: every line is a tag of six fields (name, device, address type, address,
    # comment, data type).
    assert all(len(line) == 6 for line in lines)
    assert lines[0][0] != "Name" and lines[0][2] in ("0x", "1x", "3x", "4x")
    by_name = {line[0]: line for line in lines}
    name, device, kind, address, comment, data_type = by_name["R100"]
    assert (device, kind, address, data_type) == ("plcemu", "4x", "101", "16-bit Signed")
    assert "TPCTL sv" in comment
    assert by_name["Y30"][1:4] == ["plcemu", "0x", "31"] and by_name["Y30"][5] == ""
    assert by_name["R300"][5] == "16-bit Unsigned"
    expected = plc_rows(DEFAULT)
    assert [line[0] for line in lines] == [e["device"] for e in expected]
    for line, e in zip(lines, expected):
        assert line[2] == DIGIT[e["table"]] + "x" and line[3] == e["address_1based"], e
        assert line[5] == WEINTEK_TYPE[e["type"]]

    plc = plcemud(DEFAULT)
    plc.freeze()
    plc.write("R100", 777)
    assert read_at(plc, 1, TABLE_OF_DIGIT[kind[0]], int(address) - 1, "int16") == 777


def test_a_32_bit_counter_is_one_long_tag_in_each_format(tmp_path):
    p = tmp_path / "c.yaml"
    p.write_text("profile: vb\nprogram:\n  - CNT: {en: M9013, c: C235, k: 5}\n")
    e = next(r for r in plc_rows(p) if r["device"] == "CN235")
    _, rows = kepware(p)
    k = next(r for r in rows if r["Tag Name"] == "CN235")
    assert (k["Data Type"], k["Address"]) == ("Long", "4%05d" % int(e["address_1based"]))
    i = next(t for t in ignition(p)["tags"] if t["name"] == "CN235")
    assert i["opcItemPath"] == f"ns=1;s=[plcemu]1.HRI{e['address_1based']}"
    w = next(line for line in weintek(p) if line[0] == "CN235")
    assert w[5] == "32-bit Signed"


def test_a_plcs_config_puts_each_entry_under_its_own_device(tmp_path):
    def entry(path, **keys):
        cfg = yaml.safe_load(path.read_text())
        cfg.update(keys)
        return cfg
    p = tmp_path / "plcs.yaml"
    p.write_text(yaml.safe_dump({"plcs": [
        entry(DEFAULT, name="kiln", station=1, simulator={"unit": 201}),
        entry(REPO / "config" / "vb.yaml", name="press", station=2, simulator={"unit": 202}),
        entry(REPO / "config" / "fb-example.yaml",
              modbus={"tcp": {"bind": "127.0.0.1", "port": 5021}}),
    ]}))
    expected = plc_rows(p)
    assert {e["plc"] for e in expected} == {"kiln", "press", "plcs[2]"}

    # Kepware: each entry a tag group (kiln.R100) of the device that reaches it.
    _, rows = kepware(p)
    assert [r["Tag Name"] for r in rows] == [
        e["name"].replace("plcs[2].", "plcs_2_.") for e in expected]
    assert next(r for r in rows if r["Tag Name"] == "kiln.R100")["Address"] == "400101"
    d100 = next(e for e in expected if e["name"] == "press.D100")
    assert next(r for r in rows if r["Tag Name"] == "press.D100")["Address"] == (
        "4%05d" % int(d100["address_1based"]))

    # Ignition: a folder per entry, its item paths on the entry's device and station.
    folders = ignition(p)["tags"]
    assert [(f["name"], f["tagType"]) for f in folders] == [
        ("kiln", "Folder"), ("press", "Folder"), ("plcs_2_", "Folder")]
    for folder, station in zip(folders, (1, 2, 1)):
        for t in folder["tags"]:
            device, unit, *_ = parse_ignition_path(t["opcItemPath"])
            assert (device, unit) == (folder["name"], station), t
    assert sum(len(f["tags"]) for f in folders) == len(expected)

    # Weintek: the entry's device in the device column, names unique in the library.
    lines = weintek(p)
    assert [(line[0], line[1]) for line in lines] == [
        (e["name"].replace("plcs[2].", "plcs_2_.").replace(".", "_", 1),
         e["plc"].replace("plcs[2]", "plcs_2_")) for e in expected]
    assert len({line[0] for line in lines}) == len(lines)
