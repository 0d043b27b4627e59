"""The control loops of profile fb's FUN86 TPCTL and FUN73 TSTC through the REST API
(`GET /api/v1/plcs/{plc}/loops`, docs/console.md, "Loops"), each checked against what the PLC
answers over Modbus TCP on the same image, frozen and stepped through the simulator unit: one
loop per point with its plant channel, its PV, SV and output registers, the readings' unit and
scale (whole degrees for thermocouples, 0.1 degC for RTDs, degF with R4009), Kc/Ti/Td/Os, the
working registers' bits and the ALM/AO1 outputs as alarms, and a set point written through the
API (docs/profile-fb.md, "FUN86 TPCTL" and "FUN73 TSTC")."""

import pytest

from conftest import free_port
from test_fb_tp4 import FB, on, tp4
from test_http_api import flags, loops, put, start_config_file, wait_listening
from test_vb import SIM, coils, freeze, regs, step, write

SIM_FAULTS = 100  # + 10c: b0 sensor broken (docs/simulator-and-plant.md)


def start(start_plcemud, body):
    """A frozen FB with `http:` -> (Modbus client, HTTP port)."""
    hp = free_port()
    d = start_plcemud(FB + f"http: {{port: {hp}}}\n" + body)
    wait_listening(d, [hp])
    c = d.client()
    freeze(c)
    return c, hp


def plant(channels):
    """Channels held at their ambient (k 0, no noise): {channel: degC}."""
    lines = "".join(f"    {ch}: {{ambient: {t}}}\n" for ch, t in channels.items())
    return "plant:\n  defaults: {k: 0, noise: 0}\n  channels:\n" + lines


def bit(word, b):
    return (word >> b) & 1 == 1


def alarm(loop, name):
    """The alarm `name` of `loop`: (device, bit, on)."""
    found = [(a["device"], a["bit"], a["on"]) for a in loop["alarms"] if a["name"] == name]
    assert len(found) == 1, (name, loop["alarms"])
    return found[0]


# --- FUN86 TPCTL: points Sn..Sn+Zn-1, PV = TPSNS's TR + Sn + i --------------------------------

# Sn 4, Zn 20: points 0-19 on channels 4-23, points 16-19 in the second word of each WR pair.
TPCTL_PROGRAM = (
    "temperature:\n  modules: [FB-4AK24]\n"
    "program:\n"
    "  - TPSNS: {en: M1, tp: 0, pl: 0, tr: R0, wr: R250, err: M120, alm: M121}\n"
    "  - TPCTL: {en: M0, hc: 1, yn: Y30, sn: 4, zn: 20, sv: R100, os: R130, pr: R160, ir: R190,"
    " dr: R220, or: R300, wr: R400, err: M100, alm: M101}\n")
# Every controlled channel near 150 degC, a different reading each; channel 21 (point 17) at
# 400 degC, above R4008's 350: over temperature.
TPCTL_CHANNELS = {ch: 146 + ch % 8 for ch in range(4, 24)} | {21: 400}


def test_tpctl_loops_are_its_points_on_their_channels(start_plcemud):
    """docs/profile-fb.md, "FUN86 TPCTL": Sn 4, Zn 20 are 20 loops, point i on channel 4 + i,
    PV TR + Sn + i (R4 + i), SV/OS/PR/IR/DR/OR their word i, WR's bits (WR+1, +3, +6, +8 for
    points 16-19) and ALM; before any scan every flag is off."""
    c, hp = start(start_plcemud, plant(TPCTL_CHANNELS) + TPCTL_PROGRAM)
    ls = loops(hp)
    assert [lp["name"] for lp in ls] == [f"TPCTL point {i} (channel {4 + i})" for i in range(20)]
    assert [lp["channel"] for lp in ls] == list(range(4, 24))
    for i, lp in enumerate(ls):
        assert (lp["unit"], lp["scale"], lp["output_full"]) == ("°C", 1, 4095), lp
        assert lp["pv"]["device"] == f"R{4 + i}", lp
        assert lp["sv"]["device"] == f"R{100 + i}", lp
        assert lp["output"]["device"] == f"R{300 + i}", lp
        assert [(q["name"], q["device"], q["unit"]) for q in lp["parameters"]] == [
            ("Kc", f"R{160 + i}", "1-999"), ("Ti", f"R{190 + i}", "0.01 repeats/min"),
            ("Td", f"R{220 + i}", "0.01 min"), ("in-zone offset", f"R{130 + i}", "°C")], lp
        half, b = divmod(i, 16)
        assert [(n, d, bb) for n, d, bb, _ in flags(lp)] == [
            ("in zone", f"R{400 + half}", b), ("warning", f"R{402 + half}", b),
            ("over temperature", f"R{405 + half}", b), ("heater open", f"R{407 + half}", b),
            ("control warning (ALM)", "M101", 0)], lp
        assert lp["manual"] is None and lp["tuning"] is None, lp
    # Nothing has run: the PVs are the still empty readings, the flags off.
    assert all(lp["pv"]["raw"] == 0 for lp in ls)
    assert not any(on for lp in ls for *_, on in flags(lp))


def test_tpctl_loops_follow_the_image(start_plcemud):
    """Once PID runs the loops show what Modbus reads: PVs, SVs, outputs, the first execution's
    gains, the in-zone and over-temperature bits (point 17 at 400 degC, in WR+1/WR+6) and ALM;
    an SV and an Os written through the API change the loop and the PLC; R4009 = 1 is degF."""
    c, hp = start(start_plcemud, plant(TPCTL_CHANNELS) + TPCTL_PROGRAM)
    for i in range(20):
        write(c, 100 + i, 150)
        write(c, 130 + i, 5)
    on(c, 1)
    on(c, 0)
    step(c, 220)  # every group read at scan 201, then 10 scans above R4008 for channel 21
    ls = loops(hp)
    readings = regs(c, 4, 20)
    assert [lp["pv"]["raw"] for lp in ls] == readings
    assert [lp["pv"]["value"] for lp in ls] == readings
    # The readings are the channels' (point i on channel 4 + i), not TR's first words.
    assert readings[17] == 400 and all(145 <= r <= 155 for k, r in enumerate(readings) if k != 17)
    assert [lp["sv"]["raw"] for lp in ls] == [150] * 20
    assert [lp["output"]["raw"] for lp in ls] == regs(c, 300, 20)
    # The first execution's gains, as Modbus reads them.
    assert [q["value"] for q in ls[0]["parameters"]] == regs(c, 160) + regs(c, 190) + regs(
        c, 220) + [5]
    assert [q["value"] for q in ls[0]["parameters"]] == [60, 17, 100, 5]
    wr = regs(c, 400, 9)
    for i, lp in enumerate(ls):
        half, b = divmod(i, 16)
        hot = i == 17
        assert alarm(lp, "in zone") == (f"R{400 + half}", b, not hot), lp
        assert alarm(lp, "in zone")[2] == bit(wr[half], b)
        assert alarm(lp, "over temperature") == (f"R{405 + half}", b, hot), lp
        assert alarm(lp, "over temperature")[2] == bit(wr[5 + half], b)
        assert alarm(lp, "warning") == (f"R{402 + half}", b, hot), lp
        assert alarm(lp, "heater open")[2] is False
        assert alarm(lp, "control warning (ALM)") == ("M101", 0, True), lp
    assert coils(c, 2101) == [True]

    # A set point written through the API is the loop's, and the PLC's: point 1 (channel 5, 151
    # degC) out of zone at SV 200.
    r = put(hp, "/api/v1/plcs/0/devices/R101", {"values": [200]})
    assert r.status == 200, r
    assert regs(c, 101) == [200]
    lp = loops(hp)[1]
    assert lp["sv"] == {"device": "R101", "raw": 200, "value": 200}, lp
    assert alarm(lp, "in zone")[2] is True  # not scanned yet
    step(c, 1)
    lp = loops(hp)[1]
    assert alarm(lp, "in zone") == ("R400", 1, False), lp
    assert not bit(regs(c, 400)[0], 1)
    # An in-zone offset written through the API: 50 degC takes 151 back into the zone.
    assert put(hp, "/api/v1/plcs/0/devices/R131", {"values": [50]}).status == 200
    step(c, 1)
    lp = loops(hp)[1]
    assert lp["parameters"][3] == {"name": "in-zone offset", "device": "R131", "value": 50,
                                   "unit": "°C"}, lp
    assert alarm(lp, "in zone")[2] is True and bit(regs(c, 400)[0], 1)

    # R4009 = 1: the readings are degF.
    write(c, 4009, 1)
    lp = loops(hp)[0]
    assert lp["unit"] == "°F" and lp["parameters"][3]["unit"] == "°F", lp


def test_tpctl_with_sn_zn_out_of_range_has_no_loops(start_plcemud):
    """FB manual FUN86: Sn + Zn = 25 loads, is never executed (ERR ON), and runs no loop."""
    program = TPCTL_PROGRAM.replace("sn: 4, zn: 20", "sn: 20, zn: 5")
    c, hp = start(start_plcemud, plant({0: 25}) + program)
    on(c, 1)
    on(c, 0)
    step(c, 5)
    assert coils(c, 2100) == [True]
    assert loops(hp) == []


def test_fb_tpctl_yaml_lists_its_24_loops(start_plcemud):
    """config/fb-tpctl.yaml: 24 loops on channels 0-23, PV R0-R23, SV R100-R123 at 150."""
    plc = start_config_file(start_plcemud, "fb-tpctl.yaml")
    ls = loops(plc.http)
    assert [(lp["name"], lp["channel"], lp["pv"]["device"], lp["sv"]["device"]) for lp in ls] == [
        (f"TPCTL point {i} (channel {i})", i, f"R{i}", f"R{100 + i}") for i in range(24)]
    assert all(lp["sv"]["value"] == 150 for lp in ls)
    assert all("true_temperature_c" in lp for lp in ls)


# --- FUN73 TSTC: points Sh..Sh+Zh-1, PV = TR + (Sh + i - Sm) -----------------------------------

# Its own module is points 0-3 (TR R0-R3); it controls points 2-7, a TP4 measures 4-7 (TR R4).
TSTC_PROGRAM = (
    "program:\n"
    "  - TSTC: {en: M0, hc: 1, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R0, yh: Y48, sh: 2,"
    " zh: 6, sv: R100, os: R120, pr: R140, ir: R160, dr: R180, or: R300, wr: R200, err: M100,"
    " ao0: M101, ao1: M102}\n"
    + tp4("M0", 0, 0, 4, "Y24", "R3845", "R4", "R220"))


def test_tstc_loops_are_its_points_with_their_module_and_warnings(start_plcemud):
    """docs/profile-fb.md, "FUN73 TSTC": Sm 0, Sh 2, Zh 6 are 6 loops on channels 2-7, PV
    TR + (Sh + i - Sm), the loop's bits from WR+8, WR+0's broken bit for its own module's points
    2 and 3, and AO1; channel 3's open thermocouple lights its loop's sensor-broken and
    over-temperature lamps as WR says; an SV written through the API takes point 4 out of zone."""
    c, hp = start(start_plcemud, plant({ch: 146 + ch for ch in range(8)}) + TSTC_PROGRAM)
    ls = loops(hp)
    assert [(lp["name"], lp["channel"]) for lp in ls] == [
        (f"TSTC point {i} (channel {2 + i})", 2 + i) for i in range(6)]
    for i, lp in enumerate(ls):
        assert (lp["unit"], lp["scale"], lp["output_full"]) == ("°C", 1, 4095), lp
        assert (lp["pv"]["device"], lp["sv"]["device"], lp["output"]["device"]) == (
            f"R{2 + i}", f"R{100 + i}", f"R{300 + i}"), lp
        assert [(q["name"], q["device"], q["unit"]) for q in lp["parameters"]] == [
            ("Kc", f"R{140 + i}", "1-999"), ("Ti", f"R{160 + i}", "0.01 repeats/min"),
            ("Td", f"R{180 + i}", "0.01 min"), ("in-zone offset", f"R{120 + i}", "°C")], lp
        # The loop's words from WR+8; WR+0's broken bit only for points of its own module (2, 3).
        own = [("sensor broken", "R200", 2 + i)] if i < 2 else []
        assert [(n, d, b) for n, d, b, _ in flags(lp)] == [
            ("in zone", "R208", i), ("warning", "R210", i), ("over temperature", "R213", i),
            ("heater open", "R215", i)] + own + [("control warning (AO1)", "M102", 0)], lp

    # Channel 3's thermocouple open; SV 150 +- 5 on every point: channels 2 and 4-7 (148-153
    # degC) in zone, channel 3, broken, out of zone.
    write(c, SIM_FAULTS + 10 * 3, 1, unit=SIM)
    for i in range(6):
        write(c, 100 + i, 150)
        write(c, 120 + i, 5)
    on(c, 0)
    step(c, 230)  # both modules read by scan 201, then over 10 scans of over-temperature
    ls = loops(hp)
    readings = regs(c, 2, 6)
    assert [lp["pv"]["raw"] for lp in ls] == readings
    assert readings[1] == 991  # a broken K thermocouple reads full scale
    assert [lp["output"]["raw"] for lp in ls] == regs(c, 300, 6)
    wr = regs(c, 200, 17)
    assert bit(wr[0], 3) and not bit(wr[0], 2)
    assert alarm(ls[1], "sensor broken") == ("R200", 3, True)
    assert alarm(ls[0], "sensor broken") == ("R200", 2, False)
    for i, lp in enumerate(ls):
        broken = i == 1
        assert alarm(lp, "in zone") == ("R208", i, not broken), lp
        assert alarm(lp, "in zone")[2] == bit(wr[8], i)
        assert alarm(lp, "over temperature") == ("R213", i, broken), lp
        assert alarm(lp, "over temperature")[2] == bit(wr[13], i)
        assert alarm(lp, "control warning (AO1)") == ("M102", 0, True), lp
    assert coils(c, 2101, 2) == [True, True]

    # A set point through the API: point 4 (channel 6, 152 degC) out of zone at SV 100.
    assert put(hp, "/api/v1/plcs/0/devices/R104", {"values": [100]}).status == 200
    step(c, 1)
    lp = loops(hp)[4]
    assert lp["sv"] == {"device": "R104", "raw": 100, "value": 100}, lp
    assert regs(c, 104) == [100]
    assert alarm(lp, "in zone") == ("R208", 4, False) and not bit(regs(c, 208)[0], 4)


def test_tstc_rtd_loops_are_in_tenths_of_a_degree(start_plcemud):
    """An FB-2AH4 (Tp 2, Pt100): readings, SV and Os in 0.1 degC."""
    program = TSTC_PROGRAM.replace("tp: 0,", "tp: 2,", 1).replace("sh: 2, zh: 6", "sh: 0, zh: 4")
    program = program.split("  - TP4")[0]
    c, hp = start(start_plcemud, plant({0: 50, 1: 60, 2: 70, 3: 80}) + program)
    write(c, 100, 555)
    on(c, 0)
    step(c, 201)
    ls = loops(hp)
    assert [lp["name"] for lp in ls] == [f"TSTC point {i} (channel {i})" for i in range(4)]
    assert regs(c, 0, 4) == [500, 600, 700, 800]
    for i, lp in enumerate(ls):
        assert (lp["unit"], lp["scale"]) == ("°C", 0.1), lp
        assert lp["pv"] == {"device": f"R{i}", "raw": 500 + 100 * i,
                            "value": pytest.approx(50.0 + 10 * i)}, lp
        assert lp["parameters"][3]["unit"] == "0.1 °C", lp
        assert alarm(lp, "sensor broken") == ("R200", i, False), lp
    assert ls[0]["sv"]["raw"] == 555 and ls[0]["sv"]["value"] == pytest.approx(55.5)


def test_fb_example_yaml_lists_its_16_tstc_loops(start_plcemud):
    """config/fb-example.yaml (the FB manual's FUN73 example 1): 16 loops on channels 0-15."""
    plc = start_config_file(start_plcemud, "fb-example.yaml")
    ls = loops(plc.http)
    assert [(lp["name"], lp["channel"], lp["pv"]["device"], lp["output"]["device"]) for lp in ls
            ] == [(f"TSTC point {i} (channel {i})", i, f"R{i}", f"R{300 + i}") for i in range(16)]
    # M102 is no operand of the example's TSTC: no AO1; WR+0's bits for points 0-3 only.
    assert [len(lp["alarms"]) for lp in ls] == [5] * 4 + [4] * 12
