"""Several PLCs in one process: a config with `plcs:` (README, "Several PLCs in one process";
docs/configuration.md, "Several PLCs" and "Sharing a listener"). Each PLC has its own image,
state file and program, on a listener of its own or shared with others (stations on one serial
line, stations behind one TCP port); one event loop serves them all."""

import contextlib
import re
import signal
import socket
import time
from pathlib import Path

import pytest
from pymodbus.client import ModbusTcpClient

from conftest import Daemon, free_port, port_open, raw_exchange, run_plcemud, spawn_plcs
from rtu_pty import PtyPair, RawLine, frame as frame_of
from test_http_api import get, parse_metrics

D0 = 6000  # fbs: holding 6000 is D0 (retentive by default)
VB_D200 = 200  # vb: holding 200 is D200 (latched)
VB_D9010 = 8010  # vb: scan time in 0.1 ms, read-only
R4057 = 4057  # fbs: power-up counter


def plcs_config(ports, tmp_path, b_dest="R1"):
    a, b, v = ports
    return f"""\
log: {{level: info}}
plcs:
  - name: line-a
    profile: fbs
    modbus: {{tcp: {{bind: 127.0.0.1, port: {a}}}}}
  - name: line-b
    profile: fbs
    station: 2
    modbus: {{tcp: {{bind: 127.0.0.1, port: {b}}}}}
    program:
      - MOV: {{en: M1926, s: R0, d: {b_dest}}}
  - profile: vb
    scan_ms: 20
    modbus: {{tcp: {{bind: 127.0.0.1, port: {v}}}}}
"""


def spawn(tmp_path: Path, text: str, ports, host="127.0.0.1") -> Daemon:
    """plcemud on a `plcs:` config (no --port: each PLC names its own), once every port listens
    on `host`."""
    return spawn_plcs(tmp_path, text, ports, host)


def client_on(d: Daemon, port: int):
    d.port = port
    return d.client()


def reg(c, addr, unit=1):
    r = c.read_holding_registers(addr, 1, slave=unit)
    assert not r.isError(), r
    return r.registers[0]


@pytest.fixture
def ports():
    return free_port(), free_port(), free_port()


def test_three_plcs_keep_their_own_images_maps_state_and_programs(tmp_path, ports):
    d = spawn(tmp_path, plcs_config(ports, tmp_path), ports)
    try:
        a, b, v = (client_on(d, p) for p in ports)
        # Writes are isolated: the same address on each PLC holds its own value.
        assert not a.write_register(D0, 111, slave=1).isError()
        assert not b.write_register(D0, 222, slave=2).isError()
        assert not v.write_register(D0, 333, slave=1).isError()  # vb: D6000
        assert reg(a, D0) == 111
        assert reg(b, D0, unit=2) == 222
        assert reg(v, D0) == 333
        # Each answers with its own profile's map: vb's D9010 is its scan time (20 ms), once
        # a scan has ended after the first (the PLCs start their scans a few ms apart).
        deadline = time.monotonic() + 2
        while reg(v, VB_D9010) == 0 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert reg(v, VB_D9010) == 200
        assert not v.write_register(VB_D200, 444, slave=1).isError()
        # line-b's program copies R0 to R1; line-a has none.
        assert not a.write_register(0, 7, slave=1).isError()
        assert not b.write_register(0, 9, slave=2).isError()
        time.sleep(0.2)
        assert reg(a, 1) == 0
        assert reg(b, 1, unit=2) == 9
        assert reg(a, R4057) == 1

        # SIGHUP with line-b's MOV now writing R2: only line-b changes, images stay.
        Path(d.config_path).write_text(plcs_config(ports, tmp_path, b_dest="R2"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: plcs[1] (line-b): done"), d.log_text()
        assert d.wait_log("reload: applied to 1 of 3 PLCs; 2 unchanged run on untouched"), \
            d.log_text()
        time.sleep(0.2)
        assert reg(b, 2, unit=2) == 9
        assert reg(a, 2) == 0
        assert reg(a, D0) == 111 and reg(b, D0, unit=2) == 222 and reg(v, D0) == 333

        # A bad entry rejects the whole reload, naming the entry: every PLC keeps its config.
        bad = plcs_config(ports, tmp_path, b_dest="R3").replace("scan_ms: 20", "scan_ms: 5000")
        Path(d.config_path).write_text(bad)
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("configuration rejected"), d.log_text()
        assert f"{d.config_path}:13:14: plcs[2]: scan_ms" in d.log_text(), d.log_text()
        assert not b.write_register(0, 10, slave=2).isError()
        time.sleep(0.2)
        assert reg(b, 2, unit=2) == 10  # still the reloaded program (R2), not R3
        assert reg(b, 3, unit=2) == 0
        assert reg(v, VB_D9010) == 200
        assert d.proc.poll() is None
    finally:
        assert d.stop() == 0

    # Each PLC wrote a state file of its own; a restart keeps each one's retentive devices.
    for name in ("plant-line-a.state", "plant-line-b.state", "plant-2.state"):
        assert (tmp_path / name).exists(), name
    d = spawn(tmp_path, plcs_config(ports, tmp_path, b_dest="R2"), ports)
    try:
        a, b, v = (client_on(d, p) for p in ports)
        assert reg(a, D0) == 111
        assert reg(b, D0, unit=2) == 222
        assert reg(v, VB_D200) == 444
        assert reg(a, R4057) == 2
    finally:
        assert d.stop() == 0


def test_a_reload_that_renames_or_adds_an_entry_is_refused(tmp_path, ports):
    d = spawn(tmp_path, plcs_config(ports, tmp_path), ports)
    try:
        a, b = client_on(d, ports[0]), client_on(d, ports[1])
        # Each attempt also moves line-b's copy to R2: refused, it keeps copying to R1.
        renamed = plcs_config(ports, tmp_path, b_dest="R2").replace("line-b", "line-c")
        added = plcs_config(ports, tmp_path, b_dest="R2") + (
            f"  - {{name: extra, profile: fbs, modbus: {{tcp: {{port: {free_port()}}}}}}}\n")
        for n, (text, why) in enumerate([
            (renamed, "reload: plcs[1] (line-c): was plcs[1] (line-b); restart plcemud to "
                      "rename or reorder PLCs"),
            (added, "reload: the config has 4 PLC(s), 3 are running; restart plcemud to add or "
                    "remove PLCs"),
        ], start=1):
            Path(d.config_path).write_text(text)
            d.proc.send_signal(signal.SIGHUP)
            wait_count(d, "configuration rejected", n)
            assert why in d.log_text(), d.log_text()
            assert not b.write_register(0, n, slave=2).isError()
            assert wait_reg(b, 1, n, unit=2) == n
            assert reg(b, 2, unit=2) == 0
            assert reg(a, D0) == 0
        assert "reload: plcs[0] (line-a): done" not in d.log_text()
    finally:
        assert d.stop() == 0


def test_check_config_and_print_map_name_each_plc(tmp_path, ports):
    path = tmp_path / "plant.yaml"
    path.write_text(plcs_config(ports, tmp_path))
    r = run_plcemud("-c", path, "--check-config")
    assert r.returncode == 0, r.stderr
    assert f"{path}: plcs[0] (line-a): ok, profile fbs, station 1" in r.stdout
    assert f"{path}: plcs[2]: ok, profile vb, station 1" in r.stdout
    r = run_plcemud("-c", path, "--print-map")
    assert r.returncode == 0, r.stderr
    assert f"plcs[1] (line-b), tcp 127.0.0.1:{ports[1]}:\nModbus map, profile fbs" in r.stdout
    assert f"plcs[2], tcp 127.0.0.1:{ports[2]}:\nModbus map, profile vb" in r.stdout
    r = run_plcemud("-c", path, "--print-map", "--format", "csv")
    assert r.returncode == 0, r.stderr
    # Each PLC's rows under their own header (the device column is the vendor's).
    assert '\n\nplc,table,modbus_5digit,modbus_6digit,wire,vigor,' in r.stdout
    assert '\n"plcs[2]","holding registers",' in r.stdout


def rtu_disagrees(setting):
    """Two stations on /dev/ttyS9, the second with `setting` (key: value): (text, where, message),
    the position being the value's."""
    key = setting.split(":")[0]
    line = f"     rtu: {{device: /dev/ttyS9, {setting}}}}}}}\n"
    return ("plcs:\n  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {port: 1502},\n"
            "     rtu: {device: /dev/ttyS9}}}\n"
            "  - {name: b, profile: fbs, station: 2, simulator: {unit: 0},"
            " modbus: {tcp: {port: 1503},\n" + line, f":5:{line.index(setting) + len(key) + 3}:",
            f"plcs[1] (b): modbus.rtu.{key}: differs from plcs[0]'s, which shares the serial line "
            "'/dev/ttyS9'")


def tcp_disagrees(setting):
    """Two PLCs behind 0.0.0.0:1502, the second with `setting` (key: value), as rtu_disagrees."""
    key = setting.split(":")[0]
    line = f"     modbus: {{tcp: {{port: 1502, {setting}}}}}}}\n"
    return ("plcs:\n  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {port: 1502}}}\n"
            "  - {name: b, profile: fbs, station: 2, simulator: {unit: 0},\n" + line,
            f":4:{line.index(setting) + len(key) + 3}:",
            f"plcs[1] (b): modbus.tcp.{key}: differs from plcs[0]'s, which shares the tcp "
            "listener 0.0.0.0:1502")


@pytest.mark.parametrize(
    "text, where, message",
    [
        # Names: 1 to 32 letters, digits, '_' or '-'.
        ("plcs:\n  - {name: a b, profile: fbs}\n",
         ":2:12:", "plcs[0]: name: expected 1 to 32 letters, digits, '_' or '-', got 'a b'"),
        ("plcs:\n  - {name: " + "n" * 33 + ", profile: fbs}\n",
         ":2:12:", "plcs[0]: name: expected 1 to 32 letters, digits, '_' or '-'"),
        # Digits alone: /api/v1/plcs/0 reached the entry named "0", not the first.
        ("plcs:\n  - {name: \"0\", profile: fbs}\n",
         ":2:12:", "plcs[0]: name: '0' is digits alone, which the console reads as an entry's "
         "position in plcs:; give it a letter"),
        # Every setting of a shared line, and of a shared TCP listener, must agree.
        rtu_disagrees("parity: O"),
        rtu_disagrees("baud: 19200"),
        rtu_disagrees("stop_bits: 2"),
        tcp_disagrees("allow: [10.0.0.0/8]"),
        tcp_disagrees("max_clients: 2"),
        tcp_disagrees("idle_timeout_s: 30"),
        tcp_disagrees("frame_timeout_ms: 1000"),
        # Two PLCs on one port, one on every address and one on 127.0.0.1: no shared listener.
        ("plcs:\n  - {profile: fbs, modbus: {tcp: {port: 1502}}}\n"
         "  - {profile: vb, modbus: {tcp: {bind: 127.0.0.1, port: 1502}}}\n",
         ":3:57:", "plcs[1]: modbus.tcp.port: 1502 is also plcs[0]'s on another address"),
        # Two PLCs behind one listener with one station (both 1 by default).
        ("plcs:\n  - {profile: fbs, modbus: {tcp: {port: 1502}}}\n"
         "  - {profile: vb, simulator: {unit: 0}, modbus: {tcp: {port: 1502}}}\n",
         ":3:5:", "plcs[1]: station: 1 is also plcs[0]'s on the shared tcp listener 0.0.0.0:1502"),
        # ... or one simulator unit (247 by default).
        ("plcs:\n  - {profile: fbs, modbus: {tcp: {port: 1502}}}\n"
         "  - {profile: fbs, station: 2, modbus: {tcp: {port: 1502}}}\n",
         ":3:5:", "plcs[1]: simulator.unit: 247 is also plcs[0]'s simulator unit on the shared "
         "tcp listener 0.0.0.0:1502"),
        # ... or a station that is the other's simulator unit.
        ("plcs:\n  - {profile: fbs, simulator: {unit: 2}, modbus: {tcp: {port: 1502}}}\n"
         "  - {profile: fbs, station: 2, simulator: {unit: 0}, modbus: {tcp: {port: 1502}}}\n",
         ":3:29:", "plcs[1]: station: 2 is plcs[0]'s simulator unit on the shared tcp listener"),
        # PLCs behind one listener must agree on its settings.
        ("plcs:\n  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {port: 1502}}}\n"
         "  - {profile: fbs, station: 2, simulator: {unit: 0},\n"
         "     modbus: {tcp: {port: 1502, unknown_unit: silent}}}\n",
         ":4:47:", "plcs[1]: modbus.tcp.unknown_unit: differs from plcs[0]'s, which shares the "
         "tcp listener 0.0.0.0:1502"),
        # Stations on one serial line must agree on its settings ...
        ("plcs:\n  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {port: 1502},\n"
         "     rtu: {device: /dev/ttyS9}}}\n"
         "  - {name: b, profile: fbs, station: 2, simulator: {unit: 0}, modbus: {tcp: {port: 1503},\n"
         "     rtu: {device: /dev/ttyS9, baud: 19200}}}\n",
         ":5:38:", "plcs[1] (b): modbus.rtu.baud: differs from plcs[0]'s, which shares the serial "
         "line '/dev/ttyS9'"),
        # ... and have stations of their own.
        ("plcs:\n  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {port: 1502},\n"
         "     rtu: {device: /dev/ttyS9}}}\n"
         "  - {profile: fbs, station: 1, simulator: {unit: 0}, modbus: {tcp: {port: 1503},\n"
         "     rtu: {device: /dev/ttyS9}}}\n",
         ":4:29:", "plcs[1]: station: 1 is also plcs[0]'s on the shared serial line '/dev/ttyS9'"),
        # One listener written two ways is one listener: the PLCs must agree on its settings ...
        ("plcs:\n  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {bind: '::1', port: 1502}}}\n"
         "  - {profile: fbs, station: 2, simulator: {unit: 0},\n"
         "     modbus: {tcp: {bind: '0:0:0:0:0:0:0:1', port: 1502, unknown_unit: silent}}}\n",
         ":4:72:", "plcs[1]: modbus.tcp.unknown_unit: differs from plcs[0]'s, which shares the "
         "tcp listener 0:0:0:0:0:0:0:1:1502"),
        # ... and have stations of their own; so must stations on one device written two ways.
        ("plcs:\n  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {bind: '::1', port: 1502}}}\n"
         "  - {profile: fbs, simulator: {unit: 0},\n"
         "     modbus: {tcp: {bind: '0:0:0:0:0:0:0:1', port: 1502}}}\n",
         ":3:5:", "plcs[1]: station: 1 is also plcs[0]'s on the shared tcp listener"),
        ("plcs:\n  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {enabled: false},\n"
         "     rtu: {device: /dev/ttyS9}}}\n"
         "  - {profile: fbs, simulator: {unit: 0}, modbus: {tcp: {enabled: false},\n"
         "     rtu: {device: /dev//ttyS9}}}\n",
         ":4:5:", "plcs[1]: station: 1 is also plcs[0]'s on the shared serial line '/dev//ttyS9'"),
        # A simulator unit that could never be reached, in a plcs: entry or a file of one PLC.
        ("plcs:\n  - {profile: fbs, simulator: {unit: 255}}\n",
         ":2:38:", 'plcs[0]: simulator.unit: 255 is "the device itself" over Modbus TCP'),
        ("profile: fbs\nsimulator: {unit: 255}\n",
         ":2:19:", 'simulator.unit: 255 is "the device itself" over Modbus TCP'),
        ("profile: fbs\nstation: 247\n",
         ":2:10:", "station: 247 is also this PLC's simulator unit (simulator.unit defaults to 247)"),
        ("profile: vb\nstation: 5\nsimulator: {unit: 5}\n",
         ":3:19:", "simulator.unit: 5 is also this PLC's station, so the simulator could never be "
         "reached"),
        # One state file for two.
        ("plcs:\n  - {profile: fbs, modbus: {tcp: {port: 1502}}, persistence: {file: x.state}}\n"
         "  - {profile: fbs, modbus: {tcp: {port: 1503}}, persistence: {file: x.state}}\n",
         ":3:69:", "plcs[1]: persistence.file: 'x.state' is also plcs[0]'s state file"),
        # One's state file the other's temporary or lock: a start unlinked the temporary, the
        # other PLC's live file, as a leftover.
        ("plcs:\n  - {profile: fbs, modbus: {tcp: {port: 1502}}, persistence: {file: y.state.new}}\n"
         "  - {profile: fbs, modbus: {tcp: {port: 1503}}, persistence: {file: y.state}}\n",
         ":3:69:", "plcs[1]: persistence.file: 'y.state' and plcs[0]'s state file ('y.state.new' "
         "at "),
        ("plcs:\n  - {profile: fbs, modbus: {tcp: {port: 1502}}, persistence: {file: z.state}}\n"
         "  - {profile: fbs, modbus: {tcp: {port: 1503}}, persistence: {file: z.state.lock}}\n",
         ":3:69:", "plcs[1]: persistence.file: 'z.state.lock' and plcs[0]'s state file ('z.state' "
         "at "),
        # One console for every PLC cannot be on a port of the kernel's choosing for each.
        ("http: {port: 0}\nplcs:\n  - {profile: fbs}\n",
         ":1:14:", "http.port: 0 beside plcs: each PLC would get a console of its own"),
        # A per-PLC key beside plcs:.
        ("profile: fbs\nplcs:\n  - {profile: fbs}\n",
         ":1:1:", "profile: belongs to one PLC; beside 'plcs:' only 'log:' and 'http:' may stand"),
        # log: inside an entry.
        ("plcs:\n  - name: k1\n    profile: fbs\n    log: {level: debug}\n",
         ":4:10:", "plcs[0] (k1): log: applies to the whole process"),
        # A bad entry names itself.
        ("plcs:\n  - {profile: fbs}\n  - {name: oven, profile: nope}\n",
         ":3:27:", "plcs[1] (oven): profile: expected one of"),
        ("plcs:\n  - {profile: fbs, name: a, modbus: {tcp: {port: 1}}}\n"
         "  - {profile: fbs, name: a, modbus: {tcp: {port: 2}}}\n",
         ":3:26:", "plcs[1] (a): name: 'a' is also plcs[0] (a)'s"),
    ],
)
def test_bad_plcs_entries_are_refused_at_load(tmp_path, text, where, message):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    r = run_plcemud("-c", path, "--check-config")
    assert r.returncode == 2, r.stdout + r.stderr
    assert f"{path}{where} {message}" in r.stderr, r.stderr


def test_a_name_of_32_characters_is_accepted(tmp_path):
    name = "A-z_9" + "n" * 27
    path = tmp_path / "ok.yaml"
    path.write_text(f"plcs:\n  - {{name: {name}, profile: fbs}}\n")
    r = run_plcemud("-c", path, "--check-config")
    assert r.returncode == 0, r.stderr
    assert f"plcs[0] ({name}): ok" in r.stdout


def test_a_device_and_a_symlink_to_it_are_one_serial_line(tmp_path):
    (tmp_path / "ttyX").write_text("")
    (tmp_path / "link").symlink_to(tmp_path / "ttyX")
    path = tmp_path / "bad.yaml"
    path.write_text(
        "plcs:\n"
        f"  - {{profile: fbs, simulator: {{unit: 0}}, modbus: {{tcp: {{enabled: false}},\n"
        f"     rtu: {{device: {tmp_path}/ttyX}}}}}}\n"
        f"  - {{profile: fbs, station: 2, simulator: {{unit: 0}}, modbus: {{tcp: {{enabled: false}},\n"
        f"     rtu: {{device: {tmp_path}/link, baud: 19200}}}}}}\n")
    r = run_plcemud("-c", path, "--check-config")
    assert r.returncode == 2, r.stdout + r.stderr
    assert f"{path}:5:" in r.stderr, r.stderr
    assert ("plcs[1]: modbus.rtu.baud: differs from plcs[0]'s, which shares the serial "
            "line") in r.stderr, r.stderr


@pytest.mark.parametrize("first,second", [
    ("::1", "0:0:0:0:0:0:0:1"),
    # An IPv4-mapped address takes the IPv4 address's port: --check-config said ok, and the
    # start failed on the second bind.
    ("127.0.0.1", "::ffff:127.0.0.1"),
    ("::ffff:127.0.0.1", "127.0.0.1"),
])
def test_one_address_written_two_ways_is_one_listener(tmp_path, first, second):
    port = free_port()
    host = first.removeprefix("::ffff:")
    d = spawn(tmp_path, f"""\
plcs:
  - {{profile: fbs, station: 1, simulator: {{unit: 0}}, modbus: {{tcp: {{bind: '{first}', port: {port}}}}}}}
  - {{profile: fbs, station: 2, simulator: {{unit: 0}},
     modbus: {{tcp: {{bind: '{second}', port: {port}}}}}}}
""", [port], host=host)
    try:
        assert d.wait_log(f"listening on tcp {first}:{port} for plcs[0], plcs[1]"), d.log_text()
        c = ModbusTcpClient(host, port=port, timeout=3, retries=1)
        assert c.connect()
        try:
            assert not c.write_register(D0, 7, slave=2).isError()
            assert reg(c, D0, unit=2) == 7 and reg(c, D0, unit=1) == 0
        finally:
            c.close()
    finally:
        assert d.stop() == 0


@pytest.mark.parametrize("check", [[], ["--check-config"], ["--print-program"], ["--print-map"],
                                   ["--export-tags", "csv"]])
def test_port_override_is_refused_with_plcs(tmp_path, check):
    # --check-config and the printing commands refuse what a start would (they said ok).
    path = tmp_path / "p.yaml"
    path.write_text(f"plcs:\n  - {{profile: fbs, modbus: {{tcp: {{port: {free_port()}}}}}}}\n")
    r = run_plcemud("-c", path, "--port", free_port(), *check, timeout=10)
    assert r.returncode == 2, r
    assert "--port: a config with plcs: sets each PLC's port itself" in r.stderr


# --- Shared listeners (docs/configuration.md, "Sharing a listener") ---

FC06 = 0x06
FC03 = 0x03


def fc06(addr, value):
    return bytes([FC06, addr >> 8, addr & 0xFF, value >> 8, value & 0xFF])


def fc03(addr, n=1):
    return bytes([FC03, addr >> 8, addr & 0xFF, 0, n])


def multidrop_config(device, port):
    """Three stations on one serial line; the first also has a TCP port of its own."""
    rtu = f"rtu: {{device: {device}, baud: 38400}}"
    return f"""\
plcs:
  - {{name: st1, profile: fbs, station: 1, simulator: {{unit: 201}},
     modbus: {{tcp: {{bind: 127.0.0.1, port: {port}}}, {rtu}}}}}
  - {{name: st2, profile: fbs, station: 2, simulator: {{unit: 202}},
     modbus: {{tcp: {{enabled: false}}, {rtu}}}}}
  - {{name: st3, profile: vb, station: 3, simulator: {{unit: 203}},
     modbus: {{tcp: {{enabled: false}}, {rtu}}}}}
"""


@contextlib.contextmanager
def multidrop(tmp_path):
    """plcemud serving multidrop_config on a pty pair: (daemon, the master's line, pair, port)."""
    pair = PtyPair(tmp_path)
    port = free_port()
    d = spawn(tmp_path, multidrop_config(pair.slave, port), [port])
    line = RawLine(pair.master)
    try:
        assert d.wait_log(f"listening on rtu {pair.slave}"), d.log_text()
        yield d, line, pair, port
    finally:
        line.close()
        assert d.stop() == 0
        pair.stop()


def test_three_stations_on_one_serial_line(tmp_path):
    with multidrop(tmp_path) as (d, line, pair, port):
        assert "for plcs[0] (st1), plcs[1] (st2), plcs[2] (st3)" in d.log_text()
        # Each station answers its own frames; writes stay in the PLC they were sent to.
        for unit in (1, 2, 3):
            assert line.request(unit, fc06(D0, 100 * unit), 8) == fc06(D0, 100 * unit)
        for unit in (1, 2, 3):
            assert line.request(unit, fc03(D0), 7)[2:] == (100 * unit).to_bytes(2, "big")
        # A broadcast write reaches all three, and none of them answers it.
        line.send(frame_of(0, fc06(100, 4242)))
        assert line.silent(0.3)
        for unit in (1, 2, 3):
            assert line.request(unit, fc03(100), 7)[2:] == (4242).to_bytes(2, "big")
        # A station nobody on the line has: silence, as on a real RS-485 line.
        line.send(frame_of(9, fc03(D0)))
        assert line.silent(0.3)
        # Each PLC's simulator unit is on the line too: freeze st2 alone.
        freeze = 1  # docs/simulator-and-plant.md: 1 = scans stopped
        assert line.request(202, fc06(freeze, 1), 8) == fc06(freeze, 1)
        assert line.request(202, fc03(freeze), 7)[2:] == (1).to_bytes(2, "big")
        assert line.request(201, fc03(freeze), 7)[2:] == (0).to_bytes(2, "big")
        # st1 also has a TCP port of its own: the same image behind both.
        c = client_on(d, port)
        assert reg(c, D0) == 100


def shared_tcp_config(shared, own, b_dest="R1", shared_b=None):
    shared_b = shared if shared_b is None else shared_b
    return f"""\
plcs:
  - {{name: a, profile: fbs, station: 1, simulator: {{unit: 201}},
     modbus: {{tcp: {{bind: 127.0.0.1, port: {shared}}}}}}}
  - name: b
    profile: fbs
    station: 2
    simulator: {{unit: 202}}
    modbus: {{tcp: {{bind: 127.0.0.1, port: {shared_b}}}}}
    program:
      - MOV: {{en: M1926, s: R0, d: {b_dest}}}
  - {{name: own, profile: fbs, modbus: {{tcp: {{bind: 127.0.0.1, port: {own}}}}}}}
"""


def exception_code(r):
    assert r.isError(), r
    return r.exception_code


def test_two_stations_behind_one_listener_and_one_on_its_own(tmp_path):
    shared, own = free_port(), free_port()
    d = spawn(tmp_path, shared_tcp_config(shared, own), [shared, own])
    try:
        assert d.wait_log(f"listening on tcp 127.0.0.1:{shared} for plcs[0] (a), plcs[1] (b)")
        s, o = client_on(d, shared), client_on(d, own)
        # Routed by unit ID; writes isolated between the PLCs.
        assert not s.write_register(D0, 11, slave=1).isError()
        assert not s.write_register(D0, 22, slave=2).isError()
        assert not o.write_register(D0, 33, slave=1).isError()
        assert reg(s, D0, unit=1) == 11
        assert reg(s, D0, unit=2) == 22
        assert reg(o, D0, unit=1) == 33
        # Units nobody has behind the shared listener, 0 and 255 included: exception 0Bh.
        for unit in (3, 0, 255):
            assert exception_code(s.read_holding_registers(D0, 1, slave=unit)) == 0x0B, unit
        # The PLC alone on its port keeps the single-PLC rule: 0 and 255 are the device itself.
        assert reg(o, D0, unit=0) == 33
        assert reg(o, D0, unit=255) == 33
        # Each simulator unit goes to its PLC: freezing b leaves a scanning.
        freeze = 1  # docs/simulator-and-plant.md: 1 = scans stopped
        assert not s.write_register(freeze, 1, slave=202).isError()
        assert reg(s, freeze, unit=202) == 1
        assert reg(s, freeze, unit=201) == 0

        # SIGHUP: b's program changes and the shared listener moves to a new port, both PLCs
        # alike; the routes follow b's new PLC.
        moved = free_port()
        Path(d.config_path).write_text(shared_tcp_config(moved, own, b_dest="R2"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: applied to 2 of 3 PLCs"), d.log_text()
        assert d.wait_log(f"listening on tcp 127.0.0.1:{moved}"), d.log_text()
        assert not port_open(shared)
        m = client_on(d, moved)
        assert reg(m, D0, unit=1) == 11 and reg(m, D0, unit=2) == 22
        assert not m.write_register(0, 5, slave=2).isError()
        assert reg(m, freeze, unit=202) == 1  # still frozen: no scan copied R0 yet
        time.sleep(0.1)
        assert reg(m, 2, unit=2) == 0
        assert not m.write_register(freeze, 0, slave=202).isError()  # b scans again
        time.sleep(0.2)
        assert reg(m, 2, unit=2) == 5
        assert reg(m, 1, unit=2) == 0  # the old program's destination
        assert reg(m, 0, unit=1) == 0

        # A reload that splits the shared listener is refused; everything stays as it was.
        Path(d.config_path).write_text(shared_tcp_config(moved, own, shared_b=free_port()))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("configuration rejected"), d.log_text()
        assert ("reload: plcs[0] (a): the PLCs sharing its tcp listener changed; restart "
                "plcemud to apply it") in d.log_text()
        assert reg(m, D0, unit=2) == 22
        assert d.proc.poll() is None
    finally:
        assert d.stop() == 0


def two_ovens(a_port, b_port):
    return f"""\
plcs:
  - name: a
    profile: fbs
    persistence: {{enabled: false}}
    init: {{R0: [111]}}
    modbus: {{tcp: {{bind: 127.0.0.1, port: {a_port}}}}}
  - name: b
    profile: fbs
    persistence: {{enabled: false}}
    init: {{R0: [222]}}
    modbus: {{tcp: {{bind: 127.0.0.1, port: {b_port}}}}}
"""


def r0_over(sock):
    """R0 read over an open connection (None when no answer comes)."""
    reply = raw_exchange(sock, b"\x03\x00\x00\x00\x01")
    return None if reply is None or reply[0] != 3 else int.from_bytes(reply[2:4], "big")


def r0_on(port):
    with socket.create_connection(("127.0.0.1", port), timeout=3) as s:
        return r0_over(s)


def test_a_reload_gives_a_port_one_plc_leaves_to_another(tmp_path):
    """A port freed by the same reload is not "in use": the PLC leaving it lets go of it first
    (and gets it back if the reload fails), so ports can move between PLCs, even swap."""
    p1, p2, p3 = free_port(), free_port(), free_port()
    d = spawn(tmp_path, two_ovens(p1, p2), [p1, p2])
    try:
        assert (r0_on(p1), r0_on(p2)) == (111, 222)
        # b takes a's port, a moves to a new one.
        Path(d.config_path).write_text(two_ovens(p3, p1))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: applied to 2 of 2 PLCs"), d.log_text()
        assert (r0_on(p3), r0_on(p1)) == (111, 222)
        assert not port_open(p2)
        assert f"reload: plcs[1] (b): closing tcp 127.0.0.1:{p1} to listen on 127.0.0.1:{p1}" \
            in d.log_text()
        # A swap: each PLC's port is held by the other's listener until the reload closes it.
        Path(d.config_path).write_text(two_ovens(p1, p3))
        d.proc.send_signal(signal.SIGHUP)
        wait_count(d, "reload: applied to 2 of 2 PLCs", 2)
        assert (r0_on(p1), r0_on(p3)) == (111, 222)
        # A port nobody in the daemon gives up is still refused, and what ran goes on.
        with socket.create_server(("127.0.0.1", 0)) as other:
            taken = other.getsockname()[1]
            Path(d.config_path).write_text(two_ovens(taken, p1))
            d.proc.send_signal(signal.SIGHUP)
            assert d.wait_log("configuration rejected"), d.log_text()
        assert f"cannot listen on tcp 127.0.0.1:{taken}" in d.log_text()
        assert (r0_on(p1), r0_on(p3)) == (111, 222)
        assert d.proc.poll() is None
    finally:
        assert d.stop() == 0


def test_a_reload_refused_for_an_address_disturbs_no_client(tmp_path):
    """docs/operations.md, "Reload": a reload refused leaves what runs alone. One whose new
    address is no address of this host freed the port of the running listener first (its
    clients were closed) as if the port were in use; so did one where a later listener of the
    same reload could not be had after an earlier one had freed a port."""
    p1, p2, p3 = free_port(), free_port(), free_port()
    d = spawn(tmp_path, two_ovens(p1, p2), [p1, p2])
    nowhere = "bind: 192.0.2.1"  # an address of no interface here
    try:
        with socket.create_connection(("127.0.0.1", p1), timeout=3) as a, \
                socket.create_connection(("127.0.0.1", p2), timeout=3) as b:
            for text in (
                    # a's port on a new address.
                    two_ovens(p1, p2).replace(f"bind: 127.0.0.1, port: {p1}",
                                              f"{nowhere}, port: {p1}"),
                    # a takes b's port (b's listener would go first), b's new one cannot be.
                    two_ovens(p2, p3).replace(f"bind: 127.0.0.1, port: {p3}",
                                              f"{nowhere}, port: {p3}")):
                rejected = d.log_text().count("configuration rejected")
                Path(d.config_path).write_text(text)
                d.proc.send_signal(signal.SIGHUP)
                wait_count(d, "configuration rejected", rejected + 1)
                assert r0_over(a) == 111 and r0_over(b) == 222, d.log_text()
        log = d.log_text()
        assert log.count("Cannot assign requested address") == 2, log
        assert "to listen on" not in log and "server stopping" not in log, log
    finally:
        assert d.stop() == 0


def three_ovens(a_port, b_port, c_port):
    return two_ovens(a_port, b_port) + f"""\
  - name: c
    profile: fbs
    persistence: {{enabled: false}}
    init: {{R0: [333]}}
    modbus: {{tcp: {{bind: 127.0.0.1, port: {c_port}}}}}
"""


def test_a_reload_refused_for_a_port_in_use_elsewhere_closes_nothing_first(tmp_path):
    """a and b swap ports (each frees the other's), c moves to a port another process holds:
    refused, and a's and b's listeners were closed before c was looked at, their clients
    dropped. Whether that happened hung on the order of plcs:."""
    p1, p2, p3 = free_port(), free_port(), free_port()
    d = spawn(tmp_path, three_ovens(p1, p2, p3), [p1, p2, p3])
    try:
        with socket.create_server(("127.0.0.1", 0)) as other, \
                socket.create_connection(("127.0.0.1", p1), timeout=3) as a, \
                socket.create_connection(("127.0.0.1", p2), timeout=3) as b:
            Path(d.config_path).write_text(three_ovens(p2, p1, other.getsockname()[1]))
            d.proc.send_signal(signal.SIGHUP)
            assert d.wait_log("configuration rejected"), d.log_text()
            assert r0_over(a) == 111 and r0_over(b) == 222, d.log_text()
        assert "to listen on" not in d.log_text(), d.log_text()
    finally:
        assert d.stop() == 0


def test_the_port_a_port_0_listener_was_given_can_be_written_in(tmp_path):
    """docs/operations.md, "Reload": a port this reload gives up is not "in use". Pinning
    the port the kernel gave a port-0 listener was refused as in use."""
    p2 = free_port()
    d = spawn_plcs(tmp_path, two_ovens(0, p2), [p2])
    try:
        m = re.search(r"plcs\[0\] \(a\): listening on tcp 127\.0\.0\.1:(\d+)", d.log_text())
        assert m, d.log_text()
        given = int(m.group(1))
        Path(d.config_path).write_text(two_ovens(given, p2))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: applied"), d.log_text()
        assert r0_on(given) == 111
    finally:
        assert d.stop() == 0


# --- Unit IDs in force: R4055 and reloads (docs/configuration.md, "Sharing a listener") ---

R4055 = 4055  # fbs: the station; 55h in the high byte sets it


def wait_reg(c, addr, value, unit, timeout=2.0):
    """Polls `unit` until the register holds `value` (a scan has run, the unit answers); returns
    what it last held, or None when the unit never answered."""
    deadline = time.monotonic() + timeout
    while True:
        r = c.read_holding_registers(addr, 1, slave=unit)
        got = None if r.isError() else r.registers[0]
        if got == value or time.monotonic() > deadline:
            return got
        time.sleep(0.02)


def wait_count(d, text, n, timeout=5.0):
    """Waits until the log holds `text` `n` times."""
    deadline = time.monotonic() + timeout
    while d.log_text().count(text) < n:
        assert time.monotonic() < deadline, d.log_text()
        time.sleep(0.02)


def test_max_clients_of_a_shared_listener_counts_every_plcs_clients(tmp_path):
    shared, own = free_port(), free_port()
    d = spawn(tmp_path, shared_tcp_config(shared, own).replace(
        f"port: {shared}}}", f"port: {shared}, max_clients: 2}}"), [shared, own])
    try:
        assert d.wait_log("disconnected"), d.log_text()  # spawn's probe has gone
        first, second = (socket.create_connection(("127.0.0.1", shared), timeout=1)
                         for _ in range(2))
        with first, second:
            for c in (first, second):  # both talk to a
                assert raw_exchange(c, fc03(D0), unit=1) == b"\x03\x02\x00\x00"
            # A third is refused, though it would talk to b.
            with socket.create_connection(("127.0.0.1", shared), timeout=1) as third:
                with contextlib.suppress(ConnectionResetError):
                    assert raw_exchange(third, fc03(D0), unit=2) is None
            assert d.wait_log("refused: 2 clients already connected (modbus.tcp.max_clients)")
            assert raw_exchange(second, fc03(D0), unit=2) == b"\x03\x02\x00\x00"
    finally:
        assert d.stop() == 0


def test_r4055_cannot_take_a_unit_served_on_the_plcs_listeners(tmp_path):
    shared, own = free_port(), free_port()
    d = spawn(tmp_path, shared_tcp_config(shared, own), [shared, own])
    try:
        s, o = client_on(d, shared), client_on(d, own)
        assert not s.write_register(D0, 11, slave=1).isError()
        assert not s.write_register(D0, 22, slave=2).isError()
        # b's station, b's simulator unit, a's own simulator unit: refused, the station stays.
        for taken, holder in ((2, "plcs[1] (b)'s station"), (202, "plcs[1] (b)'s simulator unit"),
                              (201, "its own simulator unit")):
            assert not s.write_register(R4055, 0x5500 | taken, slave=1).isError()
            assert wait_reg(s, R4055, 1, unit=1) == 1, taken
            assert d.wait_log(f"plcs[0] (a): R4055: station {taken} refused: it is {holder} on "
                              f"tcp 127.0.0.1:{shared}"), d.log_text()
        assert reg(s, D0, unit=1) == 11 and reg(s, D0, unit=2) == 22
        assert not s.write_register(D0, 12, slave=1).isError()
        assert reg(s, D0, unit=2) == 22  # the write went to a, not to b
        # A free unit is taken as before: a answers 3 now, and 1 is nobody's.
        assert not s.write_register(R4055, 0x5503, slave=1).isError()
        assert wait_reg(s, R4055, 3, unit=3) == 3
        assert reg(s, D0, unit=3) == 12
        assert exception_code(s.read_holding_registers(D0, 1, slave=1)) == 0x0B
        # A PLC alone on its listener may not take its own simulator unit either.
        assert not o.write_register(R4055, 0x5500 | 247, slave=1).isError()
        assert wait_reg(o, R4055, 1, unit=1) == 1
        assert d.wait_log("plcs[2] (own): R4055: station 247 refused: it is its own simulator "
                          "unit"), d.log_text()
        assert not o.write_register(R4055, 0x5505, slave=1).isError()
        assert wait_reg(o, R4055, 5, unit=5) == 5
    finally:
        assert d.stop() == 0


def test_a_broadcast_r4055_on_a_line_gives_the_station_to_one_plc(tmp_path):
    with multidrop(tmp_path) as (d, line, _, _):
        # st1 and st2 (FBs) both execute it; the first to scan takes 9, the other keeps its own.
        line.send(frame_of(0, fc06(R4055, 0x5509)))
        assert line.silent(0.3)
        assert line.request(9, fc03(R4055), 7)[2:] == (9).to_bytes(2, "big")
        kept = []
        for unit in (1, 2):
            line.send(frame_of(unit, fc03(R4055)))
            reply = line.receive(7, 0.3)
            if reply:
                assert reply[3:5] == unit.to_bytes(2, "big"), reply.hex()
                kept.append(unit)
        assert len(kept) == 1, kept
        assert d.wait_log("R4055: station 9 refused: it is plcs["), d.log_text()


def test_reload_checks_units_against_the_stations_in_force(tmp_path):
    shared, own = free_port(), free_port()
    d = spawn(tmp_path, shared_tcp_config(shared, own), [shared, own])
    try:
        s = client_on(d, shared)
        assert not s.write_register(D0, 11, slave=1).isError()
        assert not s.write_register(D0, 22, slave=2).isError()
        assert not s.write_register(R4055, 0x5505, slave=1).isError()  # a is station 5 now
        assert wait_reg(s, R4055, 5, unit=5) == 5
        # b's config asks for 5, which a holds live: refused, every PLC keeps its config.
        Path(d.config_path).write_text(
            shared_tcp_config(shared, own, b_dest="R2").replace("station: 2", "station: 5"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("configuration rejected"), d.log_text()
        assert ("reload: plcs[1] (b): its station 5 is also plcs[0] (a)'s station 5 (in force: "
                f"set through R4055; the config says 1) on the shared tcp listener "
                f"127.0.0.1:{shared}") in d.log_text(), d.log_text()
        assert reg(s, D0, unit=5) == 11 and reg(s, D0, unit=2) == 22
        # a's config station does not change: a keeps 5 across this reload and the next.
        for n in (1, 2):
            Path(d.config_path).write_text(shared_tcp_config(shared, own, b_dest=f"R{n + 2}"))
            d.proc.send_signal(signal.SIGHUP)
            wait_count(d, "reload: applied to 1 of 3 PLCs", n)
            assert reg(s, D0, unit=5) == 11 and reg(s, D0, unit=2) == 22, n
    finally:
        assert d.stop() == 0


def with_programs(text):
    """multidrop_config with st1 and st2 copying R0 to R1 in every scan."""
    mov = "program: [{MOV: {en: M1926, s: R0, d: R1}}], "
    return text.replace("{name: st1, ", "{name: st1, " + mov).replace("{name: st2, ",
                                                                      "{name: st2, " + mov)


def test_a_shared_line_that_cannot_be_reopened_at_a_reload(tmp_path):
    with multidrop(tmp_path) as (d, line, pair, port):
        # Like a PLC alone on its line: the reload applies, and its PLCs run without the line,
        # which is tried again with back-off until the device is there (docs/configuration.md,
        # "Several PLCs").
        later = tmp_path / "later"
        later.mkdir()
        missing = later / "plcemu-rtu-a"  # where PtyPair(later) will put its device
        Path(d.config_path).write_text(with_programs(multidrop_config(missing, port)))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: applied to 3 of 3 PLCs"), d.log_text()
        assert d.wait_log(f"reload: rtu: cannot open {missing}: No such file or directory; trying "
                          "it again with back-off for plcs[0] (st1), plcs[1] (st2), plcs[2] (st3)"
                          ), d.log_text()
        assert "rtu: rtu:" not in d.log_text()
        assert "configuration rejected" not in d.log_text()
        # st1 took its new config: its new program copies R0 to R1, seen on its TCP port.
        c = client_on(d, port)
        assert not c.write_register(0, 41, slave=1).isError()
        assert wait_reg(c, 1, 41, unit=1) == 41
        # The old line is closed: nobody answers on it.
        line.send(frame_of(2, fc03(D0)))
        assert line.silent(0.2)

        # The device appears: the back-off opens it without a reload (it took another SIGHUP),
        # and every station answers on it, st2 with its new program.
        back = PtyPair(later)
        assert back.slave == str(missing)
        line = RawLine(back.master)  # the old line's own is closed by multidrop()
        try:
            assert d.wait_log(f"rtu: {missing}: reopened", timeout=8), d.log_text()
            assert "reload: applied to 0 of 3" not in d.log_text()
            assert line.request(2, fc06(0, 42), 8) == fc06(0, 42)
            deadline = time.monotonic() + 2
            while line.request(2, fc03(1), 7)[2:] != (42).to_bytes(2, "big"):
                assert time.monotonic() < deadline, "st2's new program never copied R0 to R1"
                time.sleep(0.02)
            for unit in (1, 3):
                assert line.request(unit, fc03(D0), 7)[2:] == (0).to_bytes(2, "big"), unit
            assert reg(c, 1, unit=1) == 41  # st1 kept its image across both reloads
        finally:
            line.close()
            back.stop()

def test_falling_behind_real_time_names_the_plc(tmp_path, ports):
    # Scans of 100 us in real time: 1.5 s behind is more than one catch-up round can run.
    text = plcs_config(ports, tmp_path).replace("    profile: fbs\n",
                                                "    profile: fbs\n    scan_ms: 1\n"
                                                "    time_scale: 10\n")
    d = spawn(tmp_path, text, ports)
    try:
        # The ports accept once bound, before the event loop runs: an answer says it runs (a
        # process stopped before that had no scan to fall behind).
        with ModbusTcpClient("127.0.0.1", port=ports[0], timeout=3) as c:
            reg(c, 0, unit=1)
        # A stopped process falls behind real time in every PLC's scans.
        d.proc.send_signal(signal.SIGSTOP)
        time.sleep(1.5)
        d.proc.send_signal(signal.SIGCONT)
        # The two PLCs share a deadline, so either may be woken (and log) first.
        assert d.wait_log("plcs[1] (line-b): scan: more than 1 s behind real time"), d.log_text()
        assert d.wait_log("plcs[0] (line-a): scan: more than 1 s behind real time"), d.log_text()
    finally:
        assert d.stop() == 0


def reload_config(hp, p0, p1, b_preset, head=""):
    """Two fbs PLCs, a and b, and the console beside them; b presets R100 with `b_preset`;
    `head` goes first (a comment moves every line below it)."""
    entry = ("  - {{name: {n}, profile: fbs, modbus: {{tcp: {{bind: 127.0.0.1, port: {p}}}}}, "
             "persistence: {{enabled: false}}, init: {{R100: {v}}}}}\n")
    return (f"{head}http: {{bind: 127.0.0.1, port: {hp}}}\nplcs:\n" +
            entry.format(n="a", p=p0, v=5) + entry.format(n="b", p=p1, v=b_preset))


def scans(hp):
    m = parse_metrics(get(hp, "/metrics").body.decode())
    return (m[("plcemu_scans_total", (("plc", "a"),))], m[("plcemu_scans_total", (("plc", "b"),))])


def test_a_reload_rebuilds_only_the_plcs_whose_entry_changed(tmp_path):
    """docs/operations.md, "Reload (SIGHUP)": with `plcs:`, a PLC whose entry reads as it did
    (wherever its lines now stand) runs on untouched; the one whose entry changed is rebuilt.
    /metrics counts each PLC's scans since it was built."""
    hp, p0, p1 = free_port(), free_port(), free_port()
    d = spawn(tmp_path, reload_config(hp, p0, p1, 7), [hp, p0, p1])
    try:
        deadline = time.monotonic() + 10
        while min(scans(hp)) < 100:
            assert time.monotonic() < deadline
            time.sleep(0.05)
        a0, b0 = scans(hp)
        # b's preset changes; a comment first moves every line of both entries.
        Path(d.config_path).write_text(reload_config(hp, p0, p1, 8, head="# moved\n\n"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: applied to 1 of 2 PLCs; 1 unchanged run on untouched"), \
            d.log_text()
        assert d.wait_log("reload: plcs[1] (b): init: changed"), d.log_text()
        assert "reload: plcs[0] (a):" not in d.log_text(), d.log_text()
        a1, b1 = scans(hp)
        assert a1 > a0, (a0, a1)  # a's program was not restarted
        assert b1 < b0, (b0, b1)  # b's was
        assert reg(client_on(d, p1), 100) == 7  # retained values win over presets at a reload

        # `log:` is the process's: a new level changes no PLC.
        while scans(hp)[1] < 100:
            assert time.monotonic() < deadline + 10
            time.sleep(0.05)
        a1, b1 = scans(hp)
        Path(d.config_path).write_text("log: {level: warn}\n" +
                                       reload_config(hp, p0, p1, 8, head="# moved\n\n"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: log.level: info -> warn"), d.log_text()
        time.sleep(0.2)  # the reload is through, its last lines below the new level
        a2, b2 = scans(hp)
        assert a2 > a1 and b2 > b1, (a1, b1, a2, b2)
        assert "applied to 0 of 2" not in d.log_text()  # said at info, now below the level
    finally:
        assert d.stop() == 0


def test_a_state_file_that_cannot_be_had_names_its_plc(tmp_path):
    # Of many PLCs, the error says which one's file it is, as its other lines do.
    (tmp_path / "b.state").mkdir()
    path = tmp_path / "two.yaml"
    ports = [free_port(), free_port()]
    path.write_text(
        "plcs:\n"
        f"  - {{name: a, profile: fbs, modbus: {{tcp: {{bind: 127.0.0.1, port: {ports[0]}}}}},"
        f" persistence: {{file: '{tmp_path / 'a.state'}'}}}}\n"
        f"  - {{name: b, profile: fbs, modbus: {{tcp: {{bind: 127.0.0.1, port: {ports[1]}}}}},"
        f" persistence: {{file: '{tmp_path / 'b.state'}'}}}}\n")
    r = run_plcemud("-c", path, timeout=20)
    assert r.returncode == 1, r
    assert f"plcs[1] (b): state file {tmp_path / 'b.state'}" in r.stderr, r.stderr
