"""The VIGOR VB profile (docs/profile-vb.md) through Modbus TCP against the real daemon: the
acceptance checks of the map and of the special relays, every row of the default map (its first
and last address hold the right device, the addresses around it are exception 02), FC02/FC04,
read-only items, octal X/Y, the config errors of the profile, FC17/FC43, --print-map and the
`modbus.map` override."""

import csv
import io
import re
import time

import pytest

from conftest import REPO, _spawn, raw_request, run_plcemud

ILLEGAL_FUNCTION = 1
ILLEGAL_ADDRESS = 2

SIM = 247  # simulator.unit default (docs/simulator-and-plant.md, "Simulator-control unit")

VB = "profile: vb\nmodbus: {tcp: {bind: 127.0.0.1}}\n"


def exc(resp):
    """The exception code of a pymodbus response, 0 when it is not an exception."""
    assert resp is not None
    return getattr(resp, "exception_code", 0) if resp.isError() else 0


def regs(client, addr, count=1, unit=1):
    r = client.read_holding_registers(addr, count, slave=unit)
    assert not r.isError(), f"read {addr}x{count} unit {unit}: {r}"
    return r.registers


def coils(client, addr, count=1):
    r = client.read_coils(addr, count, slave=1)
    assert not r.isError(), f"read coils {addr}x{count}: {r}"
    return r.bits[:count]


def inputs(client, addr, count=1):
    r = client.read_discrete_inputs(addr, count, slave=1)
    assert not r.isError(), f"read discrete inputs {addr}x{count}: {r}"
    return r.bits[:count]


def input_regs(client, addr, count=1):
    r = client.read_input_registers(addr, count, slave=1)
    assert not r.isError(), f"read input registers {addr}x{count}: {r}"
    return r.registers


def write(client, addr, value, unit=1):
    r = client.write_register(addr, value, slave=unit)
    assert not r.isError(), f"write {addr}={value} unit {unit}: {r}"


def freeze(client):
    """Stops the scans (simulator unit, register 1)."""
    write(client, 1, 1, unit=SIM)


def step(client, scans):
    """Runs `scans` scans and waits until they ran (register 2 reads the scans still queued)."""
    while scans > 0:
        k = min(scans, 60000)
        write(client, 2, k, unit=SIM)
        scans -= k
    deadline = time.monotonic() + 60
    while regs(client, 2, unit=SIM) != [0]:
        assert time.monotonic() < deadline, "the queued scans did not run"
        time.sleep(0.01)


def running(client):
    """Waits until the second scan has begun (M9003 ON), so the first scan's specials are set;
    returns the client."""
    deadline = time.monotonic() + 10
    while not coils(client, 7683)[0]:
        assert time.monotonic() < deadline, "no second scan"
        time.sleep(0.01)
    return client


def check_config(tmp_path, text, name="vb.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p, run_plcemud("-c", p, "--check-config")


def expect_config_error(tmp_path, text, line, col, needle):
    p, r = check_config(tmp_path, text)
    assert r.returncode == 2, r.stdout + r.stderr
    assert f"{p}:{line}:{col}: " in r.stderr, r.stderr
    assert needle in r.stderr, r.stderr
    return r.stderr


# --- acceptance: map spot checks and specials ----------------------------------------------


def test_map_spot_checks(start_plcemud):
    """docs/profile-vb.md, "Modbus map": D0 at 0, D9129 at 8129, M9000 at 1E00h, Y0 at 3300h
    as coil and discrete input, X10 at 3408h as discrete input only, D9010 read-only and
    scan_ms x 10, C200 at 9700 low word first."""
    d = start_plcemud(
        VB
        + """
init:
  CN200: [0xFFFF, 0x0000]   # 65535: the next count carries into the high word
  X10: 1
program:
  - CNT: {en: M0, c: C200, k: K100000}
"""
    )
    c = running(d.client())
    write(c, 0, 1234)
    assert regs(c, 0) == [1234]  # D0
    assert regs(c, 8129) == [0]  # D9129, 0 at start
    assert coils(c, 7680) == [True]  # M9000
    assert exc(c.write_coil(13056, True, slave=1)) == 0  # Y0
    assert coils(c, 13056) == [True]
    assert inputs(c, 13056) == [True]
    assert inputs(c, 13320) == [True]  # X10 = 3408h
    assert exc(c.read_coils(13312, 1, slave=1)) == ILLEGAL_ADDRESS  # no X among the coils
    assert exc(c.write_register(8010, 1, slave=1)) == ILLEGAL_ADDRESS  # D9010
    assert regs(c, 8010) == [100]  # scan_ms 10 in 0.1 ms
    # C200, 32-bit: low word at 9700, high word at 9701.
    freeze(c)
    assert regs(c, 9700, 2) == [0xFFFF, 0x0000]
    assert exc(c.write_coil(0, True, slave=1)) == 0  # M0: one count
    step(c, 1)
    assert regs(c, 9700, 2) == [0x0000, 0x0001]
    # M9200 ON: C200 counts down.
    assert exc(c.write_coil(7680 + 200, True, slave=1)) == 0
    assert exc(c.write_coil(0, False, slave=1)) == 0
    step(c, 1)
    assert exc(c.write_coil(0, True, slave=1)) == 0
    step(c, 1)
    assert regs(c, 9700, 2) == [0xFFFF, 0x0000]


def test_specials_clock_counter_and_initial_pulse(start_plcemud):
    """docs/profile-vb.md, "Special relays and registers": C1 counting M9013 (1 s clock) reads
    60 +/- 1 after 60 s; C2 counting M9002 (initial pulse) reads 1 whatever the scans; M9000 is
    always ON and M9001 always OFF."""
    d = start_plcemud(
        VB
        + """
time_scale: 0.001   # nearly still until frozen: the steps below are the whole run
program:
  - CNT: {en: M9013, c: C1, k: K32767}
  - CNT: {en: M9002, c: C2, k: K10}
"""
    )
    c = d.client()
    freeze(c)
    for _ in range(6):
        step(c, 1000)  # 10 s
        assert coils(c, 7680, 2) == [True, False]  # M9000, M9001
        assert inputs(c, 7680, 2) == [True, False]
        assert regs(c, 9502) == [1]  # CN2
    assert 59 <= regs(c, 9501)[0] <= 61  # CN1 after 60 s
    assert coils(c, 12801, 2) == [False, False]  # C1 < K32767, C2 < K10
    assert regs(c, 8010, 3) == [100, 100, 100]  # D9010-D9012


def test_first_scan_relays_and_clock_phases(start_plcemud):
    """M9002 ON in the first scan only, M9003 its opposite; M9013 (1 s) and M9014 (1 min) ON in
    the first half of their period; M9011 (half period shorter than the scan) toggles every
    scan. With time_scale 0.001 at most the first scan (at 0 s) runs before the freeze, so the
    last scan's time is known to 10 ms."""
    d = start_plcemud(
        VB
        + """
time_scale: 0.001
program:
  - MOV: {en: M9002, s: K1, d: D10}      # D10 = 1 once M9002 was ON in a scan
  - MOV: {en: M9003, s: K2, d: D11}
"""
    )
    c = d.client()
    freeze(c)
    step(c, 2)  # the last scan ran at 0.01 or 0.02 s
    assert regs(c, 10, 2) == [1, 2]
    assert coils(c, 7682, 2) == [False, True]
    write(c, 10, 0)
    step(c, 8)  # 0.09-0.10 s
    assert regs(c, 10) == [0]  # M9002 never again
    before = coils(c, 7691)[0]
    step(c, 1)
    assert coils(c, 7691) == [not before]  # M9011 toggles every 10 ms scan
    step(c, 1)
    assert coils(c, 7691) == [before]
    # 0.11-0.12 s: M9012 (0.1 s) ON, M9013 and M9014 ON.
    assert coils(c, 7692, 3) == [True, True, True]
    step(c, 4)  # 0.15-0.16 s: M9012 in its OFF half
    assert coils(c, 7692) == [False]
    step(c, 60)  # 0.75-0.76 s: M9013 OFF, M9014 ON
    assert coils(c, 7693, 2) == [False, True]
    step(c, 3000)  # 30.75-30.76 s: M9014 OFF
    assert coils(c, 7694) == [False]
    step(c, 2930)  # 60.05-60.06 s: both ON again
    assert coils(c, 7693, 2) == [True, True]


def test_calendar_registers(start_plcemud):
    """D9013-D9019: second, minute, hour, day, month, year (two digits), weekday of the host's
    local time."""
    d = start_plcemud(VB)
    c = running(d.client())
    s, mi, h, day, mon, yr, wd = regs(c, 8013, 7)
    now = time.localtime()
    assert 0 <= s <= 59 and 0 <= mi <= 59 and 0 <= h <= 23
    assert 1 <= day <= 31 and 1 <= mon <= 12 and 0 <= wd <= 6
    assert yr == now.tm_year % 100 or (mon, day) == (12, 31)


# --- every row of the default map ----------------------------------------------------------

# Presets that give each row's first and last device a value no other row's device has.
ROWS_CONFIG = (
    VB
    + """
persistence: {enabled: false}
init:
  M0: 1
  M3071: 1
  M9255: 1
  S0: 1
  S999: 1
  TS0: 1
  T255: 1
  CS0: 1
  C255: 1
  Y0: 1
  Y377: 1
  X0: 1
  X377: 1
  D0: 0x1000
  D7999: 0x1F3F
  D9000: 0x9000
  D9255: 0x9255
  TN0: 0x7000
  TN255: 0x7255
  CN0: 0x6000
  CN199: 0x6199
  CN200: [0x0200, 0x8200]
  CN255: [0x0255, 0x8255]
"""
)

# (label, table, first wire, last wire, what reads at first, what reads at last, unmapped
# neighbours). Bit rows read two elements at each end; M9000-M9003 are RUN, OFF, the initial
# pulse (over) and its opposite.
BIT_ROWS = [
    ("M0-M3071", 0x0000, 0x0BFF, [1, 0], [0, 1], [0x0C00]),
    ("M9000-M9255", 0x1E00, 0x1EFF, [1, 0, 0, 1], [0, 1], [0x1DFF, 0x1F00]),
    ("S0-S999", 0x2000, 0x23E7, [1, 0], [0, 1], [0x1FFF, 0x23E8]),
    ("T0-T255", 0x3000, 0x30FF, [1, 0], [0, 1], [0x2FFF, 0x3100]),
    ("C0-C255", 0x3200, 0x32FF, [1, 0], [0, 1], [0x31FF]),
    ("Y0-Y377", 0x3300, 0x33FF, [1, 0], [0, 1], []),
]
# FC01/05/15 at 3400h: X is not a coil.
ROWS = [(f"coils {r[0]}", "coils", *r[1:5], r[5] + ([0x3400] if r[0] == "Y0-Y377" else []))
        for r in BIT_ROWS]
ROWS += [(f"discrete inputs {r[0]}", "inputs", *r[1:]) for r in BIT_ROWS]
ROWS += [("discrete inputs X0-X377", "inputs", 0x3400, 0x34FF, [1, 0], [0, 1], [0x3500])]
WORD_ROWS = [
    ("D0-D7999", 0x0000, 0x1F3F, [0x1000], [0x1F3F], []),
    ("D9000-D9255", 0x1F40, 0x203F, [0x9000], [0x9255], [0x2040]),
    ("TN0-TN255", 0x2328, 0x2427, [0x7000], [0x7255], [0x2327, 0x2428]),
    ("CN0-CN199", 0x251C, 0x25E3, [0x6000], [0x6199], [0x251B]),
    ("CN200-CN255", 0x25E4, 0x2653, [0x0200, 0x8200], [0x0255, 0x8255], [0x2654]),
]
ROWS += [(f"holding {r[0]}", "holding", *r[1:]) for r in WORD_ROWS]
ROWS += [(f"input {r[0]}", "input", *r[1:]) for r in WORD_ROWS]


@pytest.fixture(scope="module")
def rows_plc(tmp_path_factory):
    """One daemon on ROWS_CONFIG for the row tests (they read, or write and restore), and a
    client."""
    d = _spawn(tmp_path_factory.mktemp("vb-rows"), 0, ROWS_CONFIG, [])
    yield running(d.client())
    d.stop()


def read(client, table, addr, count):
    if table == "coils":
        return client.read_coils(addr, count, slave=1)
    if table == "inputs":
        return client.read_discrete_inputs(addr, count, slave=1)
    if table == "holding":
        return client.read_holding_registers(addr, count, slave=1)
    return client.read_input_registers(addr, count, slave=1)


def values(resp, table, count):
    assert not resp.isError(), resp
    if table in ("coils", "inputs"):
        return [int(b) for b in resp.bits[:count]]
    return resp.registers


@pytest.mark.parametrize("row", ROWS, ids=[r[0] for r in ROWS])
def test_default_map_row(rows_plc, row):
    """docs/profile-vb.md, "Modbus map": the first and last address of the row hold its first
    and last device; the addresses next to it that no row maps are exception 02."""
    _, table, first, last, at_first, at_last, outside = row
    c = rows_plc
    assert values(read(c, table, first, len(at_first)), table, len(at_first)) == at_first
    n = len(at_last)
    # A bit row's last element is read with the one before it; a 32-bit counter is two words.
    assert values(read(c, table, last - n + 1, n), table, n) == at_last
    # The whole row in one request where the quantity allows.
    if last - first + 1 <= (2000 if table in ("coils", "inputs") else 125):
        assert exc(read(c, table, first, last - first + 1)) == 0
    for a in outside:
        assert exc(read(c, table, a, 1)) == ILLEGAL_ADDRESS, hex(a)
        lo, hi = (a, first) if a < first else (last, a)
        assert exc(read(c, table, lo, hi - lo + 1)) == ILLEGAL_ADDRESS, hex(a)


@pytest.mark.parametrize(
    "coil,device",
    [(0x0000, "M0"), (0x0BFF, "M3071"), (0x1EFF, "M9255"), (0x2000, "S0"), (0x23E7, "S999"),
     (0x3000, "T0"), (0x30FF, "T255"), (0x3200, "C0"), (0x32FF, "C255"), (0x3300, "Y0"),
     (0x33FF, "Y377")],
)
def test_coil_writes_show_in_the_discrete_input_twin(rows_plc, coil, device):
    """Coils and discrete inputs share addresses and devices (FX3U MODBUS manual (JY997D26201)
    §9.3)."""
    c = rows_plc
    before = coils(c, coil)[0]
    assert exc(c.write_coil(coil, not before, slave=1)) == 0, device
    assert inputs(c, coil) == [not before], device
    assert exc(c.write_coils(coil, [before], slave=1)) == 0, device
    assert inputs(c, coil) == [before], device


@pytest.mark.parametrize("reg", [0x0000, 0x1F3F, 0x1F40, 0x203F, 0x2328, 0x2427, 0x251C, 0x25E3,
                                 0x25E4, 0x2653])
def test_holding_writes_show_in_the_input_register_twin(rows_plc, reg):
    c = rows_plc
    before = regs(c, reg)[0]
    write(c, reg, 0xBEEF)
    assert input_regs(c, reg) == [0xBEEF]
    write(c, reg, before)
    assert input_regs(c, reg) == [before]


def test_counter_rows_continue_each_other(rows_plc):
    """CN199 at 9699 and CN200 at 9700 are one run of counter words: served as one request."""
    c = rows_plc
    assert regs(c, 9699, 3) == [0x6199, 0x0200, 0x8200]


def test_request_across_two_rows_of_other_devices_is_served_as_one(rows_plc):
    """D7999 at 7999 and D9000 at 8000, C255 and Y0, Y377 and X0 are adjacent wire addresses:
    one request reads both rows, and a write across them lands in both or in neither."""
    c = rows_plc
    assert values(c.read_holding_registers(7999, 2, slave=1), "holding", 2) == [0x1F3F, 0x9000]
    assert values(c.read_input_registers(7999, 2, slave=1), "input", 2) == [0x1F3F, 0x9000]
    assert values(c.read_coils(0x32FF, 2, slave=1), "coils", 2) == [1, 1]  # C255, Y0
    assert values(c.read_discrete_inputs(0x33FF, 2, slave=1), "inputs", 2) == [1, 1]  # Y377, X0
    assert not c.write_registers(7999, [0x1111, 0x2222], slave=1).isError()
    assert values(c.read_holding_registers(7999, 2, slave=1), "holding", 2) == [0x1111, 0x2222]
    # D9009 is writable, D9010 (scan time) is not: the whole write is refused, D9009 unchanged.
    before = values(c.read_holding_registers(8009, 1, slave=1), "holding", 1)
    assert exc(c.write_registers(8009, [7, 7], slave=1)) == 2
    assert values(c.read_holding_registers(8009, 1, slave=1), "holding", 1) == before
    # A request that runs from a row into a gap is refused whole.
    assert exc(c.read_holding_registers(8255, 2, slave=1)) == 2
    c.write_registers(7999, [0x1F3F, 0x9000], slave=1)  # restore for the other row tests


# --- FC02/FC04, read-only items --------------------------------------------------------------


def test_fc02_fc04_served_by_the_default_map(start_plcemud):
    d = start_plcemud(VB + "init: {M5: 1, D5: 555}\n")
    c = d.client()
    assert inputs(c, 5) == [True]
    assert input_regs(c, 5) == [555]
    assert exc(c.read_discrete_inputs(0, 2000, slave=1)) == 0
    assert exc(c.read_input_registers(0, 125, slave=1)) == 0


# (name, table, wire address, a write request over it and writable neighbours: start, length,
# the writable neighbour checked).
READ_ONLY = [
    ("M9000", "coil", 7680, 7680, 5, 7684),
    ("M9001", "coil", 7681, 7680, 5, 7684),
    ("M9002", "coil", 7682, 7680, 5, 7684),
    ("M9003", "coil", 7683, 7683, 2, 7684),
    ("M9011", "coil", 7691, 7690, 2, 7690),
    ("M9012", "coil", 7692, 7690, 6, 7690),
    ("M9013", "coil", 7693, 7693, 3, 7695),
    ("M9014", "coil", 7694, 7694, 2, 7695),
    ("D9010", "reg", 8010, 8009, 2, 8009),
    ("D9011", "reg", 8011, 8009, 5, 8013),
    ("D9012", "reg", 8012, 8012, 2, 8013),
]


@pytest.mark.parametrize("name,table,addr,span,n,neighbour", READ_ONLY,
                         ids=[r[0] for r in READ_ONLY])
def test_read_only_items_refuse_writes_unchanged(start_plcemud, name, table, addr, span, n,
                                                 neighbour):
    """docs/profile-vb.md, "Modbus map": writes get exception 02 and change nothing, also in a
    request that writes a writable neighbour too (the scans are frozen, so the clocks and the
    calendar stand still)."""
    d = start_plcemud(VB)
    c = d.client()
    freeze(c)
    step(c, 1)  # past the first scan: M9002 OFF, M9003 ON
    if table == "coil":
        before = coils(c, addr)[0]
        other = coils(c, neighbour)[0]
        assert exc(c.write_coil(addr, not before, slave=1)) == ILLEGAL_ADDRESS
        assert exc(c.write_coils(addr, [not before], slave=1)) == ILLEGAL_ADDRESS
        assert exc(c.write_coils(span, [True] * n, slave=1)) == ILLEGAL_ADDRESS
        assert exc(c.write_coils(span, [False] * n, slave=1)) == ILLEGAL_ADDRESS
        assert coils(c, addr) == [before]
        assert coils(c, neighbour) == [other]
        if name in ("M9000", "M9003"):
            assert before is True
        if name in ("M9001", "M9002"):
            assert before is False
    else:
        before = regs(c, addr)[0]
        other = regs(c, neighbour)[0]
        assert before == 100  # scan_ms 10 in 0.1 ms: current, minimum, maximum
        assert exc(c.write_register(addr, 0x7777, slave=1)) == ILLEGAL_ADDRESS
        assert exc(c.write_registers(addr, [0x7777], slave=1)) == ILLEGAL_ADDRESS
        assert exc(c.write_registers(span, [0x7777] * n, slave=1)) == ILLEGAL_ADDRESS
        assert exc(c.mask_write_register(addr, 0, 0x7777, unit=1)) == ILLEGAL_ADDRESS
        rw = c.readwrite_registers(read_address=0, read_count=1, write_address=addr,
                                   write_registers=[0x7777], unit=1)
        assert exc(rw) == ILLEGAL_ADDRESS
        assert regs(c, addr) == [before]
        assert regs(c, neighbour) == [other]


def test_x_cannot_be_written(start_plcemud):
    """X exists only as discrete inputs: FC05/FC15 at 3400h are unmapped addresses."""
    d = start_plcemud(VB + "init: {X0: 1}\n")
    c = d.client()
    assert exc(c.write_coil(0x3400, False, slave=1)) == ILLEGAL_ADDRESS
    assert exc(c.write_coils(0x3400, [False], slave=1)) == ILLEGAL_ADDRESS
    assert inputs(c, 0x3400) == [True]


def test_other_specials_are_plain_storage(start_plcemud):
    """M9067, D9067, D9069 and the other M9000-M9255 / D9000-D9255 may be written."""
    d = start_plcemud(VB)
    c = d.client()
    assert coils(c, 7680 + 67) == [False] and regs(c, 8067) == [0] and regs(c, 8069) == [0]
    assert exc(c.write_coil(7680 + 67, True, slave=1)) == 0
    write(c, 8067, 6730)
    write(c, 8129, 50)
    assert coils(c, 7680 + 67) == [True] and regs(c, 8067) == [6730] and regs(c, 8129) == [50]


# --- octal X/Y and config errors ---------------------------------------------------------------


def test_y10_is_the_ninth_output(start_plcemud):
    d = start_plcemud(VB + "init: {Y10: 1, X17: 1}\n")
    c = d.client()
    assert coils(c, 0x3300, 16) == [i == 8 for i in range(16)]  # Y10 = 3308h
    assert inputs(c, 0x3400, 16) == [i == 15 for i in range(16)]  # X17 = 340Fh


def test_profile_vb_alone_is_a_valid_config(tmp_path, start_plcemud):
    p, r = check_config(tmp_path, "{profile: vb}\n")
    assert r.returncode == 0, r.stderr
    assert "ok" in r.stdout
    d = start_plcemud("{profile: vb}\n")
    c = running(d.client())
    assert coils(c, 7680) == [True]  # M9000


@pytest.mark.parametrize(
    "name", ["vb.yaml", "vb-pid.yaml", "vb-tpid.yaml", "vb-mbus.yaml", "vb-mbus-slave.yaml"])
def test_config_vb_yaml_is_valid(name):
    """The vb example configs: config/vb-pid.yaml and config/vb-tpid.yaml are the VB manual's
    FNC88 and FNC92 program examples, config/vb-mbus.yaml an FNC149 master polling the slave of
    config/vb-mbus-slave.yaml."""
    r = run_plcemud("-c", REPO / "config" / name, "--check-config")
    assert r.returncode == 0, r.stderr
    assert "ok" in r.stdout


@pytest.mark.parametrize(
    "text,line,col,needle",
    [
        ("profile: vb\ninit:\n  X8: 1\n", 3, 3, "octal"),
        ("profile: vb\ninit:\n  Y7: 1\n  Y18: 1\n", 4, 3, "octal"),
        ("profile: vb\ninit:\n  D8000: 1\n", 3, 3, "D8000 does not exist"),
        ("profile: vb\ninit:\n  M3072: 1\n", 3, 3, "M3072 does not exist"),
        ("profile: vb\ninit:\n  R0: 1\n", 3, 3, "'R0' is not a device"),
        ("profile: vb\nprogram:\n  - MOV: {s: R0, d: D0}\n", 3, 14,
         "MOV.s: expected a register (D, TN, CN)"),
        ("profile: vb\nmodel: FBs-24MC\n", 2, 8, "VIGOR model"),
        ("profile: vb\nstation: 248\n", 2, 10, "1..247"),
        ("profile: vb\ntemperature:\n  table: D0\n", 3, 3, "profile vb has no such subsystem"),
        ("profile: vb\ntemperature: {table: D0}\n", 2, 14, "profile vb has no such subsystem"),
    ],
    ids=["X8", "Y18", "D8000", "M3072", "R0", "R-operand", "model", "station", "temperature",
         "temperature-flow"],
)
def test_config_errors_name_file_line_col(tmp_path, text, line, col, needle):
    expect_config_error(tmp_path, text, line, col, needle)


@pytest.mark.parametrize("model", ["VB2-32M", "VB-14MR", "VH-40MT", "VB1-24MRD"])
def test_model_names(tmp_path, model):
    _, r = check_config(tmp_path, f"profile: vb\nmodel: {model}\n")
    assert r.returncode == 0, r.stderr


def test_constants_k_and_h(start_plcemud):
    """The VB manual writes constants K100 and H0011."""
    d = start_plcemud(VB + "init: {D0: K100, D1: H0011, D2: K-5}\nprogram:\n"
                      "  - MOV: {s: H00FF, d: D3}\n")
    c = d.client()
    deadline = time.monotonic() + 5
    while regs(c, 3) != [0x00FF]:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert regs(c, 0, 3) == [100, 0x11, 0xFFFB]


# --- identity, --print-map ---------------------------------------------------------------------


def version():
    r = run_plcemud("--version")
    return r.stdout.split()[1]


def test_report_slave_id_and_device_identification(start_plcemud):
    """docs/profile-vb.md, "Identity": FC17 "VIGOR <model> plcemu <version>", FC43/14 vendor
    VIGOR, product code the model."""
    d = start_plcemud(VB + "station: 7\n")
    report = raw_request(d.port, bytes([0x11]), unit=7)
    assert report[0] == 0x11 and report[2] == 7 and report[3] == 0xFF
    assert report[4:].decode() == f"VIGOR VB2-32M plcemu {version()}"
    reply = raw_request(d.port, bytes([0x2B, 0x0E, 0x01, 0x00]), unit=7)
    objects, k = {}, 7
    for _ in range(reply[6]):
        oid, n = reply[k], reply[k + 1]
        objects[oid] = reply[k + 2 : k + 2 + n].decode()
        k += 2 + n
    assert objects[0] == "VIGOR" and objects[1] == "VB2-32M" and objects[2] == version()
    d2 = start_plcemud(VB + "model: VH-40MR\n")
    assert b"VIGOR VH-40MR plcemu" in raw_request(d2.port, bytes([0x11]))


def test_print_map_text(tmp_path):
    p, _ = check_config(tmp_path, "profile: vb\n")
    r = run_plcemud("-c", p, "--print-map")
    assert r.returncode == 0, r.stderr
    assert "VIGOR VB2-32M" in r.stdout
    lines = r.stdout.splitlines()
    x = [ln for ln in lines if "X0-X377 (octal)" in ln]
    assert len(x) == 1 and "discrete inputs" in x[0] and "13312-13567" in x[0]
    assert "113313-113568" in x[0]
    y = [ln for ln in lines if "Y0-Y377 (octal)" in ln]
    assert len(y) == 2 and "13056-13311" in y[0]
    m = [ln for ln in lines if "M9000-M9255" in ln and ln.startswith("coils")]
    assert "M9000-M9003 M9011-M9014 (read-only)" in m[0]
    assert any("D9010-D9012 (read-only)" in ln for ln in lines if ln.startswith("holding"))


def test_print_map_csv(tmp_path):
    p, _ = check_config(tmp_path, "profile: vb\n")
    r = run_plcemud("-c", p, "--print-map", "--format", "csv")
    assert r.returncode == 0, r.stderr
    rows = [row for row in csv.DictReader(io.StringIO(r.stdout)) if "unit" not in row["table"]]
    assert len(rows) == 6 + 7 + 5 + 5
    by = {(row["table"], row["wire"]): row for row in rows}
    x = by[("discrete inputs", "13312-13567")]
    assert x["vigor"].startswith("X0-X377") and x["function_codes"] == "02"
    assert x["modbus_5digit"] == "-"  # 5-digit numbers end at 19999
    assert by[("coils", "8192-9191")]["modbus_5digit"] == "08193-09192"
    assert by[("coils", "13056-13311")]["vigor"].startswith("Y0-Y377")
    assert by[("holding registers", "9700-9811")]["modbus_6digit"] == "409701-409812"
    assert by[("input registers", "0-7999")]["function_codes"] == "04"
    assert not any(row["table"] == "coils" and row["wire"].startswith("13312") for row in rows)


# --- modbus.map ----------------------------------------------------------------------------------

OWN_MAP = """profile: vb
modbus:
  tcp: {bind: 127.0.0.1}
  map:
    - {table: holding, start: 0, device: D0, count: 100}
    - {table: holding, start: 0x2478, device: WM0, count: 4}
    - {table: coils, start: 0x3300, device: Y0, count: 256, access: ro}
init: {Y0: 1}
program:
  - MOV: {en: M0, s: K1, d: D1}
  - MOV: {en: M15, s: K2, d: D2}
"""


def test_own_map_replaces_the_default(start_plcemud):
    d = start_plcemud(OWN_MAP)
    c = d.client()
    assert exc(c.read_holding_registers(8000, 1, slave=1)) == ILLEGAL_ADDRESS  # D9000 gone
    assert exc(c.read_holding_registers(99, 2, slave=1)) == ILLEGAL_ADDRESS  # D99 is the last
    assert exc(c.read_coils(0, 1, slave=1)) == ILLEGAL_ADDRESS  # M0 no longer a coil
    # Tables no row serves are not served at all.
    assert exc(c.read_discrete_inputs(0, 1, slave=1)) == ILLEGAL_FUNCTION
    assert exc(c.read_input_registers(0, 1, slave=1)) == ILLEGAL_FUNCTION


def test_own_map_packed_bits(start_plcemud):
    """WM0 at 2478h: 16 M per register, M0 in b0."""
    d = start_plcemud(OWN_MAP)
    c = d.client()
    write(c, 0x2478, 0x8001)  # M0 and M15
    assert regs(c, 0x2478, 4) == [0x8001, 0, 0, 0]
    deadline = time.monotonic() + 5
    while regs(c, 1, 2) != [1, 2]:  # the program saw M0 and M15 ON
        assert time.monotonic() < deadline, regs(c, 1, 2)
        time.sleep(0.01)
    assert exc(c.read_holding_registers(0x2478 + 3, 2, slave=1)) == ILLEGAL_ADDRESS


def test_own_map_read_only_row(start_plcemud):
    d = start_plcemud(OWN_MAP)
    c = d.client()
    assert coils(c, 0x3300, 2) == [True, False]
    assert exc(c.write_coil(0x3300, False, slave=1)) == ILLEGAL_ADDRESS
    assert exc(c.write_coils(0x3301, [True], slave=1)) == ILLEGAL_ADDRESS
    assert coils(c, 0x3300, 2) == [True, False]


def test_own_map_in_print_map(tmp_path):
    p, r = check_config(tmp_path, OWN_MAP)
    assert r.returncode == 0, r.stderr
    out = run_plcemud("-c", p, "--print-map").stdout
    assert "not the profile's default" in out
    assert "M0-M63, 16 per register" in out
    assert re.search(r"coils\s.*13056-13311\s+Y0-Y377\s.*read-only", out)


@pytest.mark.parametrize(
    "rows,line,col,needle",
    [
        ("    - {table: holding, start: 0, device: D0, count: 100}\n"
         "    - {table: holding, start: 99, device: D200, count: 10}\n", 5, 7, "overlap"),
        ("    - {table: holding, start: 0, device: D7990, count: 20}\n", 4, 7,
         "D7990-D8009 does not exist"),
        ("    - {table: holding, start: 0, device: CN250, count: 20}\n", 4, 7, "outside"),
        ("    - {table: holding, start: 0, device: M0, count: 10}\n", 4, 42,
         "16 packed bits such as WM0"),
        ("    - {table: coils, start: 0, device: D0, count: 10}\n", 4, 40, "needs a bit device"),
        ("    - {table: coils, start: 0, device: X8, count: 10}\n", 4, 40, "octal"),
    ],
    ids=["overlap", "hole", "off-the-end", "bits-without-W", "word-in-coils", "octal"],
)
def test_own_map_errors(tmp_path, rows, line, col, needle):
    expect_config_error(tmp_path, "profile: vb\nmodbus:\n  map:\n" + rows, line, col, needle)
