#!/usr/bin/env python3
"""Read latency of an idle PLC while other PLCs of the same `plcs:` process are stepped through
their simulator units (docs/performance.md, "Stepping many PLCs"). Starts PLCEMUD on a config of
1 + STEPPERS PLCs behind one TCP listener (the idle one is station 1), freezes the others and
queues scans on each, then reads R0 of the idle PLC every few milliseconds and prints p50, p99 and
max as `name value unit` lines.

    stepping_fairness.py --plcemud build-bench/plcemud --steppers 10 --seconds 5 --label x
"""

import argparse
import os
import pathlib
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time

SIM_BASE = 100  # PLC i's simulator unit is SIM_BASE + i
STEP_WRITES = 256  # 256 x 65535 scans: the most one PLC can have queued


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def read_exactly(sock, n):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("plcemud closed the connection")
        data += chunk
    return data


def exchange(sock, tid, unit, pdu):
    sock.sendall(struct.pack(">HHHB", tid & 0xFFFF, 0, len(pdu) + 1, unit) + pdu)
    head = read_exactly(sock, 7)
    return read_exactly(sock, struct.unpack(">HHHB", head)[2] - 1)


def config(port, steppers, program_lines):
    program = "".join(f"      - MOV: {{s: K{i}, d: D{i}}}\n" for i in range(program_lines))
    out = "plcs:\n"
    for i in range(1 + steppers):
        out += (
            f"  - name: plc{i}\n    profile: fbs\n    station: {i + 1}\n"
            f"    simulator: {{unit: {SIM_BASE + i}}}\n    persistence: {{enabled: false}}\n"
            f"    modbus: {{tcp: {{bind: 127.0.0.1, port: {port}}}}}\n"
        )
        if program:
            out += "    program:\n" + program
    return out


def percentile(sorted_values, fraction):
    return sorted_values[min(len(sorted_values) - 1, int(fraction * len(sorted_values)))]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--plcemud", required=True)
    ap.add_argument("--steppers", type=int, default=10)
    ap.add_argument("--seconds", type=float, default=5)
    ap.add_argument("--program", type=int, default=20, help="MOV instructions in each program")
    ap.add_argument("--label", default="stepping")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        port = free_port()
        path = pathlib.Path(tmp) / "stepping.yaml"
        path.write_text(config(port, a.steppers, a.program))
        log = open(pathlib.Path(tmp) / "plcemud.log", "wb")
        proc = subprocess.Popen([a.plcemud, "-c", str(path)], stdin=subprocess.DEVNULL,
                                stdout=log, stderr=log)
        try:
            deadline = time.monotonic() + 20
            while True:
                try:
                    s = socket.create_connection(("127.0.0.1", port), timeout=5)
                    break
                except OSError:
                    if proc.poll() is not None or time.monotonic() > deadline:
                        sys.exit(f"stepping_fairness: plcemud did not start:\n"
                                 f"{(pathlib.Path(tmp) / 'plcemud.log').read_text()}")
                    time.sleep(0.05)
            s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            # Every stepper frozen and given its scans in one pipelined burst, before the first
            # read.
            burst = []
            for i in range(1, 1 + a.steppers):
                burst.append((SIM_BASE + i, struct.pack(">BHH", 6, 1, 1)))  # freeze
                burst += [(SIM_BASE + i, struct.pack(">BHH", 6, 2, 65535))] * STEP_WRITES
            s.sendall(b"".join(struct.pack(">HHHB", t & 0xFFFF, 0, len(pdu) + 1, unit) + pdu
                               for t, (unit, pdu) in enumerate(burst)))
            for _ in burst:
                head = read_exactly(s, 7)
                read_exactly(s, struct.unpack(">HHHB", head)[2] - 1)
            tid = len(burst)
            samples = []
            end = time.monotonic() + a.seconds
            while time.monotonic() < end:
                tid += 1
                t0 = time.perf_counter()
                reply = exchange(s, tid, 1, struct.pack(">BHH", 3, 0, 1))
                samples.append(time.perf_counter() - t0)
                assert reply[0] == 3, reply
                time.sleep(0.002)
            queued = struct.unpack(">H", exchange(s, tid + 1, SIM_BASE + a.steppers,
                                                  struct.pack(">BHH", 3, 2, 1))[2:4])[0]
            for i in range(1, 1 + a.steppers):  # cancel what is left
                exchange(s, tid + 1 + i, SIM_BASE + i, struct.pack(">BHH", 6, 2, 0))
            s.close()
        finally:
            proc.send_signal(signal.SIGTERM)
            proc.wait(timeout=10)
            log.close()
    samples.sort()
    name = f"{a.label}.idle_read"
    print(f"{name}.p50 {percentile(samples, 0.50) * 1e3:.2f} ms")
    print(f"{name}.p99 {percentile(samples, 0.99) * 1e3:.2f} ms")
    print(f"{name}.max {samples[-1] * 1e3:.2f} ms")
    # Still stepping at the end (a nonzero queue): the figures are of reads under stepping.
    print(f"# {a.label}: {len(samples)} reads; the last stepper still had "
          f"{'some' if queued else 'no'} scans queued at the end", file=sys.stderr)
    return 0 if queued else 1


if __name__ == "__main__":
    sys.exit(main())
