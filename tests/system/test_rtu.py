"""Modbus RTU slave (docs/profile-fbs.md, "Modbus RTU (serial)") through a socat pty pair made
by scripts/rtu-pty.sh, with pymodbus' serial client, mbpoll, and exact raw frames.

The pty ignores the baud rate, but plcemud times frames by it: the tests that depend on gaps run
the line at 300 baud (t1.5 = 55 ms, t3.5 = 128 ms) so that a busy test machine cannot blur them.
"""

import os
import re
import signal
import struct
import subprocess
import time
from pathlib import Path

import pytest
import json
import urllib.request

from conftest import free_port, run_plcemud
from pymodbus.client import ModbusSerialClient
from pymodbus.diag_message import ReturnBusMessageCountRequest
from pymodbus.mei_message import ReadDeviceInformationRequest
from pymodbus.other_message import ReportSlaveIdRequest
from pymodbus.pdu import ExceptionResponse
from rtu_pty import PtyPair, RawLine, crc16, echoing, frame, rtu_config

# FC02 and FC04 need the user maps (FBs manual 13-50/51): DI 0.. -> M100.., IR 0.. -> R200...
USER_MAPS = "init:\n  R3972: [0, 100, 16]\n  R3975: [0, 200, 8]\n"


@pytest.fixture
def start_rtu(start_plcemud, pty):
    """start_rtu(extra_rtu="", extra="") -> Daemon serving RTU on pty.slave (and TCP)."""

    def start(extra_rtu: str = "", extra: str = USER_MAPS):
        d = start_plcemud(rtu_config(pty.slave, extra_rtu, extra))
        assert d.wait_log("listening on rtu"), d.log_text()
        return d

    return start


@pytest.fixture
def line(pty):
    raw = RawLine(pty.master)
    yield raw
    raw.close()


def serial_client(path, **kw) -> ModbusSerialClient:
    # A pty carries bytes whatever the parity, and pyserial's tcsetattr with parity on a pty
    # fails (EINVAL) on some kernels: the client end stays N, the daemon's end says E.
    kw.setdefault("baudrate", 9600)
    kw["parity"] = "N"
    c = ModbusSerialClient(path, bytesize=8, stopbits=kw.pop("stopbits", 1), timeout=1,
                           retries=1, **kw)
    assert c.connect()
    return c


def ok(r):
    assert not r.isError(), f"unexpected error reply: {r}"
    return r


def exception_code(r) -> int:
    assert isinstance(r, ExceptionResponse), f"expected an exception, got {r}"
    return r.exception_code


def version() -> str:
    return run_plcemud("--version").stdout.split()[-1]


def mbpoll(device, *args, write=(), baud=9600, parity="even"):
    """Runs mbpoll once; values to write come after the device, as mbpoll wants them."""
    cmd = ["mbpoll", "-m", "rtu", "-b", str(baud), "-P", parity, "-o", "1", *map(str, args),
           device, *map(str, write)]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=20)


def mbpoll_values(out: str) -> dict:
    return {int(a): int(v) for a, v in re.findall(r"^\[(\d+)\]:\s+(-?\d+)", out, re.M)}


def read_words_pdu(addr, qty, fc=3):
    return struct.pack(">BHH", fc, addr, qty)


# --------------------------------------------------------------------------- line settings


def test_default_line_is_9600_8e1_and_logged(start_rtu, pty):
    d = start_rtu()
    assert f"listening on rtu {pty.slave} 9600 8E1" in d.log_text()
    c = serial_client(pty.master)
    assert ok(c.read_holding_registers(4055, 1, slave=1)).registers == [1]  # R4055 station
    c.close()


@pytest.mark.parametrize("baud,parity,stop,text", [(19200, "O", 2, "19200 8O2"),
                                                   (115200, "N", 1, "115200 8N1")])
def test_other_line_settings(start_rtu, pty, baud, parity, stop, text):
    d = start_rtu(f"baud: {baud}, parity: {parity}, stop_bits: {stop}")
    assert f"listening on rtu {pty.slave} {text}" in d.log_text()
    c = serial_client(pty.master, baudrate=baud, parity=parity, stopbits=stop)
    assert ok(c.write_register(30, 777, slave=1))
    assert ok(c.read_holding_registers(30, 1, slave=1)).registers == [777]
    c.close()


def test_a_line_a_pty_takes_in_part_is_opened_again_at_a_restart_and_a_reload(start_rtu, line,
                                                                               pty):
    # A pty takes the speed and ignores parity (8E1 is the default). Opened a second time with
    # the same settings it finds nothing left it can change, which the C library answers
    # EINVAL: a restart on the same pty exited 1 ("cannot configure ..."), and every reload that
    # opened the line again lost it. A reload opens it again when its settings change (an
    # unchanged line stays open).
    pdu = read_words_pdu(4055, 1)
    first = start_rtu()
    assert line.request(1, pdu, 7) == bytes([3, 2, 0, 1])
    assert first.stop() == 0
    d = start_rtu()
    assert line.request(1, pdu, 7) == bytes([3, 2, 0, 1]), d.log_text()
    assert "did not take every line setting" in d.log_text()
    Path(d.config_path).write_text(rtu_config(pty.slave, "parity: O", USER_MAPS))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log(f"listening on rtu {pty.slave} 9600 8O1"), d.log_text()
    assert line.request(1, pdu, 7) == bytes([3, 2, 0, 1]), d.log_text()
    assert "cannot configure" not in d.log_text()


def test_missing_device_is_a_clear_startup_error(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(rtu_config(str(tmp_path / "no-such-tty")))
    r = run_plcemud("-c", cfg, "--port", "0", timeout=10)
    assert r.returncode != 0
    assert "no-such-tty" in r.stderr


# --------------------------------------------------------------------------- function codes


def test_pymodbus_serial_every_function_code(start_rtu, pty):
    start_rtu()
    c = serial_client(pty.master)
    # 06 / 03: R10
    ok(c.write_register(10, 0x1234, slave=1))
    assert ok(c.read_holding_registers(10, 1, slave=1)).registers == [0x1234]
    # 16 / 03: D0-D2 (register 6000)
    ok(c.write_registers(6000, [1, 2, 3], slave=1))
    assert ok(c.read_holding_registers(6000, 3, slave=1)).registers == [1, 2, 3]
    # 05 / 01: M0 (coil 2000)
    ok(c.write_coil(2000, True, slave=1))
    assert ok(c.read_coils(2000, 2, slave=1)).bits[:2] == [True, False]
    # 15 / 01: Y0-Y2
    ok(c.write_coils(0, [True, False, True], slave=1))
    assert ok(c.read_coils(0, 3, slave=1)).bits[:3] == [True, False, True]
    # 22 mask write: (0x1234 AND 00FFh) OR (5600h AND NOT 00FFh)
    # (pymodbus rc1: these two take the request's own `unit=`, not `slave=`)
    ok(c.mask_write_register(10, 0x00FF, 0x5600, unit=1))
    assert ok(c.read_holding_registers(10, 1, slave=1)).registers == [0x5634]
    # 23 read/write: the write happens first
    r = ok(c.readwrite_registers(read_address=10, read_count=2, write_address=11,
                                 write_registers=[0x0BAD], unit=1))
    assert r.registers == [0x5634, 0x0BAD]
    # 02: DI 0.. -> M100..
    ok(c.write_coil(2100, True, slave=1))
    assert ok(c.read_discrete_inputs(0, 3, slave=1)).bits[:3] == [True, False, False]
    # 04: IR 0.. -> R200..
    ok(c.write_registers(200, [42, 43], slave=1))
    assert ok(c.read_input_registers(0, 2, slave=1)).registers == [42, 43]
    # 08 subfunction 00: the data comes back
    # (pymodbus rc1's RTU framer expects exactly one data word back for FC08)
    r = ok(c.diag_query_data(0xA55A, slave=1))
    assert list(r.message) == [0xA55A]
    # 11h: slave ID (the station), run indicator FFh, then the identification text
    r = ok(c.execute(ReportSlaveIdRequest(unit=1)))
    assert r.identifier[0] == 1 and r.identifier[1] == 0xFF
    assert b"FATEK FBs-24MC" in r.identifier
    # 2Bh/0Eh basic, regular and individual
    r = ok(c.execute(ReadDeviceInformationRequest(read_code=1, object_id=0, unit=1)))
    assert r.information == {0: b"FATEK", 1: b"FBs-24MC", 2: version().encode()}
    r = ok(c.execute(ReadDeviceInformationRequest(read_code=2, object_id=0, unit=1)))
    assert r.information[5] == b"FBs-24MC"  # ModelName, a regular object
    r = ok(c.execute(ReadDeviceInformationRequest(read_code=4, object_id=1, unit=1)))
    assert r.information == {1: b"FBs-24MC"}
    c.close()


def test_pymodbus_serial_exceptions(start_rtu, pty):
    start_rtu(extra="")  # no user maps: FC02/FC04 are not served
    c = serial_client(pty.master)
    assert exception_code(c.read_holding_registers(4500, 1, slave=1)) == 2  # unmapped
    assert exception_code(c.write_register(3850, 1, slave=1)) == 2  # IR is read-only
    assert exception_code(c.read_holding_registers(0, 126, slave=1)) == 3  # > 125
    assert exception_code(c.read_discrete_inputs(0, 1, slave=1)) == 1  # no user map
    assert exception_code(c.read_input_registers(0, 1, slave=1)) == 1  # no user map
    assert exception_code(c.read_exception_status(slave=1)) == 1  # FC07 not implemented
    assert exception_code(c.execute(ReturnBusMessageCountRequest(unit=1))) == 1  # FC08 sub 0Bh
    c.close()


def test_raw_exceptions_for_other_function_codes(start_rtu, line):
    start_rtu()
    # FC08/00 echoes any amount of data
    echo = b"\x08\x00\x00" + bytes(range(50))
    assert line.request(1, echo, len(echo) + 3) == echo
    for pdu in (b"\x41", b"\x2b\x0d\x00\x00", b"\x14\x00"):
        assert line.request(1, pdu, 5) == bytes([pdu[0] | 0x80, 1]), pdu.hex()
    # 2Bh/0Eh with an unknown read code: 03; an unknown individual object: 02
    assert line.request(1, b"\x2b\x0e\x05\x00", 5) == b"\xab\x03"
    assert line.request(1, b"\x2b\x0e\x04\x42", 5) == b"\xab\x02"
    # FC05 with a value other than 0000h/FF00h: 03
    assert line.request(1, b"\x05\x07\xd0\x12\x34", 5) == b"\x85\x03"


def test_mbpoll_rtu(start_rtu, pty):
    start_rtu()
    dev = pty.master
    r = mbpoll(dev, "-a", 1, "-0", "-r", 6010, "-t", 4, write=(11, 22, 33))  # FC16
    assert r.returncode == 0 and "Written 3 references" in r.stdout, r.stdout + r.stderr
    r = mbpoll(dev, "-a", 1, "-0", "-r", 6010, "-c", 3, "-1")  # FC03
    assert mbpoll_values(r.stdout) == {6010: 11, 6011: 22, 6012: 33}, r.stdout
    r = mbpoll(dev, "-a", 1, "-0", "-r", 6013, "-t", 4, write=(44,))  # FC06
    assert r.returncode == 0, r.stdout + r.stderr
    r = mbpoll(dev, "-a", 1, "-0", "-r", 6013, "-1")
    assert mbpoll_values(r.stdout) == {6013: 44}, r.stdout
    r = mbpoll(dev, "-a", 1, "-0", "-r", 2000, "-t", 0, write=(1, 0, 1))  # FC15: M0-M2
    assert r.returncode == 0, r.stdout + r.stderr
    r = mbpoll(dev, "-a", 1, "-0", "-r", 2001, "-t", 0, write=(1,))  # FC05: M1
    assert r.returncode == 0, r.stdout + r.stderr
    r = mbpoll(dev, "-a", 1, "-0", "-r", 2000, "-c", 3, "-t", 0, "-1")  # FC01
    assert mbpoll_values(r.stdout) == {2000: 1, 2001: 1, 2002: 1}, r.stdout
    r = mbpoll(dev, "-a", 1, "-0", "-r", 0, "-c", 2, "-t", 1, "-1")  # FC02: M100-M101
    assert mbpoll_values(r.stdout) == {0: 0, 1: 0}, r.stdout
    r = mbpoll(dev, "-a", 1, "-0", "-r", 200, "-t", 4, write=(9,))
    r = mbpoll(dev, "-a", 1, "-0", "-r", 0, "-t", 3, "-1")  # FC04: R200
    assert mbpoll_values(r.stdout) == {0: 9}, r.stdout
    r = mbpoll(dev, "-a", 1, "-u")  # FC11h
    assert re.search(r"Id\s*:\s*0x01", r.stdout) and re.search(r"Status\s*:\s*On", r.stdout)
    assert "FATEK FBs-24MC" in r.stdout
    r = mbpoll(dev, "-a", 1, "-0", "-r", 4500, "-1")  # exception 02
    assert "Illegal data address" in r.stdout + r.stderr, r.stdout + r.stderr


# --------------------------------------------------------------------------- unit IDs


def test_broadcast_writes_apply_without_answer(start_rtu, line):
    d = start_rtu()
    line.send(frame(0, struct.pack(">BHH", 6, 20, 0x0B0B)))  # FC06 R20
    assert line.silent(0.5)
    line.send(frame(0, struct.pack(">BHHB3H", 16, 6020, 3, 6, 7, 8, 9)))  # FC16 D20-D22
    assert line.silent(0.5)
    line.send(frame(0, struct.pack(">BHH", 5, 2050, 0xFF00)))  # FC05 M50
    assert line.silent(0.5)
    # read back via unit 1 on the line, and over TCP
    assert line.request(1, read_words_pdu(20, 1), 7) == b"\x03\x02\x0b\x0b"
    assert line.request(1, read_words_pdu(6020, 3), 11) == b"\x03\x06\x00\x07\x00\x08\x00\x09"
    t = d.client()
    assert ok(t.read_coils(2050, 1, slave=1)).bits[0] is True


def test_broadcast_reads_and_others_get_no_answer(start_rtu, line):
    start_rtu()
    for pdu in (read_words_pdu(0, 1), read_words_pdu(0, 1, fc=1), b"\x08\x00\x00\x12\x34",
                b"\x11", b"\x2b\x0e\x01\x00", b"\x41", read_words_pdu(4500, 1)):
        line.send(frame(0, pdu))
        assert line.silent(0.4), pdu.hex()
    # the line still works
    assert line.request(1, read_words_pdu(4055, 1), 7) == b"\x03\x02\x00\x01"


def test_other_stations_get_no_answer(start_rtu, line):
    start_rtu(extra="station: 5\n")
    for unit in (1, 2, 4, 6, 255, 246):
        line.send(frame(unit, read_words_pdu(0, 1)))
        assert line.silent(0.4), unit
    # the simulator-control unit (docs/simulator-and-plant.md, 247 by default) is served on the
    # line too
    line.send(frame(247, read_words_pdu(0, 1)))
    r = line.receive(5, timeout=1)
    assert r[:1] == b"\xf7", r.hex()
    line.silent(0.2)
    assert line.request(5, read_words_pdu(4055, 1), 7) == b"\x03\x02\x00\x05"


def test_station_changed_through_r4055(start_rtu, line):
    d = start_rtu()
    t = d.client()
    ok(t.write_register(4055, 0x5509, slave=1))  # 55xxh sets the station (docs/profile-fbs.md)
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        r = t.read_holding_registers(4055, 1, slave=9)
        if not r.isError():
            break
        time.sleep(0.05)
    line.send(frame(1, read_words_pdu(4055, 1)))
    assert line.silent(0.4)
    assert line.request(9, read_words_pdu(4055, 1), 7)[:2] == b"\x03\x02"


def test_bad_crc_gets_no_answer(start_rtu, line):
    start_rtu()
    good = frame(1, read_words_pdu(0, 2))
    for bad in (good[:-1] + bytes([good[-1] ^ 0x01]), good[:-2] + good[-1:] + good[-2:-1],
                bytes([good[0], good[1] ^ 0x10]) + good[2:]):
        line.send(bad)
        assert line.silent(0.4), bad.hex()
    assert line.request(1, read_words_pdu(0, 2), 9)[:2] == b"\x03\x04"


# --------------------------------------------------------------------------- timing


def test_frame_split_inside_t15_is_answered(start_rtu, line):
    start_rtu("baud: 300")  # t1.5 = 55 ms, t3.5 = 128 ms
    f = frame(1, read_words_pdu(4055, 1))
    line.send(f[:3])
    time.sleep(0.010)
    line.send(f[3:])
    r = line.receive(7, timeout=2)
    assert r[:5] == b"\x01\x03\x02\x00\x01" and crc16(r[:5]) == r[5] | r[6] << 8, r.hex()


def test_pause_longer_than_t15_inside_a_frame_drops_it(start_rtu, line):
    start_rtu("baud: 300")
    f = frame(1, read_words_pdu(4055, 1))
    # The last byte follows a pause of about 105 - 37 = 68 ms > t1.5 (55 ms) on the wire; any
    # longer pause (t3.5, 128 ms) splits the frame instead: no answer either way.
    line.send(f[:-1])
    time.sleep(0.105)
    line.send(f[-1:])
    assert line.silent(1.0)
    assert line.request(1, read_words_pdu(4055, 1), 7) == b"\x03\x02\x00\x01"


def test_two_frames_without_t35_between_are_not_answered(start_rtu, line):
    start_rtu()
    f = frame(1, read_words_pdu(4055, 1))
    line.send(f + f)  # one frame of 16 bytes as far as the line can tell: bad CRC
    assert line.silent(0.5)


# --------------------------------------------------------------------------- both transports


def test_rtu_and_tcp_share_the_image(start_rtu, pty):
    d = start_rtu()
    s = serial_client(pty.master)
    t = d.client()
    ok(t.write_registers(100, [5, 6, 7], slave=1))
    assert ok(s.read_holding_registers(100, 3, slave=1)).registers == [5, 6, 7]
    ok(s.write_registers(6100, [0xAAAA, 0x5555], slave=1))
    assert ok(t.read_holding_registers(6100, 2, slave=1)).registers == [0xAAAA, 0x5555]
    ok(s.write_coil(2200, True, slave=1))
    assert ok(t.read_coils(2200, 1, slave=1)).bits[0] is True
    ok(t.write_coil(2200, False, slave=1))
    assert ok(s.read_coils(2200, 1, slave=1)).bits[0] is False
    # interleaved, many times: each side sees the other's last write
    for i in range(20):
        ok(t.write_register(120, i, slave=1))
        assert ok(s.read_holding_registers(120, 1, slave=1)).registers == [i]
        ok(s.write_register(121, 1000 + i, slave=1))
        assert ok(t.read_holding_registers(121, 1, slave=1)).registers == [1000 + i]
    s.close()


def test_unread_replies_never_block_tcp(start_rtu, line):
    """A master that sends requests and never reads the replies fills the pty's buffers; the
    replies are written without blocking (dropped or cut short when they do not fit), so TCP
    goes on."""
    d = start_rtu("baud: 115200")
    t = d.client()
    req = frame(1, read_words_pdu(6000, 125))  # 255-byte replies
    for _ in range(600):  # 150 kB of replies; a pty pair holds about 40 kB
        line.send(req)
        time.sleep(0.003)  # more than t3.5 (1.75 ms): separate frames
    assert ok(t.read_holding_registers(4055, 1, slave=1)).registers == [1]
    assert d.proc.poll() is None
    # drain what did get through, then the line answers again
    while not line.silent(0.3):
        pass
    assert line.request(1, read_words_pdu(4055, 1), 7) == b"\x03\x02\x00\x01"


# --------------------------------------------------------------------------- device going away


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process so far (/proc/PID/stat fields 14 and 15)."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


@pytest.mark.parametrize("pdu, reply, baud, delay", [
    (b"\x06\x00\x1e\x03\x09", b"\x06\x00\x1e\x03\x09", 9600, 0),  # a write's reply repeats it
    (b"\x03\x00\x1e\x00\x01", b"\x03\x02\x03\x09", 9600, 0),        # read back R30
    # A USB adapter hands the echo back in batches: 16 ms late (an FTDI chip's timer).
    (b"\x06\x00\x1e\x03\x09", b"\x06\x00\x1e\x03\x09", 115200, 0.016),
])
def test_a_line_that_echoes_gets_one_answer_a_request(start_plcemud, tmp_path, pdu, reply, baud,
                                                      delay):
    """An RS-485 adapter with local echo hands the slave its own answer: read as a request, it
    is answered (a write's reply is the write again, an FC03 reply a malformed FC03 whose
    exception comes back as a function 83h), for ever. With `echo: true` the echo is dropped:
    one answer, and the master's own requests are served as before."""
    pair = PtyPair(tmp_path)
    try:
        d = start_plcemud(rtu_config(pair.slave, f"parity: N, baud: {baud}, echo: true"))
        assert d.wait_log("listening on rtu"), d.log_text()
        assert "(echo dropped)" in d.log_text(), d.log_text()
        c = d.client()
        assert not c.write_register(30, 0x0309, slave=1).isError()
        got = echoing(pair.master, frame(1, pdu), seconds=1.0, delay=delay)
        assert got == frame(1, reply), got.hex()
        assert c.read_holding_registers(30, 1, slave=1).registers == [0x0309]
        # A master on a line that (for once) gave no echo is served: its request is no echo.
        line = RawLine(pair.master)
        try:
            for _ in range(2):
                time.sleep(0.3)
                assert line.request(1, pdu, len(frame(1, reply))) == reply
        finally:
            line.close()
    finally:
        pair.stop()


def test_a_master_repeating_a_write_at_once_is_answered_every_time(start_plcemud, tmp_path):
    """Without `echo`, nothing is taken for an echo: a write repeated as soon as its reply came
    (the reply is the request, byte for byte) is answered each time."""
    pair = PtyPair(tmp_path)
    try:
        d = start_plcemud(rtu_config(pair.slave, "parity: N"))
        assert d.wait_log("listening on rtu"), d.log_text()
        line = RawLine(pair.master)
        try:
            pdu = b"\x06\x00\x1e\x03\x09"
            for _ in range(20):
                assert line.request(1, pdu, 8) == pdu
        finally:
            line.close()
    finally:
        pair.stop()


def console_listeners(port: int) -> str:
    """The console's listeners of the one PLC (GET /api/v1/plcs)."""
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/api/v1/plcs", timeout=5) as r:
        return json.load(r)["plcs"][0]["listeners"]


def wait_listeners(port: int, wanted, timeout: float = 10.0) -> str:
    deadline = time.monotonic() + timeout
    while True:
        text = console_listeners(port)
        if wanted(text) or time.monotonic() > deadline:
            return text
        time.sleep(0.1)


def test_console_says_while_a_line_waits_for_its_device(start_plcemud, tmp_path):
    """The listeners the console lists were described at the start and at reloads only: a
    serial line whose device was unplugged was listed as if it served. It says it waits for its
    device while it does, and no longer once the device is back."""
    pair = PtyPair(tmp_path)
    http = free_port()
    try:
        d = start_plcemud(rtu_config(pair.slave, "parity: N",
                                     f"http: {{bind: 127.0.0.1, port: {http}}}\n"))
        assert d.wait_log("listening on rtu"), d.log_text()
        served = console_listeners(http)
        assert f"rtu {pair.slave}" in served and "waiting" not in served, served

        pair.stop()
        assert d.wait_log(f"rtu: {pair.slave}: lost (", timeout=3), d.log_text()
        waiting = wait_listeners(http, lambda t: "waiting" in t)
        assert f"rtu {pair.slave}" in waiting, waiting
        assert "(waiting for the device)" in waiting, waiting

        pair = PtyPair(tmp_path)  # the same link paths
        line = RawLine(pair.master)
        back = wait_listeners(http, lambda t: "waiting" not in t)  # the back-off is at most 5 s
        assert f"rtu {pair.slave}" in back and "waiting" not in back, (back, d.log_text())
        line.close()
    finally:
        pair.stop()


def test_device_that_goes_away_is_reopened_with_back_off(start_plcemud, tmp_path):
    """socat restarted (a USB adapter unplugged and plugged back): the daemon closes the dead
    port, reopens the same path with back-off while using no CPU to speak of, answers again once
    it is back, and says so once each way."""
    pair = PtyPair(tmp_path)
    try:
        d = start_plcemud(rtu_config(pair.slave, "parity: N"))  # ptys refuse parity settings
        assert d.wait_log("listening on rtu"), d.log_text()
        line = RawLine(pair.master)
        assert line.request(1, read_words_pdu(4055, 1), 7) == b"\x03\x02\x00\x01"

        pair.stop()  # still open on this side: socat's end, not the master's, goes away
        line.close()
        assert d.wait_log(f"rtu: {pair.slave}: lost (", timeout=3), d.log_text()
        before = cpu_seconds(d.proc.pid)
        time.sleep(2)
        used = cpu_seconds(d.proc.pid) - before
        assert used < 0.3, f"{used:.2f} s of CPU in 2 s with the port gone\n{d.log_text()}"
        assert d.proc.poll() is None

        pair = PtyPair(tmp_path)  # the same link paths
        line = RawLine(pair.master)
        expected = frame(1, b"\x03\x02\x00\x01")
        deadline = time.monotonic() + 10  # the back-off is at most 5 s
        while True:
            line.send(frame(1, read_words_pdu(4055, 1)))  # flushed if sent before the reopen
            if line.receive(len(expected), timeout=0.5) == expected:
                break
            assert time.monotonic() < deadline, f"no answer after the restart\n{d.log_text()}"
            line.silent(0.1)
        # Checked while the line is still open: closing this end makes socat exit, a new loss.
        log = d.log_text()
        assert log.count(f"rtu: {pair.slave}: lost (") == 1, log
        assert log.count(f"rtu: {pair.slave}: reopened") == 1, log
        line.close()
    finally:
        pair.stop()
