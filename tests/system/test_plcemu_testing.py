"""The pytest plugin plcemu_testing (python/, docs/testing.md) on real scenarios: its `plcemud`
fixture runs the daemon, device names go through the daemon's own map, the simulator unit runs
the plant in simulated time, plant and communication faults, restart, reload and errors that
name the device."""

import inspect
import math
import os
import re
import socket
import subprocess
import sys
import time

import pytest
import yaml

from conftest import REPO, raw_exchange
from plcemu_testing import DaemonError, DeviceError, ModbusError, Plc, Plcs

DEFAULT = REPO / "config" / "default.yaml"


def start_loops(plc, points=10):
    """What a SCADA does to start config/default.yaml's TPCTL: points on (M800+), then EN (M0)."""
    plc.freeze()
    plc.write_bits("M800", [1] * points)
    plc.write_bits("M0", 1)


def test_default_config_heats_in_simulated_time(plcemud):
    plc = plcemud(DEFAULT)
    assert plc.station == 1 and plc.port > 0
    assert "listening on tcp 127.0.0.1:" in plc.log
    start_loops(plc)
    assert plc.read("R100", 10) == [1500] * 10  # the config's setpoints
    cold = plc.read("R0", 10)
    t0 = plc.sim_time
    assert plc.run(seconds=600) == t0 + 600
    hot = plc.read("R0", 10)
    assert all(c <= 300 for c in cold), cold  # ambient, 25.0 °C
    assert all(h > 1000 for h in hot), hot  # about 144 °C after ten minutes
    # The module reads the true process temperature (no noise in the config).
    assert abs(plc.true_temperature(0) - hot[0] / 10) <= 1.0
    assert 0 < plc.heater_power(0) <= 100
    # The plugin's names address what the raw client reads at the documented addresses.
    assert plc.client.read_holding_registers(0, 10, slave=1).registers == plc.read("R0", 10)


def test_run_scans_and_freeze(plcemud):
    plc = plcemud({"profile": "fbs", "scan_ms": 20})
    plc.time_scale = 100
    assert plc.time_scale == 100
    plc.freeze()
    assert plc.frozen
    t0 = plc.sim_time
    time.sleep(0.3)  # 30 simulated seconds, were it running
    assert plc.sim_time == t0
    plc.run(scans=250)  # 250 scans of 20 ms
    assert plc.sim_time == t0 + 5
    plc.run(seconds=3)
    assert plc.sim_time == t0 + 8
    with pytest.raises(TypeError):
        plc.run()


def test_heater_open_cools_and_sensor_broken_reads_32767(plcemud):
    plc = plcemud(DEFAULT)
    start_loops(plc)
    plc.run(seconds=600)
    hot = plc.true_temperature(2)
    assert plc.heater_power(2) > 0
    assert plc.fault(2, heater_open=True) == {"sensor_broken": False, "heater_open": True,
                                              "heater_shorted": False, "reading_frozen": False}
    plc.fault(4, sensor_broken=True)
    plc.run(seconds=300)
    assert plc.heater_power(2) == 0
    assert plc.true_temperature(2) < hot
    assert plc.true_temperature(3) > hot - 5  # its neighbour goes on heating
    assert plc.read("R4") == [32767]  # an open sensor
    plc.clear_faults(2)
    assert not any(plc.faults(2).values())
    plc.run(seconds=60)
    assert plc.heater_power(2) > 0


def test_plant_parameters_in_config_units(plcemud):
    plc = plcemud(DEFAULT)  # the loops are not started: no heating
    plc.freeze()
    params = plc.plant(0, ambient=40, tau=300, dead_time=0, noise=0.5)
    assert params["ambient"] == 40 and params["tau"] == 300 and params["noise"] == 0.5
    start = plc.true_temperature(0)
    plc.run(seconds=600)
    # First order towards the new ambient: T = 40 - (40 - T0) e^(-t/tau).
    expected = 40 - (40 - start) * math.exp(-600 / 300)
    assert abs(plc.true_temperature(0) - expected) < 0.2, (plc.true_temperature(0), expected)
    assert plc.heater_power(0) == 0
    assert plc.plant(0, tau=0)["tau"] == 1  # clamped by the daemon, read back
    assert plc.plant(0, lead_resistance=1.25)["lead_resistance"] == 1.25  # unit 247, 108+10c


def test_vb_pid_config_as_a_dict(plcemud):
    """config/vb-pid.yaml loaded into a dict (plant channel 0 is an int key): setting M0 starts
    the auto-tuning relay at full output on D102, which heats plant channel 0."""
    cfg = yaml.safe_load((REPO / "config" / "vb-pid.yaml").read_text())
    plc = plcemud(cfg)
    plc.freeze()
    plc.write_bits("M0", 1)
    plc.run(seconds=30)
    assert plc.read("D102") == [500]
    assert plc.heater_power(0) > 95
    assert plc.true_temperature(0) > 30
    assert plc.read("D201")[0] >> 4 & 1 == 1  # still auto-tuning


def test_vb_hour_meter_and_restart_keeps_retentive_values(plcemud):
    plc = plcemud({"profile": "vb", "program": [
        {"HOUR": {"en": "M0", "s": 2, "d1": "D7000", "d2": "Y0"}}]})
    plc.freeze()
    plc.write_bits("M0", 1)
    plc.run(seconds=2 * 3600 + 30)
    hours, seconds = plc.read("D7000", 2)
    assert hours == 2 and 20 <= seconds <= 30, (hours, seconds)
    assert plc.read_bits("Y0") == [1]  # the alarm: hours >= S
    plc.write("D100", 7)  # D0-D199 are general, D200-D7999 latched
    plc.write("D7100", 1234)
    assert plc.restart(kill=True) == -9
    assert plc.read("D7100") == [1234]
    assert plc.read("D7000") == [2]
    assert plc.read("D100") == [0]
    assert plc.restart() == 0  # SIGTERM: a clean exit
    assert plc.read("D7100") == [1234]
    assert plc.log.count("listening on tcp") == 3


def test_vb_octal_names_and_32_bit_counters(plcemud):
    plc = plcemud({"profile": "vb"})
    plc.write_bits("Y7", [1, 1])  # Y7 and Y10: octal
    assert plc.read_bits("Y6", 3) == [0, 1, 1]
    y0 = plc.map.wire("Y", "0", table="coils")[1]
    assert plc.client.read_coils(y0 + 7, 2, slave=1).bits[:2] == [True, True]
    assert plc.read_bits("X0", 8) == [0] * 8  # discrete inputs only
    plc.write("CN199", [5, 100000, -2])  # CN199 one word, CN200 and CN201 two each
    assert plc.read("CN199", 3) == [5, 100000, (1 << 32) - 2]
    assert plc.read("CN201", signed=True) == [-2]
    # Low word first on the wire: CN200 at 9700 (docs/profile-vb.md).
    assert plc.client.read_holding_registers(9700, 2, slave=1).registers == [
        100000 & 0xFFFF, 100000 >> 16]
    plc.write("WM16", 0x8001)  # M16 and M31, as 16 bits
    assert plc.read_bits("M16", 16) == [1] + [0] * 14 + [1]
    assert plc.read("WM16") == [0x8001]


def test_fbs_counter_and_timer_registers(plcemud):
    plc = plcemud({"profile": "fbs"})
    plc.write("C200", 70000)
    assert plc.read("CTR200") == [70000]  # CTRn names the value of Cn
    assert plc.client.read_holding_registers(9700, 2, slave=1).registers == [
        70000 & 0xFFFF, 70000 >> 16]
    plc.write("TMR3", 42)
    assert plc.read("T3") == [42]
    assert plc.client.read_holding_registers(9003, 1, slave=1).registers == [42]


def test_reload_applies_a_new_config_and_rejects_an_invalid_one(plcemud):
    plc = plcemud({"profile": "fbs", "init": {"M5": 0}})
    plc.write("D10", 99)
    plc.reload({"profile": "fbs", "station": 5, "init": {"M5": 1}})
    assert "reload: station: 1 -> 5" in plc.log
    assert plc.station == 5
    assert plc.read_bits("M5") == [1]  # a non-retentive preset is applied at the reload
    assert plc.read("D10") == [99]  # the image is kept
    with pytest.raises(DaemonError, match="rejected"):
        plc.reload({"profile": "fbs", "scan_ms": 0})
    assert plc.read("D10") == [99]  # still running the previous config
    plc.restart()  # with the config that runs, not the rejected one
    assert plc.station == 5 and plc.read("D10") == [99]


def test_errors_name_the_device(plcemud):
    fbs = plcemud({"profile": "fbs"})
    with pytest.raises(ModbusError, match=r"write R3840: Modbus exception 02h "
                                          r"\(illegal data address\)") as e:
        fbs.write("R3840", 1)  # IR: read-only
    assert e.value.code == 2 and e.value.device == "R3840"
    with pytest.raises(ModbusError, match="X0.*illegal data address"):
        fbs.write_bits("X0", 1)
    with pytest.raises(DeviceError, match="Q5: no Q devices"):
        fbs.read("Q5")
    with pytest.raises(DeviceError, match="D5000: not reachable over Modbus"):
        fbs.read("D5000")
    with pytest.raises(DeviceError, match="M0: a bit device"):
        fbs.read("M0")
    with pytest.raises(DeviceError, match="D0: a register"):
        fbs.read_bits("D0")
    with pytest.raises(DeviceError, match="not a device name"):
        fbs.write("100", 1)
    with pytest.raises(ValueError, match="D0: 70000 does not fit 16 bits"):
        fbs.write("D0", 70000)

    vb = plcemud({"profile": "vb"})
    with pytest.raises(DeviceError, match="X0: read-only over Modbus"):
        vb.write_bits("X0", 1)
    with pytest.raises(DeviceError, match="X8: .*octal"):
        vb.read_bits("X8")
    with pytest.raises(DeviceError, match="TMR5: no TMR devices"):
        vb.read("TMR5")  # an FBs name


def test_an_invalid_config_fails_with_the_daemons_message(plcemud):
    with pytest.raises(DaemonError, match="scan_ms"):
        plcemud({"profile": "fbs", "scan_ms": 0})


def test_the_readme_example_runs_with_p_plcemu_testing(tmp_path):
    """README's user test, run as a user would: `PYTHONPATH=python pytest -p plcemu_testing`."""
    text = (REPO / "README.md").read_text()
    block = re.search(r"```python\n(def test_.*?)```", text, re.S)
    assert block, "README.md has no pytest example"
    (tmp_path / "test_user.py").write_text(block.group(1))
    env = {**os.environ, "PYTHONPATH": str(REPO / "python")}
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "plcemu_testing",
                        "-p", "no:cacheprovider", str(tmp_path / "test_user.py")], cwd=REPO,
                       env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "1 passed" in r.stdout, r.stdout + r.stderr


def test_names_follow_a_modbus_map(plcemud):
    """Under a modbus.map the same names reach the devices at the map's addresses: D moved,
    M packed 16 to a register (WM), a row of counter values across the 16/32-bit boundary."""
    plc = plcemud({"profile": "vb", "modbus": {"map": [
        {"table": "holding", "start": 0x4000, "device": "D0", "count": 8000},
        {"table": "holding", "start": 0x2478, "device": "WM0", "count": 192},
        {"table": "holding", "start": 0x100, "device": "CN198", "count": 6}]}})
    plc.write("D7", 1234)
    assert plc.client.read_holding_registers(0x4007, 1, slave=1).registers == [1234]
    plc.write("WM32", 0x0005)  # M32 and M34: the third packed register
    assert plc.client.read_holding_registers(0x2478 + 2, 1, slave=1).registers == [5]
    assert plc.read("WM32") == [5]
    plc.write("CN198", [1, 2, 70000, 4])  # 198, 199 one word each; 200, 201 two
    assert plc.client.read_holding_registers(0x100, 6, slave=1).registers == [
        1, 2, 70000 & 0xFFFF, 70000 >> 16, 4, 0]
    with pytest.raises(DeviceError, match=r"M0: no M devices .*\(its areas: CN, D, WM\)"):
        plc.read_bits("M0")  # only packed in registers here: no coils


def two_kilns(dryer_station=2):
    """config/default.yaml twice behind one TCP listener: kiln (station 1, simulator unit 201)
    and dryer (station 2, simulator unit 202), docs/configuration.md "Sharing a listener"."""
    cfg = yaml.safe_load(DEFAULT.read_text())
    return {"plcs": [dict(cfg, name="kiln", simulator={"unit": 201}),
                     dict(cfg, name="dryer", station=dryer_station, simulator={"unit": 202})]}


def test_two_plcs_behind_one_listener_heat_independently(plcemud):
    plcs = plcemud(two_kilns())
    assert isinstance(plcs, Plcs) and len(plcs) == 2 and plcs.names == ["kiln", "dryer"]
    kiln, dryer = plcs["kiln"], plcs[1]
    assert dryer is plcs["dryer"] and list(plcs) == [kiln, dryer]
    assert kiln.port == dryer.port and (kiln.station, dryer.station) == (1, 2)
    assert (f"listening on tcp 127.0.0.1:{kiln.port} for plcs[0] (kiln), plcs[1] (dryer)"
            in plcs.log)
    dryer.freeze()
    start_loops(kiln)
    t_dryer = dryer.sim_time
    kiln.run(seconds=600)
    # The kiln heated in its simulated time; the dryer's time stood still, its loops off.
    assert min(kiln.read("R0", 10)) > 1000
    assert max(dryer.read("R0", 10)) <= 300 and dryer.sim_time == t_dryer
    assert kiln.true_temperature(0) > 100 and dryer.true_temperature(0) < 30
    # A write to one is not seen by the other: the dryer's setpoints go to 80 °C.
    dryer.write("R100", [800] * 10)
    assert kiln.read("R100", 10) == [1500] * 10
    t_kiln = kiln.sim_time
    start_loops(dryer)
    dryer.run(seconds=600)
    assert kiln.sim_time == t_kiln
    assert 60 < dryer.true_temperature(0) < 100 < kiln.true_temperature(0)
    assert dryer.heater_power(0) < 100
    # Faults and plant parameters go to one PLC's simulator unit only.
    kiln.fault(0, heater_open=True)
    assert not any(dryer.faults(0).values())
    assert dryer.plant(1, ambient=30)["ambient"] == 30 and kiln.plant(1)["ambient"] == 25
    # Each PLC's rows of the export, reached through its own handle.
    assert kiln.tag("R100")["name"] == "kiln.R100" and dryer.read_tag("R100") == 800
    assert kiln.read_tag("kiln.R100") == 1500
    assert {t["plc"] for t in plcs.tags} == {"kiln", "dryer"}
    with pytest.raises(ModbusError, match=r"write R3840: Modbus exception 02h"):
        dryer.write("R3840", 1)


def test_plcs_restart_and_reload_keep_each_plcs_state(plcemud):
    plcs = plcemud(two_kilns())
    kiln, dryer = plcs
    kiln.write("D500", 11)  # D is retentive (docs/profile-fbs.md)
    dryer.write("D500", 22)
    assert plcs.restart(kill=True) == -9
    assert kiln.read("D500") == [11] and dryer.read("D500") == [22]
    for name in ("plc-kiln.state", "plc-dryer.state"):
        assert (plcs.workdir / name).exists(), name
    plcs.reload(two_kilns(dryer_station=3))
    assert "reload: plcs[1] (dryer): station: 2 -> 3" in plcs.log
    assert dryer.station == 3 and dryer.read("D500") == [22] and kiln.read("D500") == [11]
    with pytest.raises(DaemonError, match="rejected"):
        plcs.reload({"plcs": [dict(e, scan_ms=0) for e in two_kilns()["plcs"]]})
    assert dryer.station == 3 and dryer.read("D500") == [22]
    with pytest.raises(KeyError, match="oven: no such PLC .* kiln, dryer"):
        plcs["oven"]


def test_a_single_plc_config_still_gives_a_plc(plcemud):
    plc = plcemud({"profile": "fbs"})
    assert type(plc) is Plc and plc.tag("R4136")["name"] == "R4136"


# ------------------------------------------------------------- communication faults (the kit)
# docs/communication-faults.md through plc.comm_fault(), plc.clear_comm_faults() and
# plc.comm_faults_on. The kit's own client waits 5 s for an answer; where an answer is meant to
# be missing, the test asks on a raw connection of its own with a short timeout (conftest's
# raw_exchange: None when nothing came).

FC03_R100 = bytes([0x03, 0x00, 100, 0x00, 0x01])  # read R100 (fbs: holding register 100)


def fc06_r100(value):
    return bytes([0x06, 0x00, 100]) + value.to_bytes(2, "big")


def raw_connection(plc, timeout=0.25):
    s = socket.create_connection(("127.0.0.1", plc.port), timeout=timeout)
    s.settimeout(timeout)
    return s


def timed(fn, *args):
    t = time.monotonic()
    out = fn(*args)
    return out, time.monotonic() - t


def wait_until(predicate, timeout=2.0):
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def test_comm_fault_delay_holds_each_answer(plcemud):
    plc = plcemud({"profile": "fbs", "init": {"R100": 7}})
    with plc.comm_fault(delay_ms=100):
        assert plc.comm_faults_on  # the simulator unit is never delayed
        for _ in range(3):
            value, took = timed(plc.read, "R100")
            assert value == [7] and 0.08 <= took <= 0.12, took
        _, took = timed(lambda: plc.comm_faults_on)
        assert took < 0.02, took
    assert not plc.comm_faults_on
    _, took = timed(plc.read, "R100")
    assert took < 0.02, took
    assert "comm fault on: delay 100 ms (every request)" in plc.log
    assert "comm fault off: delay 100 ms" in plc.log


def test_comm_fault_drop_every_loses_every_nth_answer_but_serves_it(plcemud):
    plc = plcemud({"profile": "fbs", "init": {"R100": 7}})
    s = raw_connection(plc)
    try:
        with plc.comm_fault(drop_every=3):
            replies = [raw_exchange(s, FC03_R100, tid=1), raw_exchange(s, FC03_R100, tid=2),
                       raw_exchange(s, fc06_r100(42), tid=3),  # the 3rd: dropped
                       raw_exchange(s, FC03_R100, tid=4), raw_exchange(s, FC03_R100, tid=5),
                       raw_exchange(s, FC03_R100, tid=6)]  # the 6th: dropped
            assert [r is None for r in replies] == [False, False, True, False, False, True]
            # The dropped write was served, its answer lost (a line that loses the reply).
            assert replies[3] == bytes([0x03, 0x02, 0x00, 42])
        # The connection stays usable, and no late answer of a dropped request turns up on it:
        # raw_exchange checks the transaction ID.
        assert raw_exchange(s, FC03_R100, tid=7) == bytes([0x03, 0x02, 0x00, 42])
    finally:
        s.close()
    assert plc.read("R100") == [42]


def test_comm_fault_exception_answers_the_code_and_changes_nothing(plcemud):
    plc = plcemud({"profile": "fbs", "init": {"R100": 7}})
    plc.comm_fault(exception=4)
    with pytest.raises(ModbusError, match=r"read R100: Modbus exception 04h "
                                          r"\(server device failure\)") as e:
        plc.read("R100")
    assert e.value.code == 4
    with pytest.raises(ModbusError) as e:
        plc.write("R100", 99)
    assert e.value.code == 4
    with pytest.raises(ModbusError) as e:
        plc.write_bits("Y0", 1)
    assert e.value.code == 4
    plc.comm_fault(exception=6)  # replaces what was on
    with pytest.raises(ModbusError, match="06h"):
        plc.read("R100")
    plc.clear_comm_faults()
    assert plc.read("R100") == [7] and plc.read_bits("Y0") == [0]  # nothing was written


def test_comm_fault_offline_and_back(plcemud):
    plc = plcemud({"profile": "fbs", "init": {"R100": 7}})
    s = raw_connection(plc)
    try:
        assert raw_exchange(s, FC03_R100, tid=1) == bytes([0x03, 0x02, 0x00, 7])
        plc.comm_fault(offline=True)
        assert plc.comm_faults_on  # the simulator unit still answers
        assert raw_exchange(s, FC03_R100, tid=2) is None
        assert raw_exchange(s, fc06_r100(99), tid=3) is None  # not served either
        # A new connection is accepted (only refuse_connections refuses) and gets no answer.
        with raw_connection(plc) as other:
            assert raw_exchange(other, FC03_R100, tid=1) is None
        plc.clear_comm_faults()
        # Back, on the connection that stayed open: the next request is answered, and the
        # write sent while offline changed nothing.
        assert raw_exchange(s, FC03_R100, tid=4) == bytes([0x03, 0x02, 0x00, 7])
    finally:
        s.close()
    assert plc.read("R100") == [7]


def test_comm_fault_disconnect_after_closes_the_kits_connection(plcemud):
    """The daemon closes the kit's connection after its 2nd answer: the kit's next request
    finds it closed and raises ModbusError; the one after opens a new connection (pymodbus
    reconnects by itself), which is again closed after 2 answers. The kit's switch has a
    connection of its own and is never closed."""
    plc = plcemud({"profile": "fbs", "init": {"R100": 7}})
    with plc.comm_fault(disconnect_after=2):
        assert plc.read("R100") == [7] and plc.read("R100") == [7]
        with pytest.raises(ModbusError, match="read R100: .*[Cc]onnection"):
            plc.read("R100")
        assert plc.comm_faults_on
        assert plc.read("R100") == [7] and plc.read("R100") == [7]  # a new connection
        with pytest.raises(ModbusError, match="read R100: .*[Cc]onnection"):
            plc.read("R100")
    assert not plc.comm_faults_on
    assert plc.read("R100") == [7] and plc.read("R100") == [7] and plc.read("R100") == [7]
    assert plc.log.count("disconnected (closed after its answer)") == 2
    assert "comm fault on: disconnect after 2 request(s) (FIN)" in plc.log


def test_comm_fault_stop_leaves_run(plcemud):
    """docs/profile-fbs.md: M1926 is the RUN relay (always ON while running); a STOP turns it
    OFF and the Y outputs off. Requests are still served while stopped."""
    plc = plcemud({"profile": "fbs"})
    plc.write_bits("Y0", 1)
    assert plc.read_bits("M1926") == [1]
    with plc.comm_fault(stop=True):
        assert wait_until(lambda: plc.read_bits("M1926") == [0]), plc.log
        assert plc.read_bits("Y0") == [0]
    assert wait_until(lambda: plc.read_bits("M1926") == [1]), plc.log


def test_comm_fault_scope_from_and_count(plcemud):
    plc = plcemud({"profile": "fbs", "init": {"R0": 1, "R100": list(range(100, 112))}})
    with plc.comm_fault(exception=4, **{"from": "R100", "count": 10}):
        assert plc.read("R0") == [1] and plc.read("R99") == [0] and plc.read("R110") == [110]
        for dev, n in (("R100", 1), ("R109", 1), ("R95", 10), ("R109", 2)):
            with pytest.raises(ModbusError) as e:
                plc.read(dev, n)  # any request that reaches one of R100-R109
            assert e.value.code == 4, dev
        plc.write("R0", 2)  # R0 is served: a write outside the scope lands
    assert plc.read("R0") == [2]
    with plc.comm_fault(delay_ms=60, **{"from": "R100", "count": 10}):
        _, took = timed(plc.read, "R105")
        assert 0.04 <= took <= 0.08, took
        _, took = timed(plc.read, "R0")
        assert took < 0.02, took
    assert "comm fault on: delay 60 ms (R100-R109)" in plc.log


def test_comm_fault_block_clears_on_exit_even_when_it_raises(plcemud):
    plc = plcemud({"profile": "fbs", "init": {"R100": 7}})
    with pytest.raises(ModbusError):
        with plc.comm_fault(exception=4) as inside:
            assert inside is plc and plc.comm_faults_on
            plc.read("R100")  # raises, and the block is left through its exception
    assert not plc.comm_faults_on
    assert plc.read("R100") == [7]
    with pytest.raises(KeyError):
        with plc.comm_fault(delay_ms=50):
            raise KeyError("the test's own failure")
    assert not plc.comm_faults_on


def test_comm_fault_refuses_an_unknown_keyword(plcemud):
    plc = plcemud({"profile": "fbs"})
    with pytest.raises(TypeError, match=r"unknown communication faults \['latency_ms'\]"):
        plc.comm_fault(latency_ms=100)
    assert not plc.comm_faults_on  # nothing was written


def test_comm_fault_from_no_device_is_refused_by_the_daemon(plcemud):
    """`from` is parsed by the daemon; a name that is no device of the PLC is refused as a
    whole (comm.status b1), which the kit raises: what was on before stays on."""
    plc = plcemud({"profile": "fbs", "init": {"R100": 7}})
    plc.comm_fault(exception=4)
    with pytest.raises(DeviceError, match="communication faults: refused"):
        plc.comm_fault(delay_ms=10, **{"from": "Q5"})  # no Q area in an FBs
    assert plc.comm_faults_on
    with pytest.raises(ModbusError, match="04h"):
        plc.read("R100")  # the exception is still on, not the refused delay
    plc.clear_comm_faults()
    assert plc.read("R100") == [7]


def test_comm_fault_from_outside_the_area_is_refused(plcemud):
    """R99999 has the form of a device but is none of this FBs (its R area is R0-R8071): the
    config (`faults.from: R99999 is outside this PLC's R area`) and the REST API refuse it,
    and so must the simulator unit."""
    plc = plcemud({"profile": "fbs"})
    for name in ("R99999", "D9999"):
        with pytest.raises(DeviceError, match="communication faults: refused"):
            plc.comm_fault(delay_ms=10, **{"from": name})
        assert not plc.comm_faults_on, name


def test_the_comm_loss_example_of_testing_md(plcemud):
    """The worked example of docs/testing.md, "Communication faults", run as it stands: its
    code block is compiled with the page's line numbers (a failure points into the page) and
    each test_ function in it is called with this test's `plcemud` fixture."""
    page = REPO / "docs" / "testing.md"
    text = page.read_text()
    section = re.search(r"^## Communication faults\n(.*?)(?=^## )", text, re.S | re.M)
    assert section, "docs/testing.md has no '## Communication faults' section"
    block = re.search(r"```python\n(.*?)```", section.group(1), re.S)
    assert block and "def test_" in block.group(1), "the section has no pytest example"
    first_line = text[:section.start(1) + block.start(1)].count("\n")
    namespace = {}
    exec(compile("\n" * first_line + block.group(1), str(page), "exec"), namespace)
    tests = [f for name, f in namespace.items() if name.startswith("test_") and callable(f)]
    assert tests
    for test in tests:
        assert list(inspect.signature(test).parameters) == ["plcemud"], test.__name__
        test(plcemud)
