"""FUN86 TPCTL over Modbus (FBs manual §21.7): config/default.yaml's ten loops, driven the way
the manual's program example describes and a SCADA would do it. The slow plant of that file
(τ 1200 s, θ 60 s) is fast-forwarded with the simulator unit's freeze and step registers."""

import time

import pytest

from conftest import REPO, free_port, run_plcemud

DEFAULT_YAML = (REPO / "config" / "default.yaml").read_text()
TIME_SCALE = "100"
POINTS = 10

# Wire addresses (docs/profile-fbs.md, "Modbus map"): R0-R4167 are holding registers 0-4167, D0 is 6000;
# Y0 is coil 0, M0 is coil 2000.
R_READING = 0  # readings of channels 0-9 (table SR+2 = 10000)
R_SV = 100
R_PR, R_IR, R_DR = 120, 130, 140
R_OR = 200
R_WR = 300
R4005 = 4005
R4008 = 4008
D_TEMP_WR = 6000  # the measurement's working registers (SR+3 = 20000): execute code
COIL_Y30 = 30
COIL_M0 = 2000
COIL_M400 = 2400  # the example's in-zone indicators M400-M409 (WR+0)
COIL_M416 = 2416  # the example's warning indicators M416-M425 (WR+2)
COIL_M800 = 2800
COIL_ERR = 2100  # M100
COIL_ALM = 2101  # M101
SIM = 247  # simulator-control unit: 0 time scale, 1 freeze, 2 step N scans, 3-4 seconds
SIM_SCALE, SIM_FREEZE, SIM_STEP, SIM_SECONDS = 0, 1, 2, 3
SIM_FAULTS = 100  # + 10c: b0 sensor broken, b1 heater open, b2 heater shorted
SCAN_MS = 10
SETTLED_S = 3000  # the example's loops are within SP ± 5.0 °C by 50 simulated minutes

TIMEOUT_S = 60.0  # real time
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


def sim_seconds(c):
    lo, hi = c.read_holding_registers(SIM_SECONDS, 2, slave=SIM).registers
    return lo | hi << 16


def advance(c, seconds):
    """Runs `seconds` (whole) of simulated time through unit 247's step register. The reply
    comes before the scans ran, so this polls the simulated time until it moved on."""
    target = sim_seconds(c) + seconds
    n = seconds * 1000 // SCAN_MS
    while n > 0:
        k = min(n, 60000)
        assert not c.write_register(SIM_STEP, k, slave=SIM).isError()
        n -= k
    wait_until(lambda: sim_seconds(c) >= target - 1, f"simulated time {target} s")
    time.sleep(0.1)  # the last second's scans (the clock may sit a scan behind a whole second)


def advance_until(c, predicate, what, limit_s, chunk_s=10):
    """Steps `chunk_s` at a time until `predicate()` holds; at most `limit_s` simulated s."""
    for _ in range(0, limit_s, chunk_s):
        if predicate():
            return
        advance(c, chunk_s)
    if not predicate():
        pytest.fail(f"{what}: not within {limit_s} simulated s")


def frozen_loops(c):
    """Freezes the simulation, starts the loops and steps past the first solution."""
    assert not c.write_register(SIM_FREEZE, 1, slave=SIM).isError()
    start_loops(c)
    advance(c, 1)


def start_loops(c):
    """What the manual's example leaves to the MMI: M800-M809 (which points run PID, copied to
    R4012 by the MOV) and M0 (EN). R4005 stays at the system default 0102h."""
    assert not c.write_coils(COIL_M800, [True] * POINTS, slave=1).isError()
    assert not c.write_coil(COIL_M0, True, slave=1).isError()


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
    d = start_plcemud(DEFAULT_YAML, "--time-scale", TIME_SCALE,
                      "--http-port", str(free_port()))
    c = d.client()
    # The measurement is running (execute code 56h) and the loops are still cold.
    wait_until(lambda: regs(c, D_TEMP_WR)[0] >> 8 == 0x56, "temperature execute code 56h")
    return d, c


def test_ten_loops_heat_from_ambient_and_settle_in_zone(plc):
    d, c = plc
    # default.yaml leaves R4005 at the system default 0102h (4 s solution interval, 2 s PWM).
    assert regs(c, R4005)[0] == 0x0102
    cold = [signed(v) for v in regs(c, R_READING, POINTS)]
    assert all(200 <= v <= 300 for v in cold), cold  # 25 °C ambient
    assert regs(c, R_OR, POINTS) == [0] * POINTS  # EN = 0: outputs off
    assert coils(c, COIL_Y30, POINTS) == [False] * POINTS

    # The first second after EN, frozen and stepped so it can be looked at: cold, so full output
    # (Kc·E = 110 × 1250 saturates), every PWM output ON, out of zone so ALM is ON.
    frozen_loops(c)
    t0 = sim_seconds(c)
    assert regs(c, R_OR, POINTS) == [16383] * POINTS
    assert coils(c, COIL_Y30, POINTS) == [True] * POINTS
    assert coils(c, COIL_ALM)[0]
    assert not coils(c, COIL_ERR)[0]
    assert regs(c, R_WR + 4)[0] == 0x0204  # in effect: PWM 2 s, solution 4 s
    # First execution gave the manual's default gains (PR was 0).
    assert regs(c, R_PR, POINTS) == [110] * POINTS
    assert regs(c, R_IR, POINTS) == [17] * POINTS
    assert regs(c, R_DR, POINTS) == [50] * POINTS
    assert coils(c, COIL_M400, 16) == [False] * 16  # the example's indicators: none in zone

    # 50 simulated minutes: every loop within SP ± 5.0 °C, ALM off, indicators as WR+0/WR+2.
    advance(c, SETTLED_S - (sim_seconds(c) - t0) - 1)
    readings = [signed(v) for v in regs(c, R_READING, POINTS)]
    assert all(1450 <= v <= 1550 for v in readings), readings
    assert regs(c, R_WR, 4) == [0x03FF, 0, 0, 0]
    assert not coils(c, COIL_ALM)[0]
    assert coils(c, COIL_M400, 16) == [True] * POINTS + [False] * 6
    assert coils(c, COIL_M416, 16) == [False] * 16
    # And they stay there: five more minutes in 10 s steps. Holding 150 °C on a 400 °C
    # full-power plant takes 31 % of full scale (5120) on average.
    samples = []
    for _ in range(30):
        advance(c, 10)
        readings = [signed(v) for v in regs(c, R_READING, POINTS)]
        assert all(1450 <= v <= 1550 for v in readings), readings
        assert not coils(c, COIL_ALM)[0]
        samples.append(regs(c, R_OR, POINTS))
    mean = [sum(s[i] for s in samples) / len(samples) for i in range(POINTS)]
    assert all(4000 < m < 6500 for m in mean), mean
    # Partial output: running again at 100x, every PWM output both ON and OFF within a second.
    assert not c.write_register(SIM_FREEZE, 0, slave=SIM).isError()
    on, off = y_seen(c)
    assert all(on) and all(off), (on, off)


def test_heater_shorted_lights_its_warning_indicator(plc):
    # Manual's example: "M416~M425: the highest temperature warning or heating abnormal
    # channel". A shorted heater on channel 3 past R4008 (here 170.0 °C, so the slow plant gets
    # there in minutes) sets WR+2 bit 3, so M419 and ALM; the other indicators stay off.
    d, c = plc
    frozen_loops(c)
    advance(c, SETTLED_S)
    assert regs(c, R_WR)[0] == 0x03FF
    assert not c.write_register(R4008, 1700, slave=1).isError()
    assert not c.write_register(SIM_FAULTS + 10 * 3, 0b0100, slave=SIM).isError()
    advance_until(c, lambda: coils(c, COIL_M416 + 3)[0], "M419", 900)
    assert coils(c, COIL_M416, 16) == [i == 3 for i in range(16)]
    assert regs(c, R_WR + 2)[0] == 1 << 3
    assert signed(regs(c, R_READING + 3)[0]) >= 1700
    assert coils(c, COIL_ALM)[0]
    assert not coils(c, COIL_M400 + 3)[0]  # and out of zone
    # Repaired: the process cools below R4008 and the indicator goes out.
    assert not c.write_register(SIM_FAULTS + 10 * 3, 0, slave=SIM).isError()
    advance_until(c, lambda: not coils(c, COIL_M416 + 3)[0], "M419 off", 900)
    assert regs(c, R_WR + 2)[0] == 0


def test_a_changed_setpoint_is_followed(plc):
    d, c = plc
    frozen_loops(c)
    advance(c, SETTLED_S)
    assert regs(c, R_WR)[0] == 0x03FF
    assert not c.write_register(R_SV, 1000, slave=1).isError()  # point 0: 100.0 °C
    advance(c, 1)
    assert regs(c, R_WR)[0] == 0x03FE  # point 0 out of zone, the others stay in
    assert coils(c, COIL_ALM)[0]
    assert coils(c, COIL_M400, POINTS) == [False] + [True] * (POINTS - 1)
    # Heating only: the output goes to 0 and the plant cools down to the new zone.
    advance_until(c, lambda: regs(c, R_OR)[0] == 0, "point 0's output off", 60, chunk_s=1)
    advance_until(c, lambda: regs(c, R_WR)[0] == 0x03FF, "point 0 back in zone", 1800)
    assert 950 <= signed(regs(c, R_READING)[0]) <= 1050
    assert not coils(c, COIL_ALM)[0]


def test_en_off_turns_every_output_off(plc):
    d, c = plc
    frozen_loops(c)
    assert all(coils(c, COIL_Y30, POINTS))  # cold: full output
    assert not c.write_coil(COIL_M0, False, slave=1).isError()
    advance(c, 1)
    assert regs(c, R_OR, POINTS) == [0] * POINTS
    assert not any(coils(c, COIL_Y30, POINTS))
    assert regs(c, R_WR, 9) == [0] * 9
    assert not coils(c, COIL_ALM)[0]
    assert coils(c, COIL_M400, 16) == [False] * 16
    # EN on again: the loops restart.
    assert not c.write_coil(COIL_M0, True, slave=1).isError()
    advance(c, 1)
    assert all(v > 0 for v in regs(c, R_OR, POINTS))


def test_r4012_bit_off_leaves_that_point_without_pid(plc):
    d, c = plc
    assert not c.write_register(SIM_FREEZE, 1, slave=SIM).isError()
    start_loops(c)
    assert not c.write_coil(COIL_M800 + 4, False, slave=1).isError()  # R4012 bit 4 via the MOV
    advance(c, SETTLED_S)
    assert regs(c, R_WR)[0] == 0x03EF  # the nine enabled points in zone, point 4 not
    assert regs(c, R_OR + 4)[0] == 0
    assert not coils(c, COIL_Y30 + 4)[0]
    assert not coils(c, COIL_ALM)[0]  # a point without PID does not alarm
    assert signed(regs(c, R_READING + 4)[0]) < 400  # still near ambient


def test_b_thermocouple_at_room_temperature_reads_its_range_floor_and_heats(start_plcemud):
    # A B thermocouple's range starts at 350 °C (manual §21.1): at room temperature it reads
    # 350.0 °C, not a broken line (docs/profile-fbs.md decision), so FUN86 heats it towards a 400.0 °C SP.
    text = DEFAULT_YAML.replace("0x0101, 0x0002]", "0x0501, 0x0002]")  # TC6 with type B
    assert text != DEFAULT_YAML
    d = start_plcemud(text, "--time-scale", TIME_SCALE,
                      "--http-port", str(free_port()))
    c = d.client()
    assert not c.write_register(SIM_FREEZE, 1, slave=SIM).isError()
    assert not c.write_register(R_SV, 4000, slave=1).isError()
    advance(c, 5)
    assert regs(c, R_READING)[0] == 3500
    assert regs(c, D_TEMP_WR + 1)[0] == 0  # no sensor-abnormal bit
    start_loops(c)
    advance(c, 1)
    assert regs(c, R_OR)[0] == 16383 and coils(c, COIL_Y30)[0]
    advance(c, 120)
    true_t = c.read_holding_registers(SIM_FAULTS + 6, 1, slave=SIM).registers[0]
    assert signed(true_t) > 300  # the process heats (channel 0's true T, 0.1 °C)
    # An open sensor is the broken line: 32767, abnormal bit, output off.
    assert not c.write_register(SIM_FAULTS, 0b0001, slave=SIM).isError()
    advance(c, 5)
    assert regs(c, R_READING)[0] == 32767
    assert regs(c, D_TEMP_WR + 1)[0] == 1
    assert regs(c, R_OR)[0] == 0


def test_bad_sn_zn_is_not_executed_and_sets_err(start_plcemud):
    # Sn + Zn = 40 > 32: the config loads (as a PLC program with a bad constant would), the
    # instruction is not executed and ERR (M100) is ON.
    text = DEFAULT_YAML.replace("sn: 0, zn: 10", "sn: 30, zn: 10")
    assert text != DEFAULT_YAML
    d = start_plcemud(text, "--time-scale", TIME_SCALE,
                      "--http-port", str(free_port()))
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


@pytest.mark.parametrize(
    "old, new, operand",
    [
        ("yn: Y30", "yn: Y10", "TPCTL.yn"),  # the TC6's own Y10-Y17
        ("err: M100", "err: Y25", "TPCTL.err"),  # the RTD6's last output
        ("d: WM400}", "d: WY10}", "MOV.d"),  # a word move onto Y10-Y25
    ],
)
def test_outputs_on_a_temperature_modules_own_outputs_are_refused(tmp_path, old, new, operand):
    # FBs manual §21.3: "each module occupies 1 IR and 8 DO"; after the FBs-24MC's Y0-Y9 the
    # TC6 has Y10-Y17 and the RTD6 Y18-Y25 (WR+4k of the measurement shows where they start).
    text = DEFAULT_YAML.replace(old, new, 1)
    assert text != DEFAULT_YAML
    p = tmp_path / "chain.yaml"
    p.write_text(text)
    line_no = next(i for i, line in enumerate(text.splitlines(), 1) if new in line)
    col = text.splitlines()[line_no - 1].index(new.split(": ")[1]) + 1
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2, r
    assert f"chain.yaml:{line_no}:{col}: " in r.stderr, r.stderr
    assert operand in r.stderr and "temperature modules" in r.stderr, r.stderr
