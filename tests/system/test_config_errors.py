"""Configuration errors reported together (docs/configuration.md, "Configuration"): a file with
several errors names every one, each on a line of its own at its file:line:col, in the order of
the file, at --check-config (exit status 2) and at a SIGHUP reload, a profile's own section's
too; past 20 the loader stops and says so."""

import re
import signal
import time
from pathlib import Path

from conftest import BASE_CONFIG, run_plcemud

# Three keys in error, written in another order than the loader reads them.
THREE_ERRORS = (
    "profile: fbs\n"
    "modbus:\n"
    "  tcp:\n"
    "    bind: 127.0.0.1\n"
    "    port: 70000\n"
    "scan_ms: fast\n"
    "station: 300\n"
)
EXPECTED = [
    (5, 11, "modbus.tcp.port: 70000 is out of range 0..65535"),
    (6, 10, "scan_ms: expected an integer, got 'fast'"),
    (7, 10, "station: 300 is out of range"),
]


def error_lines(log: str, path, prefix: str):
    """The `prefix` lines of `log` that name a position in `path`, as (line, col, message)."""
    pattern = re.compile(re.escape(f"{prefix}{path}:") + r"(\d+):(\d+): (.*)$")
    out = []
    for line in log.splitlines():
        m = pattern.search(line)
        if m:
            out.append((int(m.group(1)), int(m.group(2)), m.group(3)))
    return out


def assert_three_errors(found):
    assert len(found) == 3, found
    for (line, col, message), (want_line, want_col, needle) in zip(found, EXPECTED):
        assert (line, col) == (want_line, want_col), found
        assert message.startswith(needle), found


def test_check_config_prints_every_error_at_its_position_and_exits_2(tmp_path):
    p = tmp_path / "three_errors.yaml"
    p.write_text(THREE_ERRORS)
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2, r.stderr
    assert r.stdout == ""
    # One log line per error, each "config: file:line:col: message".
    assert_three_errors(error_lines(r.stderr, p, "config: "))
    assert len(r.stderr.splitlines()) == 3, r.stderr


def test_check_config_prints_every_error_of_a_profile_section(tmp_path):
    # Three errors in the FBs `temperature:` section, a profile's own, each at its position.
    p = tmp_path / "temperature.yaml"
    p.write_text(
        "profile: fbs\n"
        "temperature:\n"
        "  table: X0\n"
        "  modules: [TC6:K, TC7]\n"
        "  scan_rate: slow\n"
    )
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2, r.stderr
    found = error_lines(r.stderr, p, "config: ")
    assert [(line, col) for line, col, _ in found] == [(3, 10), (4, 20), (5, 14)], r.stderr
    assert found[0][2] == "temperature.table: expected an R or D register", r.stderr
    assert found[1][2].startswith("temperature.modules: unknown module 'TC7'"), r.stderr
    assert found[2][2] == "temperature.scan_rate: expected 'normal' or 'fast'", r.stderr
    assert len(r.stderr.splitlines()) == 3, r.stderr


def test_check_config_stops_after_twenty_errors_and_says_so(tmp_path):
    p = tmp_path / "many.yaml"
    p.write_text("profile: fbs\n" + "".join(f"key{i}: 1\n" for i in range(50)))
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2, r.stderr
    found = error_lines(r.stderr, p, "config: ")
    assert [(line, col) for line, col, _ in found] == [(i + 2, 1) for i in range(20)], r.stderr
    assert r.stderr.splitlines()[-1].endswith(
        f"config: {p}: too many errors, stopped after the 20 above"
    ), r.stderr


def test_sighup_logs_every_error_of_the_rejected_config(start_plcemud):
    d = start_plcemud(BASE_CONFIG)
    c = d.client()
    assert not c.write_register(0, 1234, slave=1).isError()
    Path(d.config_path).write_text(THREE_ERRORS)
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("configuration rejected"), d.log_text()
    log = d.log_text()
    assert_three_errors(error_lines(log, d.config_path, "reload: "))
    # The errors come before the line saying the configuration was rejected.
    assert log.index("reload: configuration rejected") > log.index(f"{d.config_path}:7:10:")
    # Still running the previous configuration.
    time.sleep(0.1)
    assert d.proc.poll() is None
    rr = c.read_holding_registers(0, 1, slave=1)
    assert not rr.isError() and rr.registers == [1234]
