"""The FNC149 MBUS master against hostile TCP slaves (docs/profile-vb.md, "Transports: `mbus:`"):
a slave that answers garbage, a wrong protocol ID, a length field that lies or closes at every
request is logged once per endpoint and cause, then counted ("N more ... in the last 2 s"), and
the master reconnects to it less and less often; a slave that floods frames nobody asked for is
closed (status 6) and costs the master little CPU. The slaves are Python sockets on loopback
(RogueSlave of test_vb_mbus.py); the master is a `vb` plcemud with the one-set table polling
station 5 through them."""

import itertools
import re
import time

import pytest

from test_vb_mbus import MASTER, RogueSlave, cpu_seconds, enable, mbap, status, tcp_mbus, wait_for

WATCH_S = 3.0  # how long each hostile slave is watched

READ_REPLY = b"\x03\x02\x00\x01"  # FC03, one register


def one_set_master(start_plcemud, port):
    """A master polling station 5 (set 1 of the manual's table only) at `port`, EN ON."""
    master = start_plcemud(MASTER.format(mbus=tcp_mbus(port), set2=2).replace("D1000: 3",
                                                                               "D1000: 1"))
    c = master.client()
    enable(c)
    return master, c


def mbus_lines(master):
    return [line for line in master.log_text().splitlines() if "mbus:" in line]


HOSTILE = {
    # A wrong protocol ID, bytes that are no frame at all: a bad MBAP header, status 6.
    "wrong-protocol": (lambda q: [q[0:2] + b"\x12\x34\x00\x03\x01\x03\x00"], "bad MBAP headers",
                       6),
    "garbage": (lambda q: [bytes(range(256)) * 4], "bad MBAP headers", 6),
    # Says 100 bytes follow and sends 5: part of a frame left at every next transfer. The
    # transfer waits for its time-out; the reconnects that follow are held back (status 6).
    "lying-length": (lambda q: [q[0:4] + b"\x00\x64" + bytes([q[6]]) + READ_REPLY],
                     "reconnects for part of a frame left", 6),
    # Closes at every request: status 5 at the time-out.
    "closing": (lambda q: None, "disconnects", 5),
}


# 160 lines a second before: a warning and a reconnect line per transfer.
@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_a_hostile_slave_is_logged_once_per_cause_then_counted(start_plcemud, name):
    reply, cause, expected = HOSTILE[name]
    rogue = RogueSlave(reply)
    try:
        master, c = one_set_master(start_plcemud, rogue.port)
        time.sleep(WATCH_S)
        lines = mbus_lines(master)
        text = "\n".join(lines)
        # The first line of each cause, its count once the 2 s window is over, and the line of
        # a fault after it: a handful, however many transfers failed.
        assert len(lines) <= 8, f"{len(lines)} lines in {WATCH_S} s:\n{text}"
        endpoint = f"mbus: 127.0.0.1:{rogue.port}: "
        assert re.search(re.escape(endpoint) + r"\d+ more " + re.escape(cause) +
                         r" in the last 2 s \(not logged one by one\)", text), text
        assert re.search(re.escape(endpoint) + r"\d+ more connects in the last 2 s", text), text
        # Reconnects back off (at once, then 100 ms doubling): 7 connects in the first 3.1 s.
        assert rogue.connections <= 8, f"{rogue.connections} connections\n{text}"
        # S2+0 keeps saying what the slave does, also while the master waits to reconnect.
        got, _ = wait_for(lambda: status(c) == (expected << 8 | 5), timeout=1.0)
        assert got, hex(status(c))
        assert master.proc.poll() is None
    finally:
        rogue.close()


# Half a core before, and never dropped: a slave that sends frames of another transaction
# without end.
def test_a_flooding_slave_is_closed_and_costs_little_cpu(start_plcemud):
    rogue = RogueSlave(lambda q: itertools.repeat(mbap(q, READ_REPLY, tid=0xBEEF) * 100))
    try:
        master, c = one_set_master(start_plcemud, rogue.port)
        pid = master.proc.pid
        flood = f"mbus: 127.0.0.1:{rogue.port}: more than 1040 bytes not asked for"
        assert master.wait_log(flood, timeout=2.0), master.log_text()
        got, _ = wait_for(lambda: status(c) == 0x0605, timeout=1.0)
        assert got, hex(status(c))
        before, start = cpu_seconds(pid), time.monotonic()
        time.sleep(WATCH_S)
        share = (cpu_seconds(pid) - before) / (time.monotonic() - start)
        # The master alone, a scan every 10 ms under the sanitizers, is a few per cent.
        assert share < 0.15, f"{share:.0%} of a core\n{master.log_text()}"
        assert rogue.connections <= 8, f"{rogue.connections} connections"
        assert len(mbus_lines(master)) <= 8, master.log_text()
        assert status(c) == 0x0605
    finally:
        rogue.close()


# A slave that lies once and then answers properly costs that one transfer: the reconnect after
# a first fault is at once, and a reply ends the back-off.
def test_one_fault_then_good_replies_polls_on(start_plcemud):
    count = itertools.count()

    def reply(q):
        if next(count) == 0:
            return [q[0:2] + b"\x12\x34\x00\x03\x01\x03\x00"]
        return [mbap(q, b"\x03\x14" + b"\x00\x2a" * 10)]  # set 1 reads 10 registers

    rogue = RogueSlave(reply)
    try:
        master, c = one_set_master(start_plcemud, rogue.port)
        got, _ = wait_for(lambda: c.read_holding_registers(2000, 1, slave=1).registers == [42],
                          timeout=2.0)
        assert got, master.log_text()
        assert rogue.connections == 2
        passes = c.read_holding_registers(102, 1, slave=1).registers[0]
        time.sleep(0.5)
        assert c.read_holding_registers(102, 1, slave=1).registers[0] - passes >= 10
        assert status(c) == 0
    finally:
        rogue.close()
