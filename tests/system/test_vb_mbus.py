"""FNC149 MBUS through two real daemons (docs/profile-vb.md, "FNC149 MBUS"): a `vb` master polls
an `fbs` slave at station 5 over Modbus TCP with the VB manual's three-set table, and is watched
through its own Modbus TCP port. Also: a master whose slave is down, silent or sends garbage
keeps serving its own clients."""

import socket
import threading
import time

import pytest

from conftest import REPO, free_port

SLAVE = """profile: fbs
station: 5
modbus: {{tcp: {{bind: 127.0.0.1, unknown_unit: {policy}}}}}
persistence: {{enabled: false}}
init:
  R0: [1001, 1002, 1003, 1004, 1005, 1006, 1007, 1008, 1009, 1010]
"""

# The VB manual's example table; set 2 goes to station `set2` (2 in the manual).
MASTER = """profile: vb
modbus: {{tcp: {{bind: 127.0.0.1}}}}
persistence: {{enabled: false}}
mbus: {{tcp: {{host: {host}, port: {port}}}}}
init:
  D1000: 3
  D1001: [5, 1, 10, 13, 2000, 4, 0]
  D1008: [{set2}, 2, 5, 13, 2010, 4, 1000]
  D1015: [3, 3, 1, 13, 2015, 4, 2000]
  D2010: [11, 12, 13, 14, 15, 16]
program:
  - MBUS: {{en: M0, s1: D1000, s2: D100}}
  - CNT: {{en: M9199, c: C0, k: 32767}}
"""


def regs(client, addr, count=1, unit=1):
    r = client.read_holding_registers(addr, count, slave=unit)
    assert not r.isError(), r
    return r.registers


def wait_for(predicate, timeout=2.0, step=0.005):
    """Polls `predicate` until it returns a true value; returns it and the seconds it took."""
    start = time.monotonic()
    while True:
        v = predicate()
        if v or time.monotonic() - start > timeout:
            return v, time.monotonic() - start
        time.sleep(step)


@pytest.fixture
def pair(start_plcemud):
    """start(policy='exception', set2=2, host=None, port=None) -> (master, slave or None)."""

    def start(policy="exception", set2=2, host="127.0.0.1", port=None):
        slave = None
        if port is None:
            slave = start_plcemud(SLAVE.format(policy=policy))
            port = slave.port
        master = start_plcemud(MASTER.format(host=host, port=port, set2=set2))
        return master, slave

    return start


def status(c):
    return regs(c, 100)[0]


def enable(c, on=True):
    assert not c.write_coil(0, on, slave=1).isError()


# Scenario: "D2000–D2009 = B's R0–R9 within 1 s".
def test_reads_land_within_one_second(pair):
    master, _ = pair()
    c = master.client()
    enable(c)
    got, took = wait_for(lambda: regs(c, 2000, 10) == list(range(1001, 1011)), timeout=1.0)
    assert got, regs(c, 2000, 10)
    assert took < 1.0


# Scenario: with B answering only station 5 and `unknown_unit: exception`, status 6 with station
# 2 or 3 in the low byte, and D103 = 0Bh (gateway target failed to respond).
def test_exception_replies_are_status_6_with_the_code_in_s2_plus_3(pair):
    master, _ = pair("exception")
    c = master.client()
    enable(c)
    got, _ = wait_for(lambda: status(c) >> 8 == 6, timeout=1.0)
    assert got, hex(status(c))
    assert status(c) & 0xFF in (2, 3)
    assert regs(c, 103) == [0x0B]


# Scenario: with `unknown_unit: silent`, status 5 after ≥ 100 ms, or ≥ 500 ms with D9129 = 50
# (the time-out runs in real time).
@pytest.mark.parametrize("d9129,least", [(0, 0.100), (50, 0.500)])
def test_silent_slave_is_status_5_after_the_d9129_time_out(pair, d9129, least):
    master, _ = pair("silent")
    c = master.client()
    assert not c.write_register(8129, d9129, slave=1).isError()
    enable(c)
    got, took = wait_for(lambda: status(c) >> 8 == 5, timeout=3.0)
    assert got, hex(status(c))
    assert status(c) & 0xFF == 2  # set 2's station is the first that stays silent
    assert took >= least
    assert took < least + 0.5


# Scenario: M9199 pulses once per pass (a CNT counts it) and D102 increments once per pass.
def test_m9199_counted_by_a_cnt_and_s2_plus_2_count_passes(pair):
    master, _ = pair()
    c = master.client()
    enable(c)
    wait_for(lambda: regs(c, 102)[0] >= 3, timeout=2.0)
    enable(c, False)
    time.sleep(0.1)
    passes = regs(c, 102)[0]
    assert passes >= 3
    assert regs(c, 9500) == [passes]  # C0
    time.sleep(0.2)
    assert regs(c, 102) == [passes], "no pass while EN is OFF"


# Scenario: D1003 = 65 → status 1; master type 13 with slave type 0 → status 4.
@pytest.mark.parametrize("register,value,expected", [(1003, 65, 0x0105), (1006, 0, 0x0405)])
def test_checks_report_status_1_and_4(pair, register, value, expected):
    master, _ = pair()
    c = master.client()
    assert not c.write_register(register, value, slave=1).isError()
    enable(c)
    got, _ = wait_for(lambda: status(c) == expected, timeout=1.0)
    assert got, hex(status(c))
    assert regs(c, 2000) == [0], "the failing set sends nothing"


# Scenario: clearing M0 stops MBUS: no further writes to D2000–D2009 (nor to the slave).
def test_en_off_stops_reads_and_writes(pair):
    master, slave = pair(set2=5)  # set 2 writes D2010–D2014 into the slave's R1000–R1004
    c = master.client()
    s = slave.client()
    enable(c)
    got, _ = wait_for(lambda: regs(s, 1000, 5, unit=5) == [11, 12, 13, 14, 15], timeout=1.0)
    assert got
    enable(c, False)
    time.sleep(0.1)
    assert not s.write_registers(0, [7] * 10, slave=5).isError()
    assert not c.write_registers(2010, [99] * 5, slave=1).isError()
    time.sleep(0.5)
    assert regs(c, 2000, 10) == list(range(1001, 1011)), "no read lands after EN OFF"
    assert regs(s, 1000, 5, unit=5) == [11, 12, 13, 14, 15], "no write after EN OFF"
    enable(c)
    got, _ = wait_for(lambda: regs(c, 2000, 10) == [7] * 10, timeout=1.0)
    assert got, "EN rising starts again"


def served_within(client, budget_s, n=100):
    """The slowest of `n` reads of the master's own registers, each timed."""
    worst = 0.0
    for _ in range(n):
        t = time.monotonic()
        regs(client, 100, 4)
        worst = max(worst, time.monotonic() - t)
        time.sleep(0.003)
    return worst


# A master whose slave is down (nothing listens) keeps serving its own clients within 50 ms,
# and reports status 5 for every set.
def test_master_with_its_slave_down_keeps_serving(pair):
    master, _ = pair(port=free_port())
    c = master.client()
    enable(c)
    assert served_within(c, 0.05) < 0.05
    assert status(c) >> 8 == 5
    got, _ = wait_for(lambda: regs(c, 102)[0] >= 1, timeout=1.0)
    assert got, "the cycle goes on past the dead slave"


class RogueSlave:
    """A TCP 'slave' that answers every request with `reply(request)` bytes (or closes)."""

    def __init__(self, reply):
        self.reply = reply
        self.sock = socket.socket()
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.port = self.sock.getsockname()[1]
        self.stopped = False
        self.connections = 0
        threading.Thread(target=self.serve, daemon=True).start()

    def serve(self):
        while not self.stopped:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.connections += 1
            threading.Thread(target=self.talk, args=(conn,), daemon=True).start()

    def talk(self, conn):
        with conn:
            while not self.stopped:
                try:
                    req = conn.recv(300)
                except OSError:
                    return
                if not req:
                    return
                out = self.reply(req)
                if out is None:
                    return  # close
                try:
                    for chunk in out:
                        conn.sendall(chunk)
                except OSError:
                    return

    def close(self):
        self.stopped = True
        self.sock.close()


def mbap(req, pdu, unit=None, tid=None):
    t = req[0:2] if tid is None else tid.to_bytes(2, "big")
    u = req[6] if unit is None else unit
    return t + b"\x00\x00" + (len(pdu) + 1).to_bytes(2, "big") + bytes([u]) + pdu


ROGUES = {
    # A reply for another function code, a wrong byte count, another unit, a stale transaction.
    "wrong-function": (lambda q: [mbap(q, b"\x04\x02\x00\x01")], 6),
    "wrong-count": (lambda q: [mbap(q, b"\x03\x04\x00\x01\x00\x02")], 6),
    "other-unit": (lambda q: [mbap(q, b"\x03\x02\x00\x01", unit=9)], 6),
    "stale-tid": (lambda q: [mbap(q, b"\x03\x02\x00\x01", tid=0xBEEF)], 5),
    # A bad MBAP header, a frame announcing more than any frame holds, random bytes.
    "bad-protocol": (lambda q: [q[0:2] + b"\x12\x34\x00\x03\x01\x03\x00"], 6),
    "huge-frame": (lambda q: [q[0:4] + b"\xff\xff" + bytes(5000)], 6),
    "noise": (lambda q: [bytes(range(256)) * 8], 6),
    # One byte every 20 ms: the deadline ends it, not the drip.
    "slow-drip": (lambda q: _drip(mbap(q, b"\x03\x02\x00\x01")), 5),
    # The connection closes without a reply: status 5 once the time-out has passed.
    "close": (lambda q: None, 5),
}


def _drip(frame):
    for b in frame:
        time.sleep(0.02)
        yield bytes([b])


@pytest.mark.parametrize("name", sorted(ROGUES))
def test_a_rogue_slave_is_a_status_and_never_stalls_the_master(start_plcemud, name):
    reply, expected = ROGUES[name]
    rogue = RogueSlave(reply)
    try:
        master = start_plcemud(
            MASTER.format(host="127.0.0.1", port=rogue.port, set2=2).replace("D1000: 3", "D1000: 1")
        )
        c = master.client()
        enable(c)
        assert served_within(c, 0.05, n=60) < 0.05
        got, _ = wait_for(lambda: status(c) == (expected << 8 | 5), timeout=2.0)
        assert got, hex(status(c))
        assert regs(c, 2000) == [0], "nothing lands from a bad reply"
        assert master.proc.poll() is None
    finally:
        rogue.close()


# config/vb-mbus.yaml against config/vb-mbus-slave.yaml, as their headers tell a user to run them
# (on free ports here).
def test_example_pair_polls(start_plcemud):
    slave_text = (REPO / "config" / "vb-mbus-slave.yaml").read_text()
    slave = start_plcemud(slave_text)
    master_text = (REPO / "config" / "vb-mbus.yaml").read_text().replace(
        "port: 5021", f"port: {slave.port}")
    master = start_plcemud(master_text)
    c = master.client()
    got, _ = wait_for(lambda: regs(c, 2000, 10) == list(range(1001, 1011)), timeout=1.0)
    assert got
    got, _ = wait_for(lambda: regs(c, 9500)[0] >= 2, timeout=1.0)
    assert got, "C0 counts the passes"
