#!/usr/bin/env python3
"""The console's cost and reach (scripts/bench.sh, hook `console`; docs/performance.md).

  console_load.py browsers --http-port P --browsers N --seconds S
      holds N browsers' worth of live-update subscribers (each: the overview's stream and a
      devices page's stream of R0-R19) for S seconds, reading everything they are sent; prints
      `console.subscribers N count` and the events received.
  console_load.py latency --http-port P --modbus-port Q --samples N
      writes R100 over Modbus (FC06) N times, each a new value, and measures how long until a
      subscriber of R100 gets an event with it: the time from the write's reply to the event
      (the write lands between two scans, so this is from the scan that made it, within one scan
      period); prints p50, p99 and max in ms.

Standard library only: raw sockets for both protocols."""

import argparse
import selectors
import socket
import struct
import sys
import time


def open_stream(port, path):
    s = socket.create_connection(("127.0.0.1", port))
    s.sendall(f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nAccept: text/event-stream\r\n\r\n".encode())
    s.setblocking(False)
    return s


def browsers(a):
    sel = selectors.DefaultSelector()
    streams = []
    for _ in range(a.browsers):
        for path in ("/api/v1/events", "/api/v1/plcs/0/events?device=R0&count=20"):
            s = open_stream(a.http_port, path)
            sel.register(s, selectors.EVENT_READ)
            streams.append(s)
    events = 0
    end = time.monotonic() + a.seconds
    while time.monotonic() < end:
        for key, _ in sel.select(timeout=0.2):
            try:
                data = key.fileobj.recv(65536)
            except BlockingIOError:
                continue
            if not data:
                sys.exit("console_load: a stream was closed by plcemud")
            events += data.count(b"\nevent: ") + data.startswith(b"event: ")
    print(f"console.subscribers {len(streams)} count")
    print(f"console.events {events} count")


def modbus_write(sock, tid, addr, value):
    pdu = struct.pack(">BHH", 6, addr, value)
    sock.sendall(struct.pack(">HHHB", tid, 0, len(pdu) + 1, 1) + pdu)
    reply = b""
    while len(reply) < 12:
        chunk = sock.recv(64)
        if not chunk:
            sys.exit("console_load: Modbus connection closed")
        reply += chunk


def latency(a):
    stream = open_stream(a.http_port, "/api/v1/plcs/0/events?device=R100")
    stream.setblocking(True)
    stream.settimeout(5)
    mb = socket.create_connection(("127.0.0.1", a.modbus_port))
    mb.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    buf = b""
    samples = []
    for i in range(a.samples):
        value = 20000 + i
        modbus_write(mb, i & 0xFFFF, 100, value)
        t0 = time.monotonic()
        want = f'"values":[{value}]'.encode()
        while want not in buf:
            buf += stream.recv(65536)
        samples.append((time.monotonic() - t0) * 1000)
        buf = buf[buf.index(want) + len(want):]
        time.sleep(0.013)  # not in step with the 50 ms poll
    samples.sort()
    def pct(p):
        return samples[min(len(samples) - 1, int(p * len(samples)))]
    print(f"console.update_latency.p50 {pct(0.50):.1f} ms")
    print(f"console.update_latency.p99 {pct(0.99):.1f} ms")
    print(f"console.update_latency.max {samples[-1]:.1f} ms")


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="what", required=True)
    b = sub.add_parser("browsers")
    b.add_argument("--http-port", type=int, required=True)
    b.add_argument("--browsers", type=int, default=10)
    b.add_argument("--seconds", type=float, default=5)
    la = sub.add_parser("latency")
    la.add_argument("--http-port", type=int, required=True)
    la.add_argument("--modbus-port", type=int, required=True)
    la.add_argument("--samples", type=int, default=200)
    a = ap.parse_args()
    browsers(a) if a.what == "browsers" else latency(a)


if __name__ == "__main__":
    main()
