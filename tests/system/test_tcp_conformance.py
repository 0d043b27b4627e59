"""Modbus TCP conformance (docs/profile-fbs.md, "Modbus map"): FC08/00, 11h and 2Bh/0Eh with
pymodbus (and mbpoll where it can: reads, writes, unit IDs), pipelined requests, a request a byte
at a time, bad MBAP headers closing only their own connection, both unknown-unit policies.
"""

import re
import socket
import struct
import subprocess
import time

import pytest
from conftest import BASE_CONFIG, run_plcemud
from pymodbus.diag_message import ReturnBusMessageCountRequest
from pymodbus.mei_message import ReadDeviceInformationRequest
from pymodbus.other_message import ReportSlaveIdRequest
from pymodbus.pdu import ExceptionResponse


def mbap(tid: int, unit: int, pdu: bytes, protocol: int = 0, length: int = None) -> bytes:
    if length is None:
        length = len(pdu) + 1
    return struct.pack(">HHHB", tid, protocol, length, unit) + pdu


def read_pdu(addr, qty, fc=3):
    return struct.pack(">BHH", fc, addr, qty)


def connect(d) -> socket.socket:
    s = socket.create_connection(("127.0.0.1", d.port), timeout=3)
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return s


def recv_exact(s: socket.socket, n: int) -> bytes:
    out = b""
    while len(out) < n:
        chunk = s.recv(n - len(out))
        if not chunk:
            break
        out += chunk
    return out


def recv_adu(s: socket.socket):
    """One reply: (transaction id, unit, PDU)."""
    head = recv_exact(s, 7)
    assert len(head) == 7, f"short MBAP header {head.hex()}"
    tid, proto, length, unit = struct.unpack(">HHHB", head)
    assert proto == 0
    pdu = recv_exact(s, length - 1)
    assert len(pdu) == length - 1
    return tid, unit, pdu


def closed_by_peer(s: socket.socket, timeout: float = 3.0) -> bool:
    s.settimeout(timeout)
    try:
        return s.recv(1) == b""
    except ConnectionResetError:
        return True
    except socket.timeout:
        return False


def no_reply(s: socket.socket, timeout: float = 0.5) -> bool:
    s.settimeout(timeout)
    try:
        data = s.recv(1)
    except socket.timeout:
        return True
    finally:
        s.settimeout(3)
    return False if data else pytest.fail("connection closed instead of staying silent")


def ok(r):
    assert not r.isError(), f"unexpected error reply: {r}"
    return r


def mbpoll_tcp(port, *args, write=()):
    """Runs mbpoll once; values to write come after the host, as mbpoll wants them."""
    cmd = ["mbpoll", "-m", "tcp", "-p", str(port), "-o", "1", *map(str, args), "127.0.0.1",
           *map(str, write)]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=20)


# --------------------------------------------------------------------------- FC08, 11h, 2Bh


def test_fc08_echo_and_other_subfunctions(daemon):
    c = daemon.client()
    r = ok(c.diag_query_data([0x1234, 0xABCD], slave=1))
    assert list(r.message) == [0x1234, 0xABCD]
    s = connect(daemon)
    s.sendall(mbap(1, 1, b"\x08\x00\x00" + bytes(range(40))))
    assert recv_adu(s) == (1, 1, b"\x08\x00\x00" + bytes(range(40)))
    s.sendall(mbap(2, 1, b"\x08\x00\x01\x00\x00"))  # restart communications: not supported
    assert recv_adu(s) == (2, 1, b"\x88\x01")
    r = c.execute(ReturnBusMessageCountRequest(unit=1))  # rc1's helper drops `slave`
    assert isinstance(r, ExceptionResponse) and r.exception_code == 1


def test_fc11_report_slave_id(daemon):
    c = daemon.client()
    for unit in (1, 255):
        r = ok(c.execute(ReportSlaveIdRequest(unit=unit)))
        assert r.identifier[0] == 1, "the slave ID is the station, whatever unit asked"
        assert r.identifier[1] == 0xFF, "run indicator ON"
        assert r.identifier[2:].startswith(b"FATEK FBs-24MC")


def test_fc2b_read_device_identification(daemon):
    c = daemon.client()
    ver = run_plcemud("--version").stdout.split()[-1].encode()
    r = ok(c.execute(ReadDeviceInformationRequest(read_code=1, object_id=0, unit=1)))
    assert r.information == {0: b"FATEK", 1: b"FBs-24MC", 2: ver}
    assert r.conformity & 0x7F == 0x02  # regular identification
    r = ok(c.execute(ReadDeviceInformationRequest(read_code=2, object_id=0, unit=1)))
    assert r.information == {0: b"FATEK", 1: b"FBs-24MC", 2: ver, 5: b"FBs-24MC"}
    r = ok(c.execute(ReadDeviceInformationRequest(read_code=4, object_id=2, unit=1)))
    assert r.information == {2: ver}
    # stream access starting at an object that does not exist restarts at 0
    r = ok(c.execute(ReadDeviceInformationRequest(read_code=1, object_id=0x40, unit=1)))
    assert 0 in r.information
    s = connect(daemon)
    s.sendall(mbap(1, 1, b"\x2b\x0e\x04\x42"))  # individual access to an unknown object: 02
    assert recv_adu(s) == (1, 1, b"\xab\x02")
    s.sendall(mbap(2, 1, b"\x2b\x0e\x00\x00"))  # read code 0: 03
    assert recv_adu(s) == (2, 1, b"\xab\x03")
    s.sendall(mbap(3, 1, b"\x2b\x0d\x00\x00"))  # MEI 0Dh (CANopen): 01
    assert recv_adu(s) == (3, 1, b"\xab\x01")


def test_model_in_identification_follows_config(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "model: FBs-60MC\n")
    r = ok(d.client().execute(ReadDeviceInformationRequest(read_code=1, object_id=0, unit=1)))
    assert r.information[1] == b"FBs-60MC"


def test_mbpoll_tcp_reads_writes_and_units(daemon):
    r = mbpoll_tcp(daemon.port, "-a", 1, "-0", "-r", 6000, "-t", 4, write=(5, 6, 7))
    assert r.returncode == 0 and "Written 3 references" in r.stdout, r.stdout + r.stderr
    for unit in (1, 255):
        r = mbpoll_tcp(daemon.port, "-a", unit, "-0", "-r", 6000, "-c", 3, "-1")
        assert re.findall(r"^\[(\d+)\]:\s+(\d+)", r.stdout, re.M) == [
            ("6000", "5"), ("6001", "6"), ("6002", "7")], r.stdout
    r = mbpoll_tcp(daemon.port, "-a", 7, "-0", "-r", 6000, "-1")
    assert "Target device failed to respond" in r.stdout + r.stderr, r.stdout + r.stderr
    r = mbpoll_tcp(daemon.port, "-a", 1, "-0", "-r", 4500, "-1")
    assert "Illegal data address" in r.stdout + r.stderr, r.stdout + r.stderr


# --------------------------------------------------------------------------- framing


def test_pipelined_requests_answered_in_order(daemon):
    s = connect(daemon)
    s.sendall(mbap(1, 1, struct.pack(">BHH", 6, 40, 111)) + mbap(2, 1, read_pdu(40, 1)) +
              mbap(3, 1, read_pdu(4500, 1)))
    assert recv_adu(s) == (1, 1, struct.pack(">BHH", 6, 40, 111))
    assert recv_adu(s) == (2, 1, b"\x03\x02\x00\x6f")
    assert recv_adu(s) == (3, 1, b"\x83\x02")


def test_many_pipelined_requests_in_one_segment(daemon):
    s = connect(daemon)
    batch = b"".join(mbap(100 + i, 1, struct.pack(">BHH", 6, 50, i)) + mbap(200 + i, 1,
                     read_pdu(50, 1)) for i in range(60))
    s.sendall(batch)
    for i in range(60):
        assert recv_adu(s) == (100 + i, 1, struct.pack(">BHH", 6, 50, i))
        assert recv_adu(s) == (200 + i, 1, struct.pack(">BBH", 3, 2, i))


def test_request_a_byte_at_a_time(daemon):
    s = connect(daemon)
    req = mbap(0x4242, 1, struct.pack(">BHHB2H", 16, 60, 2, 4, 0xBEEF, 0x0102))
    for b in req:
        s.sendall(bytes([b]))
        time.sleep(0.01)
    assert recv_adu(s) == (0x4242, 1, struct.pack(">BHH", 16, 60, 2))
    s.sendall(mbap(0x4243, 1, read_pdu(60, 2)))
    assert recv_adu(s) == (0x4243, 1, b"\x03\x04\xbe\xef\x01\x02")


@pytest.mark.parametrize("header", [
    struct.pack(">HHHB", 1, 1, 6, 1) + read_pdu(0, 1),   # protocol identifier 1
    struct.pack(">HHHB", 1, 0, 1, 1),                     # length 1: no function code
    struct.pack(">HHHB", 1, 0, 255, 1) + read_pdu(0, 1),  # length 255: beyond 254
], ids=["protocol-1", "length-1", "length-255"])
def test_bad_mbap_header_closes_only_that_connection(daemon, header):
    good = connect(daemon)
    good.sendall(mbap(1, 1, read_pdu(4055, 1)))
    assert recv_adu(good) == (1, 1, b"\x03\x02\x00\x01")
    bad = connect(daemon)
    bad.sendall(header)
    assert closed_by_peer(bad), "a bad MBAP header must close the connection"
    good.sendall(mbap(2, 1, read_pdu(4055, 1)))
    assert recv_adu(good) == (2, 1, b"\x03\x02\x00\x01")
    third = connect(daemon)  # the listener is still there
    third.sendall(mbap(3, 1, read_pdu(4055, 1)))
    assert recv_adu(third) == (3, 1, b"\x03\x02\x00\x01")


def test_bad_header_after_good_requests_answers_them_first(daemon):
    s = connect(daemon)
    s.sendall(mbap(1, 1, read_pdu(4055, 1)) + struct.pack(">HHHB", 2, 7, 6, 1) + read_pdu(0, 1))
    assert recv_adu(s) == (1, 1, b"\x03\x02\x00\x01")
    assert closed_by_peer(s)


def test_half_a_request_does_not_delay_others(daemon):
    slow = connect(daemon)
    slow.sendall(mbap(1, 1, read_pdu(0, 10))[:9])  # and then nothing
    fast = connect(daemon)
    for i in range(20):
        fast.sendall(mbap(i, 1, read_pdu(4055, 1)))
        assert recv_adu(fast) == (i, 1, b"\x03\x02\x00\x01")
    slow.sendall(mbap(1, 1, read_pdu(0, 10))[9:])
    tid, unit, pdu = recv_adu(slow)
    assert (tid, unit, pdu[:2]) == (1, 1, b"\x03\x14")


# --------------------------------------------------------------------------- unit IDs


def test_unknown_unit_exception_policy(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "station: 3\n")
    s = connect(d)
    # Unit 0 addresses the device itself over TCP (implementation guide §4.4.1.2).
    for tid, unit in enumerate((3, 255, 0), start=1):
        s.sendall(mbap(tid, unit, read_pdu(4055, 1)))
        assert recv_adu(s) == (tid, unit, b"\x03\x02\x00\x03")
    for tid, unit in enumerate((1, 2, 4, 254), start=10):
        s.sendall(mbap(tid, unit, read_pdu(4055, 1)))
        assert recv_adu(s) == (tid, unit, b"\x83\x0b"), unit
    c = d.client()
    r = c.read_holding_registers(0, 1, slave=9)
    assert isinstance(r, ExceptionResponse) and r.exception_code == 0x0B


def test_unknown_unit_silent_policy(start_plcemud):
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1, unknown_unit: silent}}\n")
    s = connect(d)
    s.sendall(mbap(1, 9, read_pdu(4055, 1)))
    assert no_reply(s), "unknown unit must get no answer"
    s.sendall(mbap(2, 7, b"\x08\x00\x00\x12\x34"))
    assert no_reply(s)
    # the connection stays open and is served for the station and 255
    s.sendall(mbap(3, 1, read_pdu(4055, 1)))
    assert recv_adu(s) == (3, 1, b"\x03\x02\x00\x01")
    s.sendall(mbap(4, 255, read_pdu(4055, 1)))
    assert recv_adu(s) == (4, 255, b"\x03\x02\x00\x01")
    r = mbpoll_tcp(d.port, "-a", 7, "-0", "-r", 6000, "-1")
    assert "timed out" in (r.stdout + r.stderr).lower() or r.returncode != 0
    assert "Gateway" not in r.stdout + r.stderr
