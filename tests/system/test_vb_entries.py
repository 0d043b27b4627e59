"""The VB program entries through Modbus TCP against the real daemon (docs/profile-vb.md,
"FNC169 HOUR" and "Program entries"): the hour meter over two simulated hours and across a
restart, the PID example's 2 s delay and the TPID example's time-proportioning output
(TMR, RST, CMPOUT), PLS, RST, WOR, MOVP, what a master's hostile writes do to them, and the
configuration errors of their operands at line and column. The scans are frozen and stepped
through the simulator unit, so every figure is exact."""

import pytest

from test_vb import VB, coils, exc, expect_config_error, freeze, regs, step, write

# Nearly still until frozen: the steps are the whole run (at most the first scan runs before).
STILL = VB + "time_scale: 0.001\n"

# Wire addresses (docs/profile-vb.md, "Modbus map").
M0 = 0
Y0 = 13056
T0 = 12288  # timer contacts
C0 = 12800  # counter contacts
TN0 = 9000
CN200 = 9700


def coil(client, addr, value):
    assert exc(client.write_coil(addr, value, slave=1)) == 0


def frozen(start_plcemud, program, **kw):
    """A daemon running `program` (YAML list entries), frozen; returns (daemon, client)."""
    d = start_plcemud(STILL + "program:\n" + program, **kw)
    c = d.client()
    freeze(c)
    return d, c


# --- FNC169 HOUR -------------------------------------------------------------------------------


def test_hour_meter_over_two_hours_and_a_restart(start_plcemud):
    """VB manual FNC169 with S = 2: after 1.5 h D7000 = 1, D7001 = 1800 and Y0 OFF; after 2 h
    D7000 = 2 and Y0 ON; M0 OFF keeps the values; a restart keeps D7000 (latched, D200-D7999)
    and clears D100 (general)."""
    program = (
        "  - HOUR: {en: M0, s: 2, d1: D7000, d2: Y0}\n"
        "  - HOUR: {en: M0, s: 2, d1: D100, d2: Y1}\n"
    )
    d, c = frozen(start_plcemud, program, name="hour")
    coil(c, M0, True)
    step(c, 540_000)  # 1.5 h of 10 ms scans
    assert regs(c, 7000, 2) == [1, 1800]
    assert regs(c, 100, 2) == [1, 1800]
    assert coils(c, Y0, 2) == [False, False]
    step(c, 180_000)  # 2 h
    assert regs(c, 7000, 2) == [2, 0]
    assert coils(c, Y0, 2) == [True, True]
    coil(c, M0, False)
    step(c, 6000)  # a minute with EN OFF
    assert regs(c, 7000, 2) == [2, 0]
    assert regs(c, 100, 2) == [2, 0]
    assert coils(c, Y0, 2) == [True, True]
    assert d.stop() == 0, d.log_text()

    d = start_plcemud(STILL + "program:\n" + program, name="hour")
    c = d.client()
    assert regs(c, 7000, 2) == [2, 0]
    assert regs(c, 100, 2) == [0, 0]


def test_hour_meter_survives_hostile_writes(start_plcemud):
    """What a master writes into the meter cannot crash or hang it: seconds beyond 3599 carry,
    the count stops at 32767 h 3599 s (DHOUR: 2147483647 h), a negative preset alarms at once."""
    _, c = frozen(
        start_plcemud,
        "  - HOUR: {en: M0, s: D10, d1: D7000, d2: Y0}\n"
        "  - DHOUR: {en: M0, s: D12, d1: D7010, d2: Y1}\n",
    )
    write(c, 10, 0xFFFF)  # S = -1
    write(c, 12, 0xFFFF)  # S = 7FFFFFFFh
    write(c, 13, 0x7FFF)
    for addr, value in ((7000, 32767), (7001, 65535), (7010, 0xFFFF), (7011, 0x7FFF),
                        (7012, 65535)):
        write(c, addr, value)
    coil(c, M0, True)
    step(c, 300)
    assert regs(c, 7000, 2) == [32767, 3599]
    assert regs(c, 7010, 3) == [0xFFFF, 0x7FFF, 3599]
    assert coils(c, Y0, 2) == [True, True]
    write(c, 7000, 0)
    write(c, 7001, 7300)  # 2 h 100 s
    step(c, 100)  # + 1 s
    assert regs(c, 7000, 2) == [2, 101]


# --- TMR, RST, CMPOUT: the examples' delay and time-proportioning output ----------------------


def test_two_second_delay_and_time_proportioning_output(start_plcemud):
    """VB manual FNC88 example: "T0 K20" on M9000 is a 2 s delay. FNC92 example I: T200 K500 is
    a 5 s cycle and "< T200 D102" switches Y0 for the first D102 counts of it; here the timer
    restarts itself with RST. Y0 follows TN200 < D102 at every step, and TN200 wraps."""
    _, c = frozen(
        start_plcemud,
        "  - TMR: {en: M9000, t: T0, k: 20}\n"
        "  - TMR: {en: M9000, t: T200, k: 500}\n"
        "  - RST: {en: T200, d: T200}\n"
        "  - CMPOUT: {op: '<', s1: TN200, s2: D102, out: Y0}\n",
    )
    write(c, 102, 150)  # 30 %
    step(c, 150)  # at most 1.51 s since the start
    assert 15 <= regs(c, TN0)[0] <= 16
    assert coils(c, T0) == [False]
    step(c, 50)  # at least 2.00 s
    assert regs(c, TN0) == [20]
    assert coils(c, T0) == [True]
    on = 0
    seen = []
    for _ in range(200):  # 1000 scans, two whole cycles
        step(c, 5)
        value = regs(c, TN0 + 200)[0]
        y0 = coils(c, Y0)[0]
        assert y0 == (value < 150), (value, y0)
        on += y0
        seen.append(value)
    assert on == 60  # 30 of every 100 samples
    assert max(seen) >= 495 and min(seen) <= 4  # it ran through whole cycles
    assert regs(c, TN0) == [20]  # the delay timer stays at K
    write(c, 102, 0)
    step(c, 1)
    assert coils(c, Y0) == [False]


def test_retentive_timer_keeps_its_value_until_rst(start_plcemud):
    """T250 (100 ms, retentive) keeps value and contact while EN is OFF; RST clears both. A
    negative K in a register does not stop anything."""
    _, c = frozen(
        start_plcemud,
        "  - TMR: {en: M0, t: T250, k: D0}\n"
        "  - RST: {en: M1, d: T250}\n",
    )
    write(c, 0, 30)
    coil(c, M0, True)
    step(c, 200)  # 2 s
    assert regs(c, TN0 + 250) == [20]
    coil(c, M0, False)
    step(c, 500)
    assert regs(c, TN0 + 250) == [20]
    coil(c, M0, True)
    step(c, 100)
    assert regs(c, TN0 + 250) == [30]
    assert coils(c, T0 + 250) == [True]
    coil(c, M0, False)
    step(c, 10)
    assert coils(c, T0 + 250) == [True]
    coil(c, 1, True)  # M1: RST
    step(c, 1)
    assert regs(c, TN0 + 250) == [0]
    assert coils(c, T0 + 250) == [False]
    coil(c, 1, False)
    write(c, 0, 0x8000)  # K = -32768
    coil(c, M0, True)
    step(c, 1)
    assert coils(c, T0 + 250) == [True]


# --- PLS, RST of a counter, WOR, MOVP ----------------------------------------------------------


def test_pls_pulses_one_scan_per_rising_edge(start_plcemud):
    """PLS M10 on M0: ON for the one scan in which M0 turns ON; C0 counts the pulses."""
    _, c = frozen(
        start_plcemud,
        "  - PLS: {en: M0, d: M10}\n"
        "  - CNT: {en: M10, c: C0, k: 100}\n",
    )
    for n in range(1, 4):
        coil(c, M0, True)
        step(c, 1)
        assert coils(c, 10) == [True]
        step(c, 1)
        assert coils(c, 10) == [False]
        coil(c, M0, False)
        step(c, 1)
        assert regs(c, 9500) == [n]


def test_rst_clears_a_32bit_counter(start_plcemud):
    """RST C200 clears both words of the value and the contact, in every scan while EN is ON."""
    _, c = frozen(
        start_plcemud,
        "  - CNT: {en: M0, c: C200, k: 5}\n"
        "  - RST: {en: M1, d: C200}\n",
    )
    assert exc(c.write_registers(CN200, [0x0001, 0x0002], slave=1)) == 0
    step(c, 1)
    assert coils(c, C0 + 200) == [True]
    coil(c, 1, True)
    step(c, 1)
    assert regs(c, CN200, 2) == [0, 0]
    assert coils(c, C0 + 200) == [False]
    coil(c, M0, True)  # an edge while RST holds it
    step(c, 1)
    assert regs(c, CN200, 2) == [0, 0]


def test_wor_and_movp(start_plcemud):
    """WOR: D1 = D0 OR 00F0h while M2 is ON. MOVP: D11 = D10 only in the scan M3 turns ON; on
    M9002 (the initial pulse) it runs once at start."""
    _, c = frozen(
        start_plcemud,
        "  - WOR: {en: M2, s1: D0, s2: H00F0, d: D1}\n"
        "  - MOV: {en: M3, s: D10, d: D11, p: true}\n"
        "  - MOV: {en: M9002, s: K1234, d: D20, p: true}\n",
    )
    step(c, 1)
    assert regs(c, 20) == [1234]
    write(c, 20, 0)
    write(c, 0, 0x1203)
    write(c, 10, 5)
    step(c, 1)
    assert regs(c, 0, 2) == [0x1203, 0]  # M2 OFF
    assert regs(c, 20) == [0]  # the initial pulse is over
    coil(c, 2, True)
    coil(c, 3, True)
    step(c, 1)
    assert regs(c, 1) == [0x12F3]
    assert regs(c, 11) == [5]
    write(c, 10, 6)
    step(c, 3)
    assert regs(c, 11) == [5]  # M3 held ON: no new edge
    coil(c, 3, False)
    step(c, 1)
    coil(c, 3, True)
    step(c, 1)
    assert regs(c, 11) == [6]


# --- configuration errors ----------------------------------------------------------------------

P = "profile: vb\nprogram:\n"


@pytest.mark.parametrize(
    "text,line,col,needle",
    [
        (P + "  - HOUR: {en: M0, s: 40000, d1: D7000, d2: Y0}\n", 3, 23,
         "HOUR.s: 40000 is out of range 0..32767"),
        (P + "  - HOUR: {en: M0, s: 1, d1: D7999, d2: Y0}\n", 3, 30, "HOUR.d1: expected 2 word(s)"),
        (P + "  - DHOUR: {en: M0, s: 1, d1: D7998, d2: Y0}\n", 3, 31,
         "DHOUR.d1: expected 3 word(s)"),
        (P + "  - HOUR: {en: M0, s: 1, d1: D0, d2: X0}\n", 3, 38, "HOUR.d2: expected a Y, M or S"),
        (P + "  - TMR: {en: M0, t: T256, k: 20}\n", 3, 22, "TMR.t"),
        (P + "  - TMR: {en: M0, t: T0, k: 32768}\n", 3, 29, "TMR.k: 32768 is out of range"),
        (P + "  - RST: {en: M0, d: X0}\n", 3, 22, "RST.d"),
        (P + "  - PLS: {en: M0, d: D0}\n", 3, 22, "PLS.d: expected a Y, M or S output"),
        (P + "  - WOR: {en: M0, s1: D0, s2: D1, d: X0}\n", 3, 38, "WOR.d"),
        (P + "  - CMPOUT: {op: '=>', s1: D0, s2: D1, out: Y0}\n", 3, 18,
         "CMPOUT.op: expected one of = <> < <= > >="),
        (P + "  - CMPOUT: {op: '<', s1: T200, s2: D102, out: Y0}\n", 3, 27,
         "(its value is TN200)"),
        (P + "  - MOV: {s: D0, d: D1, p: maybe}\n", 3, 28, "MOV.p: expected true or false"),
        (P + "  - MOV: {s: D0, d: D1}\n  - TMR:\n      en: X10\n      t: T0\n      k: X8\n", 7, 10,
         "TMR.k"),
    ],
    ids=["HOUR-s", "HOUR-d1", "DHOUR-d1", "HOUR-d2", "TMR-t", "TMR-k", "RST-d", "PLS-d", "WOR-d",
         "CMPOUT-op", "CMPOUT-T200", "MOV-p", "later-line"],
)
def test_operand_errors_name_file_line_col(tmp_path, text, line, col, needle):
    expect_config_error(tmp_path, text, line, col, needle)


def test_cmp_and_zrst_through_modbus(start_plcemud):
    """FNC10 CMP: M10-M12 say D0 > K5, D0 = K5, D0 < K5 (signed) while M0 is ON and keep their
    state while it is OFF; FNC40 ZRST clears D100-D102 while M1 is ON, D103 untouched."""
    _, c = frozen(
        start_plcemud,
        "  - CMP: {en: M0, s1: D0, s2: K5, d: M10}\n"
        "  - ZRST: {en: M1, d1: D100, d2: D102}\n",
    )
    coil(c, M0, True)
    for value, want in ((5, [False, True, False]), (0xFFFF, [False, False, True]),
                        (6, [True, False, False])):
        write(c, 0, value)
        step(c, 1)
        assert coils(c, M0 + 10, 3) == want, value
    coil(c, M0, False)
    write(c, 0, 5)
    step(c, 1)
    assert coils(c, M0 + 10, 3) == [True, False, False]
    for a in range(100, 104):
        write(c, a, 7)
    coil(c, M0 + 1, True)
    step(c, 1)
    assert regs(c, 100, 4) == [0, 0, 0, 7]
