"""A FATEK protocol master (FBs manual, Appendix 2 FATEK Communication Protocol; the daemon's
side: docs/profile-fbs.md, "FATEK protocol") for tests: frames and their checksum, and Fatek,
a client over TCP, UDP or a serial line that reads and writes devices by their FATEK names.

    fatek = Fatek.tcp(500)                   # or Fatek.udp(500), Fatek.serial("/dev/ttyS1")
    fatek.read("R0", 3)                      # [1234, 0, 65535]   (command 46)
    fatek.read("M0", 3)                      # [1, 0, 1]          (command 44)
    fatek.write("R100", [1, 2])              # command 47 (45 for discretes)
    fatek.request(0x4E, "ABC")               # (0, "ABC"): any command, unchecked
    fatek.exchange(frame(1, 0x40))           # b"\\x020140001000018\\x03": bytes in, bytes out
"""

import os
import re
import select
import socket
import termios
import time
import tty

from .errors import DeviceError, FatekError, FatekTimeout

STX = 0x02
ETX = 0x03
MAX_DATA = 500  # characters of a frame's data field
CONNECT_RETRY_S = 2.0  # how long a refused TCP connect is tried again
LOOP_BACK = 0x4E  # the one reply without an error code

DISCRETES = ("X", "Y", "M", "S", "T", "C")
FIVE_DIGITS = ("R", "D", "F", "DR", "DD", "DF")  # the others take four
NAME = re.compile(r"([A-Z]+)(\d+)")


def checksum(body):
    """The two upper-case hex digits of the low 8 bits of the sum of `body`'s bytes (STX up to
    the last data character)."""
    return b"%02X" % (sum(body) & 0xFF)


def _ascii(text):
    return text if isinstance(text, bytes) else str(text).encode("ascii")


def _code(command):
    return command if isinstance(command, int) else int(command, 16)


def frame(station, command, data=b""):
    """A whole request: STX, station and command as two hex digits each, data, checksum, ETX."""
    body = b"%c%02X%02X" % (STX, station, _code(command)) + _ascii(data)
    return body + checksum(body) + bytes([ETX])


def parse(reply):
    """(station, command, data) of a whole frame; FatekError when it is not one (framing bytes,
    checksum)."""
    if len(reply) < 8 or reply[0] != STX or reply[-1] != ETX:
        raise FatekError("reply", None, detail=f"not a frame: {reply!r}")
    if checksum(reply[:-3]) != reply[-3:-1]:
        raise FatekError("reply", None, detail=f"checksum {reply[-3:-1]!r} should be "
                                               f"{checksum(reply[:-3])!r}: {reply!r}")
    text = reply[1:-3].decode("ascii", errors="replace")
    return int(text[:2], 16), int(text[2:4], 16), text[4:]


class Device:
    """A FATEK device name (`R0`, `X0003`, `DRC200`, `WM16`) with what the protocol needs of it:
    `name` (padded: `R00000`), `bits` (1 discrete, 16 or 32 per value) and `step` (how far the
    next item's number is: 1, 2 for the 32-bit forms of R/D/F, 16 for W, 32 for DW)."""

    def __init__(self, name):
        m = NAME.fullmatch(str(name).upper())
        if not m:
            raise DeviceError(name, "not a FATEK device name (e.g. R0, D100, M0, X3, DR10, "
                                    "DRC200, WM0)")
        self.prefix, self.number = m.group(1), int(m.group(2))
        double = self.prefix.startswith("D") and len(self.prefix) > 1  # DR, DD, DRC, DWM...
        self.discrete = self.prefix in DISCRETES
        self.bits = 1 if self.discrete else 32 if double else 16
        if self.prefix.startswith("DW"):
            self.step = 32
        elif self.prefix.startswith("W"):
            self.step = 16
        elif double and self.prefix[1:] in ("R", "D", "F"):
            self.step = 2
        else:
            self.step = 1
        self.digits = 5 if self.prefix in FIVE_DIGITS else 4
        if self.number >= 10 ** self.digits:
            raise DeviceError(name, f"{self.prefix} takes {self.digits} digits")

    def at(self, k):
        """The padded name of the k-th item from this one on."""
        return f"{self.prefix}{self.number + k * self.step:0{self.digits}d}"

    @property
    def name(self):
        return self.at(0)

    def value(self, v):
        """`v` as the protocol writes it: one character for a discrete, 4 or 8 hex digits."""
        if self.discrete:
            return "1" if v else "0"
        if not isinstance(v, int) or not -(1 << (self.bits - 1)) <= v < (1 << self.bits):
            raise ValueError(f"{self.name}: {v!r} does not fit {self.bits} bits")
        return f"{v & ((1 << self.bits) - 1):0{self.bits // 4}X}"

    def values(self, text):
        """The values of a reply's data (`0`/`1` characters, or hex of the name's width)."""
        if self.discrete:
            return [int(c) for c in text]
        w = self.bits // 4
        return [int(text[i:i + w], 16) for i in range(0, len(text), w)]


class _Line:
    """Bytes to and from the slave; `receive` returns one whole frame (STX..ETX) or None."""

    def __init__(self):
        self._buffer = b""

    def receive(self, timeout):
        deadline = time.monotonic() + timeout
        while True:
            start = self._buffer.find(bytes([STX]))
            self._buffer = self._buffer[start:] if start >= 0 else b""
            end = self._buffer.find(bytes([ETX]))
            if end >= 0:
                reply, self._buffer = self._buffer[:end + 1], self._buffer[end + 1:]
                return reply
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            chunk = self._read(left)
            if chunk is None:
                return None
            self._buffer += chunk

    def drop(self):
        """Forgets whatever was received and not read yet."""
        self._buffer = b""


class _Tcp(_Line):
    def __init__(self, host, port, source=None):
        super().__init__()
        # A daemon just started opens its listeners one after another: a port refused at first
        # is tried again for a moment (the Modbus port may already answer while this one is not
        # listening yet).
        deadline = time.monotonic() + CONNECT_RETRY_S
        while True:
            self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            if source:
                self.sock.bind((source, 0))
            self.sock.settimeout(5)
            try:
                self.sock.connect((host, port))
                break
            except ConnectionRefusedError:
                self.sock.close()
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.05)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def send(self, data):
        self.sock.sendall(data)

    def _read(self, timeout):
        self.sock.settimeout(timeout)
        try:
            chunk = self.sock.recv(4096)
        except socket.timeout:
            return b""
        except ConnectionResetError:
            chunk = b""
        if not chunk:
            raise ConnectionError("the slave closed the connection")
        return chunk

    def close(self):
        self.sock.close()


class _Udp(_Line):
    def __init__(self, host, port, source=None):
        super().__init__()
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        if source:
            self.sock.bind((source, 0))
        self.sock.connect((host, port))

    def send(self, data):
        self.sock.send(data)

    def _read(self, timeout):
        self.sock.settimeout(timeout)
        try:
            return self.sock.recv(65536)
        except (socket.timeout, ConnectionRefusedError):
            return b""

    def close(self):
        self.sock.close()


class _Serial(_Line):
    """A tty opened raw (a pty carries the bytes whatever the character format)."""

    def __init__(self, path):
        super().__init__()
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        attrs = termios.tcgetattr(self.fd)
        attrs[3] &= ~termios.ECHO
        termios.tcsetattr(self.fd, termios.TCSANOW, attrs)

    def send(self, data):
        os.write(self.fd, data)

    def _read(self, timeout):
        ready, _, _ = select.select([self.fd], [], [], timeout)
        return os.read(self.fd, 4096) if ready else b""

    def close(self):
        os.close(self.fd)


class Fatek:
    """A FATEK master talking to one station through one line. Device methods raise FatekError
    with the reply's error code, and FatekTimeout when nothing answers within `timeout` s."""

    def __init__(self, line, station=1, timeout=1.0):
        self.line = line
        self.station = station
        self.timeout = timeout

    @classmethod
    def tcp(cls, port, host="127.0.0.1", station=1, timeout=1.0, source=None):
        """A client on a new TCP connection (from `source`, an address of this host, if given)."""
        return cls(_Tcp(host, port, source), station, timeout)

    @classmethod
    def udp(cls, port, host="127.0.0.1", station=1, timeout=1.0, source=None):
        """A client sending one datagram per request."""
        return cls(_Udp(host, port, source), station, timeout)

    @classmethod
    def serial(cls, path, station=1, timeout=1.0):
        """A client on a serial device (or a pty's master end)."""
        return cls(_Serial(path), station, timeout)

    def close(self):
        self.line.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # --- bytes --------------------------------------------------------------------------------

    def send(self, data):
        """Sends raw bytes (a frame, part of one, or anything)."""
        self.line.send(_ascii(data))

    def receive(self, timeout=None):
        """The next whole frame that comes back, or None when none comes within `timeout`."""
        return self.line.receive(self.timeout if timeout is None else timeout)

    def exchange(self, data, timeout=None):
        """Sends raw bytes and returns the reply frame as it came (None: no reply in time)."""
        self.send(data)
        return self.receive(timeout)

    # --- requests -----------------------------------------------------------------------------

    def request(self, command, data="", station=None):
        """Sends one request and returns (error code, data) of its reply, the error code taken
        off the data (0 for 4E, whose reply has none). A non-zero code is returned, not raised;
        silence raises FatekTimeout, a reply that is not a frame (or answers another station
        or command) FatekError."""
        station = self.station if station is None else station
        command = _code(command)
        what = f"command {command:02X}"
        self.line.drop()
        reply = self.exchange(frame(station, command, data))
        if reply is None:
            raise FatekTimeout(what, None, detail=f"no reply from station {station} within "
                                                  f"{self.timeout} s")
        got_station, got_command, text = parse(reply)
        if (got_station, got_command) != (station, command):
            raise FatekError(what, None, detail=f"reply of station {got_station:02X}, command "
                                                f"{got_command:02X}: {reply!r}")
        if command == LOOP_BACK:
            return 0, text
        if not text or text[0] not in "0123456789ABCDEF":
            raise FatekError(what, None, detail=f"reply without an error code: {reply!r}")
        return int(text[0], 16), text[1:]

    def _checked(self, operation, device, command, data=""):
        try:
            code, text = self.request(command, data)
        except FatekError as e:
            raise type(e)(operation, device, detail=e.detail) from e
        if code:
            raise FatekError(operation, device, code=code)
        return text

    # --- devices ------------------------------------------------------------------------------

    def read(self, device, n=1):
        """`n` values from `device` on: 0/1 for discretes (command 44), 16- or 32-bit values for
        registers (46: R, D, RT, RC, WM..., and the 32-bit DR, DD, DRC, DWM...)."""
        d = Device(device)
        if d.discrete:
            return self.read_bits(device, n)
        limit = 64 if d.bits == 16 else 32
        out = []
        for k in range(0, n, limit):
            count = min(limit, n - k)
            text = self._checked("read", d.at(k), 0x46, f"{count:02X}{d.at(k)}")
            out += d.values(text)
        return out

    def read_bits(self, device, n=1):
        """`n` states (0/1) of discretes from `device` on (command 44)."""
        d = self._discrete(device)
        out = []
        for k in range(0, n, 256):
            count = min(256, n - k)
            out += d.values(self._checked("read", d.at(k), 0x44, f"{count % 256:02X}{d.at(k)}"))
        return out

    def write(self, device, values):
        """Writes one value or a list from `device` on: registers with command 47 (values of the
        name's width), discretes with 45."""
        values = list(values) if isinstance(values, (list, tuple)) else [values]
        d = Device(device)
        if d.discrete:
            return self.write_bits(device, values)
        limit = 64 if d.bits == 16 else 32
        for k in range(0, len(values), limit):
            chunk = values[k:k + limit]
            self._checked("write", d.at(k), 0x47,
                          f"{len(chunk):02X}{d.at(k)}" + "".join(d.value(v) for v in chunk))
        return None

    def write_bits(self, device, values):
        """Sets discretes from `device` on to one value or a list of 0/1 (command 45)."""
        values = list(values) if isinstance(values, (list, tuple)) else [values]
        d = self._discrete(device)
        for k in range(0, len(values), 256):
            chunk = values[k:k + 256]
            self._checked("write", d.at(k), 0x45,
                          f"{len(chunk) % 256:02X}{d.at(k)}" + "".join(d.value(v) for v in chunk))

    @staticmethod
    def _discrete(device):
        d = Device(device)
        if not d.discrete:
            raise DeviceError(device, "a register: use read()/write()")
        return d

    # --- the PLC ------------------------------------------------------------------------------

    def status(self):
        """Command 40: {"running", "emergency_stop", "s1", "s2", "s3"} (s1-s3 the status bytes;
        RUN is bit 0 of s1, emergency stop bit 6)."""
        text = self._checked("status", None, 0x40)
        if len(text) != 6:
            raise FatekError("status", None, detail=f"status {text!r} is not 3 bytes")
        s1, s2, s3 = (int(text[i:i + 2], 16) for i in (0, 2, 4))
        return {"running": bool(s1 & 1), "emergency_stop": bool(s1 & 0x40),
                "s1": s1, "s2": s2, "s3": s3}

    def run(self):
        """Command 41 RUN."""
        self._checked("run", None, 0x41, "1")

    def stop(self):
        """Command 41 STOP."""
        self._checked("stop", None, 0x41, "0")
