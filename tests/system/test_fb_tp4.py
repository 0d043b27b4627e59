"""FUN72 TP4 of profile fb (docs/profile-fb.md, "FUN72 TP4" and "Conversion") through Modbus TCP
against the real daemon, frozen and stepped through the simulator unit (FB manual FUN72/FUN73): K
on 0~10 V with the relays, AR, R4016 and R4009; J and the bipolar ranges with R4017/R4018; a
broken thermocouple, R4010 and the thresholds of 0~5 V; Pt100/Pt1000 with R4020-R4022 and the
lead resistance of unit 247 register 108+10c; R4015 averaging."""

import pytest

from test_vb import SIM, coils, freeze, regs, step, write

FB = "profile: fb\nscan_ms: 10\nmodbus: {tcp: {bind: 127.0.0.1}}\n"
ROUND = 200  # scans of one 4-point round: 4 x R4014 (500 ms) / 10 ms


def s16(v):
    """A register as a signed 16-bit value."""
    return v - 0x10000 if v & 0x8000 else v


def plant(channels):
    """A `plant:` section whose channels sit at their ambient (k 0): {channel: temperature}."""
    lines = "".join(f"    {c}: {{ambient: {t}}}\n" for c, t in channels.items())
    return "plant:\n  defaults: {k: 0}\n  channels:\n" + lines


def tp4(en, tp, pl, sm, ym, ar, tr, wr, err=None, alm=None):
    extra = (f", err: {err}" if err else "") + (f", alm: {alm}" if alm else "")
    return (f"  - TP4: {{en: {en}, tp: {tp}, pl: {pl}, sm: {sm}, ym: {ym}, ar: {ar}, tr: {tr}, "
            f"wr: {wr}{extra}}}\n")


def start(start_plcemud, channels, *entries):
    """A frozen FB with `entries` in its program; returns the client."""
    d = start_plcemud(FB + plant(channels) + "program:\n" + "".join(entries))
    c = d.client()
    freeze(c)
    return c


def on(client, m):
    """Sets M`m` (coil 2000 + m)."""
    assert not client.write_coil(2000 + m, True, slave=1).isError()


S2_TP4 = tp4("M3", 0, 0, 0, "Y16", "R3842", "R0", "R220", "M110", "M111")


def test_s2_k_on_0_10v_relays_ar_r4016_r4009(start_plcemud):
    """FB manual FUN72, K on 0~10 V: channel 0 at 200 degC. Y16/Y17 during the first 50 scans,
    Y18/Y19 from scan 50; AR shows the selected point; after the first round R3968 = 826, R0 = 200,
    R220 = 0, M111 OFF, R221 = 000Fh; R4016 = 258 -> 208 (raw still 826), 238 -> 191; R4009 = 1 ->
    392 degF."""
    c = start(start_plcemud, {0: 200}, S2_TP4)
    # R3968-R3999 take Modbus writes; the measurement overwrites a point at its next sample, a
    # point nothing measures keeps the value (docs/profile-fb.md, "Modbus map").
    write(c, 3968, 1234)
    write(c, 3999, 77)
    on(c, 3)
    step(c, 1)
    assert coils(c, 16, 8) == [True, True] + [False] * 6
    assert regs(c, 3842) == [826]
    step(c, 49)  # scans 0-49: point 0
    assert coils(c, 16, 8) == [True, True] + [False] * 6
    assert regs(c, 3968) == [1234]
    step(c, 1)  # scan 50: sampled, point 1 selected
    assert coils(c, 16, 8) == [False, False, True, True] + [False] * 4
    assert regs(c, 3968) == [826] and regs(c, 0) == [200]
    step(c, 1)
    assert regs(c, 3842) == [103]  # point 1: channel 1 at the default 25 degC
    step(c, 250 - 52)
    assert regs(c, 3968) == [826]
    assert regs(c, 0) == [200]
    assert regs(c, 220, 2) == [0, 0x000F]
    assert regs(c, 3999) == [77]
    assert coils(c, 2110, 2) == [False, False]  # ERR, ALM
    write(c, 4016, 258)
    step(c, ROUND)
    assert regs(c, 0) == [208] and regs(c, 3968) == [826]
    write(c, 4016, 238)
    step(c, ROUND)
    assert regs(c, 0) == [191]
    write(c, 4016, 248)
    write(c, 4009, 1)
    step(c, ROUND)
    assert regs(c, 0) == [392]


def test_s3_j_and_bipolar_ranges(start_plcemud):
    """FB manual FUN73, R4016-R4019: J 0~10 V at 300 degC: raw 1280, reading 300, R4018 = 250 ->
    312. K -10~10 V: 200 degC raw 413 reading 200; -50 degC raw -90 (FFA6h) reading -50, R4017 = 300
    -> -52. K -5~5 V at -50 degC: raw -179, reading -49 (truncated)."""
    c = start(start_plcemud, {0: 300, 4: 200, 5: -50, 8: -50},
              tp4("M3", 1, 0, 0, "Y16", "R3842", "R0", "R220"),
              tp4("M3", 0, 2, 4, "Y24", "R3845", "R4", "R230"),
              tp4("M3", 0, 3, 8, "Y32", "R3848", "R8", "R240"))
    on(c, 3)
    step(c, ROUND + 1)
    assert regs(c, 3968) == [1280] and regs(c, 0) == [300]
    assert regs(c, 3972, 2) == [413, 0xFFA6]
    assert [s16(v) for v in regs(c, 4, 2)] == [200, -50]
    assert s16(regs(c, 3976)[0]) == -179 and s16(regs(c, 8)[0]) == -49
    # The check rule: reading = trunc(raw x m x F / 1024).
    assert int(-179 * 1 * 286 / 1024) == -49
    write(c, 4018, 250)
    write(c, 4017, 300)
    step(c, ROUND)
    assert regs(c, 0) == [312]
    assert s16(regs(c, 5)[0]) == -52
    assert regs(c, 3968) == [1280]


def test_s4_broken_thermocouple(start_plcemud):
    """FB manual FUN73, broken thermocouple: sensor_broken on channel 0 (unit 247 register 100 bit
    0): within a round R3968 = 4095, R0 = 991, R220 bit 0, M111; degF 1815 still flagged; R4010 bit
    0 = 0 -> R0 = 0, unflagged; the fault cleared -> the reading is back; R4016 = 225 -> 899, not
    flagged. 0~5 V: 455 degC reads 455 and is flagged, 451 degC reads 450 and is not."""
    c = start(start_plcemud, {0: 200, 4: 455, 5: 451}, S2_TP4,
              tp4("M3", 0, 1, 4, "Y24", "R3845", "R4", "R230", alm="M112"))
    on(c, 3)
    step(c, ROUND + 1)
    # 0~5 V: above 450 degC is broken.
    assert regs(c, 4, 2) == [455, 450]
    assert regs(c, 230)[0] & 3 == 1 and coils(c, 2112) == [True]
    write(c, 100, 1, unit=SIM)
    step(c, ROUND)
    assert regs(c, 3968) == [4095] and regs(c, 0) == [991]
    assert regs(c, 220)[0] & 1 == 1 and coils(c, 2111) == [True]
    write(c, 4009, 1)
    step(c, ROUND)
    assert regs(c, 0) == [1815] and coils(c, 2111) == [True]
    write(c, 4009, 0)
    write(c, 4010, 0xFFFE)
    step(c, ROUND)
    assert regs(c, 0) == [0] and regs(c, 220)[0] & 1 == 0 and coils(c, 2111) == [False]
    write(c, 4010, 0xFFFF)
    write(c, 100, 0, unit=SIM)
    step(c, ROUND)
    assert regs(c, 0) == [200] and coils(c, 2111) == [False]
    write(c, 100, 1, unit=SIM)
    write(c, 4016, 225)
    step(c, ROUND)
    assert regs(c, 0) == [899] and regs(c, 220)[0] & 1 == 0 and coils(c, 2111) == [False]


def test_s5_rtd_compensation_and_lead_resistance(start_plcemud):
    """FB manual FUN73, RTDs: Pt100 (tp 2, pl 2) at 50.0 degC: R0 = 500, R3968 = 2081; R4021 = 5000
    with R5000 = 10 -> 474; 40 -> 396; JIS -> 398; R4022 = 1034 -> 504; lead 1.50 ohm (unit 247
    register 108) -> 539, compensated by R5000 = 15 -> 500. Pt1000 with 1.0 ohm -> 497. 200 degC on
    10 V DIN: 1466, raw 4095, not flagged. Broken: 32767, raw 4095, WR+0 bit 0, ALM. R4020 = 0002h:
    the table in D (D5000 does not exist: none; R4021 = 100: D100+p)."""
    c = start(start_plcemud, {0: 50, 4: 50, 8: 200},
              tp4("M3", 2, 2, 0, "Y16", "R3842", "R0", "R220", alm="M111"),
              tp4("M3", 3, 2, 4, "Y24", "R3845", "R4", "R230"),
              tp4("M3", 2, 0, 8, "Y32", "R3848", "R8", "R240"))
    on(c, 3)
    step(c, ROUND + 1)
    assert regs(c, 0) == [500] and regs(c, 3968) == [2081]
    write(c, 4021, 5000)  # R8000 is not reachable over Modbus
    write(c, 5000, 10)
    step(c, ROUND)
    assert regs(c, 0) == [474]
    write(c, 5000, 40)
    step(c, ROUND)
    assert regs(c, 0) == [396]
    write(c, 4020, 0x0101)
    step(c, ROUND)
    assert regs(c, 0) == [398]
    write(c, 4020, 0x0001)
    write(c, 5000, 0)
    write(c, 4022, 1034)
    step(c, ROUND)
    assert regs(c, 0) == [504]
    write(c, 4022, 1024)
    write(c, 108, 150, unit=SIM)  # channel 0's leads: 1.50 ohm
    assert regs(c, 108, unit=SIM) == [150]
    step(c, ROUND)
    assert regs(c, 0) == [539]
    write(c, 5000, 15)
    step(c, ROUND)
    assert regs(c, 0) == [500]
    write(c, 5004, 10)  # Pt1000 at point 4
    step(c, ROUND)
    assert regs(c, 4) == [497]
    assert regs(c, 8) == [1466] and regs(c, 3976) == [4095] and regs(c, 240) == [0]
    write(c, 4020, 0x0002)  # the table in D from D5000 + p: no such D
    step(c, ROUND)
    assert regs(c, 0) == [539]
    write(c, 4021, 100)
    write(c, 6100, 15)  # D100
    step(c, ROUND)
    assert regs(c, 0) == [500]
    write(c, 100, 1, unit=SIM)
    step(c, ROUND)
    assert regs(c, 0) == [32767] and regs(c, 3968) == [4095]
    assert regs(c, 220)[0] & 1 == 1 and coils(c, 2111) == [True]


@pytest.mark.parametrize("r4015,n", [(2, 4), (0, 1)])
def test_s6_averaging(start_plcemud, r4015, n):
    """FB manual FUN73, R4015 averaging: with R4015 = 2 the reading always equals trunc(sum of the
    last <= 4 raws x 248 / (1024 x count)); with R4015 = 0 it is the latest raw's conversion. A
    noisy channel makes the raws differ from sample to sample."""
    d = start_plcemud(FB + "plant:\n  defaults: {k: 0}\n  channels:\n"
                      "    0: {ambient: 200, noise: 3}\nprogram:\n" + S2_TP4)
    c = d.client()
    freeze(c)
    write(c, 4015, r4015)
    on(c, 3)
    step(c, 51)
    raws = []
    for _ in range(8):
        raws.append(regs(c, 3968)[0])
        last = raws[-n:]
        assert regs(c, 0)[0] == sum(last) * 248 // (1024 * len(last)), raws
        step(c, ROUND)
    assert len(set(raws)) > 1, raws


@pytest.mark.parametrize("tp,pl,sm", [(6, 0, 0), (0, 4, 0), (0, 0, 2), (0, 0, 32)])
def test_operands_out_of_range_set_err_and_write_nothing(start_plcemud, tp, pl, sm):
    """docs/profile-fb.md, "FUN72 TP4": Tp, Pl or Sm out of range -> ERR ON at every scan, EN
    or not, nothing else written."""
    c = start(start_plcemud, {0: 200}, tp4("M3", tp, pl, sm, "Y16", "R3842", "R0", "R220",
                                          "M110", "M111"))
    step(c, 2)
    assert coils(c, 2110) == [True]
    on(c, 3)
    step(c, ROUND + 1)
    assert coils(c, 2110) == [True]
    assert coils(c, 16, 8) == [False] * 8
    assert regs(c, 3968, 4) == [0] * 4 and regs(c, 3842) == [0] and regs(c, 220, 8) == [0] * 8
