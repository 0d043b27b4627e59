#!/usr/bin/env python3
"""Writes a `plcs:` configuration of N copies of a one-PLC configuration (config/default.yaml by
default), PLC i on 127.0.0.1:PORT+i with its own state file in DIR, and prints its path. Beside
it, PATH.reload is the same configuration with plc0's first setpoint (R100) 1 °C higher: what
scripts/bench.sh reloads.

    many_plcs.py --count 500 --port 31000 --dir /tmp/x [--config config/default.yaml]
"""

import argparse
import copy
import pathlib
import socket
import sys

import yaml


def ports_free(first, count):
    """True when every port first…first+count-1 can be bound on 127.0.0.1 now."""
    for port in range(first, first + count):
        with socket.socket() as s:
            try:
                s.bind(("127.0.0.1", port))
            except OSError:
                return False
    return True


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--count", type=int, required=True)
    ap.add_argument("--port", type=int, required=True)
    ap.add_argument("--dir", required=True)
    ap.add_argument("--config", default="config/default.yaml")
    a = ap.parse_args()
    if not ports_free(a.port, a.count):
        sys.exit(f"many_plcs: ports {a.port}-{a.port + a.count - 1} are not all free")
    one = yaml.safe_load(pathlib.Path(a.config).read_text())
    # The PLCs' machinery is measured, not a console: default.yaml's `http:` is left out.
    one.pop("http", None)
    one.pop("modbus", None)
    plcs = []
    for i in range(a.count):
        plc = copy.deepcopy(one)
        plc["name"] = f"plc{i}"
        plc["modbus"] = {"tcp": {"bind": "127.0.0.1", "port": a.port + i}}
        plc["persistence"] = {"file": f"{a.dir}/plc{i}.state"}
        plcs.append(plc)
    out = pathlib.Path(a.dir) / f"plcs-{a.count}.yaml"
    out.write_text(yaml.safe_dump({"log": {"level": "info"}, "plcs": plcs}, sort_keys=False))
    setpoints = plcs[0].get("init", {}).get("R100")
    if isinstance(setpoints, list) and setpoints:
        setpoints[0] += 10
    (out.parent / (out.name + ".reload")).write_text(
        yaml.safe_dump({"log": {"level": "info"}, "plcs": plcs}, sort_keys=False))
    print(out)


if __name__ == "__main__":
    main()
