"""Stepping many PLCs of one `plcs:` process at once (docs/simulator-and-plant.md, "Step";
docs/performance.md, "Stepping many PLCs"): the queued scans of every stepped PLC share one
slice of the event loop per turn, so a read of an idle PLC in the same process waits for one
slice, not one per stepped PLC; every queued scan still runs, in order, with exact simulated
time."""

import socket
import struct
import time

from conftest import free_port, raw_exchange
from test_plcs import spawn

STEPPERS = 10
SIM_BASE = 100  # PLC i's simulator unit
READ_R0 = struct.pack(">BHH", 3, 0, 1)


def plcs(port: int, program: str = "") -> str:
    """PLC 0 (station 1) idle, PLCs 1…STEPPERS to be stepped, all behind one listener."""
    out = "plcs:\n"
    for i in range(1 + STEPPERS):
        out += (
            f"  - {{name: plc{i}, profile: fbs, station: {i + 1}, simulator: {{unit: "
            f"{SIM_BASE + i}}}, persistence: {{enabled: false}},\n"
            f"     modbus: {{tcp: {{bind: 127.0.0.1, port: {port}}}}}{program}}}\n"
        )
    return out


def send_all(s: socket.socket, requests) -> None:
    """Pipelines (unit, pdu) requests on `s`, then takes every reply."""
    s.sendall(
        b"".join(
            struct.pack(">HHHB", tid, 0, len(pdu) + 1, unit) + pdu
            for tid, (unit, pdu) in enumerate(requests, 1)
        )
    )
    for _ in requests:
        head = b""
        while len(head) < 7:
            head += s.recv(7 - len(head))
        length = struct.unpack(">HHHB", head)[2] - 1
        body = b""
        while len(body) < length:
            body += s.recv(length - len(body))
        assert body[0] in (3, 6), body


def sim_seconds(s: socket.socket, unit: int) -> int:
    lo, hi = struct.unpack(">HH", raw_exchange(s, struct.pack(">BHH", 3, 3, 2), unit)[2:6])
    return hi << 16 | lo


def queued(s: socket.socket, unit: int) -> int:
    return struct.unpack(">H", raw_exchange(s, struct.pack(">BHH", 3, 2, 1), unit)[2:4])[0]


def freeze(s: socket.socket) -> None:
    send_all(s, [(SIM_BASE + i, struct.pack(">BHH", 6, 1, 1)) for i in range(1, 1 + STEPPERS)])


def step(s: socket.socket, scans_per_write: int, writes: int, steppers: int = STEPPERS) -> None:
    """Queues `writes` steps of `scans_per_write` scans on the first `steppers` stepped PLCs, in
    one burst (0 scans: cancels)."""
    requests = []
    for i in range(1, 1 + steppers):
        requests += [(SIM_BASE + i, struct.pack(">BHH", 6, 2, scans_per_write))] * writes
    send_all(s, requests)


def idle_reads(s: socket.socket, steppers: int, seconds: float):
    """Reads R0 of the idle PLC every 2 ms for `seconds` while `steppers` PLCs step; returns the
    sorted read times and the simulated seconds each stepped PLC ran meanwhile."""
    step(s, 65535, 64, steppers)  # far more than runs during the reads
    start = [sim_seconds(s, SIM_BASE + i) for i in range(1, 1 + steppers)]
    times = []
    end = time.monotonic() + seconds
    tid = 1
    while time.monotonic() < end:
        tid += 1
        t0 = time.perf_counter()
        assert raw_exchange(s, READ_R0, 1, tid)[0] == 3
        times.append(time.perf_counter() - t0)
        time.sleep(0.002)
    ran = [sim_seconds(s, SIM_BASE + i) - t for i, t in enumerate(start, 1)]
    # Still stepping when the reads ended: they were all taken under load.
    assert all(queued(s, SIM_BASE + i) > 0 for i in range(1, 1 + steppers))
    step(s, 0, 1, steppers)
    return sorted(times), ran


def test_an_idle_plc_is_read_as_fast_while_ten_plcs_step_as_while_one_does(tmp_path):
    port = free_port()
    # Scans of 50 MOVs: heavy enough that a slice runs few of them.
    program = ", program: [" + ", ".join(f"MOV: {{s: K{i}, d: D{i}}}" for i in range(50)) + "]"
    d = spawn(tmp_path, plcs(port, program), [port])
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
            s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            freeze(s)
            one, _ = idle_reads(s, 1, 2.0)
            ten, ran = idle_reads(s, STEPPERS, 2.0)
    finally:
        d.stop()
    p50 = {n: round(t[len(t) // 2] * 1e3, 1) for n, t in ((1, one), (10, ten))}
    p99 = {n: round(t[int(len(t) * 0.99)] * 1e3, 1) for n, t in ((1, one), (10, ten))}
    figures = f"p50 {p50}, p99 {p99} ms"
    # One slice per loop turn however many PLCs step: ten cost about what one does. Before, each
    # stepped PLC had a slice of its own and ten multiplied the wait (under ASan on a loaded
    # 2-core machine: p50 13 -> 108 ms, p99 50 -> 198 ms).
    # The median is the figure asserted: a p99 of a two-second run on a shared machine is its
    # second or third worst read, the machine's more than the daemon's (it stays in the message).
    assert p50[10] < 3 * p50[1] + 5, figures
    # Round-robin: every stepped PLC got its share of the scans (whole simulated seconds each).
    assert sum(ran) > 0 and max(ran) <= 2 * min(ran) + 1, ran


def test_every_queued_scan_of_every_stepped_plc_runs_in_exact_simulated_time(tmp_path):
    port = free_port()
    d = spawn(tmp_path, plcs(port), [port])
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
            # Past each PLC's first scan: a PLC frozen before it steps its first scan at
            # simulated time 0, and N steps then end one scan period short of N periods.
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline and not all(
                sim_seconds(s, SIM_BASE + i) > 0 for i in range(1, 1 + STEPPERS)
            ):
                time.sleep(0.1)
            freeze(s)
            start = [sim_seconds(s, SIM_BASE + i) for i in range(1, 1 + STEPPERS)]
            # Two writes of 3000 scans of 10 ms each: 60 simulated seconds on every PLC.
            step(s, 3000, 2)
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and any(
                queued(s, SIM_BASE + i) for i in range(1, 1 + STEPPERS)
            ):
                time.sleep(0.1)
            ran = [sim_seconds(s, SIM_BASE + i) - t for i, t in enumerate(start, 1)]
            assert ran == [60] * STEPPERS
            # Frozen: nothing more runs.
            time.sleep(0.3)
            assert [sim_seconds(s, SIM_BASE + i) for i in range(1, 1 + STEPPERS)] == [
                t + 60 for t in start
            ]
    finally:
        d.stop()
