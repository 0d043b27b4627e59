#!/usr/bin/env python3
"""RTU turnaround: time from a request's last byte written to the reply's first byte read, over
a serial device (a socat pty in scripts/bench.sh). Prints `name value unit` lines.

The master side of a pty has no baud timing, so the figure is what the slave adds: its t3.5
silence (1.75 ms above 19200 baud) plus its own processing.
"""
import argparse
import os
import select
import statistics
import sys
import termios
import time
from pathlib import Path

# The RTU framing helpers of the system tests (stdlib only).
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "system"))
from rtu_pty import crc16, frame as rtu_frame  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("device")
    ap.add_argument("--count", type=int, default=300)
    ap.add_argument("--unit", type=int, default=1)
    ap.add_argument("--label", default="plcemud.rtu115200")
    args = ap.parse_args()

    fd = os.open(args.device, os.O_RDWR | os.O_NOCTTY)
    attrs = termios.tcgetattr(fd)
    attrs[0] = attrs[1] = attrs[3] = 0  # raw: no input, output or local processing
    attrs[2] = termios.CS8 | termios.CREAD | termios.CLOCAL
    attrs[4] = attrs[5] = termios.B115200
    termios.tcsetattr(fd, termios.TCSANOW, attrs)

    frame = rtu_frame(args.unit, bytes([0x03, 0x00, 0x00, 0x00, 0x0A]))  # FC03, 10 from R0
    reply_len = 3 + 20 + 2
    samples, failures = [], 0
    for _ in range(args.count):
        os.write(fd, frame)
        sent = time.perf_counter_ns()
        ready, _, _ = select.select([fd], [], [], 1.0)
        if not ready:
            failures += 1
            continue
        first = time.perf_counter_ns()
        got = b""
        deadline = time.monotonic() + 1.0
        while len(got) < reply_len and time.monotonic() < deadline:
            if select.select([fd], [], [], 0.1)[0]:
                got += os.read(fd, 256)
        if len(got) != reply_len or crc16(got[:-2]) != got[-2] | got[-1] << 8:
            failures += 1
            continue
        samples.append((first - sent) / 1e6)
        time.sleep(0.005)  # more than t3.5 between requests
    os.close(fd)
    if samples:
        q = statistics.quantiles(samples, n=100)
        print(f"{args.label}.turnaround.p50 {statistics.median(samples):.3f} ms")
        print(f"{args.label}.turnaround.p99 {q[98]:.3f} ms")
    print(f"{args.label}.turnaround.failures {failures} count")


if __name__ == "__main__":
    main()
