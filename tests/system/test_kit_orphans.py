"""The pytest kit's daemons die with the test process (docs/testing.md, "When the test process
dies"): a child pytest session starts a daemon through the `plcemud` fixture and sleeps; SIGTERM
(a CI runner's time-out) interrupts it like Ctrl-C, so the fixture stops the daemon, and SIGKILL,
when nothing of pytest runs any more, leaves it to the daemon's parent-death signal
(PLCEMUD_PARENT_PID). Either way the daemon is gone and its port closed within a few seconds."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import BASE_CONFIG, PLCEMUD, REPO, free_port, port_open, run_plcemud

CHILD_TEST = """
import json, os, time

def test_sleeps(plcemud):
    plc = plcemud({"profile": "fbs"})
    with open(os.environ["KIT_DAEMON_FILE"] + ".tmp", "w") as f:
        json.dump({"pid": plc.proc.pid, "port": plc.port, "log": str(plc.log_path)}, f)
    os.rename(os.environ["KIT_DAEMON_FILE"] + ".tmp", os.environ["KIT_DAEMON_FILE"])
    time.sleep(60)
"""


def gone(pid):
    """True once `pid` has exited (a zombie nobody has reaped yet counts as gone)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "Z"
    except FileNotFoundError:
        return True


def wait_until(predicate, timeout):
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


@pytest.fixture
def child_session(tmp_path):
    """start() -> (pytest process, {"pid", "port", "log"} of the daemon it started)."""
    procs, daemons = [], []

    def start():
        (tmp_path / "test_child.py").write_text(CHILD_TEST)
        info = tmp_path / "daemon.json"
        env = dict(os.environ, KIT_DAEMON_FILE=str(info), PLCEMUD=PLCEMUD,
                   PYTHONPATH=str(REPO / "python"))
        proc = subprocess.Popen(
            [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p",
             "plcemu_testing", "--rootdir", str(tmp_path), str(tmp_path / "test_child.py")],
            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        procs.append(proc)
        assert wait_until(lambda: info.exists() or proc.poll() is not None, 20), "no daemon"
        assert info.exists(), proc.communicate()[0].decode(errors="replace")
        daemon = json.loads(info.read_text())
        daemons.append(daemon)
        assert port_open(daemon["port"])
        return proc, daemon

    yield start
    for p in procs:
        if p.poll() is None:
            p.kill()
        p.communicate()
    for d in daemons:  # an orphan of a failed test
        if not gone(d["pid"]):
            os.kill(d["pid"], signal.SIGKILL)


def test_sigterm_to_pytest_stops_the_daemon_through_the_fixture(child_session):
    proc, daemon = child_session()
    proc.send_signal(signal.SIGTERM)
    out = proc.communicate(timeout=15)[0].decode(errors="replace")
    # Interrupted as by Ctrl-C (exit status 2), the fixture's teardown ran.
    assert proc.returncode == 2, out
    assert "KeyboardInterrupt" in out, out
    assert wait_until(lambda: gone(daemon["pid"]), 5), out
    assert not port_open(daemon["port"])
    with open(daemon["log"]) as f:
        assert "SIGTERM: stopping" in f.read()


def test_sigkill_to_pytest_stops_the_daemon_by_its_parent_death_signal(child_session):
    proc, daemon = child_session()
    proc.kill()
    proc.wait(timeout=5)
    assert wait_until(lambda: gone(daemon["pid"]), 5), f"plcemud {daemon['pid']} still runs"
    assert not port_open(daemon["port"])
    with open(daemon["log"]) as f:
        log = f.read()
    # A normal stop: the parent-death signal is SIGTERM.
    assert "SIGTERM: stopping" in log, log


# The parent died before plcemud asked for the signal (between fork and prctl): the kernel would
# send nothing, so plcemud sees its parent is not the process named and that it is gone, and
# does not start.
def test_a_parent_gone_before_the_start_means_no_daemon(tmp_path):
    dead = subprocess.Popen(["true"])
    dead.wait()
    config = tmp_path / "p.yaml"
    config.write_text(BASE_CONFIG)
    r = run_plcemud("-c", config, "--port", free_port(), timeout=10, cwd=tmp_path,
                    env=dict(os.environ, PLCEMUD_PARENT_PID=str(dead.pid)))
    assert r.returncode == 0, r.stderr
    assert f"PLCEMUD_PARENT_PID={dead.pid}: that process is gone; not starting" in r.stderr
    assert "listening" not in r.stderr
