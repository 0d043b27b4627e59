"""A reload that changes only `plant:` says what it changed, key by key, and applies it
(docs/operations.md, "Reload (SIGHUP)"; docs/simulator-and-plant.md, "Simulator-control unit")."""

import signal
from pathlib import Path

SIM = 247          # the simulator unit (simulator.unit's default)
CH0_AMBIENT = 101  # sim.ch0.ambient, 0.1 °C
CH0_TAU = 103      # sim.ch0.tau, s


def config(tmp_path, plant):
    return (
        "profile: fbs\n"
        "modbus: {tcp: {bind: 127.0.0.1}}\n"
        f"persistence: {{file: '{tmp_path / 'plc.state'}'}}\n"
        f"plant: {plant}\n"
    )


def test_a_plant_only_reload_names_each_changed_key(start_plcemud, tmp_path):
    d = start_plcemud(config(tmp_path, "{defaults: {ambient: 25}, channels: {0: {tau: 120}}}"))
    c = d.client()
    rr = c.read_holding_registers(CH0_AMBIENT, 3, slave=SIM)
    assert not rr.isError(), rr
    assert (rr.registers[0], rr.registers[2]) == (250, 120)

    Path(d.config_path).write_text(
        config(tmp_path, "{defaults: {ambient: 30}, channels: {0: {tau: 300}}, seed: 9}"))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    log = d.log_text()
    assert "reload: plant.defaults.ambient: 25 -> 30" in log, log
    assert "reload: plant.channels.0.tau: 120 -> 300" in log, log
    assert "reload: plant.seed: 1 -> 9" in log, log
    # Channel 0's ambient only follows the default: said once, for plant.defaults.
    assert "plant.channels.0.ambient" not in log, log
    assert "no setting changed" not in log, log

    # Applied: the simulator unit shows the new parameters.
    rr = c.read_holding_registers(CH0_AMBIENT, 3, slave=SIM)
    assert not rr.isError(), rr
    assert (rr.registers[0], rr.registers[2]) == (300, 300)


def test_a_reload_without_changes_still_says_so(start_plcemud, tmp_path):
    text = config(tmp_path, "{channels: {0: {tau: 120}}}")
    d = start_plcemud(text)
    Path(d.config_path).write_text(text)
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    assert "reload: no setting changed" in d.log_text(), d.log_text()
    assert "plant." not in d.log_text(), d.log_text()
