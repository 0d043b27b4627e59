"""FNC149 MBUS through two real daemons (docs/profile-vb.md, "FNC149 MBUS"): a `vb` master polls
an `fbs` slave at station 5 with the VB manual's three-set table, over Modbus TCP and again over
Modbus RTU through a socat pty pair (tests/system/rtu_pty.py), and is watched through its own
Modbus TCP port. Also: a master whose slave is down, silent or sends garbage keeps serving its
own clients; a device that goes away is reopened; SIGHUP moves the master to another endpoint
or device, and a bad reload keeps it polling where it did."""

import signal
import socket
import threading
import time

import pytest

from conftest import REPO, free_port
from rtu_pty import PtyPair, RawLine, crc16, frame

# The slave's line: Modbus TCP (for the test's own reads, and the master's over TCP) and, over
# RTU, the pty end it serves. A pty takes no parity setting: both ends run 8N1.
SLAVE = """profile: fbs
station: 5
modbus: {{tcp: {{bind: 127.0.0.1, unknown_unit: {policy}}}{rtu}}}
persistence: {{enabled: false}}
init:
  R0: [{r0}]
"""
R0 = ", ".join(str(v) for v in range(1001, 1011))

# The VB manual's example table; set 2 goes to station `set2` (2 in the manual).
MASTER = """profile: vb
modbus: {{tcp: {{bind: 127.0.0.1}}}}
persistence: {{enabled: false}}
mbus: {mbus}
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


def tcp_mbus(port, host="127.0.0.1"):
    return f"{{tcp: {{host: {host}, port: {port}}}}}"


def rtu_mbus(device):
    return f"{{transport: rtu, rtu: {{device: {device}, parity: N}}}}"


def slave_config(policy="exception", device=None, r0=R0):
    rtu = f", rtu: {{device: {device}, parity: N}}" if device else ""
    return SLAVE.format(policy=policy, rtu=rtu, r0=r0)


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


def new_dir(parent, stem):
    """A new directory under `parent` (PtyPair names its two links the same in each)."""
    n = 0
    while (parent / f"{stem}{n}").exists():
        n += 1
    d = parent / f"{stem}{n}"
    d.mkdir()
    return d


@pytest.fixture(params=["tcp", "rtu"])
def transport(request):
    return request.param


@pytest.fixture
def pair(start_plcemud, transport, tmp_path):
    """start(policy='exception', set2=2, slave_up=True) -> (master, slave or None), over the
    transport the test runs with. Over RTU only station 5 answers: a serial slave is silent to
    other stations whatever its `unknown_unit` (a TCP policy) says."""
    ptys = []

    def start(policy="exception", set2=2, slave_up=True):
        slave = None
        if transport == "tcp":
            if slave_up:
                slave = start_plcemud(slave_config(policy))
            mbus = tcp_mbus(slave.port if slave else free_port())
        else:
            pty = PtyPair(new_dir(tmp_path, "pty"))
            ptys.append(pty)
            if slave_up:
                slave = start_plcemud(slave_config(policy, pty.slave))
                # Its TCP port listens before its serial line is open: a request that came
                # before would be flushed.
                assert slave.wait_log("listening on rtu"), slave.log_text()
            mbus = rtu_mbus(pty.master)
        master = start_plcemud(MASTER.format(mbus=mbus, set2=set2))
        return master, slave

    start.ptys = ptys
    yield start
    for p in ptys:
        p.stop()


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
# 2 or 3 in the low byte, and D103 = 0Bh (gateway target failed to respond). Over RTU stations 2
# and 3 are silent; station 5 answers a read of input registers (FC04), which an FBs without a
# user map does not have, with exception 01.
def test_exception_replies_are_status_6_with_the_code_in_s2_plus_3(pair, transport):
    master, _ = pair("exception")
    c = master.client()
    stations, code = (2, 3), 0x0B
    if transport == "rtu":
        assert not c.write_registers(1008, [5, 1, 5, 13, 2020, 3, 0], slave=1).isError()
        stations, code = (5,), 0x01
    enable(c)
    got, _ = wait_for(lambda: status(c) >> 8 == 6, timeout=1.0)
    assert got, hex(status(c))
    assert status(c) & 0xFF in stations
    assert regs(c, 103) == [code]


# Scenario: with `unknown_unit: silent`, status 5 after ≥ 100 ms, or ≥ 500 ms with D9129 = 50
# (the time-out runs in real time). Over RTU stations 2 and 3 are silent whatever the policy.
@pytest.mark.parametrize("d9129,least", [(0, 0.100), (50, 0.500)])
def test_silent_slave_is_status_5_after_the_d9129_time_out(pair, d9129, least):
    master, _ = pair("silent")
    c = master.client()
    assert not c.write_register(8129, d9129, slave=1).isError()
    enable(c)
    # Set 2's station is the first that stays silent.
    got, took = wait_for(lambda: status(c) == 0x0502, timeout=3.0)
    assert got, hex(status(c))
    assert took >= least
    assert took < least + 0.5


def sim_seconds(c):
    lo, hi = regs(c, 3, 2, unit=247)
    return lo | hi << 16


# VB FNC149 time-out (docs/profile-vb.md, "The cycle"): D9129 is measured in real time, whatever
# the simulation does: at time scale 10000 the 500 ms time-out still takes 500 real ms while the
# scans run through well over a simulated minute.
def test_the_time_out_is_real_time_at_any_time_scale(pair):
    master, _ = pair("silent")
    c = master.client()
    assert not c.write_register(8129, 50, slave=1).isError()
    assert not c.write_register(0, 10000, slave=247).isError()
    before = sim_seconds(c)
    enable(c)
    got, took = wait_for(lambda: status(c) == 0x0502, timeout=3.0)
    assert got, hex(status(c))
    assert 0.5 <= took < 1.0
    assert sim_seconds(c) - before >= 60


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


# File registers are read-only program data: a read set whose master devices are file registers
# is status 3 and nothing lands there; the other sets go on (set 2 writes to the slave).
def test_a_read_into_file_registers_is_status_3_and_lands_nowhere(start_plcemud):
    slave = start_plcemud(slave_config())
    text = MASTER.format(mbus=tcp_mbus(slave.port), set2=5).replace("D1000: 3", "D1000: 2")
    text = text.replace("init:\n", "file_registers: D2000-D2009\ninit:\n  D2000: [9, 9]\n")
    master = start_plcemud(text)
    c = master.client()
    enable(c)
    s = slave.client()
    got, _ = wait_for(lambda: regs(s, 1000, 5, unit=5) == [11, 12, 13, 14, 15], timeout=1.0)
    assert got, "set 2 writes"
    got, _ = wait_for(lambda: status(c) == 0x0305 and regs(c, 102)[0] >= 2, timeout=1.0)
    assert got, hex(status(c))
    assert regs(c, 2000, 10) == [9, 9] + [0] * 8


# A master whose slave is down (nothing listens on the port, nothing on the other end of the
# line) keeps serving its own clients within 50 ms, and reports status 5 for every set.
def test_master_with_its_slave_down_keeps_serving(pair):
    """Every client of the master, four of them at once, is answered within 50 ms while its
    transfers to the dead slave time out one after another."""
    master, _ = pair(slave_up=False)
    clients = [master.client() for _ in range(4)]
    enable(clients[0])
    worst = [None] * len(clients)

    def poll(i):
        worst[i] = served_within(clients[i], 0.05)

    threads = [threading.Thread(target=poll, args=(i,)) for i in range(len(clients))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(w is not None and w < 0.05 for w in worst), worst
    assert status(clients[0]) >> 8 == 5
    got, _ = wait_for(lambda: regs(clients[0], 102)[0] >= 1, timeout=1.0)
    assert got, "the cycle goes on past the dead slave"


def test_stop_and_run_again_keep_mbus_polling(pair):
    """A transfer in flight when the PLC goes to STOP (the communication fault `stop`) is given
    up at the first scan in RUN, and the passes go on (MBUS once never sent again, its link
    holding that transfer's completion, until a reload)."""
    master, _ = pair(slave_up=False)
    c = master.client()
    assert not c.write_register(8129, 50, slave=1).isError()  # D9129: 0.5 s a transfer
    enable(c)
    got, _ = wait_for(lambda: status(c) >> 8 == 5, timeout=3.0)
    assert got, hex(status(c))
    assert not c.write_register(31, 1, slave=247).isError()  # STOP, a transfer in flight
    time.sleep(0.3)
    assert not c.write_register(31, 0, slave=247).isError()  # RUN
    passes = regs(c, 102)[0]
    got, _ = wait_for(lambda: regs(c, 102)[0] >= passes + 1, timeout=4.0)
    assert got, f"no pass after RUN: S2+2 stays {regs(c, 102)[0]}\n{master.log_text()}"


def polling_over_rtu(start_plcemud, pty, d9129=None):
    """A slave on one end of `pty`, a master on the other with set 1 of the table only (the
    read from station 5), EN ON and its first read landed: (slave, master, master's client)."""
    slave = start_plcemud(slave_config(device=pty.slave))
    assert slave.wait_log("listening on rtu"), slave.log_text()
    master = start_plcemud(
        MASTER.format(mbus=rtu_mbus(pty.master), set2=2).replace("D1000: 3", "D1000: 1"))
    c = master.client()
    if d9129 is not None:
        assert not c.write_register(8129, d9129, slave=1).isError()
    enable(c)
    got, _ = wait_for(lambda: regs(c, 2000, 10) == list(range(1001, 1011)), timeout=2.0)
    assert got, regs(c, 2000, 10)
    return slave, master, c


# Over RTU, a slave that stops answering (its daemon stopped) is status 5 with its station after
# the D9129 time-out, and answers again once it is back.
def test_rtu_slave_stopped_is_status_5_after_the_d9129_time_out(start_plcemud, tmp_path):
    pty = PtyPair(tmp_path)
    try:
        slave, _, c = polling_over_rtu(start_plcemud, pty, d9129=50)
        assert status(c) == 0
        stopping = time.monotonic()
        slave.stop()  # it stops answering before it has exited
        got, _ = wait_for(lambda: status(c) == 0x0505, timeout=3.0)
        took = time.monotonic() - stopping
        assert got, hex(status(c))
        # The transfer in flight when it stopped answering began at most a reply's time before.
        assert took >= 0.45
        passes = regs(c, 102)[0]
        time.sleep(1.2)
        assert 1 <= regs(c, 102)[0] - passes <= 3, "one pass per 500 ms time-out"
    finally:
        pty.stop()


def cpu_seconds(pid):
    """User + system CPU time of a process so far (/proc/PID/stat fields 14 and 15)."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / 100.0


# The master's serial device goes away (socat stopped: an unplugged adapter): status 5, one
# "lost" line, no spinning, its clients still served; once the device is back under the same
# path the next transfer opens it and polling resumes.
def test_rtu_device_that_goes_away_is_status_5_and_reopened(start_plcemud, tmp_path):
    pty = PtyPair(tmp_path)
    try:
        slave, master, c = polling_over_rtu(start_plcemud, pty)
        pty.stop()
        assert master.wait_log(f"mbus: rtu {pty.master}: lost (", timeout=3), master.log_text()
        got, _ = wait_for(lambda: status(c) == 0x0505, timeout=2.0)
        assert got, hex(status(c))
        # Idle cost with the device gone, against the same seconds with it there: a scan every
        # 10 ms and one failed open() per 100 ms time-out.
        before = cpu_seconds(master.proc.pid)
        assert served_within(c, 0.05, n=100) < 0.05
        used = cpu_seconds(master.proc.pid) - before
        assert used < 0.6, f"{used:.2f} s of CPU with the device gone\n{master.log_text()}"
        assert master.proc.poll() is None
        slave.stop()

        pty = PtyPair(tmp_path)  # the same link paths
        start_plcemud(slave_config(device=pty.slave, r0=", ".join(["7"] * 10)))
        got, _ = wait_for(lambda: regs(c, 2000, 10) == [7] * 10, timeout=3.0)
        assert got, master.log_text()
        log = master.log_text()
        assert log.count(f"mbus: rtu {pty.master}: lost (") == 1, log
        assert log.count(f"mbus: rtu {pty.master}: reopened") == 1, log
    finally:
        pty.stop()


# A device that comes and goes again and again (a loose adapter) is not two lines a flap: the
# master logs it going and coming back once each per 2 s, and counts the rest in one line.
def test_a_flapping_rtu_device_is_logged_within_a_budget(start_plcemud, tmp_path):
    pty = PtyPair(tmp_path)
    try:
        slave, master, c = polling_over_rtu(start_plcemud, pty)
        flaps = 8
        for _ in range(flaps):
            pty.stop()
            time.sleep(0.3)  # the master's read fails: lost
            pty = PtyPair(tmp_path)  # the same link paths
            time.sleep(0.3)  # the next transfer opens it again
        time.sleep(2.2)  # the window ends; the next transfer sums it up
        assert master.wait_log("more disconnects in the last 2 s", timeout=3), master.log_text()
        log = master.log_text()
        lost = log.count(f"mbus: rtu {pty.master}: lost (")
        assert 1 <= lost <= 4, log
        assert log.count(f"mbus: rtu {pty.master}: reopened") <= 4, log
        assert master.proc.poll() is None
    finally:
        pty.stop()


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
            MASTER.format(mbus=tcp_mbus(rogue.port), set2=2).replace("D1000: 3", "D1000: 1")
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
    example_polls(start_plcemud(master_text))


def example_polls(master):
    """The example master's reads land within 1 s and C0 counts its passes; returns its
    client."""
    c = master.client()
    got, _ = wait_for(lambda: regs(c, 2000, 10) == list(range(1001, 1011)), timeout=1.0)
    assert got
    got, _ = wait_for(lambda: regs(c, 9500)[0] >= 2, timeout=2.0)
    assert got, "C0 counts the passes"
    return c


# The same pair with the RTU variant their comments describe, on a pty pair of the test's own.
def test_example_pair_polls_over_rtu(start_plcemud, tmp_path):
    pty = PtyPair(tmp_path)
    try:
        slave_text = (REPO / "config" / "vb-mbus-slave.yaml").read_text()
        rtu_line = "  # rtu: {device: /tmp/plcemu-rtu-a,"
        assert rtu_line in slave_text
        slave_text = slave_text.replace(rtu_line, f"  rtu: {{device: {pty.slave},")
        slave = start_plcemud(slave_text)
        assert slave.wait_log("listening on rtu"), slave.log_text()
        master_text = (REPO / "config" / "vb-mbus.yaml").read_text()
        for line in ("  transport: tcp\n", "  tcp: {host: 127.0.0.1, port: 5021}\n",
                     "  # transport: rtu\n", "  # rtu: {device: /tmp/plcemu-rtu-b,"):
            assert line in master_text
        master_text = (
            master_text.replace("  transport: tcp\n", "")
            .replace("  tcp: {host: 127.0.0.1, port: 5021}\n", "")
            .replace("  # transport: rtu\n", "  transport: rtu\n")
            .replace("  # rtu: {device: /tmp/plcemu-rtu-b,", f"  rtu: {{device: {pty.master},")
        )
        c = example_polls(start_plcemud(master_text))
        assert status(c) >> 8 == 5, "stations 2 and 3 go unanswered on a serial line"
    finally:
        pty.stop()


# ------------------------------------------------------------------------------ SIGHUP reload


def reload(daemon, text):
    """Rewrites the daemon's config, sends SIGHUP and waits for the reload to end either way;
    returns the log lines it added."""
    before = daemon.log_text()
    with open(daemon.config_path, "w") as f:
        f.write(text)
    daemon.proc.send_signal(signal.SIGHUP)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        added = daemon.log_text()[len(before):]
        if "reload: done" in added or "configuration rejected" in added:
            return added
        time.sleep(0.02)
    pytest.fail(f"no end of reload in the log\n{daemon.log_text()}")


def values(start, n=10):
    return list(range(start, start + n))


def r0_of(start):
    return ", ".join(str(v) for v in values(start))


def bad_reload_keeps_polling(master, mbus, error, slave):
    """A reload with `mbus` is rejected with `error`, and the master still polls `slave`: new
    values there land in D2000-D2009."""
    added = reload(master, MASTER.format(mbus=mbus, set2=2))
    assert "configuration rejected" in added and error in added, added
    assert not slave.client().write_registers(0, values(3001), slave=5).isError()
    c = master.client()
    got, _ = wait_for(lambda: regs(c, 2000, 10) == values(3001), timeout=1.0)
    assert got, "still polling where it did"
    assert master.proc.poll() is None


# A reload that gives station 5 a route of its own moves its transfers there; the statuses and
# the pass counter go on; a reload the config check rejects keeps the master polling where it
# did.
def test_reload_routes_the_tcp_master_elsewhere_and_a_bad_reload_keeps_it(start_plcemud):
    a = start_plcemud(slave_config(r0=r0_of(1001)))
    b = start_plcemud(slave_config(r0=r0_of(2001)))
    master = start_plcemud(MASTER.format(mbus=tcp_mbus(a.port), set2=2))
    c = master.client()
    enable(c)
    got, _ = wait_for(lambda: regs(c, 2000, 10) == values(1001), timeout=1.0)
    assert got

    routed = f'{{tcp: {{host: 127.0.0.1, port: {a.port}}}, routes: {{5: "127.0.0.1:{b.port}"}}}}'
    added = reload(master, MASTER.format(mbus=routed, set2=2))
    assert "reload: done" in added and "mbus: changed" in added, added
    got, _ = wait_for(lambda: regs(c, 2000, 10) == values(2001), timeout=1.0)
    assert got, regs(c, 2000, 10)
    # Stations 2 and 3 still go to `a`, which answers them with exception 0Bh.
    got, _ = wait_for(lambda: status(c) >> 8 == 6 and regs(c, 103) == [0x0B], timeout=1.0)
    assert got, hex(status(c))
    passes = regs(c, 102)[0]
    got, _ = wait_for(lambda: regs(c, 102)[0] >= passes + 2, timeout=1.0)
    assert got, "passes go on after the reload"

    bad_reload_keeps_polling(master, "{tcp: {host: plc.local, port: 502}}",
                             "expected an IP address", b)


# Over RTU, a reload naming another device moves the master to it (the old line is closed); a
# rejected reload keeps it on the device it polls.
def test_reload_moves_the_rtu_master_to_another_device(start_plcemud, tmp_path):
    first = PtyPair(new_dir(tmp_path, "pty"))
    second = PtyPair(new_dir(tmp_path, "pty"))
    try:
        a = start_plcemud(slave_config(device=first.slave, r0=r0_of(1001)))
        b = start_plcemud(slave_config(device=second.slave, r0=r0_of(2001)))
        for d in (a, b):
            assert d.wait_log("listening on rtu"), d.log_text()
        master = start_plcemud(MASTER.format(mbus=rtu_mbus(first.master), set2=2))
        c = master.client()
        enable(c)
        got, _ = wait_for(lambda: regs(c, 2000, 10) == values(1001), timeout=1.0)
        assert got

        added = reload(master, MASTER.format(mbus=rtu_mbus(second.master), set2=2))
        assert "reload: done" in added and f"mbus: master via rtu {second.master}" in added, added
        got, _ = wait_for(lambda: regs(c, 2000, 10) == values(2001), timeout=1.0)
        assert got, regs(c, 2000, 10)
        got, _ = wait_for(lambda: status(c) == 0x0502, timeout=1.0)
        assert got, hex(status(c))

        bad_reload_keeps_polling(master, "{transport: rtu}", "transport rtu needs rtu:", b)
    finally:
        first.stop()
        second.stop()


# A reload that names a device not there yet keeps the master port: status 5 meanwhile, and the
# first transfer after the device appears opens it.
def test_reload_to_a_device_not_there_yet_is_status_5_until_it_appears(start_plcemud, tmp_path):
    first = PtyPair(new_dir(tmp_path, "pty"))
    later = new_dir(tmp_path, "pty")
    second = None
    try:
        _, master, c = polling_over_rtu(start_plcemud, first)
        device = str(later / "plcemu-rtu-b")  # PtyPair's name for its master end
        added = reload(master, MASTER.format(mbus=rtu_mbus(device), set2=2))
        assert "reload: done" in added and "trying again at every transfer" in added, added
        got, _ = wait_for(lambda: status(c) >> 8 == 5, timeout=1.0)
        assert got, hex(status(c))
        assert served_within(c, 0.05, n=30) < 0.05

        second = PtyPair(later)
        assert second.master == device
        slave = start_plcemud(slave_config(device=second.slave, r0=r0_of(2001)))
        assert slave.wait_log("listening on rtu"), slave.log_text()
        got, _ = wait_for(lambda: regs(c, 2000, 10) == values(2001), timeout=2.0)
        assert got, master.log_text()
        assert f"mbus: rtu {device}: opened" in master.log_text()
    finally:
        first.stop()
        if second:
            second.stop()
