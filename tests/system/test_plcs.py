"""Several PLCs in one process: a config with `plcs:` (README, "Several PLCs in one process";
docs/configuration.md, "Several PLCs"). Each PLC has its own listener, image, state file and
program; one event loop serves them all."""

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from conftest import PLCEMUD, Daemon, free_port, port_open, run_plcemud

D0 = 6000  # fbs: holding 6000 is D0 (retentive by default)
VB_D200 = 200  # vb: holding 200 is D200 (latched)
VB_D9010 = 8010  # vb: scan time in 0.1 ms, read-only
R4057 = 4057  # fbs: power-up counter


def plcs_config(ports, tmp_path, b_dest="R1"):
    a, b, v = ports
    return f"""\
log: {{level: info}}
plcs:
  - name: line-a
    profile: fbs
    modbus: {{tcp: {{bind: 127.0.0.1, port: {a}}}}}
  - name: line-b
    profile: fbs
    station: 2
    modbus: {{tcp: {{bind: 127.0.0.1, port: {b}}}}}
    program:
      - MOV: {{en: M1926, s: R0, d: {b_dest}}}
  - profile: vb
    scan_ms: 20
    modbus: {{tcp: {{bind: 127.0.0.1, port: {v}}}}}
"""


def spawn(tmp_path: Path, text: str, ports) -> Daemon:
    """plcemud on a `plcs:` config (no --port: each PLC names its own), once every port listens."""
    config_path = tmp_path / "plant.yaml"
    config_path.write_text(text)
    log_path = tmp_path / f"plcemud-{time.monotonic_ns()}.log"
    env = dict(os.environ)
    env.pop("STATE_DIRECTORY", None)
    with open(log_path, "wb") as log:
        proc = subprocess.Popen(
            [PLCEMUD, "-c", str(config_path)],
            stdin=subprocess.DEVNULL, stdout=log, stderr=log, env=env, cwd=tmp_path,
        )
    d = Daemon(proc, ports[0], config_path, log_path)
    deadline = time.monotonic() + 10
    while not all(port_open(p) for p in ports):
        if proc.poll() is not None or time.monotonic() > deadline:
            d.stop(signal.SIGKILL)
            pytest.fail(f"plcemud did not listen on {ports}\n{d.log_text()}")
        time.sleep(0.05)
    return d


def client_on(d: Daemon, port: int):
    d.port = port
    return d.client()


def reg(c, addr, unit=1):
    r = c.read_holding_registers(addr, 1, slave=unit)
    assert not r.isError(), r
    return r.registers[0]


@pytest.fixture
def ports():
    return free_port(), free_port(), free_port()


def test_three_plcs_keep_their_own_images_maps_state_and_programs(tmp_path, ports):
    d = spawn(tmp_path, plcs_config(ports, tmp_path), ports)
    try:
        a, b, v = (client_on(d, p) for p in ports)
        # Writes are isolated: the same address on each PLC holds its own value.
        assert not a.write_register(D0, 111, slave=1).isError()
        assert not b.write_register(D0, 222, slave=2).isError()
        assert not v.write_register(D0, 333, slave=1).isError()  # vb: D6000
        assert reg(a, D0) == 111
        assert reg(b, D0, unit=2) == 222
        assert reg(v, D0) == 333
        # Each answers with its own profile's map: vb's D9010 is its scan time (20 ms).
        assert reg(v, VB_D9010) == 200
        assert not v.write_register(VB_D200, 444, slave=1).isError()
        # line-b's program copies R0 to R1; line-a has none.
        assert not a.write_register(0, 7, slave=1).isError()
        assert not b.write_register(0, 9, slave=2).isError()
        time.sleep(0.2)
        assert reg(a, 1) == 0
        assert reg(b, 1, unit=2) == 9
        assert reg(a, R4057) == 1

        # SIGHUP with line-b's MOV now writing R2: only line-b changes, images stay.
        Path(d.config_path).write_text(plcs_config(ports, tmp_path, b_dest="R2"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: plcs[1] (line-b): done"), d.log_text()
        assert d.wait_log("reload: plcs[2]: done"), d.log_text()
        time.sleep(0.2)
        assert reg(b, 2, unit=2) == 9
        assert reg(a, 2) == 0
        assert reg(a, D0) == 111 and reg(b, D0, unit=2) == 222 and reg(v, D0) == 333

        # A bad entry rejects the whole reload, naming the entry: every PLC keeps its config.
        bad = plcs_config(ports, tmp_path, b_dest="R3").replace("scan_ms: 20", "scan_ms: 5000")
        Path(d.config_path).write_text(bad)
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("configuration rejected"), d.log_text()
        assert f"{d.config_path}:13:14: plcs[2]: scan_ms" in d.log_text(), d.log_text()
        assert not b.write_register(0, 10, slave=2).isError()
        time.sleep(0.2)
        assert reg(b, 2, unit=2) == 10  # still the reloaded program (R2), not R3
        assert reg(b, 3, unit=2) == 0
        assert reg(v, VB_D9010) == 200
        assert d.proc.poll() is None
    finally:
        assert d.stop() == 0

    # Each PLC wrote a state file of its own; a restart keeps each one's retentive devices.
    for name in ("plant-line-a.state", "plant-line-b.state", "plant-2.state"):
        assert (tmp_path / name).exists(), name
    d = spawn(tmp_path, plcs_config(ports, tmp_path, b_dest="R2"), ports)
    try:
        a, b, v = (client_on(d, p) for p in ports)
        assert reg(a, D0) == 111
        assert reg(b, D0, unit=2) == 222
        assert reg(v, VB_D200) == 444
        assert reg(a, R4057) == 2
    finally:
        assert d.stop() == 0


def test_check_config_and_print_map_name_each_plc(tmp_path, ports):
    path = tmp_path / "plant.yaml"
    path.write_text(plcs_config(ports, tmp_path))
    r = run_plcemud("-c", path, "--check-config")
    assert r.returncode == 0, r.stderr
    assert f"{path}: plcs[0] (line-a): ok, profile fbs, station 1" in r.stdout
    assert f"{path}: plcs[2]: ok, profile vb, station 1" in r.stdout
    r = run_plcemud("-c", path, "--print-map")
    assert r.returncode == 0, r.stderr
    assert f"plcs[1] (line-b), tcp 127.0.0.1:{ports[1]}:\nModbus map, profile fbs" in r.stdout
    assert f"plcs[2], tcp 127.0.0.1:{ports[2]}:\nModbus map, profile vb" in r.stdout
    r = run_plcemud("-c", path, "--print-map", "--format", "csv")
    assert r.returncode == 0, r.stderr
    # Each PLC's rows under their own header (the device column is the vendor's).
    assert '\n\nplc,table,modbus_5digit,modbus_6digit,wire,vigor,' in r.stdout
    assert '\n"plcs[2]","holding registers",' in r.stdout


@pytest.mark.parametrize(
    "text, where, message",
    [
        # Two PLCs on one port.
        ("plcs:\n  - {profile: fbs, modbus: {tcp: {port: 1502}}}\n"
         "  - {profile: vb, modbus: {tcp: {port: 1502}}}\n",
         ":3:40:", "plcs[1]: modbus.tcp.port: 1502 is also plcs[0]'s"),
        # One state file for two.
        ("plcs:\n  - {profile: fbs, modbus: {tcp: {port: 1502}}, persistence: {file: x.state}}\n"
         "  - {profile: fbs, modbus: {tcp: {port: 1503}}, persistence: {file: x.state}}\n",
         ":3:69:", "plcs[1]: persistence.file: 'x.state' is also plcs[0]'s state file"),
        # A per-PLC key beside plcs:.
        ("profile: fbs\nplcs:\n  - {profile: fbs}\n",
         ":1:1:", "profile: belongs to one PLC; beside 'plcs:' only 'log:' may stand"),
        # log: inside an entry.
        ("plcs:\n  - name: k1\n    profile: fbs\n    log: {level: debug}\n",
         ":4:10:", "plcs[0] (k1): log: applies to the whole process"),
        # A bad entry names itself.
        ("plcs:\n  - {profile: fbs}\n  - {name: oven, profile: nope}\n",
         ":3:27:", "plcs[1] (oven): profile: expected one of"),
        ("plcs:\n  - {profile: fbs, name: a, modbus: {tcp: {port: 1}}}\n"
         "  - {profile: fbs, name: a, modbus: {tcp: {port: 2}}}\n",
         ":3:26:", "plcs[1] (a): name: 'a' is also plcs[0] (a)'s"),
    ],
)
def test_bad_plcs_entries_are_refused_at_load(tmp_path, text, where, message):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    r = run_plcemud("-c", path, "--check-config")
    assert r.returncode == 2, r.stdout + r.stderr
    assert f"{path}{where} {message}" in r.stderr, r.stderr


def test_port_override_is_refused_with_plcs(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text(f"plcs:\n  - {{profile: fbs, modbus: {{tcp: {{port: {free_port()}}}}}}}\n")
    r = run_plcemud("-c", path, "--port", free_port(), timeout=10)
    assert r.returncode == 2
    assert "--port: a config with plcs: sets each PLC's port itself" in r.stderr
