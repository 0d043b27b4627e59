#!/usr/bin/python3
"""Records a closed-loop run of a plcemud config in virtual time to CSV.

Starts plcemud on a free port with a copy of the config (persistence off, TCP on 127.0.0.1, no
serial port), freezes it through the simulator-control unit, does what a SCADA does to start the
loops, then steps the scans and samples every TPCTL point once per sampling interval:

  time_s, and per point (named after its channel c): c<c>_pv, c<c>_sp (°C), c<c>_or (0-16383),
  c<c>_duty (% : the heater power the plant measured on the point's Y output, mean of 8 s)

Usage: trace.py --plcemud BIN --config FILE [--minutes 30] [--interval 1] [--out trace.csv]
                [--no-start] [DEVICE=VALUE ...]
The DEVICE=VALUE writes are done first (e.g. R4005=0 R100=1800 WM800=0x3FF); then, unless
--no-start, every TPCTL's EN device is set and every WMn word that the program moves into
R4012/R4013 is set to FFFFh (all points enabled), as a SCADA starts the loops.
"""

import argparse
import csv
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time

import yaml
from pymodbus.client import ModbusTcpClient


def fail(msg):
    print(f"trace: {msg}", file=sys.stderr)
    sys.exit(2)


DEVICE = re.compile(r"^(W?)([A-Z]+)(\d+)$")


def parse_device(text):
    m = DEVICE.match(str(text).strip().upper())
    if not m:
        return None
    return m.group(1) == "W", m.group(2), int(m.group(3))


def wire(area, index):
    """(table, wire address) of a device in the fbs Modbus map (FBs manual 13-50/51)."""
    if area == "Y":
        return "coil", index
    if area == "M":
        return "coil", 2000 + index
    if area == "R" and (index <= 4167 or 5000 <= index <= 5998):
        return "reg", index
    if area == "D" and index <= 2998:
        return "reg", 6000 + index
    fail(f"{area}{index} is not reachable over Modbus")


def number(text):
    s = str(text).strip().upper()
    if s.startswith("K"):
        s = s[1:]
    return int(s, 0)


class Plc:
    def __init__(self, client, sim_unit):
        self.c = client
        self.sim = sim_unit

    def regs(self, addr, count=1, unit=1):
        r = self.c.read_holding_registers(addr, count, slave=unit)
        if r.isError():
            fail(f"read {addr} (unit {unit}): {r}")
        return r.registers

    def write_reg(self, addr, value, unit=1):
        r = self.c.write_register(addr, value & 0xFFFF, slave=unit)
        if r.isError():
            fail(f"write {addr}={value} (unit {unit}): {r}")

    def write_coils(self, addr, bits):
        r = self.c.write_coils(addr, bits, slave=1)
        if r.isError():
            fail(f"write coils {addr}: {r}")

    def set_device(self, text, value):
        d = parse_device(text)
        if not d:
            fail(f"'{text}' is not a device")
        word_of_bits, area, index = d
        if word_of_bits:
            table, addr = wire(area, index)
            self.write_coils(addr, [bool(value >> b & 1) for b in range(16)])
        elif area in ("Y", "M"):
            self.write_coils(wire(area, index)[1], [bool(value)])
        else:
            self.write_reg(wire(area, index)[1], value)

    def step(self, scans):
        while scans > 0:
            n = min(scans, 2000)
            self.write_reg(2, n, unit=self.sim)
            scans -= n
        # Steps run in slices after the reply; register 2 reads the scans still queued.
        while self.c.read_holding_registers(2, 1, slave=self.sim).registers[0] != 0:
            time.sleep(0.001)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--plcemud", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--interval", type=float, default=1.0, help="sampling interval, s")
    ap.add_argument("--out", default="trace.csv")
    ap.add_argument("--no-start", action="store_true",
                    help="do not turn on the TPCTL enables (only the writes given)")
    ap.add_argument("writes", nargs="*", help="DEVICE=VALUE")
    a = ap.parse_args()

    with open(a.config) as f:
        cfg = yaml.safe_load(f) or {}
    scan_ms = int(cfg.get("scan_ms", 10))
    sim_unit = int((cfg.get("simulator") or {}).get("unit", 247))
    if sim_unit == 0:
        fail("the config turns the simulator unit off (simulator.unit: 0)")
    table = (cfg.get("temperature") or {}).get("table")
    if not table:
        fail("the config has no temperature.table: nothing to trace")
    points = []
    starts = []
    for entry in cfg.get("program") or []:
        (mnemonic, ops), = entry.items()
        ops = {str(k).lower(): v for k, v in (ops or {}).items()}
        if mnemonic.upper() == "MOV" and str(ops.get("d", "")).upper() in ("R4012", "R4013"):
            src = parse_device(ops.get("s", ""))
            if src and src[0]:
                starts.append((str(ops["s"]), 0xFFFF))
        if mnemonic.upper() != "TPCTL":
            continue
        sn, zn = number(ops["sn"]), number(ops["zn"])
        en = parse_device(ops.get("en", 1))
        if en:
            starts.append((str(ops["en"]), 1))
        for i in range(zn):
            sv, orr = parse_device(ops["sv"]), parse_device(ops["or"])
            points.append({"ch": sn + i, "sv": wire(sv[1], sv[2] + i)[1],
                           "or": wire(orr[1], orr[2] + i)[1]})
    if not points:
        fail("the config's program has no TPCTL")
    writes = []
    for w in a.writes:
        if "=" not in w:
            fail(f"'{w}': expected DEVICE=VALUE")
        k, v = w.split("=", 1)
        writes.append((k, int(v, 0)))
    # The given writes first (e.g. R4005, read when EN rises), then what starts the loops.
    if not a.no_start:
        writes += starts

    # A copy of the config that touches nothing of the user's: no state file, no serial port.
    port = free_port()
    cfg["persistence"] = {"enabled": False}
    modbus = cfg.setdefault("modbus", {}) or {}
    cfg["modbus"] = modbus
    modbus.pop("rtu", None)
    modbus["tcp"] = {**(modbus.get("tcp") or {}), "enabled": True, "bind": "127.0.0.1",
                     "port": port}
    tmp = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)
    yaml.safe_dump(cfg, tmp)
    tmp.close()
    # Time scale 0.001: after the first scan nothing runs until the trace freezes the PLC.
    proc = subprocess.Popen([a.plcemud, "-c", tmp.name, "--time-scale", "0.001"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 10
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                if proc.poll() is not None or time.monotonic() > deadline:
                    fail(f"plcemud did not start:\n{proc.stderr.read() if proc.stderr else ''}")
                time.sleep(0.05)
        client = ModbusTcpClient("127.0.0.1", port=port, timeout=30)
        if not client.connect():
            fail(f"cannot connect to plcemud on port {port}")
        plc = Plc(client, sim_unit)
        plc.write_reg(1, 1, unit=sim_unit)  # freeze
        for dev, value in writes:
            plc.set_device(dev, value)

        # Where the readings are: the table's SR+2 (10000+n = Rn, 20000+n = Dn).
        tdev = parse_device(table)
        sr2 = plc.regs(wire(tdev[1], tdev[2] + 2)[1])[0]
        if 10000 <= sr2 < 20000:
            readings = ("R", sr2 - 10000)
        elif 20000 <= sr2 < 30000:
            readings = ("D", sr2 - 20000)
        else:
            fail(f"the table's reading start {sr2} is not a register reference")

        def signed(v):
            return v - 0x10000 if v & 0x8000 else v

        def read_all(addrs, unit=1, gap=0):
            """Values of holding registers, read in runs (words between them up to `gap`)."""
            want = sorted(set(addrs))
            got = {}
            i = 0
            while i < len(want):
                j = i
                while (j + 1 < len(want) and want[j + 1] - want[j] <= gap + 1
                       and want[j + 1] - want[i] < 125):
                    j += 1
                vals = plc.regs(want[i], want[j] - want[i] + 1, unit=unit)
                for a_ in want[i:j + 1]:
                    got[a_] = vals[a_ - want[i]]
                i = j + 1
            return got

        rd = {p["ch"]: wire(readings[0], readings[1] + p["ch"])[1] for p in points}
        pw = {p["ch"]: 100 + 10 * p["ch"] + 7 for p in points}
        samples = round(a.minutes * 60 / a.interval)
        per_sample = max(1, round(a.interval * 1000 / scan_ms))
        with open(a.out, "w", newline="") as f:
            out = csv.writer(f)
            head = ["time_s"]
            for p in points:
                c = p["ch"]
                head += [f"c{c}_pv", f"c{c}_sp", f"c{c}_or", f"c{c}_duty"]
            out.writerow(head)
            for k in range(samples + 1):
                if k:
                    plc.step(per_sample)
                v = read_all(list(rd.values()) + [p["sv"] for p in points] +
                             [p["or"] for p in points])
                power = read_all(pw.values(), unit=sim_unit, gap=9)
                row = [round(k * per_sample * scan_ms / 1000, 3)]
                for p in points:
                    c = p["ch"]
                    pv = signed(v[rd[c]])
                    row += [pv / 10 if pv != 32767 else "", signed(v[p["sv"]]) / 10, v[p["or"]],
                            power[pw[c]] / 10]
                out.writerow(row)
        client.close()
        print(f"trace: {samples} samples of {len(points)} points over {a.minutes:g} simulated "
              f"minutes -> {a.out}")
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
        os.unlink(tmp.name)


if __name__ == "__main__":
    main()
