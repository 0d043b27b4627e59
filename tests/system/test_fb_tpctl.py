"""FUN85 TPSNS and the FB's FUN86 TPCTL of profile fb (docs/profile-fb.md, "FUN85 TPSNS" and "FUN86
TPCTL") through Modbus TCP against the real daemon, frozen and stepped through the simulator
unit: the first-execution defaults by TPSNS's Pl, ERR for Sn/Zn at run time, TPSNS's EN gating
TPCTL, the measuring round of ceil(N/4) x R4004, `md` refused, a program mixing TP4 or TSTC
with TPSNS refused naming both, devices shared by TPSNS and TPCTL refused, and config/fb-tpctl.yaml
running."""

from test_fb_tp4 import FB, on, s16
from test_fb_tstc import SCANS_PER_S
from test_vb import check_config, coils, expect_config_error, freeze, regs, step, write

MODULES = "temperature:\n  modules: [FB-4AK24]\n"
PLANT = "plant:\n  defaults: {k: 0, ambient: 200}\n"


def tpsns(pl=0, en="M1"):
    return f"  - TPSNS: {{en: {en}, tp: 0, pl: {pl}, tr: R0, wr: R250}}\n"


def tpctl(sn=0, zn=24, extra=""):
    return (f"  - TPCTL: {{en: M0, hc: 1{extra}, yn: Y30, sn: {sn}, zn: {zn}, sv: R100, os: R130, "
            "pr: R160, ir: R190, dr: R220, or: R300, wr: R400, err: M100, alm: M101}\n")


def start(start_plcemud, program):
    d = start_plcemud(FB + MODULES + PLANT + "program:\n" + program)
    c = d.client()
    freeze(c)
    return c


def heat_until_all_read(c):
    """SP 300 degC on the 24 points (far above the 200 degC readings), both ENs on, 201 scans:
    the last group is read at the last one."""
    for i in range(24):
        write(c, 100 + i, 300)
    on(c, 1)
    on(c, 0)
    step(c, 201)


def test_s11_first_execution_defaults_by_tpsns_pl(start_plcemud):
    """FB manual FUN86 with FUN73's first execution: at the first scan with M0 ON, PR = 60,
    IR = 17, DR = 100 on all 24 points (TPSNS pl 0); with pl 1 Kc 30, with pl 2 Kc 120."""
    for pl, kc in ((0, 60), (1, 30), (2, 120)):
        c = start(start_plcemud, tpsns(pl) + tpctl())
        on(c, 1)
        step(c, 3)
        assert regs(c, 160, 24) == [0] * 24
        on(c, 0)
        step(c, 1)
        assert regs(c, 160, 24) == [kc] * 24, pl
        assert regs(c, 190, 24) == [17] * 24
        assert regs(c, 220, 24) == [100] * 24
        c.close()


def test_s11_sn_zn_out_of_range_is_err_at_run_time(start_plcemud):
    """FB manual FUN86: sn 20 zn 5 (Sn + Zn = 25 > 24) loads, and ERR is ON at every scan."""
    c = start(start_plcemud, tpsns() + tpctl(sn=20, zn=5))
    on(c, 1)
    on(c, 0)
    step(c, 300)
    assert coils(c, 2100) == [True]
    assert regs(c, 160, 5) == [0] * 5
    assert regs(c, 400, 9) == [0] * 9


def test_s11_tpsns_en_off_stops_tpctl(start_plcemud):
    """FB manual FUN86: "FUN85 … must be enabled, then, can the FUN86 start working". With SP
    far above the 200 degC readings every OR is 4095; M1 OFF (TPSNS's EN) turns Y30-Y53 OFF and
    OR 0; M1 ON again restarts PID once the 24 points are read (one round, 1998 ms)."""
    c = start(start_plcemud, tpsns() + tpctl())
    heat_until_all_read(c)
    assert regs(c, 300, 24) == [4095] * 24
    assert regs(c, 404) == [0x0202]
    assert not c.write_coil(2001, False, slave=1).isError()
    step(c, 1)
    assert regs(c, 300, 24) == [0] * 24
    assert coils(c, 30, 24) == [False] * 24
    assert regs(c, 404) == [0]
    on(c, 1)
    step(c, 200)
    assert regs(c, 300) == [0]
    step(c, 1)
    assert regs(c, 300, 24) == [4095] * 24


def test_s11_tpctl_before_tpsns_runs_a_scan_late(start_plcemud):
    """docs/profile-fb.md, "FUN86 TPCTL", program order: a TPCTL ahead of its TPSNS loads and
    runs on the readings of the scan before, so OR reaches 4095 at scan 202, one scan after the
    last group is read (scan 201 with the TPSNS first)."""
    c = start(start_plcemud, tpctl() + tpsns())
    heat_until_all_read(c)
    assert regs(c, 300) == [0]
    step(c, 1)
    assert regs(c, 300, 24) == [4095] * 24


def test_s11_round_is_ceil_n_over_4_times_r4004(start_plcemud):
    """FB manual FUN85/FUN86: 24 points are read in ceil(24/4) x R4004 = 6 x 333 = 1998 ms (the
    last group, points 20-23, on the scan at 2000 ms); with R4004 = 166, 996 ms. Raw values in
    R3968+p (826 for K at 200 degC), readings in TR+p."""
    c = start(start_plcemud, tpsns())
    on(c, 1)
    step(c, 200)
    assert regs(c, 252, 2) == [0xFFFF, 0x000F]
    step(c, 1)
    assert regs(c, 252, 2) == [0xFFFF, 0x00FF]
    assert regs(c, 3968, 24) == [826] * 24
    assert regs(c, 0, 24) == [200] * 24
    c.close()

    c = start(start_plcemud, tpsns())
    write(c, 4004, 166)
    on(c, 1)
    step(c, 100)
    assert regs(c, 253) == [0x000F]
    step(c, 1)
    assert regs(c, 253) == [0x00FF]


def test_s11_md_is_a_config_error(tmp_path):
    """FB manual FUN86 has no Md: `md:` on a TPCTL in profile fb is refused at its line and
    column, status 2."""
    text = FB + MODULES + "program:\n" + tpsns() + tpctl(extra=", md: 1")
    expect_config_error(tmp_path, text, 8, 32, "has no Md")


def test_s12_tp4_or_tstc_with_tpsns_exits_2_naming_both(tmp_path):
    """FB manual FUN73: the FB-2A…4 modules "cannot be used together with … FB-4AJ(K)xx": a
    program with both a TP4 (or a TSTC) and a TPSNS exits with status 2, naming both entries."""
    tp4 = "  - TP4: {en: M3, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R40, wr: R220}\n"
    text = FB + "program:\n" + tp4 + tpsns()
    err = expect_config_error(tmp_path, text, 6, 5, "the TPSNS cannot be used with the TP4")
    assert f"{tmp_path / 'vb.yaml'}:5:5" in err
    p, r = check_config(tmp_path, FB + "program:\n" + tpsns() + tp4)
    assert r.returncode == 2 and f"{p}:6:5: the TP4 cannot be used with the TPSNS at {p}:5:5" \
        in r.stderr, r.stderr
    tstc = ("  - TSTC: {en: M0, hc: 1, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R40, "
            "yh: Y48, sh: 0, zh: 4, sv: R100, os: R120, pr: R140, ir: R160, dr: R180, or: R300, "
            "wr: R200, err: M100, ao0: M101, ao1: M102}\n")
    err = expect_config_error(tmp_path, FB + "program:\n" + tstc + tpsns(), 6, 5,
                              "the TPSNS cannot be used with the TSTC")
    assert f"{tmp_path / 'vb.yaml'}:5:5" in err
    p, r = check_config(tmp_path, FB + "program:\n" + tpsns() + tstc)
    assert r.returncode == 2 and f"{p}:6:5: the TSTC cannot be used with the TPSNS at {p}:5:5" \
        in r.stderr, r.stderr


def test_s12_shared_devices_exit_2_naming_both(tmp_path):
    """docs/profile-fb.md, "FUN86 TPCTL", checks at load: TPSNS's readings on TPCTL's setpoints
    (TR R100 = SV R100), TPSNS's ERR on TPCTL's PWM outputs (Y30) and both ERRs on M100 each exit
    with status 2 at the TPCTL's operand, naming the TPSNS; the TPCTL ahead of the TPSNS loads."""
    head = FB + MODULES + "program:\n"
    for program, col, needle in (
            (tpsns().replace("tr: R0", "tr: R100") + tpctl(), 56,
             "R100-R123 overlaps R100-R123 of the TPSNS at {p}:7:5 (it writes them, and this "
             "instruction reads them as settings)"),
            (tpsns().replace("}", ", err: Y30}") + tpctl(), 32,
             "Y30-Y53 overlaps Y30 of the TPSNS at {p}:7:5"),
            (tpsns().replace("}", ", err: M100}") + tpctl(), 127,
             "M100 overlaps M100 of the TPSNS at {p}:7:5")):
        err = expect_config_error(tmp_path, head + program, 8, col, "")
        p = tmp_path / "vb.yaml"
        assert needle.format(p=p) in err, err
    p, r = check_config(tmp_path, head + tpctl() + tpsns())
    assert r.returncode == 0, r.stderr


def test_fb_tpctl_yaml_runs(start_plcemud):
    """config/fb-tpctl.yaml: TPSNS on an FB-4AK24 and a TPCTL over its 24 points with the
    first execution's defaults Kc 60, Ti 17, Td 100; the 24 slow loops from 25 degC are within
    150 +- 5 by 20 simulated minutes, every in-zone bit of WR+0/WR+1 set."""
    from conftest import REPO
    text = (REPO / "config" / "fb-tpctl.yaml").read_text()
    text = text.replace("    port: 5020\n", "")
    d = start_plcemud(text)
    c = d.client()
    freeze(c)
    step(c, 2)
    assert regs(c, 160, 24) == [60] * 24
    assert regs(c, 190, 24) == [17] * 24
    assert regs(c, 220, 24) == [100] * 24
    step(c, 1200 * SCANS_PER_S)
    readings = [s16(v) for v in regs(c, 0, 24)]
    assert all(145 <= v <= 155 for v in readings), readings
    assert regs(c, 400, 2) == [0xFFFF, 0x00FF]
