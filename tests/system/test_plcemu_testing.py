"""The pytest plugin plcemu_testing (python/, docs/testing.md) on real scenarios: its `plcemud`
fixture runs the daemon, device names go through the daemon's own map, the simulator unit runs
the plant in simulated time, faults, restart, reload and errors that name the device."""

import math
import os
import re
import subprocess
import sys
import time

import pytest
import yaml

from conftest import REPO
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
