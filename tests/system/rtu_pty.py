"""Modbus RTU over a socat pty pair (scripts/rtu-pty.sh) for the system tests.

PtyPair: runs scripts/rtu-pty.sh with two paths of its own; `.slave` is the end plcemud opens,
`.master` the end the tests (pymodbus, mbpoll, raw frames, libmodbus) talk on.
RawLine: a master end opened raw, to send exact bytes (bad CRC, split frames) and to see whether
any answer comes back.
"""

import os
import select
import signal
import subprocess
import termios
import time
import tty
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "rtu-pty.sh"


def crc16(data: bytes) -> int:
    """Modbus CRC-16 (A001h reflected, initial FFFFh), written independently of the daemon's."""
    crc = 0xFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return crc


def frame(unit: int, pdu: bytes) -> bytes:
    """An RTU frame: address, PDU, CRC low byte first."""
    body = bytes([unit]) + pdu
    crc = crc16(body)
    return body + bytes([crc & 0xFF, crc >> 8])


def rtu_config(device: str, extra_rtu: str = "", extra: str = "") -> str:
    """A config with TCP on 127.0.0.1 (the fixture's port) and the serial slave on `device`."""
    rtu = f"device: {device}" + (f", {extra_rtu}" if extra_rtu else "")
    return f"profile: fbs\nmodbus:\n  tcp: {{bind: 127.0.0.1}}\n  rtu: {{{rtu}}}\n{extra}"


class PtyPair:
    """A running scripts/rtu-pty.sh; stop() ends it (and its socat)."""

    def __init__(self, directory: Path):
        self.slave = str(directory / "plcemu-rtu-a")
        self.master = str(directory / "plcemu-rtu-b")
        self.proc = subprocess.Popen(
            [str(SCRIPT), self.slave, self.master],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        printed = [self.proc.stdout.readline().strip(), self.proc.stdout.readline().strip()]
        if printed != [self.slave, self.master]:
            self.stop()
            raise RuntimeError(f"rtu-pty.sh printed {printed!r}: {self.proc.stderr.read()}")

    def stop(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self.proc.stdout.close()
        self.proc.stderr.close()


class RawLine:
    """The master end of the pair, raw: exact bytes out, whatever comes back in."""

    def __init__(self, path: str):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        attrs = termios.tcgetattr(self.fd)
        attrs[3] &= ~termios.ECHO
        termios.tcsetattr(self.fd, termios.TCSANOW, attrs)

    def close(self):
        os.close(self.fd)

    def send(self, data: bytes):
        os.write(self.fd, data)

    def receive(self, expected: int, timeout: float = 1.0) -> bytes:
        """Reads until `expected` bytes came or nothing more arrives for `timeout` seconds."""
        out = b""
        deadline = time.monotonic() + timeout
        while len(out) < expected:
            left = deadline - time.monotonic()
            if left <= 0:
                break
            ready, _, _ = select.select([self.fd], [], [], left)
            if not ready:
                break
            out += os.read(self.fd, 1024)
        return out

    def silent(self, timeout: float = 0.5) -> bool:
        """True when nothing at all arrives within `timeout` seconds."""
        ready, _, _ = select.select([self.fd], [], [], timeout)
        if ready:
            os.read(self.fd, 4096)
        return not ready

    def request(self, unit: int, pdu: bytes, reply_len: int, timeout: float = 1.0) -> bytes:
        """Sends one frame and returns the reply PDU after checking its address and CRC."""
        self.send(frame(unit, pdu))
        r = self.receive(reply_len, timeout)
        assert len(r) == reply_len, f"reply {r.hex()} (expected {reply_len} bytes)"
        assert r[0] == unit, f"reply from unit {r[0]}"
        assert crc16(r[:-2]) == r[-2] | r[-1] << 8, f"reply CRC wrong: {r.hex()}"
        return r[1:-2]


def echoing(path: str, request: bytes, seconds: float = 1.0, delay: float = 0.0) -> bytes:
    """Acts as a line that echoes: sends `request` on the master end at `path`, then for
    `seconds` writes back whatever comes, `delay` seconds later (as an RS-485 adapter with local
    echo hands the slave its own answer, a USB one in batches); returns every byte that came."""
    line = RawLine(path)
    try:
        line.send(request)
        got = b""
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            ready, _, _ = select.select([line.fd], [], [], left)
            if ready:
                chunk = os.read(line.fd, 1024)
                got += chunk
                time.sleep(delay)
                line.send(chunk)
        return got
    finally:
        line.close()
