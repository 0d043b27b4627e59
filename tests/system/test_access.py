"""Access control through Modbus: modbus.tcp.allow, max_clients, idle_timeout_s, modbus.read_only,
modbus.write_protect (docs/operations.md, "Access control"). Refused writes answer exception 02 and change
nothing (docs/profile-fbs.md, "Modbus map")."""

import signal
import socket
import struct
import time
from pathlib import Path

import pytest

D0 = 6000
M0 = 2000


class Raw:
    """A plain TCP Modbus client: no reconnects, so a closed connection shows as closed."""

    def __init__(self, port, source="127.0.0.1"):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.sock.settimeout(3)
        self.sock.bind((source, 0))
        self.sock.connect(("127.0.0.1", port))
        self.tid = 0

    def request(self, pdu: bytes, unit=1) -> bytes:
        """Sends one PDU; returns the reply PDU, or b"" when the server closed the connection."""
        self.tid = (self.tid + 1) & 0xFFFF
        self.sock.sendall(struct.pack(">HHHB", self.tid, 0, len(pdu) + 1, unit) + pdu)
        head = self._recv(7)
        if len(head) < 7:
            return b""
        _, _, length, _ = struct.unpack(">HHHB", head)
        return self._recv(length - 1)

    def read_registers(self, address, count=1):
        pdu = self.request(struct.pack(">BHH", 3, address, count))
        assert pdu[:1] == b"\x03", pdu
        return list(struct.unpack(f">{count}H", pdu[2:]))

    def closed_by_server(self, timeout=3.0) -> bool:
        """True when the server closes the connection within `timeout`."""
        self.sock.settimeout(timeout)
        try:
            return self.sock.recv(1) == b""
        except ConnectionResetError:
            return True
        except socket.timeout:
            return False

    def _recv(self, n):
        buf = b""
        while len(buf) < n:
            try:
                chunk = self.sock.recv(n - len(buf))
            except ConnectionResetError:
                return buf
            if not chunk:
                return buf
            buf += chunk
        return buf

    def close(self):
        self.sock.close()


def base(extra_tcp="", extra=""):
    return ("profile: fbs\n"
            f"modbus:\n  tcp: {{bind: 127.0.0.1{extra_tcp}}}\n{extra}"
            "persistence: {enabled: false}\n")


def exception_code(pdu: bytes, fc: int):
    assert pdu[0] == fc | 0x80, f"expected an exception reply to FC{fc:02d}, got {pdu.hex()}"
    return pdu[1]


# --- modbus.tcp.allow


def test_allow_list_closes_other_peers_at_accept(start_plcemud):
    d = start_plcemud(base(", allow: [127.0.0.2/32, 10.0.0.0/8]"))
    allowed = Raw(d.port, source="127.0.0.2")
    assert allowed.read_registers(D0) == [0]
    refused = Raw(d.port, source="127.0.0.3")
    assert refused.closed_by_server()
    assert d.wait_log("127.0.0.3")
    assert "refused: not in modbus.tcp.allow" in d.log_text()
    assert allowed.read_registers(D0) == [0]  # the allowed one is unaffected


def test_allow_list_with_a_prefix(start_plcemud):
    d = start_plcemud(base(", allow: [127.0.0.0/30]"))
    assert Raw(d.port, source="127.0.0.3").read_registers(D0) == [0]
    assert Raw(d.port, source="127.0.0.4").closed_by_server()


def test_reload_that_drops_a_peer_from_the_allow_list_closes_its_connection(start_plcemud):
    d = start_plcemud(base(", allow: [127.0.0.2, 127.0.0.3]"))
    keep = Raw(d.port, source="127.0.0.2")
    drop = Raw(d.port, source="127.0.0.3")
    assert keep.read_registers(D0) == [0] and drop.read_registers(D0) == [0]
    Path(d.config_path).write_text(base(", allow: [127.0.0.2]"))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    assert drop.closed_by_server()
    assert "no longer in modbus.tcp.allow" in d.log_text()
    assert keep.read_registers(D0) == [0]


# --- modbus.tcp.max_clients


def test_max_clients_refuses_extra_connections_and_keeps_the_others(start_plcemud):
    d = start_plcemud(base(", max_clients: 2"))
    time.sleep(0.2)  # let the fixture's readiness probe go
    a, b = Raw(d.port), Raw(d.port)
    assert a.read_registers(D0) == [0] and b.read_registers(D0) == [0]
    extra = Raw(d.port)
    assert extra.closed_by_server()
    assert "modbus.tcp.max_clients" in d.log_text()
    assert a.read_registers(D0) == [0] and b.read_registers(D0) == [0]
    a.close()
    assert d.wait_log("disconnected (closed by peer)")
    deadline = time.monotonic() + 3
    while True:  # the server notices the close asynchronously
        c = Raw(d.port)
        reply = c.request(struct.pack(">BHH", 3, D0, 1))
        if reply or time.monotonic() > deadline:
            break
        time.sleep(0.05)
    assert reply[:1] == b"\x03"


# --- modbus.tcp.idle_timeout_s


def test_idle_connections_are_closed_busy_ones_kept(start_plcemud):
    d = start_plcemud(base(", idle_timeout_s: 1"))
    idle, busy = Raw(d.port), Raw(d.port)
    assert idle.read_registers(D0) == [0]
    start = time.monotonic()
    closed_at = None
    while time.monotonic() - start < 3.5:
        assert busy.read_registers(D0) == [0]  # activity every 0.2 s keeps it open
        if closed_at is None:
            if idle.closed_by_server(timeout=0.2):
                closed_at = time.monotonic() - start
        else:
            time.sleep(0.2)
    assert closed_at is not None, "the idle connection was never closed"
    assert closed_at >= 0.9  # not before its timeout
    assert "idle timeout" in d.log_text()


# --- modbus.read_only


def test_read_only_refuses_every_write_with_exception_02(start_plcemud):
    d = start_plcemud(base(extra="  read_only: true\ninit: {D10: 10, M20: 1}\n"))
    c = Raw(d.port)
    writes = {
        6: struct.pack(">BHH", 6, D0 + 10, 99),
        16: struct.pack(">BHHBHH", 16, D0 + 10, 2, 4, 1, 2),
        5: struct.pack(">BHH", 5, M0 + 20, 0x0000),
        15: struct.pack(">BHHBB", 15, M0 + 16, 8, 1, 0x00),
        22: struct.pack(">BHHH", 22, D0 + 10, 0x0000, 0x0001),
        23: struct.pack(">BHHHHBH", 23, D0, 1, D0 + 10, 1, 2, 99),
    }
    for fc, pdu in writes.items():
        assert exception_code(c.request(pdu), fc) == 2, f"FC{fc}"
    assert c.read_registers(D0 + 10) == [10]
    coils = c.request(struct.pack(">BHH", 1, M0 + 20, 1))
    assert coils == b"\x01\x01\x01"
    assert c.read_registers(D0, 11)[10] == 10  # reads are fine


# --- modbus.write_protect


def test_write_protect_refuses_writes_touching_protected_ranges(start_plcemud):
    d = start_plcemud(base(extra="  write_protect: [D100-D199, M0-M9]\n"))
    c = Raw(d.port)
    # FC06 inside the range.
    assert exception_code(c.request(struct.pack(">BHH", 6, D0 + 100, 1)), 6) == 2
    assert exception_code(c.request(struct.pack(">BHH", 6, D0 + 199, 1)), 6) == 2
    # FC16 straddling its start: refused as a whole, nothing written.
    pdu = struct.pack(">BHHB4H", 16, D0 + 98, 4, 8, 1, 2, 3, 4)
    assert exception_code(c.request(pdu), 16) == 2
    assert c.read_registers(D0 + 98, 4) == [0, 0, 0, 0]
    # Just outside: allowed.
    assert c.request(struct.pack(">BHH", 6, D0 + 99, 7))[:1] == b"\x06"
    assert c.request(struct.pack(">BHH", 6, D0 + 200, 8))[:1] == b"\x06"
    assert c.read_registers(D0 + 99) == [7] and c.read_registers(D0 + 200) == [8]
    # Coils: M9 refused, M10 allowed, FC15 over M5-M12 refused with nothing written.
    assert exception_code(c.request(struct.pack(">BHH", 5, M0 + 9, 0xFF00)), 5) == 2
    assert c.request(struct.pack(">BHH", 5, M0 + 10, 0xFF00))[:1] == b"\x05"
    assert exception_code(c.request(struct.pack(">BHHBB", 15, M0 + 5, 8, 1, 0xFF)), 15) == 2
    assert c.request(struct.pack(">BHH", 1, M0 + 5, 8)) == b"\x01\x01\x20"  # only M10 set
    # FC22 and FC23 writes are writes too.
    assert exception_code(c.request(struct.pack(">BHHH", 22, D0 + 150, 0, 1)), 22) == 2
    assert exception_code(c.request(struct.pack(">BHHHHBH", 23, D0, 1, D0 + 150, 1, 2, 5)), 23) == 2
    assert c.read_registers(D0 + 150) == [0]


def test_write_protect_out_of_the_plcs_range_is_a_config_error(tmp_path):
    from conftest import run_plcemud

    cfg = tmp_path / "bad.yaml"
    cfg.write_text("profile: fbs\nmodbus:\n  write_protect: [D3990-D4010]\n")
    r = run_plcemud("-c", cfg, "--check-config")
    assert r.returncode == 2
    assert f"{cfg}:3:19:" in r.stderr + r.stdout
