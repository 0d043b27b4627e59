"""Programs written as the family's instruction list (docs/program-language.md) against the real
daemon: each example configuration runs beside its program in config/programs/ in frozen time,
register by register the same; the worked example (a batch oven) driven through Modbus;
--check-config, --print-program and their errors at file:line:col; a reload of the program file
alone."""

import signal
import time

import pytest
import yaml

from conftest import REPO, run_plcemud
from test_vb import coils, freeze, regs, step

PROGRAMS = REPO / "config" / "programs"


def with_listing(config_name, listing):
    """The YAML text of config/`config_name` with `program:` replaced by the listing `listing`
    (a path), without persistence or a console (two daemons run side by side)."""
    cfg = yaml.safe_load((REPO / "config" / config_name).read_text())
    cfg["persistence"] = {"enabled": False}
    cfg.pop("http", None)
    if listing is not None:
        cfg["program"] = {"file": str(listing)}
    return yaml.safe_dump(cfg, sort_keys=False)


def set_coils(client, addrs):
    for a in addrs:
        assert not client.write_coil(a, True, slave=1).isError()


def snapshot(client, blocks):
    """Every (kind, address, count) block read: holding registers or coils."""
    out = {}
    for kind, addr, count in blocks:
        read = regs if kind == "hr" else coils
        for k in range(0, count, 100):
            n = min(100, count - k)
            out[(kind, addr + k)] = list(read(client, addr + k, n))
    return out


# (configuration, its listing, coils set before the run, blocks compared, scans)
# R4128–R4138 (calendar, scan times) read the wall clock: left out.
FBS_BLOCKS = [("hr", 0, 500), ("hr", 4000, 128), ("hr", 9000, 256), ("co", 0, 256),
              ("co", 2000, 1000)]
VB_BLOCKS = [("hr", 0, 400), ("hr", 7000, 20), ("hr", 9000, 256), ("co", 0, 1000),
             ("co", 13056, 64), ("co", 12288, 256)]
EXAMPLES = [
    ("default.yaml", "default.il", [2000] + list(range(2800, 2810)), FBS_BLOCKS, 6000),
    ("fb-example.yaml", "fb-example.il", [2003], FBS_BLOCKS, 6000),
    ("vb-pid.yaml", "vb-pid.il", [0, 24], VB_BLOCKS, 6000),
    ("vb-tpid.yaml", "vb-tpid.il", [10, 14], VB_BLOCKS, 6000),
    ("vb.yaml", "vb.il", [], VB_BLOCKS, 6000),
]


@pytest.mark.parametrize("config_name,listing,start,blocks,scans", EXAMPLES,
                         ids=[e[0] for e in EXAMPLES])
def test_examples_as_listings_run_register_for_register(start_plcemud, config_name, listing,
                                                        start, blocks, scans):
    """The example's YAML entries and its instruction list, in two daemons frozen from their
    first scan and stepped the same scans, leave every compared register and coil equal, and
    the run changed them (the comparison is not of two idle PLCs)."""
    runs = []
    for name, source in (("entries", None), ("listing", PROGRAMS / listing)):
        d = start_plcemud(with_listing(config_name, source), "--time-scale", "0.001", name=name)
        c = d.client()
        freeze(c)
        before = snapshot(c, blocks)
        set_coils(c, start)
        step(c, scans)
        runs.append((before, snapshot(c, blocks)))
        assert "warning" not in d.log_text(), d.log_text()
    (before, entries), (_, listing_run) = runs
    assert entries != before, "the run changed nothing: the comparison would prove nothing"
    for key in entries:
        assert listing_run[key] == entries[key], f"{config_name}: {key} differs"


def test_a_listing_saved_with_a_byte_order_mark_reads_as_without(tmp_path):
    """An editor's UTF-8 byte order mark was read as part of the first mnemonic, refused as
    "unknown instruction 'ORG'" with the mark invisible in the quote."""
    (tmp_path / "bom.il").write_bytes(b"\xef\xbb\xbfORG M0\r\nOUT Y0\r\n")
    cfg = tmp_path / "c.yaml"
    cfg.write_text("profile: fbs\npersistence: {enabled: false}\nprogram: {file: bom.il}\n")
    r = run_plcemud("-c", str(cfg), "--print-program")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["0001  ORG M0", "0002  OUT Y0"], r.stdout
    # A mark elsewhere is no statement, and the message shows it.
    (tmp_path / "bom.il").write_bytes(b"ORG M0\n\xef\xbb\xbfOUT Y0\n")
    r = run_plcemud("-c", str(cfg), "--check-config")
    assert r.returncode == 2 and "bom.il:2:1: unknown instruction '\\uFEFFOUT'" in r.stderr, \
        r.stderr


@pytest.mark.parametrize("ending", [b"\n", b"\r\n", b"\r"], ids=["lf", "crlf", "cr"])
def test_a_listing_ends_its_lines_as_any_editor_saves_them(tmp_path, ending):
    """A listing whose lines end in a lone CR (classic Mac OS editors) was read as one line, a
    comment when the file began with one: the start took an empty program without a word. LF,
    CR LF and CR each end a line, and an error names the line it is on."""
    lines = [b"; the oven", b"ORG M0", b"OUT Y0", b"ORG M1", b"OUT Y1"]
    (tmp_path / "p.il").write_bytes(ending.join(lines) + ending)
    cfg = tmp_path / "c.yaml"
    cfg.write_text("profile: fbs\npersistence: {enabled: false}\nprogram: {file: p.il}\n")
    r = run_plcemud("-c", str(cfg), "--print-program")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["0001  ORG M0", "0002  OUT Y0", "0003  ORG M1",
                                     "0004  OUT Y1"], r.stdout
    (tmp_path / "p.il").write_bytes(ending.join(lines[:3] + [b"ORG Q1"]) + ending)
    r = run_plcemud("-c", str(cfg), "--check-config")
    assert r.returncode == 2 and "p.il:4:" in r.stderr, r.stderr


@pytest.mark.parametrize("program, error", [
    ("program:\n  - MOV: {s: D0, d: D99999}\n", "MOV.d: expected 1 word(s)"),
    ("program: {file: bad.il}\n", "bad.il:3:1: OUT: 1 block opened by LD not joined"),
])
@pytest.mark.parametrize("option", [["--print-program"], ["--export-tags", "csv"], ["--print-map"]])
def test_what_the_start_refuses_is_not_printed(tmp_path, program, error, option):
    """--print-program printed programs --check-config refuses (an operand past its area, a
    block never joined) and exited 0, as if they read back, and --print-map described such a
    config. Each refuses it as the start does (and --export-tags did), with exit status 2."""
    (tmp_path / "bad.il").write_text("ORG M0\nLD M1\nOUT Y0\n")
    cfg = tmp_path / "c.yaml"
    cfg.write_text("profile: fbs\npersistence: {enabled: false}\n" + program)
    r = run_plcemud("-c", str(cfg), "--check-config")
    assert r.returncode == 2 and error in r.stderr, r.stderr
    r = run_plcemud("-c", str(cfg), *option)
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert error in r.stderr and r.stdout == "", (r.stdout, r.stderr)


def test_listing_checks_prints_and_refuses_at_line_and_column(tmp_path):
    """--check-config accepts config/oven-il.yaml; --print-program numbers its statements (and
    reads back as the same program); a broken listing is refused with exit 2 at file:line:col
    naming the mnemonic; a double coil is a warning, not a refusal."""
    oven = REPO / "config" / "oven-il.yaml"
    r = run_plcemud("-c", str(oven), "--check-config")
    assert r.returncode == 0, r.stderr
    r = run_plcemud("-c", str(oven), "--print-program")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == "0001  ORG M10"
    assert "0017  TMR T50 300" in lines
    assert lines[-1].endswith("  END")
    again = tmp_path / "again.il"
    again.write_text(r.stdout)
    cfg = tmp_path / "again.yaml"
    cfg.write_text(oven.read_text().replace("programs/oven.il", str(again)))
    r2 = run_plcemud("-c", str(cfg), "--print-program")
    assert r2.returncode == 0 and r2.stdout == r.stdout, r2.stderr

    bad = tmp_path / "bad.il"
    bad.write_text("ORG M0\nLD M1\nOUT Y0\n")
    cfg.write_text("profile: fbs\nprogram: {file: bad.il}\n")
    r = run_plcemud("-c", str(cfg), "--check-config")
    assert r.returncode == 2
    assert f"{bad}:3:1: OUT: 1 block opened by LD not joined (ANDLD, ORLD)" in r.stderr

    bad.write_text("LD X0\nANDLD X1\n")
    cfg.write_text("profile: vb\nprogram: {file: bad.il}\n")
    r = run_plcemud("-c", str(cfg), "--check-config")
    assert r.returncode == 2
    assert f"{bad}:2:1: unknown instruction 'ANDLD' (not in the VB instruction list" in r.stderr

    bad.write_text("LD X0\nOUT Y0\nLD X1\nOUT Y0\n")
    r = run_plcemud("-c", str(cfg), "--check-config")
    assert r.returncode == 0, r.stderr
    assert f"{bad}:4:1: OUT: double coil: Y0 is driven at {bad}:2:1 too" in r.stderr

    cfg.write_text("profile: vb\nprogram: {file: missing.il}\n")
    r = run_plcemud("-c", str(cfg), "--check-config")
    assert r.returncode == 2
    assert f"{cfg}:2:17: program.file: cannot open the program file" in r.stderr


def test_reload_reads_the_program_file_again(start_plcemud, tmp_path):
    """SIGHUP after an edit of the .il file alone: the reload says the instruction list changed
    and the new rung runs; a broken edit is refused and the old program keeps running."""
    il = tmp_path / "p.il"
    il.write_text("LD M0\nOUT Y0\n")
    d = start_plcemud("profile: vb\nmodbus: {tcp: {bind: 127.0.0.1}}\n"
                      "persistence: {enabled: false}\nprogram: {file: p.il}\n")
    # The start says what was read (it once said "program: 0 instruction(s)").
    assert "program: instruction list of 2 lines" in d.log_text(), d.log_text()
    c = d.client()
    assert not c.write_coil(0, True, slave=1).isError()
    Y0, Y1 = 13056, 13057

    def wait(pred):
        deadline = time.monotonic() + 10
        while not pred():
            assert time.monotonic() < deadline, d.log_text()
            time.sleep(0.02)

    wait(lambda: coils(c, Y0, 2) == [True, False])
    il.write_text("LD M0\nOUT Y1\n")
    d.proc.send_signal(signal.SIGHUP)
    wait(lambda: "program: instruction list changed (2 lines)" in d.log_text())
    wait(lambda: coils(c, Y1, 1) == [True])
    il.write_text("LD M0\nOUT Y1\nLD\n")
    d.proc.send_signal(signal.SIGHUP)
    wait(lambda: "p.il:3:1: LD: expected 1 operand" in d.log_text())
    time.sleep(0.1)
    assert coils(c, Y1, 1) == [True]


# The worked example's coils (fbs: M n is coil 2000 + n, Y n is coil n).
DOOR, START, STOP, ACK, TRAY, RESET = 2300, 2301, 2302, 2303, 2304, 2305
RUNNING, HEAT, ALARM = 2010, 2000, 2020
FAN, LAMP, BATCH = 0, 2, 3


def test_worked_example_oven(start_plcemud):
    """config/oven-il.yaml through Modbus, in frozen time: the door interlock, the alarm latched
    until acknowledged, the fan's 30 s run-on to the scan, the heater warming the oven, and a
    batch of ten trays."""
    text = (REPO / "config" / "oven-il.yaml").read_text()
    text = text.replace("programs/oven.il", str(PROGRAMS / "oven.il"))
    d = start_plcemud(text, "--time-scale", "0.001")
    c = d.client()
    freeze(c)

    def put(addr, value):
        assert not c.write_coil(addr, value, slave=1).isError()

    def press(addr):
        put(addr, True)
        step(c, 1)
        put(addr, False)
        step(c, 1)

    def bits(*addrs):
        return [coils(c, a)[0] for a in addrs]

    # The door open: start does nothing.
    press(START)
    assert bits(RUNNING, FAN, HEAT) == [False, False, False]
    # The door shut: start runs the oven, the fan and the heating.
    put(DOOR, True)
    press(START)
    assert bits(RUNNING, FAN, HEAT, ALARM) == [True, True, True, False]
    ambient = regs(c, 0)[0]
    step(c, 12000)  # two minutes of heating
    assert regs(c, 0)[0] > ambient + 100, "the oven did not warm by 10 °C in two minutes"
    # The door opened while running: the oven stops, the alarm latches, the fan runs on.
    put(DOOR, False)
    step(c, 1)
    assert bits(RUNNING, HEAT, ALARM, LAMP, FAN) == [False, False, True, True, True]
    step(c, 2998)  # T50: 300 counts of 0.1 s after the stop, 3000 scans
    assert bits(FAN) == [True]
    step(c, 1)
    assert bits(FAN) == [False]
    # The alarm holds through a start with the door shut, until acknowledged.
    put(DOOR, True)
    press(START)
    assert bits(RUNNING, ALARM) == [False, True]
    press(ACK)
    assert bits(ALARM, LAMP) == [False, False]
    press(START)
    assert bits(RUNNING, FAN, HEAT) == [True, True, True]
    press(STOP)
    assert bits(RUNNING, HEAT, ALARM) == [False, False, False]
    # Ten trays make a batch; the reset clears it.
    for n in range(10):
        assert bits(BATCH) == [False], n
        press(TRAY)
    assert bits(BATCH) == [True]
    assert regs(c, 9500)[0] == 10
    press(RESET)
    assert bits(BATCH) == [False] and regs(c, 9500)[0] == 0
    assert d.stop() == 0, d.log_text()


def test_an_edge_fires_again_after_stop_and_run(start_plcemud):
    """docs/program-language.md: the remembered value of an edge is OFF after STOP->RUN, so M0
    held ON across a STOP counts once more (C0 through a TU contact, C1 by its own edge) when
    the PLC runs again (the communication fault `stop`, unit 247's register 31)."""
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n"
                      "persistence: {enabled: false}\n"
                      "program: {il: ['ORG TU M0', 'OUT M10', 'ORG M10', 'CTR C0 100',"
                      " 'ORG M0', 'CTR C1 100']}\n")
    c = d.client()
    C0 = 9500

    def counts(expected):
        deadline = time.monotonic() + 5
        while regs(c, C0, 2) != expected:
            assert time.monotonic() < deadline, (regs(c, C0, 2), d.log_text())
            time.sleep(0.02)

    assert not c.write_coil(2000, True, slave=1).isError()  # M0 ON, and left ON
    counts([1, 1])
    assert not c.write_register(31, 1, slave=247).isError()  # STOP
    time.sleep(0.2)
    assert not c.write_register(31, 0, slave=247).isError()  # RUN
    counts([2, 2])
    time.sleep(0.2)
    assert regs(c, C0, 2) == [2, 2]
