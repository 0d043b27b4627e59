"""Fixtures for the system tests: run the real plcemud binary on a free port and talk to it.

API (used by every tests/system/test_*.py):
  start_plcemud(config_yaml, *extra_args, name=None, **popen) -> Daemon   (fixture returning a
      function; `name` reuses tmp_path/<name>.yaml, so a restart keeps the same state file;
      `popen` goes to subprocess.Popen, e.g. preexec_fn, or stderr to replace the log file)
  Daemon: .port .proc .config_path .log_text() .client(**kw) .stop() -> exit code
  spawn_plcs(tmp_path, text, ports) -> Daemon  a `plcs:` config (no --port), every port open;
      the fixture start_plcs(text, ports) stops them at teardown
  pty           fixture: a socat pty pair for RTU (rtu_pty.PtyPair), stopped at teardown
  BASE_CONFIG   minimal config text listening on 127.0.0.1
  free_port()   a TCP port nobody listens on right now
  PLCEMUD       path of the binary (env PLCEMUD, default build-test/plcemud)
  run_plcemud(*args)                 runs the binary to completion (--check-config, --print-map)
  raw_request(port, pdu, unit=1)     one raw Modbus TCP request -> reply PDU (None: no reply)
  raw_exchange(sock, pdu, unit=1)    the same on an open socket
The plugin plcemu_testing (python/) is loaded too: its `plcemud` fixture.
"""

import os
import signal
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

import pytest
from pymodbus.client import ModbusTcpClient

REPO = Path(__file__).resolve().parents[2]

# The pytest plugin of python/ (docs/testing.md): its `plcemud` fixture is used by
# test_plcemu_testing.py.
sys.path.insert(0, str(REPO / "python"))
pytest_plugins = ["plcemu_testing"]
PLCEMUD = str(Path(os.environ.get("PLCEMUD", REPO / "build-test" / "plcemud")).resolve())
os.environ["PLCEMUD"] = PLCEMUD  # the plugin's fixture runs the same binary

BASE_CONFIG = "profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n"

START_TIMEOUT_S = 10.0
STOP_TIMEOUT_S = 5.0


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on at the moment of the call."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def free_ports(count: int) -> list:
    """`count` distinct TCP ports on 127.0.0.1 that nothing listens on: each is held until all
    are had (free_port() twice may give the same one)."""
    held = [socket.create_server(("127.0.0.1", 0)) for _ in range(count)]
    ports = [h.getsockname()[1] for h in held]
    for h in held:
        h.close()
    return ports


def plcs_lines(ports, entry: str = "persistence: {enabled: false}") -> str:
    """A `plcs:` config of one fbs PLC per port, `oven-0`, `oven-1`, ..., each entry with
    `entry` ("{i}" in it is the PLC's index) beside its TCP listener."""
    return "plcs:\n" + "".join(
        f"  - {{name: oven-{i}, profile: fbs, {entry.replace('{i}', str(i))},"
        f" modbus: {{tcp: {{bind: 127.0.0.1, port: {p}}}}}}}\n" for i, p in enumerate(ports))


def port_open(port: int, host: str = "127.0.0.1") -> bool:
    try:
        with socket.create_connection((host, port), timeout=0.2):
            return True
    except OSError:
        return False


class Daemon:
    """One running plcemud; stderr goes to a file so it can never block the daemon."""

    def __init__(self, proc, port, config_path, log_path):
        self.proc = proc
        self.port = port
        self.config_path = str(config_path)
        self.log_path = log_path
        self._clients = []

    def log_text(self) -> str:
        """Everything the daemon wrote to stderr so far."""
        try:
            return Path(self.log_path).read_text(errors="replace")
        except FileNotFoundError:
            return ""

    def wait_log(self, text: str, timeout: float = 5.0) -> bool:
        """Waits until `text` appears in the log; returns whether it did."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if text in self.log_text():
                return True
            time.sleep(0.02)
        return text in self.log_text()

    def client(self, **kwargs) -> ModbusTcpClient:
        """A connected pymodbus client; closed at teardown."""
        kwargs.setdefault("timeout", 3)
        kwargs.setdefault("retries", 1)
        c = ModbusTcpClient("127.0.0.1", port=self.port, **kwargs)
        assert c.connect(), f"cannot connect to plcemud on port {self.port}\n{self.log_text()}"
        self._clients.append(c)
        return c

    def close_clients(self):
        for c in self._clients:
            try:
                c.close()
            except Exception:  # noqa: BLE001 - teardown must not fail on a dead socket
                pass
        self._clients.clear()

    def stop(self, sig=signal.SIGTERM) -> int:
        """Sends `sig` (SIGTERM), waits up to 5 s (then SIGKILL) and returns the exit code."""
        self.close_clients()
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                self.proc.wait(timeout=STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode


def _spawn(tmp_path: Path, index: int, config_yaml: str, extra_args, name=None, **popen) -> Daemon:
    stem = name or f"plcemud-{index}"
    config_path = tmp_path / f"{stem}.yaml"
    config_path.write_text(config_yaml)
    log_path = tmp_path / f"plcemud-{index}.log"
    port = free_port()
    args = [PLCEMUD, "-c", str(config_path), "--port", str(port), *map(str, extra_args)]
    env = dict(os.environ)
    env.pop("STATE_DIRECTORY", None)  # state files stay beside the config, in tmp_path
    with open(log_path, "wb") as log:
        popen.setdefault("stderr", log)
        proc = subprocess.Popen(
            args, stdin=subprocess.DEVNULL, stdout=log, env=env, cwd=tmp_path, **popen
        )
    d = Daemon(proc, port, config_path, log_path)
    deadline = time.monotonic() + START_TIMEOUT_S
    while True:
        if proc.poll() is not None:
            pytest.fail(
                f"plcemud exited with {proc.returncode} before listening on {port}\n"
                f"args: {args}\n--- stderr ---\n{d.log_text()}"
            )
        if port_open(port):
            return d
        if time.monotonic() > deadline:
            d.stop(signal.SIGKILL)
            pytest.fail(
                f"plcemud did not listen on {port} within {START_TIMEOUT_S} s\n"
                f"--- stderr ---\n{d.log_text()}"
            )
        time.sleep(0.05)


@pytest.fixture
def start_plcemud(tmp_path):
    """Returns start(config_yaml, *extra_args) -> Daemon; every daemon is stopped at teardown."""
    if not os.access(PLCEMUD, os.X_OK):
        pytest.fail(f"plcemud binary not found at {PLCEMUD} (build it or set PLCEMUD)")
    daemons = []

    def start(config_yaml: str = BASE_CONFIG, *extra_args, name=None, **popen) -> Daemon:
        d = _spawn(tmp_path, len(daemons), config_yaml, extra_args, name, **popen)
        daemons.append(d)
        return d

    yield start
    for d in daemons:
        d.stop()


def spawn_plcs(tmp_path: Path, text: str, ports, host="127.0.0.1", name="plant",
               **popen) -> Daemon:
    """plcemud on a `plcs:` config written to tmp_path/<name>.yaml (no --port: each PLC names
    its own), once every one of `ports` listens on `host`; `popen` goes to subprocess.Popen.
    The caller stops it."""
    config_path = tmp_path / f"{name}.yaml"
    config_path.write_text(text)
    log_path = tmp_path / f"plcemud-{time.monotonic_ns()}.log"
    env = dict(os.environ)
    env.pop("STATE_DIRECTORY", None)
    with open(log_path, "wb") as log:
        proc = subprocess.Popen(
            [PLCEMUD, "-c", str(config_path)],
            stdin=subprocess.DEVNULL, stdout=log, stderr=log, env=env, cwd=tmp_path, **popen,
        )
    d = Daemon(proc, ports[0], config_path, log_path)
    deadline = time.monotonic() + START_TIMEOUT_S
    while not all(port_open(p, host) for p in ports):
        if proc.poll() is not None or time.monotonic() > deadline:
            d.stop(signal.SIGKILL)
            pytest.fail(f"plcemud did not listen on {ports}\n{d.log_text()}")
        time.sleep(0.05)
    return d


@pytest.fixture
def start_plcs(tmp_path):
    """Returns start(text, ports, **kw) -> Daemon for a `plcs:` config (spawn_plcs); every
    daemon is stopped at teardown."""
    daemons = []

    def start(text, ports, **kw):
        d = spawn_plcs(tmp_path, text, ports, **kw)
        daemons.append(d)
        return d

    yield start
    for d in daemons:
        d.stop()


@pytest.fixture
def pty(tmp_path):
    """A socat pty pair (rtu_pty.PtyPair): plcemud opens `.slave`, the test talks on `.master`."""
    from rtu_pty import PtyPair

    pair = PtyPair(tmp_path)
    yield pair
    pair.stop()


@pytest.fixture
def daemon(start_plcemud):
    """A daemon on BASE_CONFIG."""
    return start_plcemud(BASE_CONFIG)


def run_plcemud(*args, timeout=20, **kwargs) -> subprocess.CompletedProcess:
    """Runs plcemud to completion (e.g. --check-config, --print-map) and captures its output."""
    return subprocess.run(
        [PLCEMUD, *map(str, args)], capture_output=True, text=True, timeout=timeout, **kwargs
    )


def _recv_exact(sock, n: int):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def raw_exchange(sock, pdu: bytes, unit: int = 1, tid: int = 1):
    """Sends one Modbus TCP request on `sock`; returns the reply PDU, or None when the server
    sent nothing before the socket's timeout or closed the connection."""
    sock.sendall(struct.pack(">HHHB", tid, 0, len(pdu) + 1, unit) + bytes(pdu))
    try:
        header = _recv_exact(sock, 7)
        if header is None:
            return None
        rtid, proto, length, runit = struct.unpack(">HHHB", header)
        assert (rtid, proto, runit) == (tid, 0, unit), f"bad MBAP reply {header.hex()}"
        return _recv_exact(sock, length - 1)
    except socket.timeout:
        return None


def raw_request(port: int, pdu: bytes, unit: int = 1, timeout: float = 3.0):
    """One raw request on a new connection (see raw_exchange)."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        return raw_exchange(s, pdu, unit)
