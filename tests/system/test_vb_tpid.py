"""FNC92 TPID through Modbus TCP against the real daemon (docs/profile-vb.md, "FNC92 TPID"): the
VB manual's wiring — a VB-8T read into D10 with FROM, TPID channel 1, its output bit D105 moved to
Y0, which heats plant channel 0 — with the scans frozen and stepped through the simulator unit.
Auto-tuning from cold and the repression figures, the alarms and EN OFF, error 6705 for n and for
what a master writes into the blocks, and the operand errors at line and column."""

import pytest

from test_vb import (SIM, VB, check_config, coils, expect_config_error, freeze, regs, step,
                     write)
from conftest import REPO
from test_vb_entries import STILL, coil

M0 = 0
M1 = 1
Y0 = 13056
M9067 = 7680 + 67
SECOND = 100  # scans of 10 ms

OVEN = """modules: [VB-8T]
plant:
  channels:
    0: {{drive: Y0}}
init: {{D0: 1500, D100: 200, {init}}}
program:
  - FROM: {{en: M9000, m1: 1, m2: 32, d: D10, n: 1}}
  - TPID: {{en: M0, s1: D0, s2: D10, s3: D100, s4: D7100, n: {n}}}
  - MOV: {{en: M9000, s: D105, d: WY0}}
"""

TUNED = "D7100: 398, D7101: 130, D7102: 325"


def oven(start_plcemud, init, n="1"):
    """A frozen daemon running the oven with EN (M0) ON from the next scan; returns the client
    after that first scan (t = 0)."""
    d = start_plcemud(STILL + OVEN.format(init=init, n=n))
    c = d.client()
    freeze(c)
    coil(c, M0, True)
    step(c, 1)
    return c


def signed(v):
    return v - 0x10000 if v & 0x8000 else v


def test_auto_tuning_from_cold(start_plcemud):
    """Scenario "TPID auto-tuning": D104 = 1 with EN ON. Bit 0 of D104 stays 1 until 100 ± 10 s,
    then 0; D7100 ≈ 398, D7101 ≈ 130, D7102 ≈ 325 (± 20 %); the PV peaks at 162.4 ± 1.5 °C; the
    relay drives D110 between 1000 and 0 meanwhile; no operation error."""
    c = oven(start_plcemud, "D104: 1")
    t, peak, outputs = 0, 0, set()
    while regs(c, 104)[0] & 1:
        outputs.add(regs(c, 110)[0])
        step(c, SECOND)
        t += 1
        peak = max(peak, regs(c, 10)[0])
        assert t <= 200, "auto-tuning did not end"
    assert 90 <= t <= 110, t
    kp, ti, td = regs(c, 7100, 3)
    assert abs(kp - 398) <= 0.2 * 398 and abs(ti - 130) <= 0.2 * 130 and abs(td - 325) <= 0.2 * 325
    assert abs(peak - 1624) <= 15, peak
    assert outputs == {0, 1000}
    assert regs(c, 8067)[0] == 0 and not coils(c, M9067)[0]
    assert 0 < regs(c, 110)[0] < 1000  # normal control from the relay's mean output


def cold_start(start_plcemud, r, seconds):
    """The readings once a second from EN rising, with the tuned gains and repression R."""
    c = oven(start_plcemud, f"{TUNED}, D7103: {r}")
    pv = [regs(c, 10)[0]]
    for _ in range(seconds):
        step(c, SECOND)
        pv.append(regs(c, 10)[0])
    return pv


def test_without_repression_the_cold_start_overshoots(start_plcemud):
    """Scenario "TPID auto-tuning and repression", R = 0: peak ≥ 160 °C (reference 165.0)."""
    pv = cold_start(start_plcemud, 0, 200)
    assert max(pv) >= 1600, max(pv)


def test_repression_keeps_the_overshoot_small_and_settles(start_plcemud):
    """The same with D7103 = 100 (10.0 °C): peak ≤ 154 °C (reference 152.4-152.8), within ±2 °C
    from ≤ 100 s (reference 86 s), and D10 within 1490-1505 once a second at steady state
    (minutes 10-20)."""
    pv = cold_start(start_plcemud, 100, 1200)
    assert 1500 < max(pv) <= 1540, max(pv)
    outside = [t for t, v in enumerate(pv) if not 1480 <= v <= 1520]
    assert outside and outside[-1] <= 100, outside[-1:]
    steady = pv[600:]
    assert 1490 <= min(steady) and max(steady) <= 1505, (min(steady), max(steady))


def test_alarms_then_en_off(start_plcemud):
    """Scenario "TPID alarms and EN off": D7104 = 1550, D7105 = 50, R = 0. D106 b0 is 1 exactly
    while PV > 155.0 °C (reference 52-75 s), D107 b0 while |PV − SV| > 5.0 °C (last at reference
    75 s). Clearing EN while the alarms are ON gives D105 = 0, D110 = 0, D106 = D107 = 0 and Y0
    OFF at the next scan."""
    c = oven(start_plcemud, f"{TUNED}, D7104: 1550, D7105: 50")
    limit, deviation = [], []
    for t in range(1, 151):
        step(c, SECOND)
        pv = signed(regs(c, 10)[0])
        lim, dev = (w & 1 for w in regs(c, 106, 2))
        assert lim == (pv > 1550) and dev == (abs(pv - 1500) > 50), (t, pv, lim, dev)
        if lim:
            limit.append(t)
        if dev:
            deviation.append(t)
    assert abs(limit[0] - 52) <= 5 and abs(limit[-1] - 75) <= 5, (limit[0], limit[-1])
    assert abs(deviation[-1] - 75) <= 5, deviation[-1]

    c = oven(start_plcemud, f"{TUNED}, D7104: 1550, D7105: 50")
    for _ in range(100):  # to the limitation alarm, ~52 s
        if regs(c, 106)[0]:
            break
        step(c, SECOND)
    for _ in range(10 * SECOND):  # then scan by scan to a moment with the bit ON too
        if regs(c, 105, 3) == [1, 1, 1]:
            break
        step(c, 1)
    assert regs(c, 105, 3) == [1, 1, 1] and coils(c, Y0)[0]
    coil(c, M0, False)
    step(c, 1)
    assert regs(c, 105, 3) == [0, 0, 0]
    assert regs(c, 110)[0] == 0
    assert not coils(c, Y0)[0]


def test_n_outside_1_to_16_is_6705(start_plcemud, tmp_path):
    """Decision: n outside 1-16 loads, and is error 6705 (D9067, M9067, D9069 = the entry) at
    every scan with EN ON, the instruction not executing; n from a register acts as soon as a
    master writes it, and a valid n again resumes."""
    _, r = check_config(tmp_path, VB + OVEN.format(init="D104: 0", n="17"))
    assert r.returncode == 0, r.stderr
    c = oven(start_plcemud, f"{TUNED}, D20: 1", n="D20")
    step(c, 10 * SECOND)
    assert regs(c, 8067)[0] == 0
    assert regs(c, 110)[0] == 1000  # far below SV
    write(c, 20, 17)
    write(c, 110, 4321)
    step(c, 1)
    assert regs(c, 8067)[0] == 6705 and regs(c, 8069)[0] == 2 and coils(c, M9067)[0]
    write(c, 8067, 0)
    step(c, 3 * SECOND)
    assert regs(c, 8067)[0] == 6705
    assert regs(c, 110)[0] == 4321  # not executed: nothing written
    write(c, 8067, 0)
    write(c, 20, 1)
    step(c, 1)
    assert regs(c, 8067)[0] == 0
    assert regs(c, 110)[0] == 1000


def test_hostile_block_contents(start_plcemud):
    """What a master writes into the blocks — Tc = 0, sensitivity 8000h, a negative TI, Kp 32767,
    a PV of 32767 (a broken sensor) — neither stops the scan nor leaves the outputs outside
    0-1000; out-of-range values run at the nearest valid one with 6705."""
    c = oven(start_plcemud, TUNED)
    for addr, value in ((100, 0), (101, 0x8000), (7101, 0xFFFF), (7100, 32767), (7102, 0x8000)):
        write(c, addr, value)
        step(c, 2 * SECOND)
        assert 0 <= regs(c, 110)[0] <= 1000
        assert regs(c, 105)[0] in (0, 1)
    assert regs(c, 8067)[0] == 6705
    write(c, 100, 1, unit=SIM)  # channel 0's sensor broken (simulator unit): reads 32767
    step(c, 5 * SECOND)
    assert regs(c, 10)[0] == 32767
    assert regs(c, 110)[0] == 0 and regs(c, 106)[0] == 1  # heating off, limitation alarm ON


@pytest.mark.parametrize("program,key,needle", [
    ("  - TPID: {en: M0, s1: D0, s2: D10, s3: D7900, s4: D7000, n: 16}\n", "s3",
     "S3 needs 170 registers, D7900-D8069, inside D0-D7999"),
    ("  - TPID: {en: M0, s1: D0, s2: R10, s3: D100, s4: D7000, n: 1}\n", "s2", "TPID.s2"),
    ("  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D7000, n: 1}\n"
     "  - TPID: {en: M1, s1: D0, s2: D10, s3: D7005, s4: D300, n: 1}\n", "s3",
     "overlaps D7000-D7005 of the TPID at"),
])
def test_operand_errors_at_line_and_column(tmp_path, program, key, needle):
    text = VB + "program:\n" + program
    line_no = len(text.splitlines())
    last = text.splitlines()[-1]
    expect_config_error(tmp_path, text, line_no, last.index(f" {key}: ") + len(key) + 4, needle)


# --- config/vb-tpid.yaml: the manual's Example I -----------------------------------------------
EXAMPLE = (REPO / "config" / "vb-tpid.yaml").read_text()


def test_example_config_tunes_and_holds_245_c(start_plcemud):
    """config/vb-tpid.yaml as its header tells a SCADA engineer to run it: coil 10 (M10) starts
    auto-tuning; D104 returns to 0 after about 11 simulated minutes with gains in D7000-D7002,
    and the PID then holds D10 at 245.0 °C within the 10 s contactor cycle's ripple; Y1 (alarm
    above 280.0 °C) stays OFF."""
    d = start_plcemud(EXAMPLE)
    c = d.client()
    freeze(c)
    step(c, 3 * SECOND)  # past the example's 2 s module delay
    assert regs(c, 0)[0] == 2450 and regs(c, 100)[0] == 1000
    assert 240 <= regs(c, 10)[0] <= 260  # the oven at ambient, read through the VB-8T
    coil(c, 10, True)
    step(c, 1)
    assert regs(c, 104)[0] == 1
    t = 0
    while regs(c, 104)[0] & 1:
        step(c, 10 * SECOND)
        t += 10
        assert not coils(c, Y0 + 1)[0]
        assert t <= 1200, "auto-tuning did not end"
    assert 500 <= t <= 900, t
    kp, ti, td = regs(c, 7000, 3)
    assert kp > 1 and ti > 1 and td > 0, (kp, ti, td)
    pv = []
    for _ in range(1800):
        step(c, SECOND)
        pv.append(regs(c, 10)[0])
        assert not coils(c, Y0 + 1)[0]
    last = pv[-600:]
    assert 2435 <= min(last) and max(last) <= 2465, (min(last), max(last))
    assert abs(sum(last) / len(last) - 2450) <= 3
