#!/usr/bin/python3
"""Records a closed-loop run of a plcemud config in virtual time to CSV.

Starts plcemud on a free port with a copy of the config (persistence off, TCP on 127.0.0.1, no
serial port), freezes it through the simulator-control unit, does what a SCADA does to start the
loops, then steps the scans and samples every loop once per sampling interval. The Modbus
addresses of the devices and of the simulator unit come from the daemon itself
(`plcemud -c CONFIG --print-map --format csv`), so any profile and any modbus.map work.

  time_s, then per FBs TPCTL point (named after its channel c): c<c>_pv, c<c>_sp (°C),
  c<c>_or (0-16383), c<c>_duty (% : the heater power the plant measured on the point's Y
  output, mean of 8 s);
  then per VB PID entry (k = 0, 1, ... in program order): pid<k>_pv (S2 / 10, °C),
  pid<k>_sv (S1 / 10, °C), pid<k>_mv (D, output counts), pid<k>_at (S3+1 b4: 1 = auto-tuning),
  pid<k>_kp (S3+3, %), pid<k>_ti (S3+4, x 100 ms), pid<k>_td (S3+6, x 10 ms), pid<k>_power
  (% : the heater power of the plant channel the config drives with D, mean of 8 s; empty when
  no channel is).

Usage: trace.py --plcemud BIN --config FILE [--minutes 30] [--interval 1] [--out trace.csv]
                [--no-start] [DEVICE=VALUE ...]
The DEVICE=VALUE writes are done first (e.g. R4005=0 R100=1800 WM800=0x3FF, D201=0x31); then,
unless --no-start, every TPCTL's and PID's EN device is set and every WMn word that the program
moves into R4012/R4013 is set to FFFFh (all points enabled), as a SCADA starts the loops.
"""

import argparse
import csv
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time

import yaml
from pymodbus.client import ModbusTcpClient

# The device -> wire address map is plcemu_testing's (python/ in the source tree).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from plcemu_testing.errors import PlcemuError  # noqa: E402
from plcemu_testing.plc import free_port  # noqa: E402
from plcemu_testing.wire_map import WireMap, parse_device  # noqa: E402


def fail(msg):
    print(f"trace: {msg}", file=sys.stderr)
    sys.exit(2)


def number(text):
    s = str(text).strip().upper()
    if s.startswith("K"):
        s = s[1:]
    return int(s, 0)


class Plc:
    def __init__(self, client, wires):
        self.c = client
        self.w = wires
        self.sim = wires.sim_unit

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
        word_of_bits, area, digits = d
        if word_of_bits:
            self.write_coils(self.w.wire(area, digits, table="coils")[1],
                             [bool(value >> b & 1) for b in range(16)])
            return
        table, addr = self.w.wire(area, digits)
        if table == "coils":
            self.write_coils(addr, [bool(value)])
        else:
            self.write_reg(addr, value)

    def read_all(self, addrs, unit=1, gap=0):
        """Values of holding registers, read in runs (words between them up to `gap`)."""
        want = sorted(set(addrs))
        got = {}
        i = 0
        while i < len(want):
            j = i
            while (j + 1 < len(want) and want[j + 1] - want[j] <= gap + 1
                   and want[j + 1] - want[i] < 125):
                j += 1
            vals = self.regs(want[i], want[j] - want[i] + 1, unit=unit)
            for a_ in want[i:j + 1]:
                got[a_] = vals[a_ - want[i]]
            i = j + 1
        return got

    def step(self, scans):
        while scans > 0:
            n = min(scans, 2000)
            self.write_reg(2, n, unit=self.sim)
            scans -= n
        # Steps run in slices after the reply; register 2 reads the scans still queued.
        while self.c.read_holding_registers(2, 1, slave=self.sim).registers[0] != 0:
            time.sleep(0.001)


def signed(v):
    return v - 0x10000 if v & 0x8000 else v


def drive_channels(cfg):
    """{register or Y name: plant channel} of the config's plant.channels.N.drive."""
    out = {}
    for ch, settings in ((cfg.get("plant") or {}).get("channels") or {}).items():
        drive = (settings or {}).get("drive")
        if drive is not None:
            out.setdefault(str(drive).strip().upper(), int(ch))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--plcemud", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--interval", type=float, default=1.0, help="sampling interval, s")
    ap.add_argument("--out", default="trace.csv")
    ap.add_argument("--no-start", action="store_true",
                    help="do not turn on the TPCTL/PID enables (only the writes given)")
    ap.add_argument("writes", nargs="*", help="DEVICE=VALUE")
    a = ap.parse_args()

    with open(a.config) as f:
        cfg = yaml.safe_load(f) or {}
    scan_ms = int(cfg.get("scan_ms", 10))
    writes = []
    for w in a.writes:
        if "=" not in w:
            fail(f"'{w}': expected DEVICE=VALUE")
        k, v = w.split("=", 1)
        writes.append((k, int(v, 0)))

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
    try:
        record(a, cfg, tmp.name, port, scan_ms, writes)
    finally:
        os.unlink(tmp.name)


def record(a, cfg, config_path, port, scan_ms, writes):
    wires = WireMap(a.plcemud, config_path)
    if wires.sim_unit is None:
        fail("the config turns the simulator unit off (simulator.unit: 0)")
    drives = drive_channels(cfg)
    points = []  # FBs TPCTL points
    loops = []  # VB PID entries
    starts = []
    for entry in cfg.get("program") or []:
        (mnemonic, ops), = entry.items()
        mnemonic = mnemonic.upper()
        ops = {str(k).lower(): v for k, v in (ops or {}).items()}
        if mnemonic == "MOV" and str(ops.get("d", "")).upper() in ("R4012", "R4013"):
            src = parse_device(ops.get("s", ""))
            if src and src[0]:
                starts.append((str(ops["s"]), 0xFFFF))
        if mnemonic not in ("TPCTL", "PID"):
            continue
        en = parse_device(ops.get("en", 1))
        if en:
            starts.append((str(ops["en"]), 1))
        if mnemonic == "PID":
            s3 = str(ops["s3"])
            d = str(ops["d"]).strip().upper()
            loops.append({"sv": wires.reg(ops["s1"]), "pv": wires.reg(ops["s2"]),
                          "mv": wires.reg(d), "ctl": wires.reg(s3, 1), "kp": wires.reg(s3, 3),
                          "ti": wires.reg(s3, 4), "td": wires.reg(s3, 6),
                          "ch": drives.get(d)})
            continue
        sn, zn = number(ops["sn"]), number(ops["zn"])
        sv, orr = parse_device(ops["sv"]), parse_device(ops["or"])
        for i in range(zn):
            points.append({"ch": sn + i, "sv": wires.wire(sv[1], sv[2], i)[1],
                           "or": wires.wire(orr[1], orr[2], i)[1]})
    if not points and not loops:
        fail("the config's program has no TPCTL and no PID: nothing to trace")
    table = (cfg.get("temperature") or {}).get("table")
    if points and not table:
        fail("the config has TPCTL but no temperature.table: no readings to trace")
    # The given writes first (e.g. R4005, read when EN rises), then what starts the loops.
    if not a.no_start:
        writes += starts

    # Time scale 0.001: after the first scan nothing runs until the trace freezes the PLC.
    proc = subprocess.Popen([a.plcemud, "-c", config_path, "--time-scale", "0.001"],
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
        plc = Plc(client, wires)
        plc.write_reg(1, 1, unit=wires.sim_unit)  # freeze
        for dev, value in writes:
            plc.set_device(dev, value)

        rd = {}
        if points:
            # Where the readings are: the table's SR+2 (10000+n = Rn, 20000+n = Dn).
            tdev = parse_device(table)
            sr2 = plc.regs(wires.wire(tdev[1], tdev[2], 2)[1])[0]
            if 10000 <= sr2 < 20000:
                readings = ("R", sr2 - 10000)
            elif 20000 <= sr2 < 30000:
                readings = ("D", sr2 - 20000)
            else:
                fail(f"the table's reading start {sr2} is not a register reference")
            rd = {p["ch"]: wires.wire(readings[0], str(readings[1]), p["ch"])[1] for p in points}
        if wires.power is None:
            fail("the simulator unit has no heater power registers")
        pw = {}
        for c in [p["ch"] for p in points] + [lp["ch"] for lp in loops if lp["ch"] is not None]:
            pw[c] = wires.power[0] + wires.power[1] * c
        words = list(rd.values()) + [p[k] for p in points for k in ("sv", "or")]
        words += [lp[k] for lp in loops for k in ("sv", "pv", "mv", "ctl", "kp", "ti", "td")]
        samples = round(a.minutes * 60 / a.interval)
        per_sample = max(1, round(a.interval * 1000 / scan_ms))
        with open(a.out, "w", newline="") as f:
            out = csv.writer(f)
            head = ["time_s"]
            for p in points:
                c = p["ch"]
                head += [f"c{c}_pv", f"c{c}_sp", f"c{c}_or", f"c{c}_duty"]
            for k in range(len(loops)):
                head += [f"pid{k}_{n}" for n in ("pv", "sv", "mv", "at", "kp", "ti", "td",
                                                 "power")]
            out.writerow(head)
            for k in range(samples + 1):
                if k:
                    plc.step(per_sample)
                # Runs of up to 10 unused words between wanted ones are read in one request.
                v = plc.read_all(words, gap=10)
                power = plc.read_all(pw.values(), unit=wires.sim_unit, gap=9)
                row = [round(k * per_sample * scan_ms / 1000, 3)]
                for p in points:
                    c = p["ch"]
                    pv = signed(v[rd[c]])
                    row += [pv / 10 if pv != 32767 else "", signed(v[p["sv"]]) / 10, v[p["or"]],
                            power[pw[c]] / 10]
                for lp in loops:
                    pv = signed(v[lp["pv"]])
                    row += [pv / 10 if pv != 32767 else "", signed(v[lp["sv"]]) / 10,
                            signed(v[lp["mv"]]), v[lp["ctl"]] >> 4 & 1, signed(v[lp["kp"]]),
                            signed(v[lp["ti"]]), signed(v[lp["td"]]),
                            power[pw[lp["ch"]]] / 10 if lp["ch"] is not None else ""]
                out.writerow(row)
        client.close()
        what = []
        if points:
            what.append(f"{len(points)} TPCTL points")
        if loops:
            what.append(f"{len(loops)} PID loops")
        print(f"trace: {samples} samples of {' and '.join(what)} over {a.minutes:g} simulated "
              f"minutes -> {a.out}")
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()


if __name__ == "__main__":
    try:
        main()
    except PlcemuError as e:  # a device the map does not serve, a config plcemud refuses
        fail(e)
