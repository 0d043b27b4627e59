"""Interoperability with libmodbus' master API (docs/profile-fbs.md, "Modbus map"):
tests/interop/libmodbus_client does round trips of FC 01 02 03 04 05 06 15 16 22 23, 08/00, 11h,
2Bh/0Eh and each exception against the real daemon, over TCP and over RTU (a socat pty pair), and
exits non-zero on any mismatch.
"""

import os
import subprocess
from pathlib import Path

import pytest
from conftest import PLCEMUD
from rtu_pty import PtyPair, rtu_config

CLIENT = os.environ.get(
    "LIBMODBUS_CLIENT", str(Path(PLCEMUD).parent / "tests" / "interop" / "libmodbus_client"))

# The client expects the user maps DI 0.. -> M100.. and IR 0.. -> R200.. (FBs manual 13-50/51).
USER_MAPS = "init:\n  R3972: [0, 100, 16]\n  R3975: [0, 200, 8]\n"


@pytest.fixture
def client_binary():
    if not os.access(CLIENT, os.X_OK):
        pytest.fail(f"libmodbus_client not found at {CLIENT} (build the tests or set "
                    "LIBMODBUS_CLIENT)")
    return CLIENT


def run_client(*args):
    r = subprocess.run([*args], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, f"libmodbus_client {args[1:]} failed:\n{r.stdout}{r.stderr}"
    assert "all round trips and exceptions as expected" in r.stdout


def test_libmodbus_over_tcp(start_plcemud, client_binary):
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n" + USER_MAPS)
    run_client(client_binary, "tcp", "127.0.0.1", str(d.port))


@pytest.mark.parametrize("baud", [9600, 115200])
def test_libmodbus_over_rtu(start_plcemud, client_binary, tmp_path, baud):
    pair = PtyPair(tmp_path)
    try:
        d = start_plcemud(rtu_config(pair.slave, f"baud: {baud}", USER_MAPS))
        assert d.wait_log("listening on rtu"), d.log_text()
        run_client(client_binary, "rtu", pair.master, str(baud), "E")
    finally:
        pair.stop()


def test_client_reports_a_mismatch(start_plcemud, client_binary):
    """The check can fail: without the user maps FC02/FC04 answer exception 01."""
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n")
    r = subprocess.run([client_binary, "tcp", "127.0.0.1", str(d.port)], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 1
    assert "MISMATCH: FC02" in r.stderr and "MISMATCH: FC04" in r.stderr
