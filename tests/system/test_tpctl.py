"""FUN86 TPCTL over Modbus (SPEC §5, seed 000 §21.7): config/default.yaml's ten loops, driven the
way the manual's program example describes and a SCADA would do it, at --time-scale 100."""

import time

import pytest

from conftest import REPO, run_plcemud

DEFAULT_YAML = (REPO / "config" / "default.yaml").read_text()
TIME_SCALE = "100"
POINTS = 10

# Wire addresses (SPEC §2): R0-R4167 are holding registers 0-4167, D0 is 6000; Y0 is coil 0,
# M0 is coil 2000.
R_READING = 0  # readings of channels 0-9 (table SR+2 = 10000)
R_SV = 100
R_PR, R_IR, R_DR = 120, 130, 140
R_OR = 200
R_WR = 300
R4005 = 4005
D_TEMP_WR = 6000  # the measurement's working registers (SR+3 = 20000): execute code
COIL_Y30 = 30
COIL_M0 = 2000
COIL_M800 = 2800
COIL_ERR = 2100  # M100
COIL_ALM = 2101  # M101
SIM = 247  # simulator-control unit: 1 freeze, 2 step N scans
SIM_FREEZE, SIM_STEP = 1, 2

TIMEOUT_S = 90.0  # real time; the loops need about 2 simulated minutes (1.2 s at 100x)


def regs(c, address, count=1):
    rr = c.read_holding_registers(address, count, slave=1)
    assert not rr.isError(), rr
    return rr.registers


def coils(c, address, count=1):
    rr = c.read_coils(address, count, slave=1)
    assert not rr.isError(), rr
    return rr.bits[:count]


def signed(v):
    return v - 0x10000 if v & 0x8000 else v


def wait_until(predicate, what, timeout=TIMEOUT_S):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.05)
    pytest.fail(f"timed out waiting for {what}")


def start_loops(c):
    """What the manual's example leaves to the MMI: M800-M809 (which points run PID, copied to
    R4012 by the MOV) and M0 (EN). R4005 is preset by config/default.yaml (README, "FUN86
    TPCTL": the default 4 s solution interval limit-cycles on the default plant)."""
    assert not c.write_coils(COIL_M800, [True] * POINTS, slave=1).isError()
    assert not c.write_coil(COIL_M0, True, slave=1).isError()


def settled(c, expected=0x03FF, hold_s=2.0):
    """Waits until the in-zone bits (WR+0) read `expected` (all ten: 03FFh) without a break for
    `hold_s` real seconds (200 simulated): the first entries into the zone may still be followed
    by a small overshoot out of it."""
    deadline = time.monotonic() + TIMEOUT_S
    since = None
    while time.monotonic() < deadline:
        now = time.monotonic()
        if regs(c, R_WR)[0] == expected:
            since = now if since is None else since
            if now - since >= hold_s:
                return
        else:
            since = None
        time.sleep(0.02)
    pytest.fail(f"R300 was not {expected:04X}h for {hold_s} s in a row (it is "
                f"{regs(c, R_WR)[0]:04X}h)")


def y_seen(c, seconds=1.0):
    """For each of Y30-Y39, whether it was seen ON and seen OFF while sampling."""
    on, off = [False] * POINTS, [False] * POINTS
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        for i, b in enumerate(coils(c, COIL_Y30, POINTS)):
            on[i] |= b
            off[i] |= not b
    return on, off


@pytest.fixture
def plc(start_plcemud):
    d = start_plcemud(DEFAULT_YAML, "--time-scale", TIME_SCALE)
    c = d.client()
    # The measurement is running (execute code 56h) and the loops are still cold.
    wait_until(lambda: regs(c, D_TEMP_WR)[0] >> 8 == 0x56, "temperature execute code 56h")
    return d, c


def test_ten_loops_heat_from_ambient_and_settle_in_zone(plc):
    d, c = plc
    # default.yaml presets R4005 = 0000h (1 s solution interval, 1 s PWM cycle) over the
    # SPEC §5 default 0102h.
    assert regs(c, R4005)[0] == 0x0000
    cold = [signed(v) for v in regs(c, R_READING, POINTS)]
    assert all(200 <= v <= 300 for v in cold), cold  # 25 °C ambient
    assert regs(c, R_OR, POINTS) == [0] * POINTS  # EN = 0: outputs off
    assert coils(c, COIL_Y30, POINTS) == [False] * POINTS

    # The first second after EN, frozen and stepped so it can be looked at: cold, so full output
    # (Kc·E = 110 × 1250 saturates), every PWM output ON, out of zone so ALM is ON.
    assert not c.write_register(SIM_FREEZE, 1, slave=SIM).isError()
    start_loops(c)
    assert not c.write_register(SIM_STEP, 100, slave=SIM).isError()  # 100 scans: 1 s
    assert regs(c, R_OR, POINTS) == [16383] * POINTS
    assert coils(c, COIL_Y30, POINTS) == [True] * POINTS
    assert coils(c, COIL_ALM)[0]
    assert not coils(c, COIL_ERR)[0]
    # First execution gave the manual's default gains (PR was 0).
    assert regs(c, R_PR, POINTS) == [110] * POINTS
    assert regs(c, R_IR, POINTS) == [17] * POINTS
    assert regs(c, R_DR, POINTS) == [50] * POINTS
    assert not c.write_register(SIM_FREEZE, 0, slave=SIM).isError()

    settled(c)
    readings = [signed(v) for v in regs(c, R_READING, POINTS)]
    assert all(1450 <= v <= 1550 for v in readings), readings
    # Holding 150 °C on a 400 °C full-power plant takes 31 % of full scale (5120) on average; the
    # output itself moves with every 0.1° of reading (the derivative), so average samples.
    samples = []
    deadline = time.monotonic() + 3.0  # 300 simulated seconds
    while time.monotonic() < deadline:
        samples.append(regs(c, R_OR, POINTS))
        time.sleep(0.01)
    mean = [sum(s[i] for s in samples) / len(samples) for i in range(POINTS)]
    assert all(4000 < m < 6500 for m in mean), mean
    assert regs(c, R_WR + 2, 2) == [0, 0]  # no warnings
    assert not coils(c, COIL_ALM)[0]
    # Partial output: every PWM output both ON and OFF within a second (100 simulated).
    on, off = y_seen(c)
    assert all(on) and all(off), (on, off)


def test_a_changed_setpoint_is_followed(plc):
    d, c = plc
    start_loops(c)
    settled(c)
    assert not c.write_register(R_SV, 1000, slave=1).isError()  # point 0: 100.0 °C
    wait_until(lambda: regs(c, R_WR)[0] & 1 == 0, "point 0 out of zone after the change")
    assert coils(c, COIL_ALM)[0]
    assert regs(c, R_WR)[0] == 0x03FE  # the others stay in zone
    # Heating only: the output goes to 0 and the plant cools down to the new zone.
    wait_until(lambda: regs(c, R_OR)[0] == 0, "point 0's output off above its new SP")
    wait_until(lambda: regs(c, R_WR)[0] == 0x03FF, "point 0 back in zone at 100.0 °C")
    assert 950 <= signed(regs(c, R_READING)[0]) <= 1050
    wait_until(lambda: not coils(c, COIL_ALM)[0], "ALM off again")


def test_en_off_turns_every_output_off(plc):
    d, c = plc
    start_loops(c)
    wait_until(lambda: any(coils(c, COIL_Y30, POINTS)), "PWM outputs on")
    assert not c.write_coil(COIL_M0, False, slave=1).isError()
    wait_until(lambda: regs(c, R_OR, POINTS) == [0] * POINTS, "OR 0 after EN off")
    on, _ = y_seen(c, 0.5)
    assert not any(on), on
    assert regs(c, R_WR, 9) == [0] * 9
    assert not coils(c, COIL_ALM)[0]
    # EN on again: the loops restart.
    assert not c.write_coil(COIL_M0, True, slave=1).isError()
    wait_until(lambda: any(v > 0 for v in regs(c, R_OR, POINTS)), "outputs after EN on")


def test_r4012_bit_off_leaves_that_point_without_pid(plc):
    d, c = plc
    start_loops(c)
    assert not c.write_coil(COIL_M800 + 4, False, slave=1).isError()  # R4012 bit 4 via the MOV
    settled(c, expected=0x03EF)  # the nine enabled points in zone, point 4 not
    assert regs(c, R_OR + 4)[0] == 0
    on, _ = y_seen(c, 0.5)
    assert not on[4] and all(on[i] for i in range(POINTS) if i != 4), on
    assert not coils(c, COIL_ALM)[0]  # a point without PID does not alarm
    assert signed(regs(c, R_READING + 4)[0]) < 400  # still near ambient


def test_bad_sn_zn_is_not_executed_and_sets_err(start_plcemud):
    # Sn + Zn = 40 > 32: the config loads (as a PLC program with a bad constant would), the
    # instruction is not executed and ERR (M100) is ON.
    text = DEFAULT_YAML.replace("sn: 0, zn: 10", "sn: 30, zn: 10")
    assert text != DEFAULT_YAML
    d = start_plcemud(text, "--time-scale", TIME_SCALE)
    c = d.client()
    start_loops(c)
    wait_until(lambda: coils(c, COIL_ERR)[0], "ERR (M100) on")
    time.sleep(0.5)
    assert coils(c, COIL_ERR)[0]
    assert not coils(c, COIL_ALM)[0]
    assert regs(c, R_OR, POINTS) == [0] * POINTS
    assert coils(c, COIL_Y30, POINTS) == [False] * POINTS
    assert regs(c, R_PR, POINTS) == [0] * POINTS  # not executed: no default gains either


def test_repeated_working_registers_are_refused_at_load(tmp_path):
    # Manual: WR "can't be repeated in using". A second TPCTL on R305 overlaps R300-R308.
    second = ("  - TPCTL: {en: M2, hc: 1, sn: 10, zn: 2, yn: Y40, sv: R400, os: R410, "
              "pr: R420, ir: R430, dr: R440, or: R450, wr: R305}\n")
    p = tmp_path / "twice.yaml"
    p.write_text(DEFAULT_YAML + second)
    line = len(DEFAULT_YAML.splitlines()) + 1
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2, r
    assert f"twice.yaml:{line}:" in r.stderr, r.stderr
    assert "TPCTL.wr" in r.stderr and "can't be repeated" in r.stderr, r.stderr
