"""The config file plcemud reads (docs/configuration.md, "The config file"): a regular file of at
most 16 MiB, opened without blocking; anything else is refused with exit 2 at --check-config and
at start, and logged at a reload, which then never holds up the next reload or the shutdown
(docs/operations.md, "Reload (SIGHUP)"). Nesting past the loader's limits says so, with its
line and column."""

import os
import signal
import time

import pytest

from conftest import BASE_CONFIG, raw_request, run_plcemud

LIMIT = 16 << 20  # bytes
READ_R0 = bytes([3, 0, 0, 0, 1])
D0 = 6000  # FBs: Dn is holding register 6000+n


def check_config(path, timeout=10):
    """--check-config on `path`: (exit code, stderr, seconds taken)."""
    t0 = time.monotonic()
    r = run_plcemud("-c", path, "--check-config", timeout=timeout)
    return r.returncode, r.stderr, time.monotonic() - t0


def assert_refused(path, message: str) -> str:
    """--check-config on `path` exits 2 within 5 s saying `message` after the path; returns
    stderr."""
    rc, err, took = check_config(path)
    assert rc == 2, err
    assert f"{path}: {message}" in err, err
    assert took < 5, took
    return err


def rss_kib(pid: int) -> int:
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError("no VmRSS")


def big_program(base: str, n: int) -> str:
    return base + "program:\n" + "".join(
        f"  - MOV: {{s: K{i % 1000}, d: D{i % 4000}}}\n" for i in range(n)
    )


def reload(d, config_text=None, count=1, timeout=10.0):
    """Writes `config_text` over the config path (when given), sends SIGHUP and waits until the
    log has `count` lines of a finished reload."""
    if config_text is not None:
        if os.path.islink(d.config_path) or not os.path.isfile(d.config_path):
            os.remove(d.config_path)
        with open(d.config_path, "w") as f:
            f.write(config_text)
    d.proc.send_signal(signal.SIGHUP)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        log = d.log_text()
        if log.count("reload: done") + log.count("configuration rejected") >= count:
            return log
        time.sleep(0.02)
    raise AssertionError(d.log_text()[-3000:])


# --- what --check-config refuses


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_check_config_refuses_a_character_device_at_once(device):
    assert_refused(device, "the config file is a character device, not a regular file; refused")


def test_check_config_refuses_a_fifo_nobody_writes_without_waiting(tmp_path):
    fifo = tmp_path / "config.yaml"
    os.mkfifo(fifo)
    assert_refused(fifo, "the config file is a FIFO, not a regular file")


def test_check_config_refuses_a_directory_saying_it_is_one(tmp_path):
    err = assert_refused(tmp_path, "the config file is a directory, not a regular file")
    assert "mapping" not in err


def test_check_config_follows_a_symlink_to_a_file_and_refuses_one_to_a_device(tmp_path):
    good = tmp_path / "real.yaml"
    good.write_text(BASE_CONFIG)
    link = tmp_path / "link.yaml"
    link.symlink_to(good)
    rc, out_err, _ = check_config(link)
    assert rc == 0, out_err
    link.unlink()
    link.symlink_to("/dev/zero")
    assert_refused(link, "the config file is a character device")


def test_check_config_reads_a_file_at_the_limit_and_refuses_one_byte_more(tmp_path):
    """A config of 16 MiB (comments past its keys) is read; one byte more is refused unread."""
    path = tmp_path / "big.yaml"
    head = BASE_CONFIG.encode()
    line = b"#" * 1023 + b"\n"
    body = line * ((LIMIT - len(head)) // len(line))
    path.write_bytes(head + body + b"#" * (LIMIT - len(head) - len(body)))
    assert path.stat().st_size == LIMIT
    rc, err, _ = check_config(path, timeout=60)
    assert rc == 0, err
    with open(path, "ab") as f:
        f.write(b"#")
    assert_refused(path, "the config file is larger than 16 MiB; refused")


# --- nesting


def test_deep_flow_nesting_says_it_nests_too_deeply_with_its_position(tmp_path):
    path = tmp_path / "flow.yaml"
    path.write_text("profile: fbs\nprogram: " + "[" * 100_000 + "]" * 100_000 + "\n")
    rc, err, _ = check_config(path)
    assert rc == 2, err
    # The 65th level: "program: " then 64 brackets, on line 2.
    assert f"{path}:2:74: the config nests too deeply" in err, err
    assert "bad file" not in err


def test_deep_block_nesting_says_it_nests_too_deeply_with_its_position(tmp_path):
    path = tmp_path / "block.yaml"
    # 3,000 levels of block mappings, one a line, each indented one more.
    path.write_text("".join(" " * i + "k:\n" for i in range(3000)))
    rc, err, _ = check_config(path)
    assert rc == 2, err
    assert f"{path}:65:65: the config nests too deeply" in err, err
    assert "bad file" not in err


# --- reload


def test_a_reload_of_a_link_to_dev_zero_is_refused_and_a_corrected_config_applied(start_plcemud):
    d = start_plcemud(BASE_CONFIG)
    before = rss_kib(d.proc.pid)
    os.remove(d.config_path)
    os.symlink("/dev/zero", d.config_path)
    log = reload(d)
    assert "the config file is a character device, not a regular file" in log
    assert rss_kib(d.proc.pid) < before + 20_000, (before, rss_kib(d.proc.pid))
    assert raw_request(d.port, READ_R0)[0] == 3
    log = reload(d, BASE_CONFIG + "station: 5\n", count=2)
    assert "reload: station: 1 -> 5" in log
    assert raw_request(d.port, READ_R0, unit=5)[0] == 3
    assert d.stop() == 0


def test_a_reload_of_a_fifo_nobody_writes_neither_blocks_the_next_reload_nor_the_stop(
    start_plcemud,
):
    d = start_plcemud(BASE_CONFIG)
    os.remove(d.config_path)
    os.mkfifo(d.config_path)
    log = reload(d)
    assert "the config file is a FIFO, not a regular file" in log
    assert raw_request(d.port, READ_R0)[0] == 3
    log = reload(d, BASE_CONFIG + "station: 7\n", count=2)
    assert "reload: station: 1 -> 7" in log
    t0 = time.monotonic()
    assert d.stop() == 0
    assert time.monotonic() - t0 < 3


def test_sigterm_during_the_reload_of_a_big_config_exits_at_once_with_the_state_synced(
    start_plcemud, tmp_path
):
    state = tmp_path / "big.state"
    # A long sync period: only the shutdown's sync can keep the write below.
    cfg = BASE_CONFIG + f"persistence: {{file: '{state}', sync_ms: 600000}}\n"
    d = start_plcemud(cfg, name="big")
    c = d.client()
    assert not c.write_register(D0 + 100, 4242, slave=1).isError()  # D100: retentive
    d.close_clients()
    with open(d.config_path, "w") as f:
        f.write(big_program(cfg, 100_000))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("SIGHUP: reloading")
    time.sleep(0.3)  # into the parse, which takes seconds under the sanitizers
    assert "reload: done" not in d.log_text()
    t0 = time.monotonic()
    d.proc.send_signal(signal.SIGTERM)
    assert d.proc.wait(timeout=10) == 0, d.log_text()[-3000:]
    took = time.monotonic() - t0
    log = d.log_text()
    assert took < 3.0, (took, log[-2000:])
    assert "reload: abandoned, the daemon stops" in log
    assert f"state file {state} closed" in log
    d = start_plcemud(cfg, name="big2")
    assert "closed cleanly last time" in d.log_text()
    assert d.client().read_holding_registers(D0 + 100, 1, slave=1).registers == [4242]
