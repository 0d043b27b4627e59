"""The state file under stress: daemons started at the same instant, and a full file system.

docs/operations.md ("Retentive memory"): one daemon per state file, taken by a lock before anything is
created, so a second one exits 1 naming the file; the file's blocks are reserved when it is
created or opened, so a full file system stops the daemon at start (exit 1, "No space left") and
can never kill a running one with SIGBUS.

Wire addresses (docs/profile-fbs.md): Rn is holding register n (R0-R4167, R5000-R5998), Dn is 6000+n
(D0-D2998); R0-R2999, R5000 on and all of D are retentive by default.
"""

import errno
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from pymodbus.client import ModbusTcpClient

from conftest import PLCEMUD, free_port, port_open

D0 = 6000
R4057 = 4057  # power-up counter
ROUNDS = 10
START_TIMEOUT_S = 15.0


def config(state: Path) -> str:
    return (
        "profile: fbs\n"
        "modbus: {tcp: {bind: 127.0.0.1}}\n"
        f"persistence: {{file: '{state}', sync_ms: 200}}\n"
    )


def read(client, address, count=1):
    rr = client.read_holding_registers(address, count, slave=1)
    assert not rr.isError(), rr
    return rr.registers


def launch(config_path: Path, port: int, log_path: Path) -> subprocess.Popen:
    env = dict(os.environ)
    env.pop("STATE_DIRECTORY", None)
    with open(log_path, "wb") as log:
        return subprocess.Popen(
            [PLCEMUD, "-c", str(config_path), "--port", str(port)],
            stdin=subprocess.DEVNULL, stdout=log, stderr=log, env=env, cwd=config_path.parent,
        )


def settle(procs, ports, timeout=START_TIMEOUT_S):
    """Waits until every daemon has either exited or is listening (or the timeout passed)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if all(p.poll() is not None or port_open(port) for p, port in zip(procs, ports)):
            return
        time.sleep(0.05)


def kill_all(procs):
    for p in procs:
        if p.poll() is None:
            p.kill()
            p.wait()


# --- two daemons at the same instant on a new state file


def test_two_daemons_started_at_once_on_a_new_state_file_one_runs_one_exits_1(tmp_path):
    """Each round a fresh file and two daemons on their own ports: exactly one gets the file and
    serves, the other exits 1 naming it; neither dies of a signal (SIGBUS before the fix)."""
    if not os.access(PLCEMUD, os.X_OK):
        pytest.fail(f"plcemud binary not found at {PLCEMUD} (build it or set PLCEMUD)")
    for n in range(ROUNDS):
        state = tmp_path / f"race-{n}.state"
        configs, ports, logs = [], [], []
        for k in range(2):
            cfg = tmp_path / f"race-{n}-{k}.yaml"
            cfg.write_text(config(state))
            configs.append(cfg)
            logs.append(tmp_path / f"race-{n}-{k}.log")
            port = free_port()
            while port in ports:
                port = free_port()
            ports.append(port)
        procs = [launch(c, p, log) for c, p, log in zip(configs, ports, logs)]
        try:
            settle(procs, ports)
            codes = [p.poll() for p in procs]
            texts = [log.read_text(errors="replace") for log in logs]
            report = f"round {n}: exit codes {codes}\n" + "\n".join(
                f"--- daemon {k} ---\n{t}" for k, t in enumerate(texts)
            )
            assert all(c is None or c >= 0 for c in codes), "died of a signal\n" + report
            running = [k for k, c in enumerate(codes) if c is None]
            assert len(running) == 1, "not exactly one daemon running\n" + report
            winner, loser = running[0], 1 - running[0]
            assert codes[loser] == 1, report
            assert str(state) in texts[loser], report
            assert "in use by another process" in texts[loser], report

            c = ModbusTcpClient("127.0.0.1", port=ports[winner], timeout=3, retries=1)
            assert c.connect(), report
            try:
                assert read(c, R4057) == [1]  # a fresh file: the first start
                assert not c.write_register(D0 + n, 100 + n, slave=1).isError()
                assert read(c, D0 + n) == [100 + n]
            finally:
                c.close()
            procs[winner].send_signal(signal.SIGTERM)
            assert procs[winner].wait(timeout=10) == 0, logs[winner].read_text(errors="replace")
            assert not Path(f"{state}.new").exists()
        finally:
            kill_all(procs)


# --- a full file system


@pytest.fixture
def small_fs(tmp_path):
    """A 1 MiB tmpfs of its own (root only), unmounted at the end."""
    if os.geteuid() != 0:
        pytest.skip("mounting a small tmpfs to fill up needs root")
    mnt = tmp_path / "small-fs"
    mnt.mkdir()
    r = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=1m,mode=0700", "tmpfs", str(mnt)],
        capture_output=True, text=True,
    )
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs: {r.stderr.strip()}")
    try:
        yield mnt
    finally:
        if subprocess.run(["umount", str(mnt)], capture_output=True).returncode != 0:
            subprocess.run(["umount", "-l", str(mnt)], check=False)


def fill(directory: Path, name: str = "filler", room: int = 0) -> Path:
    """Writes a file into `directory` until its file system is full, then frees `room` bytes."""
    path = directory / name
    with open(path, "wb", buffering=0) as f:
        for size in (65536, 4096, 1):
            block = b"\xa5" * size
            while True:
                try:
                    if f.write(block) == 0:
                        break
                except OSError as e:
                    if e.errno != errno.ENOSPC:
                        raise
                    break
    assert os.statvfs(directory).f_bavail == 0
    if room:
        os.truncate(path, path.stat().st_size - room)
    return path


@pytest.mark.parametrize("room", [0, 16384], ids=["full", "room-for-less-than-the-file"])
def test_a_full_file_system_stops_the_daemon_at_start_with_exit_1(small_fs, tmp_path, room):
    """The state file cannot get its blocks: exit 1 at once, naming the file and the cause, and
    nothing half-made left. (Before the fix, with a little room the daemon started on a sparse
    file and died of SIGBUS at a later write.)"""
    state = small_fs / "plc.state"
    fill(small_fs, room=room)
    cfg = tmp_path / "full.yaml"
    cfg.write_text(config(state))
    port = free_port()
    log = tmp_path / "full.log"
    proc = launch(cfg, port, log)
    try:
        settle([proc], [port])
        code = proc.poll()
        text = log.read_text(errors="replace")
        assert code == 1, f"exit code {code} (None: still running)\n{text}"
        assert str(state) in text, text
        assert "No space left" in text, text
        assert not state.exists()
        assert not Path(f"{state}.new").exists()
    finally:
        kill_all([proc])


def test_a_file_system_filling_up_later_cannot_kill_the_daemon(small_fs, start_plcemud):
    """Start with room, fill the file system, then 2000 writes over the retentive ranges: the
    daemon keeps answering, stops cleanly, and starts again (on the still full file system) with
    every value retained."""
    state = small_fs / "plc.state"
    cfg = config(state)
    d = start_plcemud(cfg, name="filling")
    c = d.client()
    assert read(c, R4057) == [1]
    fill(small_fs)

    # Spread over the retentive image as far as the wire reaches: D0-D2998, R0-R2999, R5000-R5998.
    targets = (
        [D0 + 3 * i for i in range(1000)]
        + [4 * i for i in range(700)]
        + [5000 + 3 * i for i in range(300)]
    )
    expected = {}
    for i, address in enumerate(targets):
        value = (i * 7919 + 1) % 65535 + 1
        rr = c.write_register(address, value, slave=1)
        assert not rr.isError(), f"write {i} to {address}: {rr}\n{d.log_text()}"
        expected[address] = value
    assert d.proc.poll() is None, f"daemon died: {d.proc.returncode}\n{d.log_text()}"
    assert read(c, D0 + 2997) == [expected[D0 + 2997]]
    assert d.stop() == 0, d.log_text()

    d = start_plcemud(cfg, name="filling")
    assert "closed cleanly last time" in d.log_text()
    c = d.client()
    assert read(c, R4057) == [2]
    for address, value in expected.items():
        assert read(c, address) == [value], f"register {address}"
    assert d.stop() == 0, d.log_text()
