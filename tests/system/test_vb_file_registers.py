"""VB file registers (docs/profile-vb.md, "File registers"; VB manual FNC149: "File Registers
are read only registers and their contents are assumed as a part of program") through Modbus
against the real daemon: presets at every start and reload whatever persistence keeps, Modbus
writes refused with exception 02, program operands that would write them refused at load."""

import signal
from pathlib import Path

import pytest

from test_vb import VB, check_config, exc, expect_config_error, regs, running

FILE = VB + "file_registers: D1000-D1009\n"


def test_presets_readable_and_writes_refused(start_plcemud):
    d = start_plcemud(FILE + "init: {D1000: [11, 22, 33], D999: 5}\n")
    c = running(d.client())
    assert regs(c, 1000, 3) == [11, 22, 33]
    assert exc(c.write_register(1000, 1, slave=1)) == 2
    # A write that only touches the range is refused whole: D999 keeps its value.
    assert exc(c.write_registers(999, [7, 7], slave=1)) == 2
    assert regs(c, 999, 2) == [5, 11]
    assert exc(c.write_register(1010, 44, slave=1)) == 0  # the word after the range
    assert regs(c, 1010) == [44]


def test_presets_win_over_retained_values_at_reload(start_plcemud):
    """D1000 (latched by default) takes its preset again at reload, while a latched D300 keeps
    the value a master wrote (persistence.init: fresh spares retained values)."""
    d = start_plcemud(FILE + "init: {D1000: 5, D300: 5}\n")
    c = running(d.client())
    c.write_register(300, 77, slave=1)
    Path(d.config_path).write_text(FILE + "init: {D1000: 6, D300: 6}\n")
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    assert regs(c, 1000) == [6]
    assert regs(c, 300) == [77]


@pytest.mark.parametrize("text,line,col,needle", [
    ("program:\n  - MOV: {en: M0, s: K1, d: D1005}\n", 5, 29, "file registers"),
    ("program:\n  - FROM: {en: M0, m1: 1, m2: 0, d: D998, n: 4}\n", 5, 37, "file registers"),
    ("program:\n  - HOUR: {en: M0, s: K1, d1: D1009, d2: Y0}\n", 5, 31, "file registers"),
    ("program:\n  - RST: {en: M0, d: D1000}\n", 5, 22, "file registers"),
    ("program:\n  - PID: {en: M0, s1: D0, s2: D1, s3: D990, d: D2}\n", 5, 39, "file registers"),
])
def test_program_may_not_write_them(tmp_path, text, line, col, needle):
    expect_config_error(tmp_path, FILE + text, line, col, needle)


def test_program_reads_them(tmp_path):
    """Reading them is what they are for: a PID's SV and PV may be file registers."""
    _, r = check_config(
        tmp_path, FILE + "program:\n  - PID: {en: M0, s1: D1000, s2: D1001, s3: D200, d: D2}\n")
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("value,needle", [
    ("M0-M9", "expected a range of D0-D7999"),
    ("D7990-D8009", "expected a range of D0-D7999"),
    ("D9000-D9009", "expected a range of D0-D7999"),
    ("X0-X7", "expected a range of D0-D7999"),
    ("D1000-", "expected a device range"),
])
def test_bad_ranges(tmp_path, value, needle):
    expect_config_error(tmp_path, VB + f"file_registers: {value}\n", 3, 17, needle)
