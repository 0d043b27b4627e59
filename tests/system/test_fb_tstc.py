"""FUN73 TSTC of profile fb (docs/profile-fb.md, "FUN73 TSTC") through Modbus TCP against the real
daemon, frozen and stepped through the simulator unit (FB manual FUN73): ERR and the gating of
PID on every point read, the 4-point closed loop on the default plant, zone and warnings,
R4005's codes, and the devices it shares with a TP4 checked at load."""

from test_fb_tp4 import FB, ROUND, on, s16, tp4
from test_vb import SIM, coils, freeze, regs, step, write

SCANS_PER_S = 100  # scan_ms 10
SIM_FAULTS = 100  # + 10c: b0 sensor broken, b1 heater open, b2 heater shorted
SIM_TRUE = 106  # + 10c: true temperature, 0.1 degC
SIM_POWER = 107  # + 10c: heater power, 0.1 %


def tstc(sm=0, sh=0, zh=4, tp=0, pl=0, yh="Y48"):
    return (f"  - TSTC: {{en: M0, hc: 1, tp: {tp}, pl: {pl}, sm: {sm}, ym: Y16, ar: R3842, "
            f"tr: R0, yh: {yh}, sh: {sh}, zh: {zh}, sv: R100, os: R120, pr: R140, ir: R160, "
            "dr: R180, or: R300, wr: R200, err: M100, ao0: M101, ao1: M102}\n")


def start(start_plcemud, program, plant=""):
    d = start_plcemud(FB + plant + "program:\n" + program)
    c = d.client()
    freeze(c)
    return c


def fill(c, addr, value, n=4):
    for i in range(n):
        write(c, addr + i, value)


def s8_gains(c, n=4):
    """The closed loop's set-up: SP 150, offset 5, Kc 60, Ti 17, Td 0."""
    fill(c, 100, 150, n)
    fill(c, 120, 5, n)
    fill(c, 140, 60, n)
    fill(c, 160, 17, n)
    fill(c, 180, 0, n)


def test_s7_err_for_sh_zh_and_sh_below_sm(start_plcemud):
    """FB manual FUN73: sh 0 with sm 4, zh 0, sh + zh = 33 -> ERR at every scan whatever EN, nothing
    else written."""
    for bad in ({"sm": 4, "sh": 0}, {"zh": 0}, {"sh": 1, "zh": 32}):
        c = start(start_plcemud, tstc(**bad))
        step(c, 5)
        assert coils(c, 2100) == [True], bad
        on(c, 0)
        step(c, 300)
        assert coils(c, 2100) == [True], bad
        assert regs(c, 3968, 4) == [0] * 4, bad
        assert regs(c, 140) == [0], bad
        assert coils(c, 16, 8) == [False] * 8, bad
        c.close()


EXAMPLE1 = (tstc(zh=16, yh="Y48")
            + tp4("M1", 0, 0, 4, "Y24", "R3845", "R4", "R220")
            + tp4("M1", 0, 0, 8, "Y32", "R3848", "R8", "R230")
            + tp4("M2", 0, 0, 12, "Y40", "R3851", "R12", "R240"))


def test_s7_pid_waits_for_every_point(start_plcemud):
    """FB manual FUN73: the example 1 program (TSTC Sm 0 / Sh 0 / Zh 16, TP4 at Sm 4, 8, 12).
    With the TP4 at Sm 12 off, Y48-Y63 stay OFF and R300-R315 stay 0; switching it on, PID starts at the
    first scan after its 4 points have each been read (within 2 s)."""
    c = start(start_plcemud, EXAMPLE1)
    fill(c, 100, 150, 16)
    on(c, 0)
    on(c, 1)
    for _ in range(10):
        step(c, 500)
        assert coils(c, 48, 16) == [False] * 16
        assert regs(c, 300, 16) == [0] * 16
    assert regs(c, 200 + 12) == [0]
    on(c, 2)
    step(c, ROUND + 1)  # the 4th sample falls on the 201st scan, after the TSTC in the program
    assert regs(c, 300, 16) == [0] * 16
    assert regs(c, 240 + 1) == [0x000F]
    step(c, 1)  # the next scan's TSTC finds every point read
    assert regs(c, 300, 16) == [4095] * 16
    assert regs(c, 212) == [0x0202]


def load_error(tmp_path, program):
    from conftest import run_plcemud
    path = tmp_path / "fb.yaml"
    path.write_text(FB + "program:\n" + program)
    r = run_plcemud("--check-config", "-c", str(path))
    return r.returncode, r.stderr


def test_s7_load_errors(tmp_path):
    """docs/profile-fb.md, "FUN73 TSTC", checks at load: Ym overlapping Yh is refused at the
    operand, naming file:line:col."""
    code, err = load_error(tmp_path, tstc(yh="Y20"))
    assert code == 2
    assert "fb.yaml:5:" in err and "Y20-Y23 overlaps its own ym" in err


def test_s7_shared_devices_with_tp4_exit_2_naming_both(tmp_path):
    """docs/profile-fb.md, "Shared devices": a TP4 whose TR covers the TSTC's setpoints (SV R100),
    and a TSTC whose AO1 is a TP4's ERR (M110), exit with status 2 at the later entry's operand,
    naming the earlier entry; the TP4 on its own devices loads."""
    other = tp4("M0", 0, 0, 4, "Y24", "R3845", "R4", "R220", err="M110", alm="M111")
    assert load_error(tmp_path, tstc() + other)[0] == 0
    code, err = load_error(tmp_path, tstc() + other.replace("tr: R4,", "tr: R100,"))
    assert code == 2 and "fb.yaml:6:64" in err, err
    assert "R100-R103 overlaps R100-R103 of the TSTC at " in err and "fb.yaml:5:5" in err, err
    code, err = load_error(tmp_path, other + tstc().replace("ao1: M102", "ao1: M110"))
    assert code == 2 and "fb.yaml:6:196" in err, err
    assert "M110 overlaps M110 of the TP4 at " in err and "fb.yaml:5:5" in err, err


def test_s8_closed_loop_4_points(start_plcemud):
    """FB manual FUN73, the 4-point closed loop: the default plant (K 400, tau 120 s, theta 5 s, 25
    degC), SP 150, offset 5, Kc 60, Ti 17, Td 0, R4005 0000h, R4014 500, 30 simulated minutes: the
    first execution keeps the gains; reading >= 145 by 90 s; true temperature peaks <= 165.0;
    reading within 150 +- 5 from 300 s and 147...153 over the last 10 minutes; mean R300 over the
    last 10 minutes 1150...1400; heater power 28.0-34.0 % over the last 10 minutes; WR+8 = 000Fh,
    M102 OFF, WR+12 = 0202h at the end."""
    c = start(start_plcemud, tstc())
    s8_gains(c)
    on(c, 0)
    step(c, 1)
    assert regs(c, 140, 4) == [60] * 4 and regs(c, 180, 4) == [0] * 4
    reached = None
    peak = 0
    late, outputs, power = [], [], []
    for second in range(1, 1801):
        step(c, SCANS_PER_S)
        readings = [s16(v) for v in regs(c, 0, 4)]
        peak = max(peak, max(s16(regs(c, SIM_TRUE + 10 * ch, unit=SIM)[0]) for ch in range(4)))
        if reached is None and min(readings) >= 145:
            reached = second
        if second >= 300:
            assert all(145 <= v <= 155 for v in readings), (second, readings)
        if second > 1200:
            late.extend(readings)
            outputs.append(regs(c, 300)[0])
            power.append(regs(c, SIM_POWER, 31, unit=SIM)[0::10])
    assert reached is not None and reached <= 90, reached
    assert peak <= 1650, peak
    assert 147 <= min(late) and max(late) <= 153, (min(late), max(late))
    mean = sum(outputs) / len(outputs)
    assert 1150 <= mean <= 1400, mean
    # Heater power (0.1 %, each a mean of 8 s), averaged over the last 10 minutes: the steady
    # state needs (150 - 25) / 400 = 31.25 %.
    means = [sum(p[ch] for p in power) / len(power) for ch in range(4)]
    print(f"closed loop: >=145 at {reached} s, peak {peak / 10} degC, "
          f"last 10 min {min(late)}..{max(late)},"
          f" mean R300 {mean:.0f}, heater power {[round(m / 10, 1) for m in means]} %")
    assert all(280 <= m <= 340 for m in means), means
    assert regs(c, 208) == [0x000F]
    assert coils(c, 2102) == [False]
    assert regs(c, 212) == [0x0202]


def settled(start_plcemud):
    c = start(start_plcemud, tstc())
    s8_gains(c)
    on(c, 0)
    step(c, 600 * SCANS_PER_S)
    assert regs(c, 208) == [0x000F]
    return c


def test_s9_zone_and_warnings(start_plcemud):
    """FB manual FUN73, zone and warnings on the settled closed loop: SP far below PV clears WR+8
    bit 0 and raises AO1 at the next scan; heater_shorted on channel 1 with R4008 200 sets
    WR+10/WR+13 bit 1 once R1 >= 200 for 10 scans, and clearing the fault clears it at the first
    scan below 200; heater_open on channel 2 with R4007 300 drives R302 to >= 3686 and sets
    WR+10/WR+15 bit 2 after 300 s; R4012 bit 3 = 0 turns Y51 OFF and R303 to 0 without AO1."""
    c = settled(start_plcemud)
    write(c, 100, 100)
    step(c, 1)
    assert regs(c, 208)[0] & 1 == 0
    assert coils(c, 2102) == [True]
    write(c, 100, 150)
    step(c, 60 * SCANS_PER_S)
    assert coils(c, 2102) == [False]

    write(c, 4008, 200)
    write(c, SIM_FAULTS + 10, 4, unit=SIM)  # heater shorted
    above = 0
    for _ in range(600 * SCANS_PER_S // 10):
        step(c, 10)
        if s16(regs(c, 1)[0]) >= 200:
            above += 1
            break
    assert above, "R1 never reached 200"
    step(c, 10)
    assert regs(c, 210)[0] & 2 and regs(c, 213)[0] & 2
    assert coils(c, 2102) == [True]
    write(c, SIM_FAULTS + 10, 0, unit=SIM)
    while s16(regs(c, 1)[0]) >= 200:
        step(c, 1)
    assert regs(c, 210)[0] & 2 == 0 and regs(c, 213)[0] & 2 == 0
    write(c, 4008, 350)

    write(c, 4007, 300)
    write(c, SIM_FAULTS + 20, 2, unit=SIM)  # heater open
    high_since = None
    for second in range(1, 900):
        step(c, SCANS_PER_S)
        out = regs(c, 302)[0]
        if high_since is None and out >= 3686:
            high_since = second
        if high_since is not None and second - high_since >= 305:
            break
    assert high_since is not None, "R302 never reached 90 %"
    assert regs(c, 302)[0] >= 3686
    assert regs(c, 210)[0] & 4 and regs(c, 215)[0] & 4
    write(c, SIM_FAULTS + 20, 0, unit=SIM)

    write(c, 4012, 0xFFF7)
    step(c, 1)
    assert coils(c, 51) == [False] and regs(c, 303) == [0]
    assert regs(c, 208)[0] & 8 == 0


def test_s10_r4005_codes(start_plcemud):
    """FB manual FUN73, R4005: R4005 written with EN off is read when EN rises; WR+12 shows PWM
    (high) and Ts (low) in s: 0001h -> 0204h, 0103h -> 0401h, 0300h -> 0102h; a change while EN = 1
    does not alter WR+12 until EN falls and rises."""
    c = start(start_plcemud, tstc(), "plant:\n  defaults: {k: 0, ambient: 200}\n")
    s8_gains(c)
    for r4005, wr12 in ((0x0001, 0x0204), (0x0103, 0x0401), (0x0300, 0x0102)):
        write(c, 4005, r4005)
        on(c, 0)
        step(c, ROUND + 2)
        assert regs(c, 212) == [wr12], hex(r4005)
        write(c, 4005, 0x0000)
        step(c, 50)
        assert regs(c, 212) == [wr12], hex(r4005)
        assert not c.write_coil(2000, False, slave=1).isError()
        step(c, 1)
        assert regs(c, 212) == [0]


def test_fb_example_yaml_runs_example_1(start_plcemud):
    """config/fb-example.yaml (the FB manual's FUN73 program example 1): R4010-R4013 from
    M800-M863, the first execution's defaults Kc 60, Ti 17, Td 100 on all 16 points, and the 16
    slow loops from 25 degC within 150 +- 5 by 20 simulated minutes, every in-zone bit of WR+8."""
    from conftest import REPO
    text = (REPO / "config" / "fb-example.yaml").read_text()
    text = text.replace("    port: 5020\n", "")
    d = start_plcemud(text)
    c = d.client()
    freeze(c)
    step(c, 2)
    assert regs(c, 4010, 4) == [0xFFFF] * 4
    assert regs(c, 140, 16) == [60] * 16
    assert regs(c, 160, 16) == [17] * 16
    assert regs(c, 180, 16) == [100] * 16
    step(c, 1200 * SCANS_PER_S)
    readings = [s16(v) for v in regs(c, 0, 16)]
    assert all(145 <= v <= 155 for v in readings), readings
    assert regs(c, 208) == [0xFFFF]


def test_s7_load_errors_contiguous_tr(tmp_path):
    """FB manual FUN73, "TR must be contiguous", on the example 1 program: a TP4 with TR R5 instead
    of R4, and a TP4 with tp 1 under a tp 0 TSTC, are refused at the TP4's operand (status 2,
    file:line:col)."""
    good = EXAMPLE1.replace("en: M1", "en: M0").replace("en: M2", "en: M0")
    assert load_error(tmp_path, good)[0] == 0
    code, err = load_error(tmp_path, good.replace("tr: R4,", "tr: R5,"))
    assert code == 2 and "fb.yaml:6:" in err and "must be at R4-R7" in err, err
    code, err = load_error(tmp_path, good.replace("tp: 0, pl: 0, sm: 4", "tp: 1, pl: 0, sm: 4"))
    assert code == 2 and "fb.yaml:6:" in err and "same range and polarity" in err, err
