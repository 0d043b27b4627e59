"""docs/profile-fbs.md, "Modbus map", and the issue's point 6: many concurrent clients on one event
loop; a client that sends half a frame and goes silent never delays the others; bad MBAP headers
close only their own connection; a multi-register write is atomic."""

import socket
import struct
import threading

from pymodbus.client import ModbusTcpClient

from conftest import BASE_CONFIG, raw_exchange

CLIENTS = 40
ROUNDS = 25


def test_forty_concurrent_clients_keep_their_own_values(start_plcemud):
    d = start_plcemud(BASE_CONFIG)
    errors = []
    barrier = threading.Barrier(CLIENTS)

    def worker(i):
        c = ModbusTcpClient("127.0.0.1", port=d.port, timeout=5, retries=0)
        try:
            assert c.connect(), f"client {i} cannot connect"
            barrier.wait(timeout=30)  # all 40 connected at once
            base = 6000 + 50 * i  # D(50i)..D(50i+9), nobody else's
            coil = 6000 + 10 * i  # S(10i)..
            for k in range(ROUNDS):
                values = [(i << 8 | k) + j for j in range(10)]
                r = c.write_registers(base, values, slave=1)
                assert not r.isError(), f"client {i} write: {r}"
                r = c.read_holding_registers(base, 10, slave=1)
                assert not r.isError(), f"client {i} read: {r}"
                assert r.registers == values, f"client {i} round {k}: {r.registers} != {values}"
                bits = [bool((k >> j) & 1) for j in range(8)]
                assert not c.write_coils(coil, bits, slave=1).isError()
                assert c.read_coils(coil, 8, slave=1).bits[:8] == bits, f"client {i} coils"
        except Exception as e:  # noqa: BLE001 - reported below with the client number
            errors.append(f"client {i}: {e!r}")
        finally:
            c.close()

    threads = [threading.Thread(target=worker, args=(i,)) for i in range(CLIENTS)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not any(t.is_alive() for t in threads), "clients hung"
    assert errors == []
    # Every client's final values are still there (nobody wrote over another).
    c = d.client()
    for i in range(CLIENTS):
        k = ROUNDS - 1
        assert c.read_holding_registers(6000 + 50 * i, 10, slave=1).registers == [
            (i << 8 | k) + j for j in range(10)
        ]
    assert d.log_text().count(" connected") >= CLIENTS + 1


def connected(sock) -> bool:
    """True while the server has not closed the socket (no data pending either)."""
    sock.setblocking(False)
    try:
        data = sock.recv(1, socket.MSG_PEEK)
        return data != b""
    except BlockingIOError:
        return True
    except ConnectionError:
        return False
    finally:
        sock.setblocking(True)


def test_stalled_half_frame_does_not_delay_a_busy_client(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "init: {D0: 77}\n")
    request = struct.pack(">HHHB", 0x0101, 0, 6, 1) + struct.pack(">BHH", 3, 6000, 1)
    stalled = []
    for cut in (3, 8):  # half an MBAP header; a header and half a PDU
        s = socket.create_connection(("127.0.0.1", d.port), timeout=5)
        s.sendall(request[:cut])
        stalled.append((s, cut))

    busy = d.client(timeout=2, retries=0)  # a request that waits 2 s fails the test
    n = 500
    for k in range(n):
        r = busy.write_register(6001, k, slave=1)
        assert not r.isError(), f"request {k}: {r}"
        r = busy.read_holding_registers(6000, 2, slave=1)
        assert not r.isError() and r.registers == [77, k], f"request {k}: {r}"
        if k % 100 == 0:
            assert all(connected(s) for s, _ in stalled)
    assert all(connected(s) for s, _ in stalled), "a stalled client was dropped"

    # The stalled clients finish their frames later and get their answers.
    for s, cut in stalled:
        s.sendall(request[cut:])
        header = s.recv(7)
        assert header[:2] == b"\x01\x01"
        assert s.recv(64) == bytes([3, 2, 0, 77])
        s.close()


def test_bad_mbap_header_closes_only_that_connection(start_plcemud):
    d = start_plcemud(BASE_CONFIG)
    good = d.client()
    pdu = struct.pack(">BHH", 3, 0, 1)
    bad_frames = [
        struct.pack(">HHHB", 1, 1, 6, 1) + pdu,  # protocol identifier 1
        struct.pack(">HHHB", 1, 0, 1, 1),  # length 1
        struct.pack(">HHHB", 1, 0, 255, 1) + pdu,  # length 255
        struct.pack(">HHHB", 1, 0xFFFF, 0xFFFF, 1) + pdu,
    ]
    for frame in bad_frames:
        with socket.create_connection(("127.0.0.1", d.port), timeout=5) as s:
            s.sendall(frame)
            assert s.recv(64) == b"", f"connection kept after {frame.hex()}"
        assert not good.read_holding_registers(0, 1, slave=1).isError()
    assert "bad MBAP header" in d.log_text()


def test_pipelined_requests_are_all_answered_in_order(start_plcemud):
    d = start_plcemud(BASE_CONFIG)
    with socket.create_connection(("127.0.0.1", d.port), timeout=5) as s:
        frames = b"".join(
            struct.pack(">HHHB", tid, 0, 6, 1) + struct.pack(">BHH", 6, 6100, tid)
            for tid in range(1, 201)
        )
        s.sendall(frames)
        buf = b""
        while len(buf) < 200 * 12:
            chunk = s.recv(65536)
            assert chunk, "closed"
            buf += chunk
        for k in range(200):
            tid, proto, length, unit, fc, addr, value = struct.unpack(
                ">HHHBBHH", buf[12 * k : 12 * (k + 1)]
            )
            assert (tid, proto, length, unit, fc, addr, value) == (k + 1, 0, 6, 1, 6, 6100, k + 1)
        assert raw_exchange(s, struct.pack(">BHH", 3, 6100, 1), tid=999) == bytes([3, 2, 0, 200])


def test_multi_register_write_is_atomic(start_plcemud):
    """docs/profile-fbs.md, Modbus map: a multi-register write lands as a whole; a reader never
    sees half of one."""
    d = start_plcemud(BASE_CONFIG)
    stop = threading.Event()
    torn = []

    def reader():
        c = ModbusTcpClient("127.0.0.1", port=d.port, timeout=5, retries=0)
        c.connect()
        try:
            while not stop.is_set():
                r = c.read_holding_registers(6200, 120, slave=1)
                if r.isError() or len(set(r.registers)) != 1:
                    torn.append(r)
        finally:
            c.close()

    readers = [threading.Thread(target=reader) for _ in range(3)]
    for t in readers:
        t.start()
    w = d.client()
    try:
        for k in range(1, 300):
            assert not w.write_registers(6200, [k] * 120, slave=1).isError()
    finally:
        stop.set()
        for t in readers:
            t.join(timeout=30)
    assert torn == []
