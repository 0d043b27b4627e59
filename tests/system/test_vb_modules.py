"""The VB temperature modules and FROM/TO (docs/profile-vb.md, "Temperature modules" and "FROM
and TO") through Modbus TCP against the real daemon: a VB-8T's readings, status and modes as the
VB manual's FNC88/FNC92 examples read them, a broken sensor, a register drive with
`drive_full_scale`, operation errors for a missing module, and the config errors of `modules:`."""

import pytest

from conftest import REPO, run_plcemud
from test_vb import (SIM, VB, check_config, coils, expect_config_error, freeze, regs, running,
                     step, write)

MODULES = VB + """
modules: [VB-8T, {type: VB-2PT}]
plant:
  channels:
    0: {ambient: 25}
    3: {ambient: 80.4}
    8: {ambient: 31.2}
program:
  - FROM: {en: M9000, m1: 1, m2: 32, d: D100, n: 8}
  - FROM: {en: M9000, m1: 1, m2: 29, d: WM10, n: 1}
  - FROM: {en: M9000, m1: 1, m2: 20, d: WM40, n: 1}
  - FROM: {en: M9000, m1: 2, m2: 32, d: D110, n: 2}
  - FROM: {en: M9000, m1: 1, m2: 0, d: D120, n: 8}
  - TO: {en: M1, m1: 1, m2: 3, s: 0, n: 1, p: true}
"""


def test_readings_status_and_modes(start_plcemud):
    """VB manual FNC88/FNC92 examples: CR#32… hold the readings in 0.1 °C, CR#20 and CR#29 b14
    is "ready" (M24 and M54 here), CR#0… the channel modes (7 = K type from power-up). Plant
    channels run across modules in bus order: module 2's CH1 is channel 8."""
    d = start_plcemud(MODULES)
    c = running(d.client())
    assert regs(c, 100, 8) == [250, 250, 250, 804, 250, 250, 250, 250]
    assert regs(c, 110, 2) == [312, 250]
    assert coils(c, 24)[0] and coils(c, 54)[0], "status b14 (ready)"
    assert regs(c, 120, 8) == [7] * 8


def test_to_sets_a_mode_and_mode_0_disables(start_plcemud):
    """`TO` with `p: true` writes once at M1's rising edge; CR#3 = 0 disables CH4, which then
    reads 0, and a master sees the new mode through FROM."""
    d = start_plcemud(MODULES)
    c = running(d.client())
    assert regs(c, 103)[0] == 804
    c.write_coil(1, True, slave=1)
    freeze(c)
    step(c, 2)
    assert regs(c, 123)[0] == 0
    assert regs(c, 103)[0] == 0
    assert regs(c, 100, 3) == [250, 250, 250]


def test_broken_sensor_reads_32767(start_plcemud):
    """A broken sensor (simulator unit, channel fault b0) reads 32767 on the module, as the
    FBs readings do; clearing the fault brings the reading back."""
    d = start_plcemud(MODULES)
    c = running(d.client())
    freeze(c)
    write(c, 100 + 10 * 2, 1, unit=SIM)
    step(c, 1)
    assert regs(c, 102)[0] == 32767
    write(c, 100 + 10 * 2, 0, unit=SIM)
    step(c, 1)
    assert regs(c, 102)[0] == 250


def test_register_drive_with_full_scale(start_plcemud):
    """`plant.channels.0.drive: D102` with `drive_full_scale: 500` (the VB manual's PID example
    scale): D102 = 250 is half power, read back as heater power 50.0 % through the simulator unit,
    and a negative value (a PID output below 0) is no power."""
    d = start_plcemud(VB + """
modules: [VB-4T]
plant:
  channels:
    0: {drive: D102, drive_full_scale: 500}
    1: {drive: D103}
init: {D102: 250, D103: 500}
""")
    c = running(d.client())
    freeze(c)
    step(c, 900)  # 9 s: the heater-power mean covers the last 8 s
    assert regs(c, 107, unit=SIM)[0] == 500
    # The VB's default full scale is 1000, the TPID's analog output span.
    assert regs(c, 117, unit=SIM)[0] == 500
    write(c, 102, 0xFFFB)  # -5
    step(c, 900)
    assert regs(c, 107, unit=SIM)[0] == 0


def test_missing_module_raises_6705(start_plcemud):
    """FROM from a module that is not on the bus, or past its 64 buffer words, moves nothing and
    stores the operand-error code 6705 in D9067 with M9067 ON and the entry's step in D9069."""
    d = start_plcemud(VB + """
modules: [VB-4T]
init: {D100: 1234}
program:
  - FROM: {en: M0, m1: 2, m2: 32, d: D100, n: 1}
  - FROM: {en: M1, m1: 1, m2: 63, d: D101, n: 2}
""")
    c = running(d.client())
    assert regs(c, 8067)[0] == 0
    c.write_coil(0, True, slave=1)
    freeze(c)
    step(c, 1)
    assert regs(c, 100)[0] == 1234
    assert regs(c, 8067)[0] == 6705 and regs(c, 8069)[0] == 1
    assert coils(c, 7680 + 67)[0]
    write(c, 8067, 0)
    c.write_coil(0, False, slave=1)
    c.write_coil(1, True, slave=1)
    step(c, 1)
    assert regs(c, 8067)[0] == 6705 and regs(c, 8069)[0] == 2
    # CR#63 moved before CR#64 failed.
    assert regs(c, 101)[0] == 0


@pytest.mark.parametrize("text,line,col,needle", [
    ("modules: [VB-9T]\n", 3, 11, "unknown module 'VB-9T'"),
    ("modules: [{type: VB-8T, mode: 70000}]\n", 3, 31, "modules.mode"),
    ("modules: [{type: VB-8T, speed: 1}]\n", 3, 25, "unknown key 'speed'"),
    ("modules: VB-8T\n", 3, 10, "expected a list"),
    ("modules: [VB-8T, VB-8T, VB-8T, VB-8T, VB-2PT]\n", 3, 39, "more than 32 channels"),
    ("program:\n  - FROM: {en: M0, m1: 1, m2: 0, d: D7999, n: 2}\n", 4, 37, "D7999"),
    ("program:\n  - TO: {en: M0, m1: 1, m2: 0, s: D0, n: 1, p: maybe}\n", 4, 48, "true or false"),
    ("temperature: {table: R5000}\n", 3, 14, "no such subsystem"),
])
def test_config_errors(tmp_path, text, line, col, needle):
    expect_config_error(tmp_path, VB + text, line, col, needle)


def test_fbs_refuses_modules(tmp_path):
    p, r = check_config(tmp_path, "profile: fbs\nmodules: [VB-8T]\n")
    assert r.returncode == 2
    assert f"{p}:2:10: modules: profile fbs has no such subsystem" in r.stderr, r.stderr
