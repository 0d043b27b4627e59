"""FNC88 PID (docs/profile-vb.md, "FNC88 PID") through Modbus TCP against the real daemon, in
frozen time stepped through the simulator unit. First with a Modbus master as the sensor (it
writes PV into D101): the operation errors (6730, 6732, 6735, 6740; none for Kp = 0 while
auto-tuning), the PV and MV change alarms in S3+24, relay auto-tuning on a scripted PV, and the
load errors of the block. Then on the plant, PV read by a VB-8T through FROM and D102 driving
the heater: auto-tuning from cold, the tuned step with and without the MV limit, and the change
alarms."""

import pytest

from test_vb import coils, expect_config_error, freeze, regs, step, write

M0, M9067 = 0, 7747  # coils
D9067, D9069 = 8067, 8069  # holding registers
SV, PV, MV, S3 = 100, 101, 102, 200

SCAN_S = 0.01
SAMPLING_SCANS = 200  # Ts 2000 ms

CONFIG = """profile: vb
modbus: {tcp: {bind: 127.0.0.1}}
time_scale: 0.001   # nearly still until frozen: the steps below are the whole run
program:
  - PID: {en: M0, s1: D100, s2: D101, s3: D200, d: D102}
init:
  D100: 1500
  D101: 1490
  D102: 150
  # Ts 2 s, S3+1, alpha 0, Kp 223 %, TI 13.0 s, KD 0, TD 3.25 s: the gains the manual's example
  # tunes to on the default plant
  D200: [2000, CONTROL, 0, 223, 130, 0, 325]
  D214: [500, 0]      # auto-tuning outputs for 100 % and 0 %
  D220: [20, 20, S3_22, S3_23]
"""


def start(start_plcemud, control, s3_22=500, s3_23=0):
    text = CONFIG.replace("CONTROL", str(control))
    d = start_plcemud(text.replace("S3_22", str(s3_22)).replace("S3_23", str(s3_23)))
    c = d.client()
    freeze(c)
    return c


def sint(v):
    return v - 0x10000 if v >= 0x8000 else v


def mv(c):
    return sint(regs(c, MV)[0])


def error(c):
    """M9067 and D9067."""
    return coils(c, M9067)[0], regs(c, D9067)[0]


def clear_error(c):
    write(c, D9067, 0)
    c.write_coil(M9067, False, slave=1)


def enable(c):
    r = c.write_coil(M0, True, slave=1)
    assert not r.isError()
    step(c, 1)  # the first execution


def test_operation_errors(start_plcemud):
    """docs/profile-vb.md, "Operation errors": a stopping code freezes D102 until the block is
    right again; 6740 samples at every scan; Kp = 0 is no error while auto-tuning."""
    c = start(start_plcemud, 0x21)  # Reverse, MV limit 0-500
    enable(c)
    step(c, 10 * SAMPLING_SCANS)
    assert error(c) == (False, 0)
    moving = mv(c)
    assert 150 < moving < 500  # the I term acts on PV 1.0 below SV

    write(c, S3, 0)  # Ts = 0
    step(c, 1)
    assert error(c) == (True, 6730)
    assert regs(c, D9069) == [1]  # the first program entry
    step(c, 5 * SAMPLING_SCANS)
    assert mv(c) == moving

    write(c, S3, 2000)
    clear_error(c)
    step(c, 5 * SAMPLING_SCANS + 1)
    assert error(c) == (False, 0)
    assert mv(c) > moving

    for offset, bad, code in ((2, 100, 6732), (5, 101, 6735)):
        write(c, S3 + offset, bad)
        step(c, 1)
        assert error(c) == (True, code), offset
        write(c, S3 + offset, 0)
        clear_error(c)

    # Ts = 5 ms, below the 10 ms scan: 6740 and a sampling at every scan (PV far below SV and
    # no limit, so the I term moves D102 by about 2 a scan).
    write(c, S3 + 1, 0x01)
    write(c, PV, 250)
    write(c, S3, 5)
    step(c, 2)
    before = mv(c)
    for _ in range(5):
        step(c, 1)
        now = mv(c)
        assert now != before
        before = now
    assert error(c) == (True, 6740)

    # Auto-tuning asked (b4) with Kp = 0: no 6733; the relay drives D102 to S3+14.
    write(c, S3, 2000)
    write(c, S3 + 1, 0x31)
    write(c, S3 + 3, 0)
    clear_error(c)
    step(c, 10 * SAMPLING_SCANS)
    assert error(c) == (False, 0)
    assert mv(c) == 500


def test_rerun_gives_the_instant_response_to_a_new_set_value(start_plcemud):
    """docs/profile-vb.md, "Rerun" (VB manual FNC88: "can rerun the PID instruction for the
    instant response of output value (D)"): Ts 2 s, Kp 100 %, TI 10 s, Reverse, PV 900; three
    samplings at SV 1000 leave D102 at 60. SV 1500 and M0 OFF then ON: D102 is 680 in the
    rising scan (P 500, I 120), stays there for Ts, then the I term adds 120."""
    c = start(start_plcemud, 0x01)  # Reverse, no alarm, no limit
    for offset, value in ((3, 100), (4, 100), (6, 0)):
        write(c, S3 + offset, value)
    write(c, SV, 1000)
    write(c, PV, 900)
    write(c, MV, 0)
    enable(c)
    step(c, 3 * SAMPLING_SCANS)
    assert mv(c) == 60

    write(c, SV, 1500)
    assert not c.write_coil(M0, False, slave=1).isError()
    step(c, 1)
    assert mv(c) == 60  # EN OFF keeps D
    assert not c.write_coil(M0, True, slave=1).isError()
    step(c, 1)
    assert mv(c) == 680
    step(c, SAMPLING_SCANS - 1)
    assert mv(c) == 680
    step(c, 1)
    assert mv(c) == 800
    assert error(c) == (False, 0)


def test_pv_change_alarm(start_plcemud):
    """S3+24 b0/b1: PV rose more than S3+20, fell more than S3+21 in one sampling (D201 =
    0023h, D220 = D221 = 20); re-evaluated at every sampling."""
    c = start(start_plcemud, 0x23)
    enable(c)
    step(c, SAMPLING_SCANS)
    assert regs(c, S3 + 24) == [0]
    write(c, PV, 1490 + 65)  # the steepest rise of the manual's example, per 2 s sampling
    step(c, SAMPLING_SCANS)
    assert regs(c, S3 + 24) == [0b01]
    step(c, SAMPLING_SCANS)  # PV unchanged: cleared
    assert regs(c, S3 + 24) == [0]
    write(c, PV, 1490)
    step(c, SAMPLING_SCANS)
    assert regs(c, S3 + 24) == [0b10]
    write(c, PV, 1491)
    step(c, SAMPLING_SCANS)
    assert regs(c, S3 + 24) == [0]


def test_mv_change_alarm_and_limit_precedence(start_plcemud):
    """S3+24 b2/b3 with b2 ON and b5 OFF (D222 = D223 = 50); with b5 ON as well the limit
    applies and b2/b3 stay 0."""
    c = start(start_plcemud, 0x05, 50, 50)  # Reverse, MV change alarm
    enable(c)
    step(c, SAMPLING_SCANS)
    write(c, PV, 1400)  # EV 10 -> 100: MV rises by hundreds
    step(c, SAMPLING_SCANS)
    assert regs(c, S3 + 24) == [0b0100]
    write(c, PV, 1500)  # EV 100 -> 0: MV falls by hundreds
    step(c, SAMPLING_SCANS)
    assert regs(c, S3 + 24) == [0b1000]

    write(c, S3 + 1, 0x25)  # b5 too: S3+22/23 are the limits 50/50
    write(c, PV, 1400)
    step(c, SAMPLING_SCANS)
    assert regs(c, S3 + 24) == [0]
    assert mv(c) == 50
    assert error(c) == (False, 0)


# A triangle PV of period 20 s and +/-5.0 degrees around SV = 150.0, one value per second
# (docs/profile-vb.md, "Auto-tuning"): the relay falls at 20, 40 and 60 s, and the second cycle
# gives tau = 20 s, tau_on = 9 s, a = 100, so Kp = round(60 * 4 * 500 / (pi * 100)) = 382,
# TI = 5 * tau = 100, TD = 12.5 * tau = 250, D = round(500 * 9 / 20) = 225.
SHAPE = [0, 10, 20, 30, 40, 50, 40, 30, 20, 10, 0, -10, -20, -30, -40, -50, -40, -30, -20, -10]


def test_auto_tuning_on_a_scripted_pv(start_plcemud):
    c = start(start_plcemud, 0x31)  # Reverse, auto-tuning, limit
    write(c, S3, 1000)  # Ts 1 s
    for offset in (3, 4, 6):
        write(c, S3 + offset, 0)
    write(c, PV, 1500)
    enable(c)
    assert mv(c) == 0  # PV not below SV: the relay's low output at once
    for k in range(1, 61):
        write(c, PV, 1500 + SHAPE[k % 20])
        step(c, 100)
        if k < 60:
            assert regs(c, S3 + 1)[0] & 0x10, k
            assert mv(c) == (500 if SHAPE[k % 20] < 0 else 0), k
    assert regs(c, S3 + 1) == [0x21]
    assert [sint(v) for v in regs(c, S3 + 3, 4)] == [382, 100, 0, 250]
    assert mv(c) == 225
    assert error(c) == (False, 0)


def test_auto_tuning_needs_the_high_output_above_the_low(start_plcemud):
    """S3+14 <= S3+15: no tuning, b4 cleared, 6750."""
    c = start(start_plcemud, 0x31)
    write(c, S3 + 14, 0)
    enable(c)
    assert regs(c, S3 + 1) == [0x21]
    assert error(c) == (True, 6750)


def test_overlapping_parameter_blocks_are_a_config_error(tmp_path):
    text = """profile: vb
program:
  - PID: {en: M0, s1: D100, s2: D101, s3: D200, d: D102}
  - PID: {en: M1, s1: D110, s2: D111, s3: D224, d: D112}
"""
    expect_config_error(tmp_path, text, 4, 43,
                        "D224-D248 overlaps D200-D224, owned by the PID at")


@pytest.mark.parametrize("s3,col", [("D7976", 43), ("D9000", 43)])
def test_parameter_block_outside_d0_to_d7999_is_a_config_error(tmp_path, s3, col):
    text = f"""profile: vb
program:
  - PID: {{en: M0, s1: D100, s2: D101, s3: {s3}, d: D102}}
"""
    expect_config_error(tmp_path, text, 3, col, "S3 needs 25 registers in D0-D7999")


# --- the loop on the plant: a VB-8T reads channel 0 into D101 (FROM), D102 drives its heater
# with 500 = full power (docs/profile-vb.md, "Auto-tuning", whose figures these are) ----------

PLANT = """profile: vb
modbus: {tcp: {bind: 127.0.0.1}}
time_scale: 0.001   # nearly still until frozen: the steps below are the whole run
modules: [VB-8T]
plant:
  channels:
    0: {drive: D102, drive_full_scale: 500}
program:
  - FROM: {en: M9000, m1: 1, m2: 32, d: D101, n: 1}
  - PID: {en: M0, s1: D100, s2: D101, s3: D200, d: D102}
init:
  D100: 1500
  D200: [2000, CONTROL, 0, KP, TI, 0, TD]
  D214: [500, 0]
  D220: [20, 20, S3_22, 0]
"""


def start_plant(start_plcemud, control, kp=0, ti=0, td=0, s3_22=500):
    text = PLANT.replace("CONTROL", str(control)).replace("KP", str(kp))
    text = text.replace("TI", str(ti)).replace("TD", str(td)).replace("S3_22", str(s3_22))
    c = start_plcemud(text).client()
    freeze(c)
    c.write_coil(M0, True, slave=1)
    return c


class Sample:
    """The loop after a step: time, PV, MV, the block, M9067."""

    def __init__(self, c, t):
        self.t = t
        self.pv, self.mv = (sint(v) for v in regs(c, PV, 2))
        self.block = [sint(v) for v in regs(c, S3, 25)]
        self.error = coils(c, M9067)[0]


def samples(c, t0, seconds, every=1):
    """Steps `seconds` of simulated time from `t0`, a sample every `every` s."""
    for k in range(1, int(seconds / every) + 1):
        step(c, int(every / SCAN_S))
        yield Sample(c, t0 + k * every)


def settled(run, low, high):
    """The time of the last sample outside [low, high] (the run's start when none)."""
    outside = [s.t for s in run if not low <= s.pv <= high]
    return outside[-1] if outside else run[0].t


def test_auto_tune_from_cold(start_plcemud):
    """D201 = 0031h (Reverse, auto-tuning, limit 0-500), Kp = TI = TD = 0, PV 25 degrees: b4
    clears at 100 s with Kp 223, TI 130, TD 325 and D102 = 154; PV peaks at 162.4 degrees
    during the tuning, is within 148.0-152.0 from 27 s after it and 149.7-150.3 in minutes
    20-30; M9067 stays OFF."""
    c = start_plant(start_plcemud, 0x31)
    tuning = []
    for s in samples(c, 0, 200):
        tuning.append(s)
        if not s.block[1] & 0x10:
            break
    done = tuning[-1]
    assert 90 <= done.t <= 110
    kp, ti, td = done.block[3], done.block[4], done.block[6]
    assert 223 * 0.85 <= kp <= 223 * 1.15
    assert 130 * 0.8 <= ti <= 130 * 1.2
    assert 325 * 0.8 <= td <= 325 * 1.2
    assert 144 <= done.mv <= 164
    assert 1609 <= max(s.pv for s in tuning) <= 1639
    after = list(samples(c, done.t, 120))
    assert settled(after, 1480, 1520) - done.t <= 60
    run = list(samples(c, done.t + 120, 1800 - done.t - 120, every=5))
    late = [s for s in run if s.t >= 1200]
    assert all(1497 <= s.pv <= 1503 for s in late), [s.pv for s in late]
    assert not any(s.error for s in tuning + after + run)


def test_tuned_step(start_plcemud):
    """D201 = 0021h with the tuned gains from 25 degrees: 149.0 reached at 54 +/- 5 s, peak at
    most 156.0, within 148.0-152.0 from at most 100 s, 149.5-150.5 in minutes 20-30."""
    c = start_plant(start_plcemud, 0x21, 223, 130, 325)
    run = list(samples(c, 0, 300))
    reached = next(s.t for s in run if s.pv >= 1490)
    assert 49 <= reached <= 59
    assert max(s.pv for s in run) <= 1560
    assert settled(run, 1480, 1520) <= 100
    late = [s for s in samples(c, 300, 1500, every=5) if s.t >= 1200]
    assert all(1495 <= s.pv <= 1505 for s in late), [s.pv for s in late]


def test_tuned_step_without_the_limit_winds_up(start_plcemud):
    """D201 = 0001h: the velocity form winds D102 up far past 500 and PV peaks near 215
    degrees: the limit is what makes the step behave."""
    c = start_plant(start_plcemud, 0x01, 223, 130, 325)
    run = list(samples(c, 0, 400))
    assert max(s.mv for s in run) > 2000  # ref. 3306
    assert 2121 <= max(s.pv for s in run) <= 2181  # ref. 215.1


def test_change_alarms_on_the_plant(start_plcemud):
    """D201 = 0023h, D220 = D221 = 20: D224 b0 during the rise, 0 at steady state. With b2 and
    no b5 (D201 = 0005h, D222 = 50): D224 b2 at the first sampling."""
    c = start_plant(start_plcemud, 0x23, 223, 130, 325)
    rise = list(samples(c, 0, 120))
    assert any(s.block[24] & 0b01 for s in rise)
    step(c, int(1200 / SCAN_S))
    assert regs(c, S3 + 24) == [0]

    c = start_plant(start_plcemud, 0x05, 223, 130, 325, s3_22=50)
    step(c, 1 + SAMPLING_SCANS)  # the first execution, then the first sampling
    assert regs(c, S3 + 24)[0] & 0b0100
