"""plcemud as a service: sd_notify (READY, STATUS, RELOADING, STOPPING, watchdog pings), reload on
SIGHUP, and the systemd units (docs/operations.md, "Running as a service")."""

import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from pathlib import Path

import pytest

from conftest import PLCEMUD, REPO, free_ports, plcs_lines, port_open, spawn_plcs
from rtu_pty import PtyPair

D0 = 6000
R3000 = 3000  # not retentive
R4057 = 4057  # power-up counter


class NotifySocket:
    """A datagram socket standing in for systemd's NOTIFY_SOCKET."""

    def __init__(self):
        # sun_path is short: keep the socket out of pytest's long tmp paths.
        self.dir = tempfile.mkdtemp(prefix="plcemu-notify-", dir="/tmp")
        self.path = os.path.join(self.dir, "notify")
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.sock.bind(self.path)
        self.messages = []

    def collect(self, seconds):
        """Every message received within `seconds`."""
        deadline = time.monotonic() + seconds
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return self.messages
            self.sock.settimeout(left)
            try:
                # Larger than systemd takes (it ignores 4,096 bytes or more): a message too long
                # is seen whole here, and its length checked.
                self.messages.append(self.sock.recv(1 << 20).decode())
            except socket.timeout:
                return self.messages

    def wait_for(self, text, timeout=5.0):
        """Waits for a message containing `text`; returns it (or None)."""
        deadline = time.monotonic() + timeout
        seen = len(self.messages)
        while time.monotonic() < deadline:
            for m in self.messages[seen:]:
                if text in m:
                    return m
            seen = len(self.messages)
            self.collect(min(0.1, max(0.0, deadline - time.monotonic())))
        return next((m for m in self.messages if text in m), None)

    def close(self):
        self.sock.close()
        shutil.rmtree(self.dir, ignore_errors=True)


def built_with_libsystemd() -> bool:
    r = subprocess.run(["ldd", PLCEMUD], capture_output=True, text=True, timeout=30)
    return "libsystemd" in r.stdout


@pytest.fixture
def notify(monkeypatch):
    # The units are Type=notify: a build without sd_notify would be killed at its start timeout.
    assert built_with_libsystemd(), "plcemud must link libsystemd on Linux (libsystemd-dev)"
    n = NotifySocket()
    monkeypatch.setenv("NOTIFY_SOCKET", n.path)
    monkeypatch.delenv("WATCHDOG_PID", raising=False)
    yield n
    n.close()


def config(tmp_path, station=1, extra=""):
    return (
        "profile: fbs\n"
        f"station: {station}\n"
        "modbus: {tcp: {bind: 127.0.0.1}}\n"
        f"persistence: {{file: '{tmp_path / 'plc.state'}'}}\n" + extra
    )


# --- sd_notify


def test_ready_is_sent_once_the_listener_is_open(start_plcemud, notify, tmp_path):
    d = start_plcemud(config(tmp_path))
    ready = notify.wait_for("READY=1")
    assert ready is not None, d.log_text()
    # READY=1 is sent after the listener opened; by now it must accept connections.
    assert port_open(d.port)
    assert "STATUS=station 1, tcp 127.0.0.1:" in ready


def test_status_says_while_a_serial_line_waits_for_its_device(start_plcemud, notify, tmp_path):
    """The status line was made at the start and at reloads only: a line whose device went
    away was shown as serving. A new STATUS= says it waits, and another that it is back."""
    pair = PtyPair(tmp_path)
    try:
        d = start_plcemud("profile: fbs\n"
                          "modbus:\n  tcp: {bind: 127.0.0.1}\n"
                          f"  rtu: {{device: {pair.slave}, parity: N}}\n"  # ptys refuse parity
                          f"persistence: {{file: '{tmp_path / 'plc.state'}'}}\n")
        ready = notify.wait_for("READY=1")
        assert ready is not None and f"rtu {pair.slave}" in ready, (ready, d.log_text())
        assert "waiting" not in ready, ready
        pair.stop()
        waiting = notify.wait_for("(waiting for the device)")
        assert waiting is not None and waiting.startswith("STATUS="), (notify.messages, d.log_text())
        assert "READY=1" not in waiting, waiting
        pair = PtyPair(tmp_path)
        seen = len(notify.messages)
        deadline = time.monotonic() + 10  # the back-off is at most 5 s
        while time.monotonic() < deadline and not any(
                f"rtu {pair.slave}" in m and "waiting" not in m for m in notify.messages[seen:]):
            notify.collect(0.2)
        back = [m for m in notify.messages[seen:] if f"rtu {pair.slave}" in m]
        assert back and "waiting" not in back[-1], (notify.messages, d.log_text())
    finally:
        pair.stop()


def test_ready_fits_the_message_systemd_takes_with_many_plcs(notify, tmp_path):
    """systemd ignores a notification of 4,096 bytes or more, READY=1 with it: a Type=notify
    unit of many PLCs would never start. The status names the PLCs that fit, then the rest."""
    ports = free_ports(150)
    d = spawn_plcs(tmp_path, plcs_lines(ports), ports)
    try:
        ready = notify.wait_for("READY=1")
        assert ready is not None, d.log_text()
        assert len(ready.encode()) < 4096
        assert ready.startswith(f"READY=1\nSTATUS=plcs[0] (oven-0): station 1, tcp 127.0.0.1:{ports[0]}; "
                                f"plcs[1] (oven-1): station 1, tcp 127.0.0.1:{ports[1]}; "), ready
        shown = ready.count("station 1, tcp")
        assert 20 < shown < 150
        assert ready.endswith(f"; and {150 - shown} more PLCs"), ready[-200:]
        notify.messages.clear()
        d.proc.send_signal(signal.SIGHUP)
        again = notify.wait_for("READY=1")
        assert again == ready
    finally:
        d.stop()


def ping_times(notify, seconds):
    """When each WATCHDOG=1 came within `seconds`, on the monotonic clock."""
    times = []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        seen = len(notify.messages)
        notify.collect(min(0.02, max(0.0, deadline - time.monotonic())))
        times += [time.monotonic() for m in notify.messages[seen:] if m == "WATCHDOG=1"]
    return times


def assert_pinged_every_quarter(times, interval, seconds):
    """A ping every quarter of the interval, and never a gap near the interval."""
    expected = seconds / (interval / 4)
    assert expected - 3 <= len(times) <= expected + 2, times
    gaps = [b - a for a, b in zip(times, times[1:])]
    assert max(gaps) < interval / 2, gaps


def test_watchdog_pings_come_from_the_event_loop_every_quarter_interval(start_plcemud, notify,
                                                                        monkeypatch, tmp_path):
    monkeypatch.setenv("WATCHDOG_USEC", "1000000")  # WatchdogSec=1s
    start_plcemud(config(tmp_path))
    assert notify.wait_for("READY=1")
    notify.messages.clear()
    # One ping per 0.25 s (not one per 10 ms scan): about 8 in 2 s.
    assert_pinged_every_quarter(ping_times(notify, 2.0), 1.0, 2.0)


def test_watchdog_pings_go_on_while_the_simulation_is_frozen(start_plcemud, notify, monkeypatch,
                                                             tmp_path):
    """A frozen simulation (simulator unit 247, register 1) runs no scans but is not stuck.
    Frozen, pings came from a timer at half the interval that the ping's own spacing could
    skip: gaps of the whole interval when the two were out of step."""
    monkeypatch.setenv("WATCHDOG_USEC", "1000000")
    d = start_plcemud(config(tmp_path))
    assert notify.wait_for("READY=1")
    c = d.client()
    assert not c.write_register(1, 1, slave=247).isError()
    # Simulated time (registers 3-4) stands still: no scans.
    t0 = c.read_holding_registers(3, 2, slave=247).registers
    time.sleep(0.3)
    assert c.read_holding_registers(3, 2, slave=247).registers == t0
    notify.messages.clear()
    assert_pinged_every_quarter(ping_times(notify, 2.0), 1.0, 2.0)
    assert c.read_holding_registers(1, 1, slave=247).registers == [1]  # still frozen


def test_watchdog_pings_go_on_between_scans_far_apart(start_plcemud, notify, monkeypatch,
                                                      tmp_path):
    """A 10 ms scan at time scale 0.001 runs once in 10 s of real time: the pings came only
    after scans, and systemd would have killed a healthy daemon (WatchdogSec=10s)."""
    monkeypatch.setenv("WATCHDOG_USEC", "1000000")
    d = start_plcemud(config(tmp_path, extra="time_scale: 0.001\n"))
    assert notify.wait_for("READY=1")
    notify.messages.clear()
    assert_pinged_every_quarter(ping_times(notify, 2.0), 1.0, 2.0)
    assert d.proc.poll() is None


def test_no_watchdog_pings_unless_asked(start_plcemud, notify, monkeypatch, tmp_path):
    monkeypatch.delenv("WATCHDOG_USEC", raising=False)
    start_plcemud(config(tmp_path))
    assert notify.wait_for("READY=1")
    assert "WATCHDOG=1" not in notify.collect(0.7)


def test_reload_and_stop_are_announced(start_plcemud, notify, tmp_path):
    d = start_plcemud(config(tmp_path))
    assert notify.wait_for("READY=1")
    notify.messages.clear()
    d.proc.send_signal(signal.SIGHUP)
    assert notify.wait_for("RELOADING=1")
    assert notify.wait_for("READY=1")
    notify.messages.clear()
    assert d.stop() == 0
    assert notify.wait_for("STOPPING=1")


# --- SIGHUP


def rewrite(d, text):
    Path(d.config_path).write_text(text)


def test_sighup_with_a_broken_config_keeps_serving_the_old_one(start_plcemud, tmp_path):
    d = start_plcemud(config(tmp_path, station=1))
    c = d.client()
    assert not c.write_register(D0, 1234, slave=1).isError()
    rewrite(d, config(tmp_path, station=1) + "scan_ms: 5000\n")  # out of range 1..1000
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("configuration rejected"), d.log_text()
    log = d.log_text()
    # The error names file, line and column (docs/configuration.md, Configuration).
    assert f"{d.config_path}:5:10: scan_ms" in log, log
    assert d.proc.poll() is None
    rr = c.read_holding_registers(D0, 1, slave=1)
    assert not rr.isError() and rr.registers == [1234]
    assert not c.read_holding_registers(R4057, 1, slave=1).isError()

    # A program operand only the PLC build can reject (not the YAML reader): same outcome.
    rewrite(d, config(tmp_path, station=9) + "program:\n  - MOV: {en: M1926, s: R0, d: R99999}\n")
    d.proc.send_signal(signal.SIGHUP)
    deadline = time.monotonic() + 5
    while d.log_text().count("configuration rejected") < 2 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert d.log_text().count("configuration rejected") == 2, d.log_text()
    assert not c.read_holding_registers(D0, 1, slave=1).isError()  # still station 1
    rr = c.read_holding_registers(D0, 1, slave=9)
    assert rr.isError() and rr.exception_code == 0x0B


def test_sighup_with_a_new_station_keeps_connections_and_data(start_plcemud, tmp_path):
    d = start_plcemud(config(tmp_path, station=1))
    c = d.client()
    assert not c.write_register(D0, 1234, slave=1).isError()   # retentive
    assert not c.write_register(R3000, 77, slave=1).isError()  # not retentive
    sock = c.socket
    connections = d.log_text().count(" connected")
    disconnections = d.log_text().count(" disconnected")  # the fixture's readiness probe

    rewrite(d, config(tmp_path, station=5))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    assert "reload: station: 1 -> 5" in d.log_text()

    # Same socket, no new connection: the listener did not change, so connections were kept.
    rr = c.read_holding_registers(D0, 1, slave=5)
    assert not rr.isError(), rr
    assert rr.registers == [1234]
    assert c.socket is sock
    assert d.log_text().count(" connected") == connections
    assert d.log_text().count(" disconnected") == disconnections
    rr = c.read_holding_registers(D0, 1, slave=1)
    assert rr.isError() and rr.exception_code == 0x0B  # unknown unit on TCP (docs/profile-fbs.md)
    # A reload is not a power-up: nothing cleared, R4057 not counted.
    assert c.read_holding_registers(R3000, 1, slave=5).registers == [77]
    assert c.read_holding_registers(R4057, 1, slave=5).registers == [1]
    assert c.read_holding_registers(4055, 1, slave=5).registers == [5]


def read_station(c, unit, value, timeout=2.0):
    """Polls R4055 at `unit` until it reads `value` (a scan ran); returns what it last read."""
    deadline = time.monotonic() + timeout
    while True:
        rr = c.read_holding_registers(4055, 1, slave=unit)
        got = None if rr.isError() else rr.registers[0]
        if got == value or time.monotonic() > deadline:
            return got
        time.sleep(0.02)


# docs/configuration.md, "Sharing a listener": a PLC alone on its listener may not take its own
# simulator unit through R4055, nor be given a simulator unit equal to its station in force.
def test_a_lone_plc_keeps_its_station_and_simulator_unit_apart(start_plcemud, tmp_path):
    d = start_plcemud(config(tmp_path, station=1))
    c = d.client()
    assert not c.write_register(4055, 0x5500 | 247, slave=1).isError()
    assert read_station(c, 1, 1) == 1
    assert d.wait_log("R4055: station 247 refused: it is its own simulator unit on tcp "
                      f"127.0.0.1:{d.port}"), d.log_text()
    assert not c.write_register(4055, 0x5509, slave=1).isError()
    assert read_station(c, 9, 9) == 9
    rewrite(d, config(tmp_path, station=1) + "simulator: {unit: 9}\n")
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("configuration rejected"), d.log_text()
    assert ("reload: the PLC: its station 9 (in force: set through R4055; the config says 1) is "
            "also its simulator.unit") in d.log_text()
    assert read_station(c, 9, 9) == 9
    # With the config's station unchanged, the station a master set stays across reloads.
    for n in (1, 2):
        rewrite(d, config(tmp_path, station=1) + f"scan_ms: {10 + n}\n")
        d.proc.send_signal(signal.SIGHUP)
        deadline = time.monotonic() + 5
        while d.log_text().count("reload: done; station 9") < n and time.monotonic() < deadline:
            time.sleep(0.05)
        assert d.log_text().count("reload: done; station 9") == n, d.log_text()
    assert read_station(c, 9, 9) == 9


def test_sighup_that_changes_the_bind_address_moves_the_listener(start_plcemud, tmp_path):
    """Same port (--port), 127.0.0.1 -> 0.0.0.0: the old listener is closed first, the new one
    also answers on 127.0.0.2."""
    d = start_plcemud(config(tmp_path))
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.2", d.port), timeout=1).close()
    rewrite(d, config(tmp_path).replace("bind: 127.0.0.1", "bind: 0.0.0.0"))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    assert "reload: modbus.tcp.bind: 127.0.0.1 -> 0.0.0.0" in d.log_text()
    assert f"listening on tcp 0.0.0.0:{d.port}" in d.log_text()
    s = socket.create_connection(("127.0.0.2", d.port), timeout=2)
    s.sendall(bytes.fromhex("000100000006" "01" "03" "1770" "0001"))  # D0
    assert s.recv(64)[:9] == bytes.fromhex("000100000005" "01" "0302")
    s.close()


def test_sighup_applies_access_policy_to_open_connections(start_plcemud, tmp_path):
    d = start_plcemud(config(tmp_path))
    c = d.client()
    assert not c.write_register(D0 + 1, 11, slave=1).isError()
    rewrite(d, config(tmp_path).replace("modbus: {tcp: {bind: 127.0.0.1}}",
                                                   "modbus: {tcp: {bind: 127.0.0.1}, read_only: true}"))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    assert "reload: modbus.read_only: false -> true" in d.log_text()
    rr = c.write_register(D0 + 1, 12, slave=1)
    assert rr.isError() and rr.exception_code == 2
    assert c.read_holding_registers(D0 + 1, 1, slave=1).registers == [11]


# --- the systemd units


def test_units_pass_systemd_analyze_verify(tmp_path):
    """Both units, with ExecStart pointed at the built binary (verify checks it exists)."""
    if shutil.which("systemd-analyze") is None:
        pytest.skip("systemd-analyze is not installed (scripts/install-deps.sh test installs it)")
    probe = tmp_path / "probe"
    probe.mkdir()
    (probe / "probe.service").write_text("[Service]\nExecStart=/bin/true\n")
    r = subprocess.run(["systemd-analyze", "verify", str(probe / "probe.service")],
                       capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        pytest.skip(f"systemd-analyze verify cannot run here: {r.stderr.strip()}")

    units = tmp_path / "units"
    units.mkdir()
    for name in ("plcemud.service", "plcemud@.service"):
        text = (REPO / "systemd" / name).read_text().replace("/usr/local/bin/plcemud", PLCEMUD)
        (units / name).write_text(text)
    shutil.copy(units / "plcemud@.service", units / "plcemud@line1.service")
    for name in ("plcemud.service", "plcemud@line1.service"):
        r = subprocess.run(["systemd-analyze", "verify", str(units / name)],
                           capture_output=True, text=True, timeout=60, cwd=units)
        assert r.returncode == 0, r.stderr
        # verify exits 0 on unknown keys and bad values: any word from it is a finding.
        assert r.stderr.strip() == "", r.stderr

    # The check above can fail: a bad value is reported.
    bad = units / "bad.service"
    bad.write_text((units / "plcemud.service").read_text().replace("ProtectSystem=strict",
                                                                    "ProtectSystem=bogus"))
    r = subprocess.run(["systemd-analyze", "verify", str(bad)], capture_output=True, text=True,
                       timeout=60, cwd=units)
    assert "ProtectSystem" in r.stderr or "protect system" in r.stderr


def test_units_say_what_the_service_needs():
    for name in ("plcemud.service", "plcemud@.service"):
        text = (REPO / "systemd" / name).read_text()
        keys = {line.split("=", 1)[0] for line in text.splitlines() if "=" in line and not line.startswith("#")}
        for key in ("Type", "WatchdogSec", "ExecReload", "Restart", "DynamicUser", "StateDirectory",
                    "AmbientCapabilities", "NoNewPrivileges", "ProtectSystem", "ProtectHome",
                    "PrivateTmp", "PrivateDevices", "SystemCallFilter", "CapabilityBoundingSet"):
            assert key in keys, f"{name}: {key}"
        assert "Type=notify" in text
    assert "-c /etc/plcemu/%i.yaml" in (REPO / "systemd" / "plcemud@.service").read_text()


def test_install_script_installs_into_destdir(tmp_path):
    dest = tmp_path / "root"
    r = subprocess.run([str(REPO / "scripts" / "install.sh"), "--binary", PLCEMUD],
                       env={**os.environ, "DESTDIR": str(dest)}, capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    assert os.access(dest / "usr/local/bin/plcemud", os.X_OK)
    for f in ("etc/systemd/system/plcemud.service", "etc/systemd/system/plcemud@.service",
              "etc/plcemu/plcemud.yaml", "etc/plcemu/example.yaml"):
        assert (dest / f).is_file(), f
    # The installed example config is valid as it stands.
    r = subprocess.run([PLCEMUD, "-c", str(dest / "etc/plcemu/plcemud.yaml"), "--check-config"],
                       capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stderr
    # An existing config is never overwritten.
    (dest / "etc/plcemu/plcemud.yaml").write_text("profile: fbs\n# mine\n")
    r = subprocess.run([str(REPO / "scripts" / "install.sh"), "--binary", PLCEMUD],
                       env={**os.environ, "DESTDIR": str(dest)}, capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    assert "# mine" in (dest / "etc/plcemu/plcemud.yaml").read_text()
