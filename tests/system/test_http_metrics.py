"""What /metrics and the PLC list count (docs/operations.md, "Health and metrics"): requests by
protocol, function and error code, whatever listener carried them (Modbus TCP, Modbus RTU,
FATEK over UDP); the clients of UDP and serial listeners; connections accepted and refused;
scan lateness and duration histograms; reloads by outcome; state-file syncs."""

import signal
import socket
import time
from pathlib import Path

from plcemu_testing.fatek import Fatek, frame
from pymodbus.client import ModbusSerialClient

from conftest import free_port
from test_http_api import get, parse_metrics, wait_for, wait_listening


def metrics(port):
    r = get(port, "/metrics")
    assert r.status == 200, r
    return parse_metrics(r.body.decode())


def start(start_plcemud, body, modbus="modbus: {tcp: {bind: 127.0.0.1}}\n"):
    """An fbs PLC with `http:` and `body` (more top-level keys); returns (daemon, http port)."""
    hp = free_port()
    d = start_plcemud(f"profile: fbs\n{modbus}http: {{port: {hp}}}\n{body}")
    wait_listening(d, [hp])
    return d, hp


def count(m, name, **labels):
    return m.get((name, tuple(sorted(labels.items()))), 0)


def test_requests_and_errors_are_counted_by_protocol_function_and_code(start_plcemud):
    d, hp = start(start_plcemud, "persistence: {enabled: false}\n")
    c = d.client()
    for _ in range(5):
        assert not c.read_holding_registers(0, count=2, slave=1).isError()
    assert c.read_holding_registers(4500, count=1, slave=1).isError()  # unmapped: 02
    assert not c.write_register(100, 7, slave=1).isError()
    m = metrics(hp)
    tcp = {"plc": "0", "protocol": "modbus-tcp"}
    assert count(m, "plcemu_requests_total", function="03", **tcp) == 6
    assert count(m, "plcemu_requests_total", function="06", **tcp) == 1
    assert count(m, "plcemu_request_errors_total", function="03", code="02", **tcp) == 1
    assert count(m, "plcemu_request_errors_total", function="06", code="02", **tcp) == 0


def test_a_fatek_udp_peer_is_a_client_and_its_requests_are_counted(start_plcemud):
    fp = free_port()
    d, hp = start(start_plcemud,
                  f"persistence: {{enabled: false}}\nfatek: {{udp: {{bind: 127.0.0.1, port: {fp}}}}}\n")
    with Fatek.udp(fp) as f:
        for _ in range(3):
            assert f.exchange(frame(1, 0x40)) is not None
        plc = get(hp, "/api/v1/plcs/0").json()
        peers = [c for c in plc["clients"] if c["protocol"] == "fatek"]
        assert len(peers) == 1, plc["clients"]
        assert peers[0]["peer"].startswith("127.0.0.1:"), peers
        assert peers[0]["requests"] == 3, peers
        traffic = get(hp, "/api/v1/plcs/0/traffic").json()
        assert [e["function"] for e in traffic["exchanges"] if e["protocol"] == "fatek"] == \
            ["40h"] * 3, traffic
        # An unknown command gets FATEK's error 4, listed and counted as 04 (the digit's
        # value, not its character's code, 34h).
        assert f.exchange(frame(1, 0x99)) == frame(1, 0x99, "4")
        newest = get(hp, "/api/v1/plcs/0/traffic").json()["exchanges"][-1]
        assert (newest["function"], newest["error"]) == ("99h", "04h"), newest
    m = metrics(hp)
    assert count(m, "plcemu_requests_total", plc="0", protocol="fatek", function="40") == 3
    assert count(m, "plcemu_request_errors_total", plc="0", protocol="fatek", function="99",
                 code="04") == 1


def test_the_master_of_an_rtu_line_is_a_client_until_the_line_closes(start_plcemud, pty):
    d, hp = start(start_plcemud, "persistence: {enabled: false}\n",
                  modbus=f"modbus:\n  tcp: {{bind: 127.0.0.1}}\n  rtu: {{device: {pty.slave}}}\n")
    # A pty refuses parity settings: the master's end stays N (the bytes are the same).
    master = ModbusSerialClient(pty.master, baudrate=9600, bytesize=8, parity="N", stopbits=1,
                                timeout=1, retries=1)
    assert master.connect()
    try:
        r = wait_for(lambda: not master.read_holding_registers(0, count=1, slave=1).isError(),
                     timeout=5, what="an RTU answer")
        assert r
        plc = get(hp, "/api/v1/plcs/0").json()
        rtu = [c for c in plc["clients"] if c["protocol"] == "modbus-rtu"]
        assert [c["peer"] for c in rtu] == [pty.slave], plc["clients"]
        assert rtu[0]["requests"] >= 1
        m = metrics(hp)
        assert count(m, "plcemu_requests_total", plc="0", protocol="modbus-rtu",
                     function="03") == rtu[0]["requests"]
    finally:
        master.close()
    # The device goes away (an adapter unplugged): its master is no longer listed.
    pty.stop()
    wait_for(lambda: not [c for c in get(hp, "/api/v1/plcs/0").json()["clients"]
                          if c["protocol"] == "modbus-rtu"],
             timeout=5, what="the lost line's master to leave the clients")


def test_connections_accepted_open_and_refused_are_counted(start_plcemud):
    # The Modbus listener allows only 10.9.9.9: a connection from loopback is refused at accept.
    d, hp = start(start_plcemud, "persistence: {enabled: false}\n")
    mp = d.port
    m0 = metrics(hp)
    tcp = {"protocol": "modbus-tcp", "endpoint": f"127.0.0.1:{mp}"}
    c = d.client()
    assert not c.read_holding_registers(0, count=1, slave=1).isError()
    m1 = metrics(hp)
    assert count(m1, "plcemu_connections_open", **tcp) == 1
    assert count(m1, "plcemu_connections_accepted_total", **tcp) == \
        count(m0, "plcemu_connections_accepted_total", **tcp) + 1
    c.close()
    wait_for(lambda: count(metrics(hp), "plcemu_connections_open", **tcp) == 0, timeout=3,
             what="the closed connection to be gone")
    http = {"protocol": "http", "endpoint": f"127.0.0.1:{hp}"}
    assert count(m1, "plcemu_connections_open", **http) >= 1  # the scrape itself


def test_a_peer_outside_the_allow_list_is_a_refused_connection(start_plcemud):
    d, hp = start(start_plcemud, "persistence: {enabled: false}\n",
                  modbus="modbus: {tcp: {bind: 127.0.0.1, allow: [10.9.9.9/32]}}\n")
    tcp = {"protocol": "modbus-tcp", "endpoint": f"127.0.0.1:{d.port}"}
    before = count(metrics(hp), "plcemu_connections_refused_total", **tcp)  # the start's probe
    for _ in range(2):
        s = socket.create_connection(("127.0.0.1", d.port), timeout=2)
        s.settimeout(2)
        assert s.recv(1) == b""  # closed at accept
        s.close()
    m = wait_for(lambda: (lambda m: m if count(m, "plcemu_connections_refused_total", **tcp)
                          == before + 2 else None)(metrics(hp)),
                 timeout=3, what="two more refusals counted")
    assert count(m, "plcemu_connections_accepted_total", **tcp) == 0


def test_scan_histograms_are_cumulative_and_grow(start_plcemud):
    d, hp = start(start_plcemud, "persistence: {enabled: false}\n")
    time.sleep(0.3)
    for name in ("plcemu_scan_lateness_seconds", "plcemu_scan_duration_seconds"):
        m = metrics(hp)
        buckets = sorted(
            ((float("inf") if dict(k[1])["le"] == "+Inf" else float(dict(k[1])["le"])), v)
            for k, v in m.items() if k[0] == name + "_bucket")
        assert len(buckets) == 10, buckets
        values = [v for _, v in buckets]
        assert values == sorted(values), buckets  # cumulative
        total = count(m, name + "_count", plc="0")
        assert values[-1] == total > 10, (buckets, total)
        assert count(m, name + "_sum", plc="0") > 0
        time.sleep(0.2)
        assert count(metrics(hp), name + "_count", plc="0") > total
    plc = get(hp, "/api/v1/plcs/0").json()
    assert 0 < plc["scan_us"] < 10_000, plc  # a 10 ms scan of a small program takes far less


def test_reloads_are_counted_applied_and_rejected(start_plcemud):
    d, hp = start(start_plcemud, "persistence: {enabled: false}\n")
    config = Path(d.config_path)
    text = config.read_text()
    # A change that applies, then one that cannot (the old config is kept).
    for addition, logged, applied, rejected in (("log: {level: info}\n", "reload: done", 1, 0),
                                                ("scan_ms: nonsense\n", "rejected", 1, 1)):
        config.write_text(text + addition)
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log(logged), d.log_text()
        m = metrics(hp)
        assert count(m, "plcemu_reloads_total", outcome="applied") == applied
        assert count(m, "plcemu_reloads_total", outcome="rejected") == rejected


def test_state_file_syncs_are_counted(start_plcemud, tmp_path):
    d, hp = start(start_plcemud,
                  f"persistence: {{enabled: true, file: {tmp_path}/m.state, sync_ms: 100}}\n")
    first = wait_for(lambda: count(metrics(hp), "plcemu_state_syncs_total", outcome="ok") or None,
                     timeout=3, what="a sync")
    time.sleep(0.5)
    m = metrics(hp)
    assert count(m, "plcemu_state_syncs_total", outcome="ok") >= first + 3
    assert count(m, "plcemu_state_syncs_total", outcome="failed") == 0


def test_a_sync_writes_only_the_pages_whose_retentive_devices_changed(start_plcemud, tmp_path):
    """docs/operations.md, "Retentive memory": with no program, nothing retentive changes by
    itself; a write to non-retentive devices (M0, R3500, on pages that also hold retentive ones)
    writes no page, a write to a retentive register (R100) one."""
    d, hp = start(start_plcemud,
                  f"persistence: {{enabled: true, file: {tmp_path}/p.state, sync_ms: 50}}\n")

    def pages():
        return count(metrics(hp), "plcemu_state_pages_written_total")

    def after_syncs(n):
        """The pages written once `n` more syncs have run."""
        s0 = count(metrics(hp), "plcemu_state_syncs_total", outcome="ok")
        wait_for(lambda: count(metrics(hp), "plcemu_state_syncs_total", outcome="ok") >= s0 + n
                 or None, timeout=5, what=f"{n} syncs")
        return pages()

    # The first syncs write the file whole (a page changed while written is written again).
    settled = after_syncs(3)
    assert settled >= 9, "the first sync writes every page of the 9-page file"
    assert after_syncs(3) == settled, "nothing retentive changes by itself"
    c = d.client()
    assert not c.write_coil(2000, True, slave=1).isError()  # M0
    assert not c.write_register(3500, 7, slave=1).isError()  # R3500
    assert after_syncs(3) == settled, "only devices cleared at every start changed"
    assert not c.write_register(100, 7, slave=1).isError()  # R100, retentive
    assert after_syncs(3) == settled + 1
    m = metrics(hp)
    assert count(m, "plcemu_state_syncs_total", outcome="failed") == 0
