"""Communication faults (docs/communication-faults.md) seen from the client side: delays, drops,
exceptions, offline, refused connections, disconnects, garbled serial frames, STOP, their
scope, the config's refusals and the log, over Modbus TCP, Modbus RTU (a socat pty pair) and
the FATEK protocol.

The faults are switched through all three paths the daemon has: the config's `faults:`
section, the simulator-control unit's holding registers 20-40 (unit 247; FC16 for the block,
FC06 for one register) and the REST API (`PUT`/`DELETE /api/v1/plcs/{plc}/comm-faults`).
Clients are pymodbus, mbpoll, and raw sockets / the raw pty where timing or bytes matter.
"""

import http.client
import json
import os
import re
import select
import socket
import struct
import subprocess
import threading
import time
import tty

import pytest
from conftest import BASE_CONFIG, Daemon, free_port, port_open, run_plcemud
from plcemu_testing.fatek import Fatek
from plcemu_testing.fatek import frame as fatek_frame
from plcemu_testing.fatek import parse as fatek_parse
from pymodbus.client import ModbusSerialClient
from pymodbus.pdu import ExceptionResponse
from rtu_pty import RawLine, crc16, rtu_config
from rtu_pty import frame as rtu_frame

SIM = 247  # the simulator-control unit
NO_REPLY_S = 0.3  # how long "no answer" waits, as a master's timeout would
DELAY_TOLERANCE_S = 0.020

# fbs map (docs/profile-fbs.md): holding register n is Rn, coil n is Yn, coil 2000+n is Mn.
M1926_COIL = 2000 + 1926  # RUN relay
Y0_COIL = 0

# The simulator unit's block (docs/communication-faults.md, "On the simulator-control unit").
BLOCK_FIRST = 20
BLOCK_FIELDS = ["delay_min_ms", "delay_max_ms", "drop_every", "drop_probability", "seed",
                "exception", "offline", "refuse_connections", "disconnect", "disconnect_after",
                "garble", "stop", "unit", "function", "from_1", "from_2", "from_3", "from_4",
                "count"]
REG = {name: BLOCK_FIRST + i for i, name in enumerate(BLOCK_FIELDS)}
REG_CLEAR = 39
REG_STATUS = 40
GARBLE = {"none": 0, "crc": 1, "short": 2, "gap": 3}


def read_pdu(addr, qty=1, fc=3):
    return struct.pack(">BHH", fc, addr, qty)


def fc06_pdu(addr, value):
    return struct.pack(">BHH", 6, addr, value)


def words_reply(*values):
    return bytes([3, 2 * len(values)]) + struct.pack(f">{len(values)}H", *values)


def exception_code(r) -> int:
    assert isinstance(r, ExceptionResponse), f"expected an exception reply, got {r}"
    return r.exception_code


def ok(r):
    assert not r.isError(), f"unexpected error reply: {r}"
    return r


# --------------------------------------------------------------------------- raw Modbus TCP

CLOSED = "closed"


class Conn:
    """One raw Modbus TCP connection: ask() returns the reply PDU, None when nothing came within
    the timeout, or CLOSED when the server closed the connection (FIN)."""

    def __init__(self, port, timeout=NO_REPLY_S):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=3)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.timeout = timeout
        self.tid = 0
        self.last_s = None  # seconds between the request and its whole reply

    def close(self):
        self.sock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _recv_exact(self, n, deadline):
        data = b""
        while len(data) < n:
            left = deadline - time.monotonic()
            if left <= 0:
                raise socket.timeout()
            self.sock.settimeout(left)
            chunk = self.sock.recv(n - len(data))
            if not chunk:
                return None
            data += chunk
        return data

    def ask(self, pdu, unit=1, timeout=None):
        self.tid = (self.tid + 1) & 0xFFFF
        tid = self.tid
        t0 = time.monotonic()
        self.sock.sendall(struct.pack(">HHHB", tid, 0, len(pdu) + 1, unit) + bytes(pdu))
        deadline = t0 + (self.timeout if timeout is None else timeout)
        try:
            header = self._recv_exact(7, deadline)
            if header is None:
                return CLOSED
            rtid, proto, length, runit = struct.unpack(">HHHB", header)
            assert (rtid, proto, runit) == (tid, 0, unit), f"bad MBAP reply {header.hex()}"
            body = self._recv_exact(length - 1, deadline)
            if body is None:
                return CLOSED
        except socket.timeout:
            return None
        self.last_s = time.monotonic() - t0
        return body

    def timed(self, pdu, unit=1, timeout=2.0):
        """(reply, seconds) of one request that must be answered."""
        r = self.ask(pdu, unit, timeout)
        assert r not in (None, CLOSED), f"no reply to {pdu.hex()} ({r})"
        return r, self.last_s

    def eof_within(self, timeout):
        """'eof' when the server closes within `timeout`, 'open' when nothing comes; data or a
        reset raise."""
        self.sock.settimeout(timeout)
        try:
            data = self.sock.recv(1)
        except socket.timeout:
            return "open"
        assert data == b"", f"unexpected data {data!r}"
        return "eof"


def read_r(port, addr, unit=1):
    with Conn(port, timeout=2.0) as c:
        r = c.ask(read_pdu(addr), unit)
    assert r is not None and r != CLOSED and r[0] == 3, r
    return struct.unpack(">H", r[2:4])[0]


# --------------------------------------------------------------------------- simulator unit


def from_words(name):
    raw = name.encode("ascii").ljust(8, b"\0")
    return list(struct.unpack(">4H", raw))


def block(**fields):
    """The 19 registers 20-38 for `fields` (names of BLOCK_FIELDS, or `from` as a device)."""
    values = dict.fromkeys(BLOCK_FIELDS, 0)
    name = fields.pop("from", None)
    if name is not None:
        for i, w in enumerate(from_words(name)):
            values[f"from_{i + 1}"] = w
    for k, v in fields.items():
        assert k in values, k
        values[k] = v
    return [values[k] for k in BLOCK_FIELDS]


class Sim:
    """The simulator-control unit through a pymodbus TCP client of its own."""

    def __init__(self, d: Daemon, port=None, unit=SIM):
        saved = d.port
        if port is not None:
            d.port = port
        self.c = d.client(timeout=2, retries=0)
        d.port = saved
        self.unit = unit

    def switch(self, **fields):
        """Writes the whole block in one FC16 request (replaces whatever was on)."""
        ok(self.c.write_registers(BLOCK_FIRST, block(**fields), slave=self.unit))
        assert self.status() & 2 == 0, f"the block write {fields} was refused"

    def write(self, field, value):
        """One register (FC06)."""
        addr = REG_CLEAR if field == "clear" else REG[field]
        ok(self.c.write_register(addr, value, slave=self.unit))

    def clear(self):
        self.write("clear", 1)

    def status(self):
        return ok(self.c.read_holding_registers(REG_STATUS, 1, slave=self.unit)).registers[0]


# --------------------------------------------------------------------------- REST API


def api(hp, method, path, body=None):
    conn = http.client.HTTPConnection("127.0.0.1", hp, timeout=3)
    headers = {}
    data = None
    if body is not None:
        data = json.dumps(body)
        headers["Content-Type"] = "application/json"
    try:
        conn.request(method, path, body=data, headers=headers)
        r = conn.getresponse()
        text = r.read()
    finally:
        conn.close()
    return r.status, (json.loads(text) if text else None)


def put_faults(hp, plc="0", **fields):
    status, j = api(hp, "PUT", f"/api/v1/plcs/{plc}/comm-faults", fields)
    assert status == 200, (status, j)
    assert j["active"] is True, j
    return j


def delete_faults(hp, plc="0"):
    status, j = api(hp, "DELETE", f"/api/v1/plcs/{plc}/comm-faults")
    assert status == 200, (status, j)
    assert j["active"] is False, j
    return j


def scans(hp):
    status, j = api(hp, "GET", "/api/v1/plcs/0")
    assert status == 200, (status, j)
    return j["scans"]


def with_http(extra=""):
    """(config, http port): BASE_CONFIG with the console on 127.0.0.1 and `extra`."""
    hp = free_port()
    return BASE_CONFIG + f"http: {{bind: 127.0.0.1, port: {hp}}}\n" + extra, hp


def start_with_http(start_plcemud, extra=""):
    text, hp = with_http(extra)
    d = start_plcemud(text)
    deadline = time.monotonic() + 5
    while not port_open(hp):
        assert time.monotonic() < deadline, d.log_text()
        time.sleep(0.02)
    return d, hp


# --------------------------------------------------------------------------- RTU over a pty


@pytest.fixture
def line(pty):
    raw = RawLine(pty.master)
    yield raw
    raw.close()


def start_rtu(start_plcemud, pty, extra=""):
    d = start_plcemud(rtu_config(pty.slave, "", extra))
    assert d.wait_log("listening on rtu"), d.log_text()
    return d


def rtu_timed(line, unit, pdu, reply_len, timeout=1.0):
    """(reply bytes, seconds from the end of the request's write to the reply's last byte)."""
    line.send(rtu_frame(unit, pdu))
    t0 = time.monotonic()
    r = line.receive(reply_len, timeout)
    return r, time.monotonic() - t0


def rtu_chunks(line, expected, timeout=1.0):
    """The reply's bytes as they came: [(monotonic time, bytes), ...]."""
    out = []
    total = 0
    deadline = time.monotonic() + timeout
    while total < expected:
        left = deadline - time.monotonic()
        if left <= 0:
            break
        ready, _, _ = select.select([line.fd], [], [], left)
        if not ready:
            break
        chunk = os.read(line.fd, 1024)
        out.append((time.monotonic(), chunk))
        total += len(chunk)
    return out


def good_rtu(unit, pdu):
    return rtu_frame(unit, pdu)


# =========================================================================== delay


def test_fixed_delay_over_tcp_from_the_simulator_unit(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "init: {R0: 4242}\n")
    sim = Sim(d)
    with Conn(d.port) as c:
        _, before = c.timed(read_pdu(0))
        assert before < 0.05, before
        # comm.delay_max_ms below comm.delay_min_ms: the delay is fixed at the lower bound.
        sim.switch(delay_min_ms=200, delay_max_ms=0)
        assert sim.status() & 1 == 1
        for _ in range(3):
            r, s = c.timed(read_pdu(0))
            assert r == words_reply(4242)
            assert abs(s - 0.200) <= DELAY_TOLERANCE_S, f"reply after {s * 1000:.1f} ms"
        sim.clear()
        assert sim.status() & 1 == 0
        _, after = c.timed(read_pdu(0))
        assert after < 0.05, after


def test_fixed_delay_over_rtu_from_the_config(start_plcemud, pty, line):
    d = start_rtu(start_plcemud, pty, "faults: {delay_ms: 150}\ninit: {R0: 7}\n")
    good = good_rtu(1, words_reply(7))
    samples = []
    for _ in range(3):
        r, s = rtu_timed(line, 1, read_pdu(0), len(good))
        assert r == good, r.hex()
        samples.append(s)
    Sim(d).clear()  # the simulator unit, over TCP
    base = []
    for _ in range(3):
        r, s = rtu_timed(line, 1, read_pdu(0), len(good))
        assert r == good, r.hex()
        base.append(s)
    baseline = min(base)
    assert baseline < 0.05, base
    for s in samples:
        # The delay adds to what the line takes anyway (the end-of-frame silence t3.5).
        assert abs(s - baseline - 0.150) <= DELAY_TOLERANCE_S, (samples, base)


def measure_delays(port, n):
    out = []
    with Conn(port) as c:
        for _ in range(n):
            _, s = c.timed(read_pdu(0))
            out.append(s)
    return out


def test_random_delay_with_a_seed_repeats_after_switching_again(start_plcemud):
    d, hp = start_with_http(start_plcemud)
    j = put_faults(hp, delay_ms=[100, 300], seed=7)
    assert j["delay_ms"] == [100, 300] and j["seed"] == 7, j
    first = measure_delays(d.port, 5)
    delete_faults(hp)
    assert measure_delays(d.port, 1)[0] < 0.05
    put_faults(hp, delay_ms=[100, 300], seed=7)
    second = measure_delays(d.port, 5)
    for s in first + second:
        assert 0.100 - DELAY_TOLERANCE_S / 4 <= s <= 0.300 + DELAY_TOLERANCE_S, (first, second)
    # Uniform in [100, 300]: five draws are not one value.
    assert max(first) - min(first) > 0.030, first
    for a, b in zip(first, second):
        assert abs(a - b) <= DELAY_TOLERANCE_S, (first, second)
    status, j = api(hp, "GET", "/api/v1/plcs/0/comm-faults")
    assert status == 200 and j["figures"]["delayed"] >= 5, j
    delete_faults(hp)


def test_a_delay_holds_only_its_own_clients_replies(start_plcemud):
    d, hp = start_with_http(start_plcemud, "init: {R100: 100}\n")
    put_faults(hp, delay_ms=300, **{"from": "R100", "count": 10})
    a = d.client(timeout=3, retries=0)
    stop = threading.Event()
    a_times = []
    a_errors = []

    def poll_a():
        while not stop.is_set():
            t0 = time.monotonic()
            r = a.read_holding_registers(100, 1, slave=1)
            if r.isError() or r.registers != [100]:
                a_errors.append(r)
            a_times.append(time.monotonic() - t0)

    t = threading.Thread(target=poll_a)
    t.start()
    windows = []  # B's latencies, 200 requests per window
    try:
        time.sleep(0.05)  # A's first request is being held
        # B on a raw socket: pymodbus' own overhead would blur a 5 ms bound. A window of 200
        # requests is measured again (at most three times) when a busy host blurs its tail;
        # a B held behind A's delay would take 300 ms in every window.
        with Conn(d.port) as b:
            for _ in range(3):
                times = []
                for _ in range(200):
                    r, s = b.timed(read_pdu(0))
                    assert r == words_reply(0), r
                    times.append(s)
                    time.sleep(0.004)
                times.sort()
                windows.append(times)
                if times[int(len(times) * 0.99) - 1] < 0.005:
                    break
    finally:
        stop.set()
        t.join(5)
    p99s = [w[int(len(w) * 0.99) - 1] for w in windows]
    assert min(p99s) < 0.005, f"B's p99 per window: {[round(p * 1000, 2) for p in p99s]} ms"
    slowest = max(w[-1] for w in windows)
    assert slowest < 0.150, f"a reply to B took {slowest * 1000:.1f} ms"
    # A was held the whole time, 300 ms per request.
    assert not a_errors, a_errors
    assert len(a_times) >= 3, a_times
    for s in a_times:
        assert abs(s - 0.300) <= DELAY_TOLERANCE_S + 0.01, a_times


def test_a_client_leaving_while_its_answer_is_held_gives_its_place_to_the_next(start_plcemud):
    """A delay holds an answer, not the connection. A client that sends its end meanwhile may
    have left, or only half-closed and still wait for its answers: it gets them, then the
    connection closes; but a new client that finds the listener full takes its place at once
    (the fault still on). A client that stays gets the requests it sent behind the held one
    answered in order after it."""
    text, hp = with_http("init: {R0: 7, R1: 8}\n")
    d = start_plcemud(text.replace("bind: 127.0.0.1}", "bind: 127.0.0.1, max_clients: 2}", 1))
    deadline = time.monotonic() + 5
    while not port_open(hp):
        assert time.monotonic() < deadline, d.log_text()
        time.sleep(0.02)

    def mbap(tid):
        return struct.pack(">HHHB", tid, 0, 6, 1) + read_pdu(tid - 1)

    # Half-closed: both answers, after the delay, then the end.
    put_faults(hp, delay_ms=300)
    with Conn(d.port, timeout=3) as c:
        c.sock.sendall(mbap(1) + mbap(2))
        c.sock.shutdown(socket.SHUT_WR)
        t0 = time.monotonic()
        for tid, value in ((1, 7), (2, 8)):
            header = c._recv_exact(7, t0 + 3)
            assert header is not None and struct.unpack(">HHHB", header)[0] == tid, header
            assert c._recv_exact(4, t0 + 3) == words_reply(value)
            assert time.monotonic() - t0 >= 0.3 * tid - DELAY_TOLERANCE_S, tid
        assert c.eof_within(1.0) == "eof"
    # Gone: two clients under a five-second delay leave; two new ones are served at once.
    put_faults(hp, delay_ms=5000)
    for tid in (1, 2):
        with socket.create_connection(("127.0.0.1", d.port), timeout=3) as s:
            s.sendall(mbap(tid))
            time.sleep(0.1)  # read, and held
    put_faults(hp, delay_ms=300)
    with Conn(d.port, timeout=3) as c, Conn(d.port, timeout=3) as other:
        c.sock.sendall(mbap(1) + mbap(2))
        t0 = time.monotonic()
        for tid, value in ((1, 7), (2, 8)):
            header = c._recv_exact(7, t0 + 3)
            assert header is not None and struct.unpack(">HHHB", header)[0] == tid, header
            assert c._recv_exact(4, t0 + 3) == words_reply(value)
        assert other.ask(read_pdu(1)) == words_reply(8)
    assert d.log_text().count("evicted for a new client: it left while its answer was held") \
        == 2, d.log_text()


def test_requests_sent_behind_a_held_answer_are_cut_where_they_end(start_plcemud):
    """What a client sends while its answer is held is read then, and served after it, cut
    where each request ends: requests of different lengths, some sent before the held answer
    has gone and some after, each get their own answer (a read still under way when the held
    answer left once wrote into bytes that had moved, and the stream came apart)."""
    d, hp = start_with_http(start_plcemud)
    put_faults(hp, delay_ms=300, **{"from": "R10", "count": 1})

    def frame(tid, pdu):
        return struct.pack(">HHHB", tid, 0, len(pdu) + 1, 1) + pdu

    with Conn(d.port, timeout=3) as c:
        c.sock.sendall(frame(1, fc06_pdu(10, 1)))  # held
        time.sleep(0.1)
        c.sock.sendall(frame(2, read_pdu(20)))  # behind it
        fc16 = struct.pack(">BHHB3H", 0x10, 30, 3, 6, 5, 6, 7)
        t0 = time.monotonic()
        replies = []
        for tid, pdu in ((3, fc16), (4, read_pdu(30, 3)), (5, read_pdu(20))):
            time.sleep(0.25 if tid == 3 else 0.01)  # the 16 once the held answer is out
            c.sock.sendall(frame(tid, pdu))
        while len(replies) < 5:
            header = c._recv_exact(7, t0 + 3)
            assert header is not None, replies
            tid, _, length, _ = struct.unpack(">HHHB", header)
            replies.append((tid, c._recv_exact(length - 1, t0 + 3)))
    assert replies == [(1, fc06_pdu(10, 1)), (2, words_reply(0)),
                       (3, struct.pack(">BHH", 0x10, 30, 3)), (4, words_reply(5, 6, 7)),
                       (5, words_reply(0))], replies


def test_pipelines_under_delays_switched_on_and_off_get_every_answer_in_order(start_plcemud):
    """A delay switched on and off every few milliseconds while clients pipeline reads in
    pieces: every request is answered once, in order. (A read behind a held answer could end
    just after the hold did and serve a frame held in turn while the hold's end had already
    asked for a serve: that serve answered frames behind the new hold and replaced its answer,
    which was never sent.)"""
    import random
    d, hp = start_with_http(start_plcemud)
    stop = threading.Event()
    failures = []

    def toggle():
        rnd = random.Random(7)
        while not stop.is_set():
            if rnd.random() < 0.5:
                put_faults(hp, delay_ms=rnd.randrange(1, 10),
                           **({"from": "R10", "count": rnd.randrange(1, 5)}
                              if rnd.random() < 0.5 else {}))
            else:
                delete_faults(hp)
            time.sleep(rnd.choice([0, 0.001, 0.005]))

    def pipeline(k):
        rnd = random.Random(k)
        while not stop.is_set():
            n = rnd.choice([5, 50, 200, 600])
            stream = b"".join(struct.pack(">HHHB", t, 0, 6, 1) +
                              read_pdu(10 + rnd.randrange(0, 4), rnd.randrange(1, 30))
                              for t in range(1, n + 1))
            with Conn(d.port, timeout=3) as c:
                step = rnd.choice([12, 100, 600, 5000])
                for i in range(0, len(stream), step):
                    c.sock.sendall(stream[i:i + step])
                got = []
                deadline = time.monotonic() + 0.03 * n + 5
                try:
                    while len(got) < n:
                        header = c._recv_exact(6, deadline)
                        if header is None:
                            break
                        tid, _, length = struct.unpack(">HHH", header)
                        if c._recv_exact(length, deadline) is None:
                            break
                        got.append(tid)
                except socket.timeout:
                    pass
            if got != list(range(1, n + 1)):
                failures.append((k, n, [t for t in range(1, n + 1) if t not in got][:5]))

    threads = [threading.Thread(target=toggle)] + [
        threading.Thread(target=pipeline, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    try:
        time.sleep(6)
    finally:
        stop.set()
        for t in threads:
            t.join(30)
    assert not failures, failures


# =========================================================================== drop


def test_drop_every_second_request_over_tcp(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "init: {R50: 1}\n")
    sim = Sim(d)
    with Conn(d.port) as c:
        sim.switch(drop_every=2)
        got = [c.ask(read_pdu(50)) for _ in range(4)]
        assert got == [words_reply(1), None, words_reply(1), None], got
        # A dropped request is served; its answer is lost: the 6th, a write, lands unanswered.
        assert c.ask(fc06_pdu(50, 2)) == fc06_pdu(50, 2)  # the 5th, answered
        assert c.ask(fc06_pdu(50, 3)) is None  # the 6th, dropped
        assert c.ask(read_pdu(50)) == words_reply(3)  # the 7th
        sim.clear()
        assert [c.ask(read_pdu(50)) for _ in range(3)] == [words_reply(3)] * 3


def test_drop_every_second_request_over_rtu(start_plcemud, pty, line):
    d = start_rtu(start_plcemud, pty, "faults: {drop_every: 2}\ninit: {R0: 9}\n")
    good = good_rtu(1, words_reply(9))
    got = []
    for _ in range(6):
        line.send(rtu_frame(1, read_pdu(0)))
        got.append(line.receive(len(good), NO_REPLY_S))
    assert got == [good, b"", good, b"", good, b""], [g.hex() for g in got]
    Sim(d).clear()
    for _ in range(3):
        assert line.request(1, read_pdu(0), len(good)) == words_reply(9)


def drop_pattern(port, n=16):
    with Conn(port, timeout=0.1) as c:
        return "".join("." if c.ask(read_pdu(0)) is not None else "x" for _ in range(n))


def test_drop_probability_with_a_seed_is_reproducible(start_plcemud):
    d = start_plcemud(BASE_CONFIG)
    sim = Sim(d)
    sim.switch(drop_probability=5000, seed=42)  # 0.5
    first = drop_pattern(d.port)
    sim.clear()
    assert drop_pattern(d.port, 4) == "...."
    sim.switch(drop_probability=5000, seed=42)
    second = drop_pattern(d.port)
    assert first == second, (first, second)
    assert 0 < first.count("x") < len(first), first
    sim.clear()


# =========================================================================== exception


@pytest.mark.parametrize("code,path", [(4, "config"), (6, "simulator-unit"), (0x0B, "rest")])
def test_exception_code_and_nothing_written(start_plcemud, code, path):
    extra = "init: {R30: [1234, 5678]}\n"
    if path == "config":
        extra += f"faults: {{exception: {code}}}\n"
    d, hp = start_with_http(start_plcemud, extra)
    if path == "simulator-unit":
        Sim(d).write("exception", code)  # FC06: one register of the block
    elif path == "rest":
        put_faults(hp, exception=code)
    c = d.client(timeout=2, retries=0)
    assert exception_code(c.read_holding_registers(30, 1, slave=1)) == code
    assert exception_code(c.write_register(30, 999, slave=1)) == code
    assert exception_code(c.write_registers(30, [1, 2], slave=1)) == code
    assert exception_code(c.read_coils(0, 8, slave=1)) == code
    # mbpoll (libmodbus) sees the same exception.
    r = subprocess.run(["mbpoll", "-m", "tcp", "-p", str(d.port), "-a", "1", "-r", "31", "-c",
                        "1", "-1", "-t", "4", "-o", "1", "127.0.0.1"],
                       capture_output=True, text=True, timeout=10)
    text = (r.stdout + r.stderr).lower()
    want = {4: "failure", 6: "busy", 0x0B: "target"}[code]
    assert want in text, text
    assert "[31]:" not in text, text
    delete_faults(hp)
    assert ok(c.read_holding_registers(30, 2, slave=1)).registers == [1234, 5678]


# =========================================================================== offline


def test_offline_keeps_tcp_open_and_silent_and_the_simulator_unit_answers(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "init: {R0: 11}\n")
    with Conn(d.port) as c:
        assert c.ask(read_pdu(0)) == words_reply(11)
        # The fault switched on the same connection, through the simulator unit (FC06).
        assert c.ask(fc06_pdu(REG["offline"], 1), unit=SIM) == fc06_pdu(REG["offline"], 1)
        assert c.ask(read_pdu(0)) is None
        assert c.ask(fc06_pdu(0, 99)) is None  # nothing served either
        assert c.ask(read_pdu(0), unit=255) is None
        # The simulator unit keeps answering, on this connection and on another.
        assert c.ask(read_pdu(REG_STATUS), unit=SIM) == words_reply(1)
        assert Sim(d).status() & 1 == 1
        assert c.eof_within(0.1) == "open"
        assert c.ask(fc06_pdu(REG_CLEAR, 1), unit=SIM) == fc06_pdu(REG_CLEAR, 1)
        assert c.ask(read_pdu(0)) == words_reply(11)  # the write while offline never landed


def test_offline_rtu_is_silent_then_back(start_plcemud, pty):
    d = start_rtu(start_plcemud, pty, "faults: {offline: true}\ninit: {R0: 5}\n")
    # (pymodbus 3.0.0rc1's serial client needs a timeout of 1 s: shorter ones miss replies.)
    c = ModbusSerialClient(pty.master, baudrate=9600, bytesize=8, parity="N", stopbits=1,
                           timeout=1, retries=0)
    assert c.connect()
    try:
        assert c.read_holding_registers(0, 1, slave=1).isError()  # no answer
        # The simulator unit answers on the line meanwhile.
        assert ok(c.read_holding_registers(REG_STATUS, 1, slave=SIM)).registers[0] & 1 == 1
        Sim(d).clear()
        assert ok(c.read_holding_registers(0, 1, slave=1)).registers == [5]
    finally:
        c.close()


def test_offline_rtu_raw_line_is_silent(start_plcemud, pty, line):
    d = start_rtu(start_plcemud, pty, "init: {R0: 5}\n")
    sim = Sim(d)
    sim.switch(offline=1)
    line.send(rtu_frame(1, read_pdu(0)))
    assert line.silent(NO_REPLY_S)
    line.send(rtu_frame(0, fc06_pdu(0, 77)))  # a broadcast is not served
    time.sleep(0.05)
    sim.clear()
    assert line.request(1, read_pdu(0), 7) == words_reply(5)


def test_refuse_connections_with_offline(start_plcemud):
    d, hp = start_with_http(start_plcemud, "init: {R0: 3}\n")
    with Conn(d.port) as old:
        assert old.ask(read_pdu(0)) == words_reply(3)
        put_faults(hp, offline=True, refuse_connections=True)
        refused = 0
        deadline = time.monotonic() + 0.5
        while refused < 3:
            assert time.monotonic() < deadline, "connections were not refused"
            try:
                socket.create_connection(("127.0.0.1", d.port), timeout=0.5).close()
                refused = 0
            except ConnectionResetError:
                # Queued for accept when the listener closed: the switch is under way.
                refused = 0
            except ConnectionRefusedError:
                refused += 1
            time.sleep(0.01)
        assert old.ask(read_pdu(0)) is None  # open and silent
        assert old.eof_within(0.05) == "open"
        status, j = api(hp, "GET", "/api/v1/plcs/0/comm-faults")
        assert status == 200 and j["figures"]["silenced"] >= 1, j
        delete_faults(hp)
        t0 = time.monotonic()
        while True:
            try:
                s = socket.create_connection(("127.0.0.1", d.port), timeout=0.5)
                break
            except ConnectionRefusedError:
                assert time.monotonic() - t0 < 1.0, "still refused 1 s after clearing"
                time.sleep(0.005)
        s.close()
        assert read_r(d.port, 0) == 3
        assert old.ask(read_pdu(0)) == words_reply(3)


# =========================================================================== disconnect


def test_disconnect_after_3_closes_with_fin(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "init: {R0: 8}\n")
    sim = Sim(d)
    sim.switch(disconnect=1, disconnect_after=3)
    for _ in range(2):  # every connection gets its three answers
        with Conn(d.port) as c:
            for _ in range(3):
                assert c.ask(read_pdu(0)) == words_reply(8)
            assert c.eof_within(0.5) == "eof"
    sim.clear()
    with Conn(d.port) as c:
        for _ in range(5):
            assert c.ask(read_pdu(0)) == words_reply(8)
        assert c.eof_within(0.1) == "open"


def test_disconnect_after_3_with_reset_from_the_config(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "faults: {disconnect_after: 3, reset: true}\n"
                      "init: {R0: 8}\n")
    with Conn(d.port) as c:
        for _ in range(3):
            assert c.ask(read_pdu(0)) == words_reply(8)
        c.sock.settimeout(0.5)
        with pytest.raises(ConnectionResetError):
            c.sock.recv(1)
    # pymodbus sees its connection go after three answers as well.
    cl = d.client(timeout=1, retries=0)  # (pymodbus 3.0.0rc1 truncates timeouts to int)
    for _ in range(3):
        assert ok(cl.read_holding_registers(0, 1, slave=1)).registers == [8]
    assert cl.read_holding_registers(0, 1, slave=1).isError()


def test_disconnect_after_0_closes_at_the_next_request(start_plcemud):
    d, hp = start_with_http(start_plcemud, "init: {R0: 8}\n")
    with Conn(d.port) as a, Conn(d.port) as b:
        assert a.ask(read_pdu(0)) == words_reply(8)
        assert b.ask(read_pdu(0)) == words_reply(8)
        put_faults(hp, disconnect_after=0)
        # Not at the instant the fault is switched on: both stay open while they ask nothing.
        assert a.eof_within(0.1) == "open"
        assert b.eof_within(0.01) == "open"
        assert a.ask(read_pdu(0), timeout=1.0) == CLOSED  # no answer, FIN
        assert b.eof_within(0.1) == "open"  # b asked nothing of the PLC yet
        # A request for the simulator unit is no request for the PLC.
        assert b.ask(read_pdu(REG_STATUS), unit=SIM) == words_reply(1)
        assert b.ask(read_pdu(0), timeout=1.0) == CLOSED
        with Conn(d.port) as c:
            assert c.ask(read_pdu(0), timeout=1.0) == CLOSED
    delete_faults(hp)
    with Conn(d.port) as c:
        assert c.ask(read_pdu(0)) == words_reply(8)
        assert c.eof_within(0.05) == "open"


# =========================================================================== garble (RTU)


def test_garble_on_rtu(start_plcemud, pty, line):
    values = list(range(100, 110))
    d = start_rtu(start_plcemud, pty, f"init: {{R0: {values}}}\n")
    sim = Sim(d)
    pdu = read_pdu(0, 10)
    good = good_rtu(1, words_reply(*values))  # 25 bytes
    r, _ = rtu_timed(line, 1, pdu, len(good))
    assert r == good

    # crc: the whole frame, its checksum wrong.
    sim.switch(garble=GARBLE["crc"])
    for _ in range(2):
        r, _ = rtu_timed(line, 1, pdu, len(good))
        assert len(r) == len(good), r.hex()
        assert r[:-2] == good[:-2], r.hex()
        assert crc16(r[:-2]) != r[-2] | r[-1] << 8, f"CRC matches: {r.hex()}"
    # TCP replies are never garbled.
    assert read_r(d.port, 0) == 100

    # short: the first half of the frame, then nothing.
    sim.switch(garble=GARBLE["short"])
    line.send(rtu_frame(1, pdu))
    r = line.receive(len(good), 0.3)
    assert 0 < len(r) < len(good), r.hex()
    assert len(r) in (len(good) // 2, (len(good) + 1) // 2), r.hex()
    assert r == good[:len(r)], r.hex()

    # gap: the whole frame, correct, in two parts with a pause between them.
    sim.switch(garble=GARBLE["gap"])
    gaps = []
    for _ in range(5):
        line.send(rtu_frame(1, pdu))
        chunks = rtu_chunks(line, len(good))
        assert b"".join(c for _, c in chunks) == good, [c.hex() for _, c in chunks]
        gaps.append(max((chunks[i + 1][0] - chunks[i][0] for i in range(len(chunks) - 1)),
                        default=0.0))
        time.sleep(0.01)
    # (t1.5 + t3.5) / 2 at 9600 baud is about 2.9 ms; a read may come late, so the largest
    # pause seen must be at least 1 ms, and none is as long as a frame timeout.
    assert max(gaps) >= 0.001, gaps
    assert max(gaps) < 0.1, gaps

    sim.clear()
    for _ in range(2):
        r, _ = rtu_timed(line, 1, pdu, len(good))
        assert r == good, r.hex()


# =========================================================================== stop


def plc_running(hp):
    status, j = api(hp, "GET", "/api/v1/plcs/0")
    assert status == 200, (status, j)
    return j["running"]


def test_stop_leaves_run_and_resumes(start_plcemud):
    # The program copies R0 to R1 every scan: while it runs, R1 follows R0.
    d, hp = start_with_http(start_plcemud, "program:\n  - MOV: {en: M1926, s: R0, d: R1}\n")
    c = d.client(timeout=2, retries=0)
    sim = Sim(d)
    assert ok(c.read_coils(M1926_COIL, 1, slave=1)).bits[0] is True
    assert plc_running(hp) is True
    ok(c.write_coil(Y0_COIL, True, slave=1))
    ok(c.write_register(0, 5, slave=1))
    deadline = time.monotonic() + 2
    while ok(c.read_holding_registers(1, 1, slave=1)).registers != [5]:
        assert time.monotonic() < deadline
        time.sleep(0.01)

    sim.write("stop", 1)  # FC06
    time.sleep(0.05)
    assert ok(c.read_coils(M1926_COIL, 1, slave=1)).bits[0] is False  # RUN relay off
    assert ok(c.read_coils(Y0_COIL, 1, slave=1)).bits[0] is False  # outputs off
    assert plc_running(hp) is False
    ok(c.write_register(0, 6, slave=1))  # requests are still served ...
    time.sleep(0.2)
    assert ok(c.read_holding_registers(0, 2, slave=1)).registers == [6, 5]  # ... no scan ran
    assert ok(c.read_coils(M1926_COIL, 1, slave=1)).bits[0] is False

    sim.write("stop", 0)
    deadline = time.monotonic() + 1
    while ok(c.read_holding_registers(1, 1, slave=1)).registers != [6]:
        assert time.monotonic() < deadline, "the program did not run again"
        time.sleep(0.01)
    assert ok(c.read_coils(M1926_COIL, 1, slave=1)).bits[0] is True
    assert plc_running(hp) is True
    assert sim.status() & 1 == 0


# =========================================================================== scope


def test_scope_by_device_range_from_the_config(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "faults: {exception: 4, from: R100, count: 10}\n"
                      "init: {R0: 1, R99: 99, R110: 110}\n")
    c = d.client(timeout=2, retries=0)
    assert ok(c.read_holding_registers(0, 1, slave=1)).registers == [1]
    assert ok(c.read_holding_registers(110, 1, slave=1)).registers == [110]
    assert ok(c.read_holding_registers(99, 1, slave=1)).registers == [99]
    assert exception_code(c.read_holding_registers(100, 1, slave=1)) == 4
    assert exception_code(c.read_holding_registers(109, 1, slave=1)) == 4
    assert exception_code(c.read_holding_registers(95, 10, slave=1)) == 4  # R95-R104
    assert exception_code(c.write_register(105, 1, slave=1)) == 4
    assert ok(c.read_coils(0, 8, slave=1))  # Y: no device of the range
    # FC17h counts both of its ranges: read R0, write R105.
    with Conn(d.port) as raw:
        fc17 = struct.pack(">BHHHHBH", 0x17, 0, 1, 105, 1, 2, 7)
        assert raw.ask(fc17) == bytes([0x97, 4])
        fc17 = struct.pack(">BHHHHBH", 0x17, 105, 1, 0, 1, 2, 7)
        assert raw.ask(fc17) == bytes([0x97, 4])
        # FC08 names no device: left alone.
        assert raw.ask(b"\x08\x00\x00\x12\x34") == b"\x08\x00\x00\x12\x34"


def test_a_scope_of_32_bit_counters_counts_counters(start_plcemud):
    """CTR200-CTR255 hold two words each (holding registers 9700-9811): a scope's `count` from
    CTR200 was taken as words, so 56 covered CTR200-CTR227, 57 was taken, and the config's
    `count: 2` was CTR200 alone. Counted as the devices API counts them: counters."""
    d, hp = start_with_http(start_plcemud, "faults: {exception: 6, from: CTR200, count: 2}\n")
    assert d.wait_log("(CTR200-CTR201)"), d.log_text()
    c = d.client(timeout=2, retries=0)
    assert exception_code(c.read_holding_registers(9702, 2, slave=1)) == 6  # CTR201
    assert ok(c.read_holding_registers(9704, 2, slave=1))  # CTR202
    j = put_faults(hp, exception=4, **{"from": "CTR200", "count": 56})
    assert (j["from"], j["count"]) == ("CTR200", 56), j
    assert "CTR200-CTR255" in j["summary"]["scope"], j
    for addr in (9700, 9754, 9756, 9810):  # CTR200, CTR227, CTR228, CTR255
        assert exception_code(c.read_holding_registers(addr, 2, slave=1)) == 4, addr
    assert ok(c.read_holding_registers(9698, 2, slave=1))  # CTR198-CTR199, one word each
    # The block of the simulator unit reads the count back as counters too.
    assert ok(Sim(d).c.read_holding_registers(REG["count"], 1, slave=SIM)).registers == [56]
    status, j = api(hp, "PUT", "/api/v1/plcs/0/comm-faults",
                    {"exception": 4, "from": "CTR200", "count": 57})
    assert status == 400 and "CTR200-CTR256" in j["error"], (status, j)


def test_the_block_clamps_garble_and_reads_from_as_one_device_name(start_plcemud):
    """garble 9 was taken as none, where every register of the block is clamped to its range
    (3, gap); spaces inside `from` were dropped, so "R 1" was R1. Padding is still allowed."""
    d = start_plcemud(BASE_CONFIG)
    sim = Sim(d)
    ok(sim.c.write_registers(BLOCK_FIRST, block(garble=9), slave=SIM))
    assert ok(sim.c.read_holding_registers(REG["garble"], 1, slave=SIM)).registers == [3]
    sim.clear()
    ok(sim.c.write_registers(BLOCK_FIRST, block(**{"from": "R 1"}), slave=SIM))
    assert sim.status() & 2 == 2, "R 1 was taken for a device"
    sim.clear()
    sim.clear()
    # NUL padding in front: it was read as an empty name, and the fault scoped to nothing
    # applied to every request; a NUL inside is no name either.
    for raw, refused in [(b"\0\0R1\0\0\0\0", False), (b"R1\0R2\0\0\0", True)]:
        words = list(struct.unpack(">4H", raw))
        regs = block(exception=4)
        regs[REG["from_1"] - BLOCK_FIRST:REG["from_1"] - BLOCK_FIRST + 4] = words
        ok(sim.c.write_registers(BLOCK_FIRST, regs, slave=SIM))
        assert (sim.status() & 2 == 2) == refused, raw
        if not refused:
            c = d.client()
            assert not c.read_holding_registers(0, 1, slave=1).isError()  # R0: out of scope
            assert exception_code(c.read_holding_registers(1, 1, slave=1)) == 4
        sim.clear()
    ok(sim.c.write_registers(BLOCK_FIRST, block(**{"from": " R1  "}), slave=SIM))
    assert sim.status() & 2 == 0, "a padded R1 was refused"
    assert bytes(b for w in ok(sim.c.read_holding_registers(REG["from_1"], 4, slave=SIM)).registers
                 for b in w.to_bytes(2, "big")).rstrip(b"\0 ") == b"R1"


def test_scope_by_function_and_by_unit(start_plcemud):
    # FC04 reads R200.. through the user map (R3975: count, type, start).
    d = start_plcemud(BASE_CONFIG + "init: {R3975: [0, 200, 8], R200: 42, R0: 1}\n")
    sim = Sim(d)
    c = d.client(timeout=2, retries=0)
    sim.switch(exception=6, function=3)
    assert exception_code(c.read_holding_registers(200, 1, slave=1)) == 6
    assert ok(c.read_input_registers(0, 1, slave=1)).registers == [42]
    assert ok(c.write_register(0, 2, slave=1))  # FC06 is not FC03 either
    sim.switch(exception=6, unit=255)
    assert exception_code(c.read_holding_registers(0, 1, slave=255)) == 6
    assert ok(c.read_holding_registers(0, 1, slave=1)).registers == [2]
    assert ok(c.read_holding_registers(0, 1, slave=0)).registers == [2]
    sim.clear()
    assert ok(c.read_holding_registers(0, 1, slave=255)).registers == [2]


@pytest.fixture
def plcs(start_plcs):
    return start_plcs


def test_scope_a_plc_behind_a_shared_listener(plcs):
    shared = free_port()
    d = plcs(f"""\
plcs:
  - {{name: a, profile: fbs, station: 1, simulator: {{unit: 201}}, init: {{R0: 1}},
     modbus: {{tcp: {{bind: 127.0.0.1, port: {shared}}}}}}}
  - name: b
    profile: fbs
    station: 2
    simulator: {{unit: 202}}
    init: {{R0: 2}}
    modbus: {{tcp: {{bind: 127.0.0.1, port: {shared}}}}}
    faults: {{offline: true, refuse_connections: true}}
""", [shared])
    # b refuses connections, a does not: the shared listener keeps accepting.
    with Conn(shared) as c:
        assert c.ask(read_pdu(0), unit=1) == words_reply(1)
        assert c.ask(read_pdu(0), unit=2) is None
        assert c.ask(read_pdu(REG_STATUS), unit=202) == words_reply(1)
        assert c.ask(read_pdu(REG_STATUS), unit=201) == words_reply(0)
        assert c.ask(read_pdu(0), unit=1) == words_reply(1)
    sim_b = Sim(d, port=shared, unit=202)
    sim_b.switch(exception=4)
    c = d.client(timeout=2, retries=0)
    assert exception_code(c.read_holding_registers(0, 1, slave=2)) == 4
    for _ in range(20):
        assert ok(c.read_holding_registers(0, 1, slave=1)).registers == [1]
    sim_b.clear()
    assert ok(c.read_holding_registers(0, 1, slave=2)).registers == [2]


# =========================================================================== config errors


@pytest.mark.parametrize("section,key,at", [
    ("faults:\n  drop_probability: 2\n", "drop_probability", "2"),
    ("faults:\n  seed: 1\n  from: Q5\n", "from", "Q5"),
    ("faults: {offline: true, reset: true}\n", "reset", "true}"),
    ("faults:\n  drop_every: 2\n  drop_probability: 0.5\n", "drop_probability", "0.5"),
    ("faults:\n  delay_ms: [300, 100]\n", "delay_ms", "[300"),
    ("faults:\n  garble: wobble\n", "garble", "wobble"),
    ("faults:\n  exception: 256\n", "exception", "256"),
    ("faults:\n  from: R4200\n", "from", "R4200"),
], ids=["drop_probability-2", "from-Q5", "reset-alone", "both-drops", "delay-min-above-max",
        "garble-unknown", "exception-256", "from-outside"])
def test_bad_faults_section_is_refused_by_check_config(tmp_path, section, key, at):
    text = BASE_CONFIG + section
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(text)
    lines = text.splitlines()
    row = next(i for i, l in enumerate(lines) if f"{key}:" in l)
    col = lines[row].index(at, lines[row].index(f"{key}:")) + 1
    r = run_plcemud("--check-config", "-c", cfg, timeout=10)
    assert r.returncode == 2, (r.returncode, r.stderr)
    out = r.stdout + r.stderr
    assert re.search(re.escape(f"bad.yaml:{row + 1}:{col}: faults.{key}"), out), out


def test_a_good_faults_section_passes_check_config(tmp_path):
    cfg = tmp_path / "good.yaml"
    cfg.write_text(BASE_CONFIG + "faults: {delay_ms: [100, 300], seed: 7, from: R100, "
                   "count: 10, disconnect_after: 3, reset: true, garble: gap}\n")
    r = run_plcemud("--check-config", "-c", cfg, timeout=10)
    assert r.returncode == 0, r.stdout + r.stderr


# =========================================================================== log


def log_count(d, text):
    return sum(1 for l in d.log_text().splitlines() if text in l)


def wait_count(d, text, n, timeout=2.0):
    deadline = time.monotonic() + timeout
    while log_count(d, text) < n and time.monotonic() < deadline:
        time.sleep(0.02)
    return log_count(d, text)


def test_a_master_toggling_a_fault_cannot_flood_the_log(start_plcemud):
    """Switching a fault is logged, and a master can switch one as fast as it writes: the lines
    are rate-limited as connects are (50 in 10 s, then counted), 2,000 toggles or not."""
    d = start_plcemud(BASE_CONFIG)
    toggles = 2000
    pdus = [struct.pack(">BHH", 6, REG["exception"], 4 if i % 2 == 0 else 0)
            for i in range(toggles)]
    adus = b"".join(struct.pack(">HHHB", i + 1, 0, len(p) + 1, SIM) + p
                    for i, p in enumerate(pdus))
    with socket.create_connection(("127.0.0.1", d.port), timeout=10) as s:
        s.sendall(adus)
        want, got = 12 * toggles, b""  # each FC06 is echoed: MBAP 7 + PDU 5
        while len(got) < want:
            chunk = s.recv(65536)
            assert chunk, f"closed after {len(got)} of {want} bytes"
            got += chunk
    assert log_count(d, "comm fault o") <= 50, log_count(d, "comm fault o")
    assert log_count(d, "comm fault on: exception 04h") >= 1
    # The PLC still answers, the fault switched off by the last toggle.
    c = d.client()
    assert not c.read_holding_registers(0, 1, slave=1).isError()


def test_one_log_line_per_fault_switched(start_plcemud):
    d, hp = start_with_http(start_plcemud)
    put_faults(hp, delay_ms=300, exception=4, **{"from": "R100", "count": 10})
    assert wait_count(d, "comm fault on: delay 300 ms (R100-R109)", 1) == 1
    assert wait_count(d, "comm fault on: exception 04h", 1) == 1
    # The same delay again and the exception off: one line, for the exception.
    put_faults(hp, delay_ms=300, **{"from": "R100", "count": 10})
    assert wait_count(d, "comm fault off: exception 04h", 1) == 1
    delete_faults(hp)
    assert wait_count(d, "comm fault off: delay 300 ms", 1) == 1
    # Through the simulator unit: FC06 switches one fault from what the block held.
    sim = Sim(d)
    sim.write("offline", 1)
    sim.write("drop_every", 3)
    assert wait_count(d, "comm fault on: offline", 1) == 1
    assert wait_count(d, "comm fault on: drop every 3rd request", 1) == 1
    sim.clear()
    assert wait_count(d, "comm fault off: offline", 1) == 1
    assert wait_count(d, "comm fault off: drop every 3rd request", 1) == 1
    time.sleep(0.1)
    lines = [l for l in d.log_text().splitlines() if "comm fault" in l]
    assert len(lines) == 8, "\n".join(lines)
    assert sum("comm fault on:" in l for l in lines) == 4, "\n".join(lines)
    assert sum("comm fault off:" in l for l in lines) == 4, "\n".join(lines)


# =========================================================================== FATEK protocol


def start_fatek(start_plcemud):
    fp = free_port()
    d = start_plcemud(BASE_CONFIG + f"fatek: {{tcp: {{bind: 127.0.0.1, port: {fp}}}}}\n"
                      "init: {R0: 1234}\n")
    return d, fp


def test_fatek_exception_gives_the_error_code(start_plcemud):
    d, fp = start_fatek(start_plcemud)
    sim = Sim(d)
    with Fatek.tcp(fp, timeout=NO_REPLY_S) as f:
        assert f.request(0x46, "01R00000") == (0, "04D2")
        sim.switch(exception=4)
        assert f.request(0x46, "01R00000") == (4, "")
        assert f.request(0x40) == (4, "")
        assert f.request(0x47, "01R000000007") == (4, "")  # a write changes nothing
        sim.switch(exception=0x12)  # above Fh: sent as F
        assert f.request(0x46, "01R00000") == (0xF, "")
        sim.switch(exception=6, function=0x46)  # only command 46
        assert f.request(0x46, "01R00000") == (6, "")
        assert f.request(0x40)[0] == 0
        sim.clear()
        assert f.request(0x46, "01R00000") == (0, "04D2")


def test_fatek_offline_gives_no_reply(start_plcemud):
    d, fp = start_fatek(start_plcemud)
    sim = Sim(d)
    with Fatek.tcp(fp, timeout=NO_REPLY_S) as f:
        assert f.request(0x46, "01R00000") == (0, "04D2")
        sim.switch(offline=1)
        assert f.exchange(fatek_frame(1, 0x46, "01R00000"), timeout=NO_REPLY_S) is None
        assert f.exchange(fatek_frame(1, 0x47, "01R000000007"), timeout=NO_REPLY_S) is None
        assert f.exchange(fatek_frame(1, 0x40), timeout=NO_REPLY_S) is None
        sim.clear()
        # The same connection answers again, and the write while offline never landed.
        reply = f.exchange(fatek_frame(1, 0x46, "01R00000"), timeout=1.0)
        assert reply is not None and fatek_parse(reply) == (1, 0x46, "004D2"), reply


def test_fatek_requests_are_scoped_by_the_devices_they_name(start_plcemud):
    # from: R100, count: 10 reaches a FATEK request that names one of R100-R109: 46's run, 47's,
    # 48's items; R0 and 40 (which names no device) are served.
    d, fp = start_fatek(start_plcemud)
    sim = Sim(d)
    sim.switch(exception=4, **{"from": "R100", "count": 10})
    with Fatek.tcp(fp, timeout=NO_REPLY_S) as f:
        assert f.request(0x46, "01R00000") == (0, "04D2")
        assert f.request(0x40)[0] == 0
        assert f.request(0x46, "01R00100")[0] == 4
        assert f.request(0x46, "02R00099")[0] == 4  # R99-R100: reaches R100
        assert f.request(0x46, "02R00098")[0] == 0  # R98-R99: does not
        assert f.request(0x47, "01R001090007")[0] == 4
        assert f.request(0x48, "02R00000R00105")[0] == 4  # one item of two inside
        assert f.request(0x48, "02R00000R00110")[0] == 0
        assert f.request(0x44, "01M0000")[0] == 0  # another area
        sim.clear()
        assert f.request(0x46, "01R00100")[0] == 0


def test_answers_a_line_cannot_hold_are_counted_dropped_faulted_or_not(start_plcemud):
    # docs/communication-faults.md: 64 answers held on a line, those waiting behind them
    # included; every one dropped beyond is counted dropped (answers outside the fault's scope,
    # queued behind the held ones, were lost without a count).
    console = free_port()
    master, slave = os.openpty()
    for fd in (master, slave):
        tty.setraw(fd)
    try:
        d = start_plcemud(
            f"profile: fbs\nmodbus:\n  tcp: {{bind: 127.0.0.1}}\n"
            f"  rtu: {{device: {os.ttyname(slave)}, baud: 115200}}\n"
            f"http: {{port: {console}}}\npersistence: {{enabled: false}}\n"
            "faults: {delay_ms: 3000, from: R100, count: 1}\n")

        def figures():
            c = http.client.HTTPConnection("127.0.0.1", console, timeout=5)
            c.request("GET", "/api/v1/plcs/0/comm-faults")
            return json.loads(c.getresponse().read())["figures"]

        def send(address, n):
            for _ in range(n):
                os.write(master, rtu_frame(1, struct.pack(">BHH", 3, address, 1)))
                time.sleep(0.01)  # a frame each, the line's silence between them

        send(100, 70)
        send(0, 10)
        deadline = time.monotonic() + 5
        while figures()["dropped"] < 16 and time.monotonic() < deadline:
            time.sleep(0.1)
        f = figures()
        assert (f["delayed"], f["dropped"]) == (64, 16), (f, d.log_text())
    finally:
        os.close(master)
        os.close(slave)
