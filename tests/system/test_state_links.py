"""Links planted among the state files, one state file spelled two ways, and junk after the image.

docs/operations.md ("Retentive memory"): every file of the state set (NAME, NAME.lock, NAME.new)
is opened in its directory without following a symlink as the last component. A NAME or
NAME.lock that is a symlink (or not a regular file) stops the start with exit 1 naming it; a
leftover NAME.new is removed (a symlink as a link, its target untouched) and created anew,
exclusively. Directories on the way may be links. A file with bytes after the image is corrupted:
moved aside, and a fresh one used.

docs/configuration.md ("Several PLCs"): two `plcs:` entries whose state files are one file
however written are refused at load (exit 2), naming both entries.

Wire addresses (docs/profile-fbs.md): Dn is holding register 6000+n; D is retentive by default;
R4057 counts the starts.
"""

import os
import subprocess
import time
from pathlib import Path

import pytest

from conftest import PLCEMUD, free_port, port_open, run_plcemud
from test_state_file_hardening import config, read

D0 = 6000
R4057 = 4057
VICTIM = b"a file nobody may overwrite\n" * 100


def snapshot(path: Path):
    """What a victim file is: its bytes and its modification time."""
    return path.read_bytes(), path.stat().st_mtime_ns


def start_refused(tmp_path: Path, state) -> subprocess.CompletedProcess:
    """Starts plcemud on `state` and expects it to exit by itself (not to serve); returns the
    exit code and its log as a CompletedProcess."""
    cfg = tmp_path / "refused.yaml"
    cfg.write_text(config(state))
    port = free_port()
    env = dict(os.environ)
    env.pop("STATE_DIRECTORY", None)
    proc = subprocess.Popen(
        [PLCEMUD, "-c", str(cfg), "--port", str(port)], stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env, cwd=tmp_path,
    )
    deadline = time.monotonic() + 10
    while proc.poll() is None and time.monotonic() < deadline and not port_open(port):
        time.sleep(0.05)
    if proc.poll() is None:
        proc.kill()
        out, _ = proc.communicate()
        pytest.fail(f"plcemud started on a refused state set\n{out}")
    out, _ = proc.communicate()
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, "")


# --- links planted in the state directory


def test_a_temporary_planted_as_a_link_is_removed_and_its_target_never_written(
        start_plcemud, tmp_path):
    """p.state.new -> victim before the first start: the daemon creates p.state as a file of its
    own; the victim is unchanged after the start, writes, SIGTERM and a restart."""
    victim = tmp_path / "victim"
    victim.write_bytes(VICTIM)
    before = snapshot(victim)
    state = tmp_path / "p.state"
    Path(f"{state}.new").symlink_to(victim)

    d = start_plcemud(config(state), name="linked-new")
    log = d.log_text()
    assert f"its temporary {state}.new was a symbolic link; removed the link" in log, log
    c = d.client()
    for i in range(50):
        assert not c.write_register(D0 + i, 1000 + i, slave=1).isError()
    assert d.stop() == 0, d.log_text()

    assert snapshot(victim) == before
    assert not state.is_symlink() and state.is_file()
    assert not os.path.lexists(f"{state}.new")
    assert state.read_bytes()[:8] == b"PLCEMUST"

    d = start_plcemud(config(state), name="linked-new")
    assert "closed cleanly last time" in d.log_text()
    assert read(d.client(), D0, 50) == [1000 + i for i in range(50)]
    assert d.stop() == 0
    assert snapshot(victim) == before


def test_a_dangling_lock_link_is_refused_and_its_target_not_created(tmp_path):
    target = tmp_path / "x"
    state = tmp_path / "p.state"
    Path(f"{state}.lock").symlink_to(target)
    r = start_refused(tmp_path, state)
    assert r.returncode == 1, r.stdout
    assert f"state file {state}: its lock {state}.lock is a symbolic link" in r.stdout, r.stdout
    assert not os.path.lexists(target)
    assert not os.path.lexists(state)
    assert not os.path.lexists(f"{state}.new")


def test_a_lock_link_to_an_existing_file_is_refused_and_the_file_untouched(tmp_path):
    victim = tmp_path / "victim"
    victim.write_bytes(VICTIM)
    before = snapshot(victim)
    state = tmp_path / "p.state"
    Path(f"{state}.lock").symlink_to(victim)
    r = start_refused(tmp_path, state)
    assert r.returncode == 1, r.stdout
    assert f"{state}.lock is a symbolic link" in r.stdout, r.stdout
    assert snapshot(victim) == before
    assert not os.path.lexists(state)


@pytest.mark.parametrize("kind", ["victim", "state-file"])
def test_a_state_file_that_is_a_link_is_refused_and_its_target_untouched(
        start_plcemud, tmp_path, kind):
    """p.state -> a file elsewhere: neither read, nor moved aside, nor recreated — whether the
    target is any file (it would be corrupt, and moved aside) or a valid state file."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    target = elsewhere / "real.state"
    if kind == "victim":
        target.write_bytes(VICTIM)
    else:
        d = start_plcemud(config(target), name="real")
        assert not d.client().write_register(D0, 4321, slave=1).isError()
        assert d.stop() == 0
    before = snapshot(target)
    state = tmp_path / "p.state"
    state.symlink_to(target)

    r = start_refused(tmp_path, state)
    assert r.returncode == 1, r.stdout
    assert f"state file {state}: the file {state} is a symbolic link, which plcemud never " \
           "follows" in r.stdout, r.stdout
    assert snapshot(target) == before
    assert state.is_symlink()
    assert not list(tmp_path.glob("p.state.bad-*")) and not list(elsewhere.glob("*.bad-*"))
    assert not os.path.lexists(f"{state}.new")


def test_a_state_file_reached_through_a_linked_directory_is_used(start_plcemud, tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "linked").symlink_to(real, target_is_directory=True)
    state = tmp_path / "linked" / "p.state"
    d = start_plcemud(config(state), name="through-link")
    assert not d.client().write_register(D0 + 9, 99, slave=1).isError()
    assert d.stop() == 0
    assert (real / "p.state").is_file() and not (real / "p.state").is_symlink()
    d = start_plcemud(config(state), name="through-link")
    assert read(d.client(), D0 + 9) == [99]


# --- one state file written two ways in a plcs: config


def plcs(first: str, second: str) -> str:
    return (
        "plcs:\n"
        f"  - {{profile: fbs, modbus: {{tcp: {{port: 1502}}}}, persistence: {{file: {first}}}}}\n"
        f"  - {{profile: fbs, modbus: {{tcp: {{port: 1503}}}}, persistence: {{file: {second}}}}}\n"
    )


COLUMN = 69  # of `file:`'s value on each entry's line


@pytest.mark.parametrize("how", ["dot-slash", "link", "dangling-link", "linked-dir", "absolute"])
def test_one_state_file_written_two_ways_is_refused_at_load_naming_both(tmp_path, how):
    base = tmp_path.resolve()
    first, second = "x.state", {
        "dot-slash": "./x.state",
        "link": "y.state",
        "dangling-link": "y.state",
        "linked-dir": "linked/x.state",
        "absolute": f"{base}/x.state",
    }[how]
    if how == "link":
        (base / "x.state").write_bytes(b"")
    if how in ("link", "dangling-link"):
        (base / "y.state").symlink_to("x.state")
    if how == "linked-dir":
        (base / "linked").symlink_to(base, target_is_directory=True)
    path = base / "two.yaml"
    path.write_text(plcs(first, second))

    r = run_plcemud("-c", path, "--check-config")
    assert r.returncode == 2, r.stdout + r.stderr
    assert (
        f"{path}:3:{COLUMN}: plcs[1]: persistence.file: '{second}' is also plcs[0]'s state file "
        f"('{first}' at {path}:2:{COLUMN}; both are {base}/x.state)" in r.stderr
    ), r.stderr
    # A start is refused the same way, before any state file is touched ("another process"
    # before the fix).
    r = run_plcemud("-c", path)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "is also plcs[0]'s state file" in r.stderr
    assert "another process" not in r.stderr
    assert not os.path.lexists(base / "x.state.lock")


def test_state_files_are_compared_where_the_state_directory_puts_them(tmp_path):
    """Relative names lie in $STATE_DIRECTORY when systemd sets it: an absolute path into it is
    then the same file, and the same text without it is not."""
    base = tmp_path.resolve()
    state_dir = base / "var-lib"
    state_dir.mkdir()
    path = base / "sd.yaml"
    path.write_text(plcs("x.state", f"{state_dir}/x.state"))
    env = {**os.environ, "STATE_DIRECTORY": str(state_dir)}
    r = run_plcemud("-c", path, "--check-config", env=env)
    assert r.returncode == 2, r.stdout + r.stderr
    assert f"both are {state_dir}/x.state" in r.stderr, r.stderr
    env.pop("STATE_DIRECTORY")
    r = run_plcemud("-c", path, "--check-config", env=env)
    assert r.returncode == 0, r.stderr


# --- junk after the image


def test_a_state_file_with_junk_appended_is_moved_aside_and_a_fresh_one_used(
        start_plcemud, tmp_path):
    state = tmp_path / "junk.state"
    d = start_plcemud(config(state), name="junk")
    assert not d.client().write_register(D0 + 5, 555, slave=1).isError()
    assert d.stop() == 0
    size = state.stat().st_size
    with open(state, "ab") as f:
        f.write(b"\x5a" * 100 * 1024)
    junked = state.read_bytes()

    d = start_plcemud(config(state), name="junk")
    log = d.log_text()
    assert f"state file {state} corrupted: 102400 bytes after the image ({size + 102400} " \
           f"bytes, not {size})" in log, log
    bad = sorted(tmp_path.glob("junk.state.bad-*"))
    assert len(bad) == 1, log
    assert f"moved to {bad[0]}" in log
    assert bad[0].read_bytes() == junked  # kept as found
    assert state.stat().st_size == size
    c = d.client()
    assert read(c, D0 + 5) == [0]
    assert read(c, R4057) == [1]  # a fresh start
