"""Temperature measurement (FBs manual §21.3) and the simulator-control unit
(docs/simulator-and-plant.md) over Modbus TCP.

The daemon runs with the table at R5000 (readings R0.., working registers D0..), a TC6 (K) and an
RTD6 (Pt100 DIN) installed. Most tests freeze the simulation through unit 247 and step it, so
simulated time is exact whatever the machine's load.
"""

import time

from conftest import BASE_CONFIG

SIM = 247  # simulator.unit default
D0 = 6000  # holding register of D0
TABLE = 5000  # holding register of R5000

CONFIG = BASE_CONFIG + """
temperature:
  table: R5000
  modules: [TC6:K, RTD6:PT100_DIN]
init:
  R5000: [0xA556, 2, 10000, 20000, 0x0101, 0x0002]
"""


def regs(client, addr, count=1, unit=1):
    r = client.read_holding_registers(addr, count, slave=unit)
    assert not r.isError(), f"read {addr}x{count} unit {unit}: {r}"
    return r.registers


def write(client, addr, value, unit=1):
    r = client.write_register(addr, value, slave=unit)
    assert not r.isError(), f"write {addr}={value} unit {unit}: {r}"


def write_many(client, addr, values, unit=1):
    r = client.write_registers(addr, values, slave=unit)
    assert not r.isError(), f"write {addr}={values} unit {unit}: {r}"


def signed(v):
    return v - 0x10000 if v & 0x8000 else v


def frozen(start_plcemud, config=CONFIG, *args):
    """A daemon whose scans are stopped through unit 247, and a client."""
    d = start_plcemud(config, *args)
    c = d.client()
    write(c, 1, 1, unit=SIM)
    return d, c


def step_seconds(client, seconds, scan_ms=10):
    """Runs `seconds` of simulated time in steps of at most 5000 scans. The reply to a step comes
    before its scans ran (docs/simulator-and-plant.md, "Simulator-control unit"), so this polls the simulated time
    (registers 3-4, whole seconds) until it moved on, then gives the last second a moment."""
    target = sim_seconds(client) + int(seconds)
    n = round(seconds * 1000 / scan_ms)
    while n > 0:
        k = min(n, 5000)
        write(client, 2, k, unit=SIM)
        n -= k
    deadline = time.monotonic() + 60
    # One second short: after a reload the clock restarts a scan behind a whole second.
    while sim_seconds(client) < target - 1:
        assert time.monotonic() < deadline, f"simulated time did not reach {target - 1} s"
        time.sleep(0.01)
    time.sleep(0.1)  # the last second's scans, under 1 ms of work


def sim_seconds(client):
    lo, hi = regs(client, 3, 2, unit=SIM)
    return lo | hi << 16


def execute_code(client):
    return regs(client, D0)[0] >> 8


def test_valid_table_reaches_56h_and_reads_ambient(start_plcemud):
    # FBs manual §21.3.2: 56h once every channel was read; the plant starts at 25.0 °C.
    _, c = frozen(start_plcemud)
    step_seconds(c, 5)
    wr = regs(c, D0, 12)
    assert wr[0] == 0x5600
    assert wr[3] == (12 << 8) | 2
    assert [signed(v) for v in regs(c, 0, 12)] == [250] * 12


def test_bad_marker_gives_execute_code_00h(start_plcemud):
    # FBs manual §21.3.1: SR+0 other than A556h = no measurement; rewritten at any time by
    # FC06/FC16.
    _, c = frozen(start_plcemud)
    step_seconds(c, 5)
    assert execute_code(c) == 0x56
    write(c, TABLE, 0x1234)
    step_seconds(c, 0.01)
    assert regs(c, D0)[0] == 0x0000
    write(c, TABLE, 0xA556)  # valid again: 00h until every channel was read again
    step_seconds(c, 0.01)
    assert execute_code(c) == 0x00
    step_seconds(c, 4)
    assert execute_code(c) == 0x56


def test_nine_modules_gives_FEh(start_plcemud):
    # FBs manual §21.3.2: module count 0 or > 8 → FEh, low byte of WR+3 the count.
    _, c = frozen(start_plcemud)
    write(c, TABLE + 1, 9)
    step_seconds(c, 5)
    assert execute_code(c) == 0xFE
    assert regs(c, D0 + 3)[0] & 0xFF == 9


def test_more_than_32_channels_gives_FFh(start_plcemud):
    # FBs manual §21.3.2: channels numbered across modules; more than 32 → FFh.
    _, c = frozen(start_plcemud)
    write_many(c, TABLE + 1, [3, 10000, 20000, 0x0103, 0x0103, 0x0101])  # TC16, TC16, TC6
    step_seconds(c, 7)
    assert execute_code(c) == 0xFF
    assert regs(c, D0 + 3)[0] == (38 << 8) | 3


def test_mismatched_module_sets_its_bit_and_reads_broken(start_plcemud):
    # FBs manual §21.3.2: a table module that differs from the installed one sets bit k-1 of
    # WR+0 low byte; Decision (docs/profile-fbs.md): its channels read 32767 with their abnormal
    # bits.
    _, c = frozen(start_plcemud)
    write(c, TABLE + 5, 0x0004)  # module 2: RTD16, but an RTD6 is installed
    step_seconds(c, 5)
    wr = regs(c, D0, 3)
    assert wr[0] == 0x5602
    readings = regs(c, 0, 22)
    assert [signed(v) for v in readings[:6]] == [250] * 6
    assert readings[6:22] == [32767] * 16
    assert wr[1] == 0xFFC0 and wr[2] == 0x003F


def test_fahrenheit_by_R4009(start_plcemud):
    # FBs manual §21.3 (unit of temperature), R4009 as in FB manual FUN73: R4009 = 1 gives °F:
    # 25.0 °C reads 77.0 °F.
    _, c = frozen(start_plcemud)
    write(c, 4009, 1)
    step_seconds(c, 5)
    assert [signed(v) for v in regs(c, 0, 12)] == [770] * 12
    write(c, 4009, 0)
    step_seconds(c, 5)
    assert signed(regs(c, 0)[0]) == 250


def test_R4009_low_byte_decides_the_unit(start_plcemud):
    # FB manual (FUN73 special registers): low byte 0 °C, 1 °F; the high byte does not count.
    _, c = frozen(start_plcemud)
    write(c, 4009, 0x0101)
    step_seconds(c, 5)
    assert [signed(v) for v in regs(c, 0, 12)] == [770] * 12
    write(c, 4009, 0x0100)
    step_seconds(c, 5)
    assert [signed(v) for v in regs(c, 0, 12)] == [250] * 12


def test_R4015_4_averages_16_readings(start_plcemud):
    # FB manual (FUN73 special registers): R4015 = 4 is a 16-reading moving average. Channel 0
    # jumps from 25 °C to 125 °C (τ 1 s); it is read once per 4 s round, so after 8 rounds half
    # of the 16 readings are new: about 75 °C (an 8-reading average would show 125 °C).
    _, c = frozen(start_plcemud)
    write(c, 4015, 4)
    write_many(c, 102, [0, 1, 0], unit=SIM)  # channel 0: K 0, τ 1 s, θ 0 s
    step_seconds(c, 70)  # 16 rounds at 25.0 °C
    assert signed(regs(c, 0)[0]) == 250
    write(c, 101, 1250, unit=SIM)  # ambient 125.0 °C
    step_seconds(c, 32)
    assert 650 <= signed(regs(c, 0)[0]) <= 850, regs(c, 0)
    step_seconds(c, 40)
    assert signed(regs(c, 0)[0]) == 1250


def test_reading_below_the_range_is_clamped_not_broken(start_plcemud):
    # Decision (docs/profile-fbs.md): a B thermocouple (350-1800 °C) at room temperature reads 350.0 °C with
    # no abnormal bit; a Pt1000 above 600 °C reads 600.0 °C; only an open sensor reads 32767.
    _, c = frozen(start_plcemud)
    write_many(c, TABLE + 4, [0x0501, 0x0202])  # TC6 with B, RTD6 with Pt1000 DIN
    write(c, 100 + 10 * 6 + 1, 7000, unit=SIM)  # channel 6: ambient 700.0 °C
    write_many(c, 100 + 10 * 6 + 3, [1, 0], unit=SIM)  # τ 1 s, θ 0
    write(c, 100 + 10 * 2, 0b0001, unit=SIM)  # channel 2: open
    step_seconds(c, 10)
    readings = regs(c, 0, 12)
    assert readings[:6] == [3500, 3500, 32767, 3500, 3500, 3500]
    assert readings[6] == 6000 and readings[7:] == [250] * 5
    assert regs(c, D0 + 1)[0] == 1 << 2


def test_sensor_broken_fault_through_unit_247(start_plcemud):
    # Fault "sensor broken" (docs/simulator-and-plant.md, Thermal plant); docs/profile-fbs.md,
    # Temperature measurement: 32767 and the WR+1 bit; clears when repaired.
    _, c = frozen(start_plcemud)
    step_seconds(c, 5)
    write(c, 100 + 10 * 2, 0b0001, unit=SIM)
    write(c, 100 + 10 * 8, 0b0001, unit=SIM)
    step_seconds(c, 4)
    assert regs(c, 2)[0] == 32767
    assert regs(c, 8)[0] == 32767
    assert regs(c, D0 + 1)[0] == (1 << 2) | (1 << 8)
    write(c, 100 + 10 * 2, 0, unit=SIM)
    write(c, 100 + 10 * 8, 0, unit=SIM)
    step_seconds(c, 4)
    assert signed(regs(c, 2)[0]) == 250
    assert regs(c, D0 + 1)[0] == 0


def test_heater_shorted_heats_and_reading_frozen_holds(start_plcemud):
    # docs/simulator-and-plant.md, Thermal plant, faults: heater shorted (u = 1) heats the process;
    # a frozen reading stops changing.
    _, c = frozen(start_plcemud)
    write(c, 100 + 10 * 0, 0b0100, unit=SIM)
    step_seconds(c, 60)
    true_t = signed(regs(c, 106, unit=SIM)[0])
    assert true_t > 1000  # θ 5 s, τ 120 s, K 400: about 25 + 400·(1 - e^-0.46) = 170 °C
    assert regs(c, 107, unit=SIM)[0] == 1000  # heater power 100.0 %
    # The reading follows, up to one conversion (4 s) behind a process rising about 2 °C/s.
    assert 0 <= true_t - signed(regs(c, 0)[0]) < 150
    write(c, 100, 0b1100, unit=SIM)  # and now the reading freezes
    step_seconds(c, 4)
    held = regs(c, 0)[0]
    step_seconds(c, 30)
    assert regs(c, 0)[0] == held
    assert signed(regs(c, 106, unit=SIM)[0]) > held + 100


def test_plant_parameters_through_unit_247(start_plcemud):
    # docs/simulator-and-plant.md, "Simulator-control unit (unit 247)": per-channel ambient, K, τ,
    # θ, noise at 100 + 10c + 1..5.
    _, c = frozen(start_plcemud)
    assert regs(c, 131, 5, unit=SIM) == [250, 4000, 120, 5, 0]  # channel 3 defaults
    write(c, 131, (-100) & 0xFFFF, unit=SIM)  # ambient -10.0 °C
    write_many(c, 132, [1000, 10, 0], unit=SIM)  # K 100.0 °C, τ 10 s, θ 0 s
    step_seconds(c, 200)
    assert signed(regs(c, 136, unit=SIM)[0]) == -100
    assert signed(regs(c, 3)[0]) == -100


def test_freeze_and_step_control_simulated_time(start_plcemud):
    # Unit 247: 1 freeze, 2 step N scans, 3-4 simulated seconds (low word first).
    _, c = frozen(start_plcemud)
    t0 = sim_seconds(c)
    time.sleep(0.3)
    assert sim_seconds(c) == t0  # frozen: no scans
    write(c, 2, 1000, unit=SIM)  # 1000 scans of 10 ms, run after the reply
    deadline = time.monotonic() + 20
    while sim_seconds(c) < t0 + 10 and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.2)
    assert sim_seconds(c) == t0 + 10


def test_simulated_time_is_32_bit(start_plcemud):
    # Unit 247 registers 3-4: low word first, past 65535 s (1 s scans to get there quickly).
    _, c = frozen(start_plcemud, CONFIG + "scan_ms: 1000\n")
    step_seconds(c, 70000, scan_ms=1000)
    lo, hi = regs(c, 3, 2, unit=SIM)
    assert hi == 1 and (lo | hi << 16) in (69999, 70000)


def test_time_scale_register_and_option(start_plcemud):
    # Unit 247 register 0 shows --time-scale and changes it (1-10000).
    d = start_plcemud(CONFIG, "--time-scale", "50")
    c = d.client()
    assert regs(c, 0, unit=SIM)[0] == 50
    write(c, 0, 600, unit=SIM)
    assert regs(c, 0, unit=SIM)[0] == 600
    deadline = time.monotonic() + 20
    while sim_seconds(c) < 120 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert sim_seconds(c) >= 120
    write(c, 0, 0, unit=SIM)  # out of range: clamped
    assert regs(c, 0, unit=SIM)[0] == 1


def test_read_only_and_unmapped_words_of_unit_247(start_plcemud):
    _, c = frozen(start_plcemud)
    for addr in (3, 4, 106, 107, 109):  # 108+10c is the RTD lead resistance, writable
        r = c.write_register(addr, 1, slave=SIM)
        assert r.isError() and r.exception_code == 2, addr
    r = c.read_holding_registers(5, 1, slave=SIM)
    assert r.isError() and r.exception_code == 2
    r = c.read_holding_registers(420, 1, slave=SIM)
    assert r.isError() and r.exception_code == 2
    assert len(regs(c, 100, 120, unit=SIM)) == 120


def test_print_map_lists_the_simulator_unit(start_plcemud, tmp_path):
    from conftest import run_plcemud

    cfg = tmp_path / "c.yaml"
    cfg.write_text(CONFIG + "simulator: {unit: 200}\n")
    out = run_plcemud("--print-map", "-c", cfg).stdout
    rows = [line for line in out.splitlines() if "(unit 200)" in line]
    assert len(rows) == 5 + 21 + 10  # time control, communication faults, a channel's ten words
    assert any("106+10c" in r and "read-only" in r for r in rows)
    assert any("comm.status" in r and "read-only" in r for r in rows)
    assert sum("comm." in r and "read/write" in r for r in rows) == 20


def test_reload_keeps_process_temperatures_and_freeze(start_plcemud):
    # docs/simulator-and-plant.md, "Thermal plant": on SIGHUP the temperatures carry over and a frozen simulation stays
    # frozen; the new config's faults replace the run-time ones.
    import signal

    d, c = frozen(start_plcemud)
    write(c, 100, 0b0100, unit=SIM)  # channel 0: heater shorted
    step_seconds(c, 60)
    hot = signed(regs(c, 106, unit=SIM)[0])
    assert hot > 1000
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    c = d.client()
    assert regs(c, 1, unit=SIM)[0] == 1  # still frozen
    assert regs(c, 100, unit=SIM)[0] == 0  # the config's faults: none
    assert abs(signed(regs(c, 106, unit=SIM)[0]) - hot) <= 1
    step_seconds(c, 60)  # no heater now: it cools
    assert signed(regs(c, 106, unit=SIM)[0]) < hot - 100
