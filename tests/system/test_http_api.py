"""The HTTP side of plcemud (`http:`): the REST API under /api/v1, its refusals, live events,
the control loops of config/default.yaml, vb-pid.yaml and vb-tpid.yaml, /healthz and /metrics,
the console's pages, the OpenAPI document, and how the listener bounds its clients (HTTP/1.1
keep-alive and pipelining, frame timeout, max_clients, slow readers).

Every request here is made with the standard library (http.client, raw sockets); what the API
says is checked against what the PLC answers over Modbus TCP on the same image."""

import http.client
import json
import os
import re
import signal
import socket
import struct
import subprocess
import time
from pathlib import Path

import pytest
from pymodbus.client import ModbusTcpClient

from conftest import PLCEMUD, REPO, Daemon, free_port, port_open, run_plcemud
from test_hardening import cpu_over

TIMEOUT = 3.0  # every socket operation of a test
SIM_UNIT = 247  # the simulator-control Modbus unit (docs/simulator-and-plant.md)

# fbs Modbus map (docs/profile-fbs.md, "Modbus map"): holding register n is Rn (0-4167),
# coils 0-255 are Y0-Y255, 2000-4001 M0-M2001.
Y0_COIL = 0
M0_COIL = 2000
# vb Modbus map (docs/profile-vb.md): X0 is discrete input 13312 (octal numbering), Y0 coil 13056.
VB_X0_INPUT = 13312
VB_Y0_COIL = 13056

# The endpoints of the contract, as the OpenAPI document writes their paths.
CONTRACT_PATHS = [
    "/api/v1/plcs",
    "/api/v1/plcs/{plc}",
    "/api/v1/plcs/{plc}/devices/{device}",
    "/api/v1/plcs/{plc}/simulator",
    "/api/v1/plcs/{plc}/comm-faults",
    "/api/v1/plcs/{plc}/events",
    "/api/v1/plcs/{plc}/traffic",
    "/api/v1/plcs/{plc}/loops",
    "/api/v1/plcs/{plc}/loops/history",
    "/api/v1/events",
    "/api/v1/openapi.json",
    "/healthz",
    "/metrics",
    "/",
    "/plcs/{plc}/devices",
    "/plcs/{plc}/loops",
    "/plcs/{plc}/plant",
    "/plcs/{plc}/traffic",
    "/static/{file}",
]


# --- Talking HTTP ---------------------------------------------------------------------------


class Reply:
    """One HTTP response, whole."""

    def __init__(self, status, headers, body):
        self.status = status
        self.headers = headers  # lower-case name -> value
        self.body = body

    def header(self, name):
        return self.headers.get(name.lower())

    def json(self):
        assert self.header("content-type") == "application/json", self.headers
        return json.loads(self.body)

    def __repr__(self):
        return f"<{self.status} {self.headers} {self.body[:300]!r}>"


def request(port, method, path, body=None, headers=None, json_body=None, timeout=TIMEOUT):
    """One request on a new connection (http.client), the response read whole."""
    headers = dict(headers or {})
    if json_body is not None:
        body = json.dumps(json_body)
        headers.setdefault("Content-Type", "application/json")
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    try:
        conn.request(method, path, body=body, headers=headers)
        r = conn.getresponse()
        data = r.read()
        return Reply(r.status, {k.lower(): v for k, v in r.getheaders()}, data)
    finally:
        conn.close()


def get(port, path, **kw):
    return request(port, "GET", path, **kw)


def put(port, path, json_body=None, **kw):
    return request(port, "PUT", path, json_body=json_body, **kw)


def assert_error(reply, status, *needles):
    """`reply` is a refusal: exactly `status`, a JSON body {"error": message} whose message is a
    sentence holding every one of `needles`."""
    assert reply.status == status, reply
    body = reply.json()
    assert list(body) == ["error"], body
    message = body["error"]
    assert isinstance(message, str) and len(message) >= 10, body
    for n in needles:
        assert n in message, (n, message)
    return message


def recv_response(sock, head_only=False):
    """Reads one response from a raw socket: (status, headers, body). The body is what
    Content-Length says (nothing for a HEAD)."""
    buf = getattr(sock, "_rest", b"")
    while b"\r\n\r\n" not in buf:
        chunk = sock.recv(65536)
        assert chunk, f"connection closed inside a response head: {buf!r}"
        buf += chunk
    head, _, buf = buf.partition(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    status_line = lines[0].split(" ", 2)
    assert status_line[0] == "HTTP/1.1", lines[0]
    headers = {}
    for line in lines[1:]:
        k, _, v = line.partition(":")
        headers[k.strip().lower()] = v.strip()
    length = 0 if head_only else int(headers.get("content-length", "0"))
    while len(buf) < length:
        chunk = sock.recv(65536)
        assert chunk, "connection closed inside a response body"
        buf += chunk
    body, sock._rest = buf[:length], buf[length:]
    return Reply(int(status_line[1]), headers, body)


class RawSocket(socket.socket):
    """A socket that can keep bytes read past one response (recv_response)."""

    _rest = b""


def connect(port, timeout=TIMEOUT, rcvbuf=None) -> RawSocket:
    s = RawSocket(socket.AF_INET, socket.SOCK_STREAM)
    if rcvbuf is not None:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
    s.settimeout(timeout)
    s.connect(("127.0.0.1", port))
    return s


def raw_request(method, path, body=b"", headers=()):
    """The bytes of one HTTP/1.1 request."""
    lines = [f"{method} {path} HTTP/1.1", "Host: 127.0.0.1"]
    lines += list(headers)
    if body or method == "PUT":
        lines.append(f"Content-Length: {len(body)}")
    return ("\r\n".join(lines) + "\r\n\r\n").encode() + body


def closed_by_server(sock, within=2.0) -> bool:
    """True when the server closes `sock` (EOF or reset) within `within` seconds, whatever it
    sends first."""
    sock.settimeout(within)
    deadline = time.monotonic() + within
    try:
        while time.monotonic() < deadline:
            if not sock.recv(65536):
                return True
    except (ConnectionResetError, BrokenPipeError):
        return True
    except socket.timeout:
        return False
    return False


def json_put_request(path, values, extra_headers=()):
    body = json.dumps({"values": values}).encode()
    return raw_request("PUT", path, body, ["Content-Type: application/json", *extra_headers])


# --- Starting plcemud -----------------------------------------------------------------------


def wait_listening(d: Daemon, ports, timeout=10.0):
    deadline = time.monotonic() + timeout
    while not all(port_open(p) for p in ports):
        if d.proc.poll() is not None or time.monotonic() > deadline:
            d.stop(signal.SIGKILL)
            pytest.fail(f"plcemud did not listen on {ports}\n{d.log_text()}")
        time.sleep(0.02)


def spawn(directory: Path, text: str, ports, modbus_port=None) -> Daemon:
    """plcemud on config `text` written in `directory`, once each of `ports` listens; with
    `modbus_port`, passed as --port (a one-PLC file). The caller stops it."""
    stem = f"http-{time.monotonic_ns()}"
    config_path = directory / f"{stem}.yaml"
    config_path.write_text(text)
    log_path = directory / f"{stem}.log"
    args = [PLCEMUD, "-c", str(config_path)]
    if modbus_port is not None:
        args += ["--port", str(modbus_port)]
    env = dict(os.environ)
    env.pop("STATE_DIRECTORY", None)
    with open(log_path, "wb") as log:
        proc = subprocess.Popen(
            args, stdin=subprocess.DEVNULL, stdout=log, stderr=log, env=env, cwd=directory
        )
    d = Daemon(proc, modbus_port if modbus_port is not None else ports[0], config_path, log_path)
    wait_listening(d, ports)
    return d


def single_config(http_port, http_extra="", profile="fbs", modbus_extra="", extra=""):
    return (
        f"profile: {profile}\n"
        f"modbus: {{tcp: {{bind: 127.0.0.1}}{modbus_extra}}}\n"
        f"http: {{port: {http_port}{http_extra}}}\n"
        f"{extra}"
    )


class Plc:
    """A one-PLC plcemud with `http:`: .http (the console's port), .daemon (Modbus: .client())."""

    def __init__(self, daemon, http_port):
        self.daemon = daemon
        self.http = http_port

    def client(self):
        return self.daemon.client()


@pytest.fixture
def start_http(start_plcemud):
    """start(http_extra="", profile="fbs", modbus_extra="", extra="") -> Plc."""

    def start(http_extra="", profile="fbs", modbus_extra="", extra=""):
        hp = free_port()
        d = start_plcemud(single_config(hp, http_extra, profile, modbus_extra, extra))
        wait_listening(d, [hp])
        return Plc(d, hp)

    return start


@pytest.fixture(scope="module")
def fbs(tmp_path_factory):
    """One plain fbs PLC with `http:`, shared by the tests that leave nothing behind them
    (or only registers of their own)."""
    directory = tmp_path_factory.mktemp("http-fbs")
    hp, mp = free_port(), free_port()
    d = spawn(directory, single_config(hp), [hp, mp], modbus_port=mp)
    yield Plc(d, hp)
    d.stop()


@pytest.fixture
def start_plcs(tmp_path):
    """start(text, ports) -> Daemon for a `plcs:` config (each entry names its ports)."""
    daemons = []

    def start(text, ports):
        d = spawn(tmp_path, text, ports)
        daemons.append(d)
        return d

    yield start
    for d in daemons:
        d.stop()


def holding(client, address, count=1, unit=1):
    r = client.read_holding_registers(address, count, slave=unit)
    assert not r.isError(), r
    return list(r.registers[:count])


def coils(client, address, count=1):
    r = client.read_coils(address, count, slave=1)
    assert not r.isError(), r
    return [int(b) for b in r.bits[:count]]


def devices(port, device, count=None, plc="0"):
    q = "" if count is None else f"?count={count}"
    return get(port, f"/api/v1/plcs/{plc}/devices/{device}{q}")


def plc_state(port, plc="0"):
    r = get(port, f"/api/v1/plcs/{plc}")
    assert r.status == 200, r
    return r.json()


def wait_for(predicate, timeout=2.0, what="condition"):
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(f"{what} not reached within {timeout} s")
        time.sleep(0.02)


# --- /api/v1/plcs ---------------------------------------------------------------------------


def test_plcs_lists_the_one_plc_of_a_file_as_0(fbs):
    r = get(fbs.http, "/api/v1/plcs")
    assert r.status == 200, r
    plcs = r.json()["plcs"]
    assert len(plcs) == 1, plcs
    p = plcs[0]
    assert (p["id"], p["index"], p["profile"], p["model"]) == ("0", 0, "fbs", "FBs-24MC"), p
    assert p["station"] == 1 and p["scan_ms"] == 10 and p["running"] is True, p
    assert isinstance(p["scans"], int) and p["scans"] > 0, p
    assert f"http 127.0.0.1:{fbs.http}" in p["listeners"], p
    assert f"tcp 127.0.0.1:{fbs.daemon.port}" in p["listeners"], p
    assert set(p["time"]) == {"scale", "frozen", "pending_steps", "simulated_s"}, p
    assert p["time"]["scale"] == 1 and p["time"]["frozen"] is False, p
    one = plc_state(fbs.http, "0")
    assert (one["id"], one["profile"], one["model"]) == ("0", "fbs", "FBs-24MC"), one
    assert one["scans"] >= p["scans"], (one, p)


def test_http_beside_plcs_serves_every_entry_by_name_and_by_position(start_plcs):
    hp, ma, mb = free_port(), free_port(), free_port()
    d = start_plcs(
        f"""\
http: {{port: {hp}}}
plcs:
  - name: alpha
    profile: fbs
    modbus: {{tcp: {{bind: 127.0.0.1, port: {ma}}}}}
  - name: beta
    profile: vb
    modbus: {{tcp: {{bind: 127.0.0.1, port: {mb}}}}}
""",
        [hp, ma, mb],
    )
    r = get(hp, "/api/v1/plcs")
    assert r.status == 200, r
    plcs = r.json()["plcs"]
    assert [(p["id"], p["index"], p["profile"]) for p in plcs] == [
        ("alpha", 0, "fbs"), ("beta", 1, "vb")], plcs
    assert plcs[1]["model"] == "VB2-32M", plcs
    for ref, want in [("alpha", "alpha"), ("0", "alpha"), ("beta", "beta"), ("1", "beta")]:
        assert plc_state(hp, ref)["id"] == want, ref
    # Writes reach the PLC named, and only it: alpha's R100 (holding 100) and beta's D100
    # (holding 100 on a VB).
    assert put(hp, "/api/v1/plcs/alpha/devices/R100", {"values": [111]}).status == 200
    assert put(hp, "/api/v1/plcs/1/devices/D100", {"values": [222]}).status == 200
    d.port = ma
    a = d.client()
    d.port = mb
    b = d.client()
    assert holding(a, 100) == [111]
    assert holding(b, 100) == [222]
    assert devices(hp, "R100", plc="0").json()["values"] == [111]
    assert devices(hp, "D100", plc="beta").json()["values"] == [222]
    # An R on a VB does not exist; a third PLC does not either.
    assert_error(devices(hp, "R100", plc="beta"), 404, "R100", "vb")
    assert_error(get(hp, "/api/v1/plcs/2"), 404, "'2'", "alpha, beta")
    assert_error(get(hp, "/api/v1/plcs/gamma/devices/R1"), 404, "'gamma'", "alpha, beta")


def test_an_entry_with_its_own_http_port_is_served_there_alone(start_plcs):
    shared, own, ma, mb = free_port(), free_port(), free_port(), free_port()
    d = start_plcs(
        f"""\
http: {{port: {shared}}}
plcs:
  - name: alpha
    profile: fbs
    modbus: {{tcp: {{bind: 127.0.0.1, port: {ma}}}}}
  - name: beta
    profile: fbs
    modbus: {{tcp: {{bind: 127.0.0.1, port: {mb}}}}}
    http: {{port: {own}}}
""",
        [shared, own, ma, mb],
    )
    assert [p["id"] for p in get(shared, "/api/v1/plcs").json()["plcs"]] == ["alpha"]
    assert [p["id"] for p in get(own, "/api/v1/plcs").json()["plcs"]] == ["beta"]
    assert_error(get(own, "/api/v1/plcs/alpha"), 404, "'alpha'", "beta")
    assert_error(get(shared, "/api/v1/plcs/beta"), 404, "'beta'", "alpha")
    assert_error(put(own, "/api/v1/plcs/alpha/devices/R7", {"values": [5]}), 404, "alpha")
    assert put(own, "/api/v1/plcs/beta/devices/R7", {"values": [77]}).status == 200
    d.port = ma
    a = d.client()
    d.port = mb
    b = d.client()
    assert holding(b, 7) == [77]
    assert holding(a, 7) == [0]


def test_a_position_names_the_entrys_place_in_plcs(start_plcs):
    # The contract: {plc} is the entry's name, or its position "0", "1", ... in plcs:. Entry 1
    # has a console of its own, so the shared console serves entries 0 and 2: "1" is not there,
    # and "2" is gamma.
    shared, own, m0, m1, m2 = (free_port() for _ in range(5))
    start_plcs(
        f"""\
http: {{port: {shared}}}
plcs:
  - name: alpha
    profile: fbs
    modbus: {{tcp: {{bind: 127.0.0.1, port: {m0}}}}}
  - profile: fbs
    modbus: {{tcp: {{bind: 127.0.0.1, port: {m1}}}}}
    http: {{port: {own}}}
  - name: gamma
    profile: fbs
    modbus: {{tcp: {{bind: 127.0.0.1, port: {m2}}}}}
""",
        [shared, own, m0, m1, m2],
    )
    assert plc_state(shared, "2")["id"] == "gamma"
    assert_error(get(shared, "/api/v1/plcs/1"), 404, "'1'")
    assert [p["id"] for p in get(own, "/api/v1/plcs").json()["plcs"]] == ["1"]
    assert plc_state(own, "1")["index"] == 1


# --- Devices: reads ---------------------------------------------------------------------------


def test_read_words_equal_what_modbus_reads(fbs):
    c = fbs.client()
    assert not c.write_registers(100, [11, 22, 33], slave=1).isError()
    r = devices(fbs.http, "R100", 3)
    assert r.status == 200, r
    body = r.json()
    assert body == {"device": "R100", "names": ["R100", "R101", "R102"], "bits": False,
                    "words": [1, 1, 1], "values": [11, 22, 33]}, body
    assert body["values"] == holding(c, 100, 3)
    # count defaults to 1; names are case-insensitive on the way in
    assert devices(fbs.http, "r100").json()["values"] == [11]
    assert devices(fbs.http, "R100").json()["names"] == ["R100"]


def test_read_bits_give_0_and_1(fbs):
    c = fbs.client()
    assert not c.write_coils(M0_COIL + 10, [True, False, True], slave=1).isError()
    assert not c.write_coils(Y0_COIL, [True, False, True, True], slave=1).isError()
    m = devices(fbs.http, "M10", 3).json()
    assert m == {"device": "M10", "names": ["M10", "M11", "M12"], "bits": True,
                 "words": [1, 1, 1], "values": [1, 0, 1]}, m
    y = devices(fbs.http, "Y0", 4).json()
    assert y["bits"] is True and y["values"] == [1, 0, 1, 1] == coils(c, Y0_COIL, 4), y


def test_read_a_word_of_bits(fbs):
    c = fbs.client()
    bits = [False] * 32
    bits[0] = bits[15] = True  # M800, M815
    bits[16 + 1] = True  # M817
    assert not c.write_coils(M0_COIL + 800, bits, slave=1).isError()
    r = devices(fbs.http, "WM800", 2).json()
    assert r == {"device": "WM800", "names": ["WM800", "WM816"], "bits": False,
                 "words": [1, 1], "values": [0x8001, 0x0002]}, r


def test_read_big_counts_and_the_end_of_an_area(fbs):
    r = devices(fbs.http, "R0", 1000).json()
    assert len(r["values"]) == len(r["names"]) == 1000 and r["names"][-1] == "R999", r["names"][-1]
    assert devices(fbs.http, "D3999", 1).json()["names"] == ["D3999"]
    assert_error(devices(fbs.http, "D3999", 2), 400, "D3999", "D3999")
    assert_error(devices(fbs.http, "Y250", 7), 400, "Y250", "Y255")


def test_vb_numbers_x_and_y_in_octal(start_http):
    plc = start_http(profile="vb", extra="init: {X17: 1}\n")
    c = plc.client()
    r = devices(plc.http, "X17", 2)
    assert r.status == 200, r
    body = r.json()
    assert body == {"device": "X17", "names": ["X17", "X20"], "bits": True, "words": [1, 1],
                    "values": [1, 0]}, body
    di = c.read_discrete_inputs(VB_X0_INPUT + 0o17, 2, slave=1)
    assert not di.isError(), di
    assert [int(b) for b in di.bits[:2]] == body["values"]
    assert devices(plc.http, "X7", 2).json()["names"] == ["X7", "X10"]
    assert_error(devices(plc.http, "X8"), 404, "'X8'", "octal")
    assert_error(devices(plc.http, "Y19"), 404, "'Y19'", "octal")
    # Y10 is the ninth output: coil 13056 + 8.
    assert put(plc.http, "/api/v1/plcs/0/devices/Y10", {"values": [1]}).status == 200
    assert coils(c, VB_Y0_COIL + 8) == [1]
    assert coils(c, VB_Y0_COIL + 10) == [0]
    # D8000-D8999 do not exist on a VB: not alone, not inside a span.
    assert_error(devices(plc.http, "D8000"), 404, "'D8000'", "D8000-D8999")
    assert_error(devices(plc.http, "D7999", 2), 400, "D7999", "D8000-D8999")
    assert_error(put(plc.http, "/api/v1/plcs/0/devices/D7999", {"values": [1, 2]}), 400,
                 "D8000-D8999")
    assert devices(plc.http, "D7999").json()["values"] == [0]
    assert devices(plc.http, "D9000", 2).json()["names"] == ["D9000", "D9001"]


# --- Devices: writes --------------------------------------------------------------------------


def test_a_write_is_read_back_over_modbus_in_the_same_scan(start_http):
    plc = start_http()
    c = plc.client()
    # Frozen: no scan runs between the write and the Modbus read.
    assert put(plc.http, "/api/v1/plcs/0/simulator", {"frozen": True}).status == 200
    time.sleep(0.05)
    scans = plc_state(plc.http)["scans"]
    r = put(plc.http, "/api/v1/plcs/0/devices/R120",
            {"values": [1234, -1, -32768, 65535, 0, True]})
    assert r.status == 200, r
    body = r.json()
    assert body == {"device": "R120", "names": [f"R{n}" for n in range(120, 126)],
                    "values": [1234, 65535, 32768, 65535, 0, 1]}, body
    assert holding(c, 120, 6) == [1234, 65535, 32768, 65535, 0, 1]
    assert devices(plc.http, "R120", 6).json()["values"] == body["values"]
    assert plc_state(plc.http)["scans"] == scans
    # Bits, and a word of bits.
    assert put(plc.http, "/api/v1/plcs/0/devices/Y0", {"values": [1, 0, True]}).status == 200
    assert coils(c, Y0_COIL, 3) == [1, 0, 1]
    r = put(plc.http, "/api/v1/plcs/0/devices/WM800", {"values": [0x0102]})
    assert r.status == 200 and r.json()["names"] == ["WM800"], r
    assert coils(c, M0_COIL + 800, 16) == [1 if n in (1, 8) else 0 for n in range(16)]
    assert plc_state(plc.http)["scans"] == scans
    # Content-Type with parameters is still JSON.
    r = request(plc.http, "PUT", "/api/v1/plcs/0/devices/R130", body='{"values": [5]}',
                headers={"Content-Type": "application/json; charset=utf-8"})
    assert r.status == 200, r
    assert holding(c, 130) == [5]


# --- Devices: refusals ------------------------------------------------------------------------


@pytest.mark.parametrize(
    "method,path,needles",
    [
        ("GET", "/api/v1/plcs/7", ["'7'", "there are: 0"]),
        ("GET", "/api/v1/plcs/kiln/devices/R100", ["'kiln'", "there are: 0"]),
        ("PUT", "/api/v1/plcs/1/devices/R100", ["'1'"]),
        ("GET", "/api/v1/plcs/7/simulator", ["'7'"]),
        ("GET", "/api/v1/plcs/7/events", ["'7'"]),
        ("GET", "/api/v1/plcs/7/traffic", ["'7'"]),
        ("GET", "/api/v1/plcs/7/loops", ["'7'"]),
        ("GET", "/api/v1/plcs/0/devices/Q5", ["'Q5'", "fbs"]),
        ("GET", "/api/v1/plcs/0/devices/R99999", ["'R99999'"]),
        ("GET", "/api/v1/plcs/0/devices/R-1", ["'R-1'"]),
        ("PUT", "/api/v1/plcs/0/devices/Q5", ["'Q5'"]),
        ("GET", "/api/v1/plcs/0/events?device=Q5", ["'Q5'"]),
    ],
)
def test_unknown_plcs_and_devices_are_404(fbs, method, path, needles):
    r = request(fbs.http, method, path, json_body={"values": [1]} if method == "PUT" else None)
    assert_error(r, 404, *needles)


@pytest.mark.parametrize(
    "path,quoted",
    [
        # U+202E (right-to-left override), U+2066 (an isolate), a line separator, controls and
        # a byte that is not UTF-8: what a link can put in a message a person reads.
        ("/api/v1/plcs/%E2%80%AEnlik", r"'\u202Enlik'"),
        ("/api/v1/plcs/0/devices/R1%E2%81%A6", r"'R1\u2066'"),
        ("/api/v1/nothing%E2%80%A8here%0D%0A%1B[31m", r"nothing\u2028here\r\n\x1B[31m"),
        ("/api/v1/plcs/%FFx", r"'\xFFx'"),
    ],
)
def test_a_refusal_shows_what_was_sent_escaped(fbs, path, quoted):
    # docs/console.md, "The API": the message quotes the address with the log's escapes.
    message = assert_error(get(fbs.http, path), 404, quoted)
    assert not any(c in message for c in "\u202e\u2066\u2028\r\n\x1b\ufffd"), message


def test_a_refusal_cuts_what_was_sent_between_characters(fbs):
    # A key cut at 40 bytes split the euro sign and showed "\\xE2".
    r = request(fbs.http, "PUT", "/api/v1/plcs/0/devices/R140",
                json_body={"a" * 39 + "\u20ac\u20ac": [1]})
    message = assert_error(r, 400, "unknown key")
    assert "a" * 39 + "\u20ac\u2026" in message and "\\x" not in message, message


@pytest.mark.parametrize("count", ["0", "1001", "abc", "-1", "", "1e3", "99999999999999999999"])
def test_count_out_of_range_is_400(fbs, count):
    assert_error(devices(fbs.http, "R100", count), 400, "count", "1000")


def test_count_out_of_range_on_events_is_400(fbs):
    assert_error(get(fbs.http, "/api/v1/plcs/0/events?device=R100&count=0"), 400, "count")
    assert_error(get(fbs.http, "/api/v1/plcs/0/events?device=R100&count=1001"), 400, "count")
    assert_error(get(fbs.http, "/api/v1/plcs/0/events?device=D3999&count=2"), 400, "D3999")


@pytest.mark.parametrize(
    "body,needles",
    [
        ({"values": ["a"]}, ["values", "whole numbers"]),
        ({"values": [1.5]}, ["values", "whole numbers"]),
        ({"values": [None]}, ["values", "whole numbers"]),
        ({"values": [[1]]}, ["values", "whole numbers"]),
        ({"values": [9, "x"]}, ["values", "whole numbers"]),
        ({"values": [65536]}, ["65536", "out of range", "-32768 to 65535"]),
        ({"values": [9, -32769]}, ["-32769", "out of range"]),
        # Past 2^63 the JSON library keeps a number unsigned: read as signed, 2^64 - 1 became -1
        # and was written as 65535.
        ({"values": [2**64 - 1]}, ["18446744073709551615 is out of range"]),
        ({"values": [2**64 - 5]}, ["18446744073709551611 is out of range"]),
        ({"values": [2**63]}, ["9223372036854775808 is out of range"]),
        ({"values": [-2**63]}, ["-9223372036854775808 is out of range"]),
        ({"values": []}, ["values", "list"]),
        ({"values": "5"}, ["values", "list"]),
        ({"values": 5}, ["values", "list"]),
        ({}, ["values"]),
        ({"value": [5]}, ["values"]),
        # The count said is the one sent (it said 1001 for any longer list).
        ({"values": [0] * 1500}, ["values", "1 to 1000", "got 1500"]),
    ],
)
def test_bad_values_are_400_and_write_nothing(fbs, body, needles):
    c = fbs.client()
    assert not c.write_registers(140, [4040, 4141], slave=1).isError()
    assert_error(put(fbs.http, "/api/v1/plcs/0/devices/R140", body), 400, *needles)
    assert holding(c, 140, 2) == [4040, 4141]


def test_bad_bit_values_are_400_and_write_nothing(fbs):
    c = fbs.client()
    assert not c.write_coils(Y0_COIL + 20, [False, False], slave=1).isError()
    assert_error(put(fbs.http, "/api/v1/plcs/0/devices/Y20", {"values": [1, 2]}), 400,
                 "out of range", "0 or 1")
    assert_error(put(fbs.http, "/api/v1/plcs/0/devices/Y20", {"values": [-1]}), 400, "0 or 1")
    assert_error(put(fbs.http, "/api/v1/plcs/0/devices/Y20", {"values": [2**64 - 1]}), 400,
                 "18446744073709551615 is out of range", "0 or 1")
    assert coils(fbs.client(), Y0_COIL + 20, 2) == [0, 0]
    # A span past the end of the area writes nothing either.
    assert_error(put(fbs.http, "/api/v1/plcs/0/devices/Y254", {"values": [1, 1, 1]}), 400,
                 "Y254", "Y255")
    assert coils(c, Y0_COIL + 254, 2) == [0, 0]


@pytest.mark.parametrize("body", ["{", "[1, 2]", '"values"', "5", "", "null", '{"values": [1]} x'])
def test_a_body_that_is_not_a_json_object_is_400(fbs, body):
    c = fbs.client()
    assert not c.write_registers(145, [45], slave=1).isError()
    r = request(fbs.http, "PUT", "/api/v1/plcs/0/devices/R145", body=body,
                headers={"Content-Type": "application/json"})
    assert_error(r, 400, "not a JSON object")
    assert holding(c, 145) == [45]


C200_WIRE = 9700  # C200-C255 current values, two words each, low word first


def test_a_32_bit_counter_is_one_device_of_both_words(fbs):
    """CTR200-CTR255 were read and written a word at a time: CTR200 gave its low word alone,
    count=2 named CTR200 twice, and a PUT of -1 left the counter at 65535."""
    c = fbs.client()
    before = c.read_holding_registers(C200_WIRE - 1, 5, slave=1).registers  # C199-C201
    try:
        assert not c.write_registers(C200_WIRE, [70000 & 0xFFFF, 70000 >> 16, 0xFFFE, 0xFFFF],
                                     slave=1).isError()
        r = get(fbs.http, "/api/v1/plcs/0/devices/CTR199?count=3")
        assert r.status == 200, r.body
        body = r.json()
        assert body["names"] == ["CTR199", "CTR200", "CTR201"], body
        assert body["words"] == [1, 2, 2], body
        assert body["values"] == [before[0], 70000, 0xFFFFFFFE], body

        r = put(fbs.http, "/api/v1/plcs/0/devices/CTR200", json_body={"values": [-1, 100000]})
        assert r.status == 200, r.body
        assert r.json()["names"] == ["CTR200", "CTR201"], r.json()
        assert r.json()["values"] == [0xFFFFFFFF, 100000], r.json()
        assert c.read_holding_registers(C200_WIRE, 4, slave=1).registers == \
            [0xFFFF, 0xFFFF, 100000 & 0xFFFF, 100000 >> 16]

        assert_error(put(fbs.http, "/api/v1/plcs/0/devices/CTR201", json_body={"values": [2**32]}),
                     400, "4294967296 is out of range for CTR201", "32-bit counter")
        assert_error(put(fbs.http, "/api/v1/plcs/0/devices/CTR199",
                         json_body={"values": [65536, 0]}),
                     400, "65536 is out of range for CTR199", "a word")
        r = put(fbs.http, "/api/v1/plcs/0/devices/CTR199", json_body={"values": [5, 65536]})
        assert r.status == 200 and r.json()["values"] == [5, 65536], r.body  # C200 takes it
        assert_error(get(fbs.http, "/api/v1/plcs/0/devices/CTR255?count=2"), 400,
                     "go past the last", "CTR255")
        r = get(fbs.http, "/api/v1/plcs/0/devices/CTR255")
        assert r.status == 200 and r.json()["names"] == ["CTR255"], r.body
    finally:
        c.write_registers(C200_WIRE - 1, before, slave=1)


@pytest.mark.parametrize("body, why", [
    ('{"values": [1e400]}', "number overflow parsing '1e400'"),
    ("[1, 2]", "(it is an array)"),
    ('"values"', "(it is a string)"),
    ("{", "syntax error"),
    ("", "unexpected end of input"),
])
def test_a_refused_body_says_what_is_wrong_with_it(fbs, body, why):
    """A number past a double's range was "not a JSON object" with no more said, though the
    body was one: the parser's reason is given, or what the body is instead."""
    c = fbs.client()
    assert not c.write_registers(145, [45], slave=1).isError()
    r = request(fbs.http, "PUT", "/api/v1/plcs/0/devices/R145", body=body,
                headers={"Content-Type": "application/json"})
    assert_error(r, 400, "not a JSON object", why)
    assert holding(c, 145) == [45]


def recv_until(sock, marker: bytes) -> bytes:
    """What `sock` receives until `marker` has come (and whatever came with it)."""
    got = b""
    while marker not in got:
        chunk = sock.recv(4096)
        assert chunk, got
        got += chunk
    return got


def status_of(port, raw: bytes) -> int:
    """The status code the daemon answers `raw` with, on a connection of its own."""
    with connect(port) as s:
        s.sendall(raw)
        head = recv_until(s, b"\r\n")
    return int(head.split(b" ", 2)[1])


def test_requests_rfc_9112_refuses_are_refused_and_write_nothing(fbs):
    """No Host in HTTP/1.1, two Host headers, a Host that is no host[:port], a transfer coding
    other than chunked: 400, 400, 400, 501. A Content-Type is the media type application/json in any case, with
    parameters or not, and nothing else (no prefix, no list)."""
    c = fbs.client()
    assert not c.write_registers(145, [45], slave=1).isError()
    path = "/api/v1/plcs/0/devices/R145"
    body = json.dumps({"values": [7]}).encode()
    json_type = "Content-Type: application/json"
    two_hosts = raw_request("GET", "/api/v1/plcs", headers=["Host: evil.example"])
    assert status_of(fbs.http, two_hosts) == 400
    # HTTP/1.1 requires a Host; HTTP/1.0 has none to require.
    no_host = raw_request("GET", "/api/v1/plcs").replace(b"Host: 127.0.0.1\r\n", b"")
    assert status_of(fbs.http, no_host) == 400
    assert status_of(fbs.http, no_host.replace(b"HTTP/1.1", b"HTTP/1.0")) == 200
    for host, status in ((b"127.0.0.1:abc", 400), (b"[::1]x", 400), (b"127.0.0.1:", 200),
                         (b"[::1]:80", 200), (b"localhost:8020", 200)):
        raw = raw_request("GET", "/api/v1/plcs").replace(b"Host: 127.0.0.1", b"Host: " + host)
        assert status_of(fbs.http, raw) == status, host
    chunked = b"%x\r\n%s\r\n0\r\n\r\n" % (len(body), body)
    for coding, status in (("gzip, chunked", 501), ("chunked, chunked", 501)):
        raw = raw_request("PUT", path, b"", [json_type]).replace(
            b"Content-Length: 0", f"Transfer-Encoding: {coding}".encode()) + chunked
        assert status_of(fbs.http, raw) == status, coding
    for content_type in ("application/jsonx", "application/json, text/plain", "text/plain"):
        raw = raw_request("PUT", path, body, [f"Content-Type: {content_type}"])
        assert status_of(fbs.http, raw) == 415, content_type
    assert holding(c, 145) == [45]
    # What is taken: chunked alone, the type in capitals, with a charset.
    raw = raw_request("PUT", path, b"", [json_type]).replace(
        b"Content-Length: 0", b"Transfer-Encoding: chunked") + chunked
    assert status_of(fbs.http, raw) == 200
    assert holding(c, 145) == [7]
    for n, content_type in enumerate(("APPLICATION/JSON", "application/json; charset=utf-8")):
        raw = raw_request("PUT", path, json.dumps({"values": [8 + n]}).encode(),
                          [f"Content-Type: {content_type}"])
        assert status_of(fbs.http, raw) == 200, content_type
        assert holding(c, 145) == [8 + n]


def test_a_device_write_with_an_unknown_key_is_400_and_writes_nothing(fbs):
    """docs/console.md: an unknown key is a 400, as for the simulator and the faults."""
    c = fbs.client()
    assert not c.write_registers(145, [45], slave=1).isError()
    r = put(fbs.http, "/api/v1/plcs/0/devices/R145", json_body={"values": [7], "bogus": 1})
    assert_error(r, 400, "bogus", "unknown key", "values")
    assert holding(c, 145) == [45]


@pytest.mark.parametrize("path, key", [("/api/v1/plcs/0/devices/R145", "values"),
                                       ("/api/v1/plcs/0/comm-faults", "from")])
def test_a_body_nested_thousands_deep_is_400_and_the_daemon_lives_on(fbs, path, key):
    """An error message quoting a deeply nested value once overflowed the daemon's stack
    (the JSON library's dump() recurses a level at a time): 4,000 levels in 8 KB did it."""
    c = fbs.client()
    assert not c.write_registers(145, [45], slave=1).isError()
    for depth in (33, 4000, 12000):
        body = '{"%s": %s%s}' % (key, "[" * depth, "]" * depth)
        r = request(fbs.http, "PUT", path, body=body, headers={"Content-Type": "application/json"})
        assert_error(r, 400, "nests deeper than 32 levels")
    # 32 levels are read as any body is: a list of lists is no list of numbers.
    r = put(fbs.http, "/api/v1/plcs/0/devices/R145", json_body={"values": [[[[1]]]]})
    assert_error(r, 400, "whole numbers")
    assert holding(c, 145) == [45]
    assert get(fbs.http, "/api/v1/plcs/0").status == 200


@pytest.mark.parametrize("content_type", [None, "text/plain", "application/x-www-form-urlencoded",
                                          "multipart/form-data; boundary=x", "text/json"])
def test_a_write_that_is_not_json_is_415(fbs, content_type):
    c = fbs.client()
    assert not c.write_registers(146, [46], slave=1).isError()
    headers = {} if content_type is None else {"Content-Type": content_type}
    r = request(fbs.http, "PUT", "/api/v1/plcs/0/devices/R146", body='{"values": [7]}',
                headers=headers)
    assert_error(r, 415, "Content-Type: application/json")
    r = request(fbs.http, "PUT", "/api/v1/plcs/0/simulator", body='{"frozen": true}',
                headers=headers)
    assert_error(r, 415, "Content-Type: application/json")
    assert holding(c, 146) == [46]
    assert plc_state(fbs.http)["time"]["frozen"] is False


def test_write_protected_devices_are_403_and_unchanged(start_http):
    plc = start_http(modbus_extra=", write_protect: [R200-R209]")
    c = plc.client()
    assert_error(put(plc.http, "/api/v1/plcs/0/devices/R205", {"values": [7]}), 403,
                 "R200-R209", "may not be written")
    # A span that only touches the range is refused whole.
    assert_error(put(plc.http, "/api/v1/plcs/0/devices/R198", {"values": [1, 2, 3]}), 403,
                 "R200-R209")
    assert holding(c, 198, 12) == [0] * 12
    assert devices(plc.http, "R205").json()["values"] == [0]
    # Beside it, writes go through.
    assert put(plc.http, "/api/v1/plcs/0/devices/R210", {"values": [9]}).status == 200
    assert holding(c, 210) == [9]
    # The PLC's own read-only devices: inputs and the scan-time registers.
    assert_error(put(plc.http, "/api/v1/plcs/0/devices/X0", {"values": [1]}), 403, "X0-X255")
    assert_error(put(plc.http, "/api/v1/plcs/0/devices/R4136", {"values": [1]}), 403, "R4136")


def test_a_read_only_console_refuses_every_write_with_403(start_http):
    plc = start_http(http_extra=", read_only: true")
    c = plc.client()
    assert_error(put(plc.http, "/api/v1/plcs/0/devices/R100", {"values": [7]}), 403,
                 "read-only", "http.read_only")
    assert_error(put(plc.http, "/api/v1/plcs/0/simulator", {"frozen": True}), 403, "read-only")
    assert holding(c, 100) == [0]
    assert get(plc.http, "/api/v1/plcs/0/simulator").json()["frozen"] is False
    # Reads are still served.
    assert devices(plc.http, "R100").status == 200
    assert get(plc.http, "/api/v1/plcs/0/simulator").status == 200


def test_a_token_guards_writes_with_401(start_http):
    plc = start_http(http_extra=", token: s3cret")
    c = plc.client()
    path = "/api/v1/plcs/0/devices/R100"
    r = put(plc.http, path, {"values": [1]})
    assert_error(r, 401, "Authorization: Bearer")
    assert r.header("WWW-Authenticate") == "Bearer", r
    for auth in ["Bearer nope", "Bearer s3cre", "Bearer s3cretX", "Bearer ", "Basic czNjcmV0",
                 "Bearer S3CRET", "s3cret"]:
        r = put(plc.http, path, {"values": [1]}, headers={"Authorization": auth})
        assert_error(r, 401, "token")
        assert r.header("WWW-Authenticate").startswith("Bearer"), (auth, r)
    r = put(plc.http, "/api/v1/plcs/0/simulator", {"frozen": True})
    assert_error(r, 401, "token")
    assert holding(c, 100) == [0]
    assert get(plc.http, "/api/v1/plcs/0/simulator").json()["frozen"] is False
    # The right token writes; reads need none.
    r = put(plc.http, path, {"values": [42]}, headers={"Authorization": "Bearer s3cret"})
    assert r.status == 200, r
    assert holding(c, 100) == [42]
    assert devices(plc.http, "R100").json()["values"] == [42]
    # The scheme's name is case-insensitive; the token is not.
    r = put(plc.http, path, {"values": [43]}, headers={"Authorization": "bearer s3cret"})
    assert r.status == 200, r
    assert holding(c, 100) == [43]
    r = put(plc.http, "/api/v1/plcs/0/simulator", {"time_scale": 2},
            headers={"Authorization": "Bearer s3cret"})
    assert r.status == 200 and r.json()["time_scale"] == 2, r


# --- Framing refusals -------------------------------------------------------------------------


def test_empty_lines_before_a_request_line_are_ignored(fbs):
    """RFC 9112 §2.2: a server SHOULD ignore at least one empty line before a request line (a
    client may send a CRLF after a PUT's body). They were a 400 "bad method"."""
    with connect(fbs.http) as s:
        s.sendall(b"\r\n\r\n" + raw_request("GET", "/healthz"))
        assert recv_response(s).status == 200
        body = json.dumps({"values": [152]}).encode()
        s.sendall(raw_request("PUT", "/api/v1/plcs/0/devices/R152", body,
                              ["Content-Type: application/json"]) + b"\r\n")
        assert recv_response(s).status == 200
        # Sent in pieces, the blank line alone first.
        s.sendall(b"\r\n")
        time.sleep(0.05)
        s.sendall(raw_request("GET", "/api/v1/plcs/0/devices/R152"))
        r = recv_response(s)
        assert r.status == 200 and r.json()["values"] == [152], r
    assert holding(fbs.client(), 152) == [152]
    # Lines ended in LF alone are refused for what they are (it was "bad version"), a header's
    # line as well ("bad value"); bytes that are no text (a TLS hello) are not said to be.
    for head in (b"GET /healthz HTTP/1.1\nHost: 127.0.0.1\n\n",
                 b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\nX-A: b\r\n\r\n"):
        with connect(fbs.http) as s:
            s.sendall(head)
            assert_error(recv_response(s), 400, "its lines end in LF alone")
    with connect(fbs.http) as s:
        s.sendall(bytes.fromhex("16030100a5010000a10303") + bytes(range(32)) + b"\n\n")
        message = assert_error(recv_response(s), 400, "not an HTTP/1.1 request")
        assert "LF alone" not in message, message


def test_a_body_over_24_kib_is_413_and_closes(fbs):
    path = "/api/v1/plcs/0/devices/R150"
    # Exactly 24 KiB is taken.
    body = json.dumps({"values": [150]}).encode()
    body += b" " * (24 * 1024 - len(body))
    with connect(fbs.http) as s:
        s.sendall(raw_request("PUT", path, body, ["Content-Type: application/json"]))
        r = recv_response(s)
        assert r.status == 200, r
    assert holding(fbs.client(), 150) == [150]
    body = json.dumps({"values": [151]}).encode()
    body += b" " * (24 * 1024 + 1 - len(body))
    with connect(fbs.http) as s:
        s.sendall(raw_request("PUT", path, body, ["Content-Type: application/json"]))
        r = recv_response(s)
        assert_error(r, 413, "24576")
        assert r.header("Connection") == "close", r
        assert closed_by_server(s)
    assert holding(fbs.client(), 150) == [150]
    # Announced too large, before any of it is sent.
    with connect(fbs.http) as s:
        s.sendall(b"PUT /api/v1/plcs/0/devices/R150 HTTP/1.1\r\nHost: x\r\n"
                  b"Content-Type: application/json\r\nContent-Length: 1000000\r\n\r\n")
        assert_error(recv_response(s), 413, "body")
        assert closed_by_server(s)


def test_a_head_over_8_kib_is_431_and_closes(fbs):
    with connect(fbs.http) as s:
        s.sendall(raw_request("GET", "/healthz", headers=["X-Pad: " + "a" * 7000]))
        assert recv_response(s).status == 200
    with connect(fbs.http) as s:
        s.sendall(raw_request("GET", "/healthz", headers=["X-Pad: " + "a" * 9000]))
        r = recv_response(s)
        assert_error(r, 431, "8192")
        assert closed_by_server(s)


@pytest.mark.parametrize(
    "garbage",
    [
        b"\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03" + bytes(range(32)),  # a TLS hello
        b"\x00\x01\x00\x00\x00\x06\x01\x03\x00\x00\x00\x01",  # a Modbus TCP request
        b"hello world\r\n\r\n",
        b"GET /healthz HTTP/9.9\r\n\r\n",
        b"GET /healthz HTTP/1.1\r\nContent-Length: x\r\n\r\n",
    ],
)
def test_bytes_that_are_not_http_get_400_and_the_connection_closes(fbs, garbage):
    with connect(fbs.http) as s:
        s.sendall(garbage)
        r = recv_response(s)
        assert_error(r, 400, "not an HTTP/1.1 request")
        assert r.header("Connection") == "close", r
        assert closed_by_server(s)
    assert get(fbs.http, "/healthz").status == 200


@pytest.mark.parametrize("target", ["/api/v1/plcs/%zz", "/api/v1/plcs/0/devices/R1?count=%4"])
def test_bad_percent_encoding_is_400(fbs, target):
    with connect(fbs.http) as s:
        s.sendall(raw_request("GET", target))
        assert_error(recv_response(s), 400, "percent-encoding")


@pytest.mark.parametrize(
    "method,path,allow",
    [
        ("DELETE", "/api/v1/plcs", "GET, HEAD"),
        ("POST", "/api/v1/plcs", "GET, HEAD"),
        ("OPTIONS", "/api/v1/plcs", "GET, HEAD"),
        ("PUT", "/api/v1/plcs/0", "GET, HEAD"),
        ("DELETE", "/api/v1/plcs/0/devices/R100", "GET, HEAD, PUT"),
        ("POST", "/api/v1/plcs/0/devices/R100", "GET, HEAD, PUT"),
        ("OPTIONS", "/api/v1/plcs/0/devices/R100", "GET, HEAD, PUT"),
        ("PATCH", "/api/v1/plcs/0/simulator", "GET, HEAD, PUT"),
        ("POST", "/api/v1/plcs/0/comm-faults", "GET, HEAD, PUT, DELETE"),
        ("PATCH", "/api/v1/plcs/0/comm-faults", "GET, HEAD, PUT, DELETE"),
        ("POST", "/api/v1/plcs/0/events", "GET, HEAD"),
        ("PUT", "/api/v1/plcs/0/traffic", "GET, HEAD"),
        ("PUT", "/api/v1/plcs/0/loops", "GET, HEAD"),
        ("DELETE", "/api/v1/events", "GET, HEAD"),
        ("PUT", "/api/v1/openapi.json", "GET, HEAD"),
        ("POST", "/healthz", "GET, HEAD"),
        ("DELETE", "/metrics", "GET, HEAD"),
        ("POST", "/", "GET, HEAD"),
        ("PUT", "/plcs/0/devices", "GET, HEAD"),
    ],
)
def test_other_methods_are_405_with_allow(fbs, method, path, allow):
    r = request(fbs.http, method, path, json_body={"values": [1]})
    assert_error(r, 405, "not allowed", allow)
    assert r.header("Allow") == allow, r
    assert devices(fbs.http, "R100").status == 200


@pytest.mark.parametrize(
    "path",
    ["/api/v1/nothing", "/api/v2/plcs", "/api", "/api/v1", "/nope", "/api/v1/plcs/0/devices",
     "/api/v1/plcs/0/devices/R1/more", "/api/v1/plcs/0/nothing", "/static/nope.js",
     "/plcs/0/nothing", "/favicon.ico"],
)
def test_unknown_paths_are_404_json(fbs, path):
    assert_error(get(fbs.http, path), 404)


def test_head_gives_the_headers_of_get_without_a_body(fbs):
    with connect(fbs.http) as s:
        # Pipelined behind the HEADs: a body sent for one would be read as the next answer.
        s.sendall(raw_request("HEAD", "/api/v1/plcs/0/devices/R100?count=3")
                  + raw_request("HEAD", "/api/v1/plcs/0/events?device=R100")
                  + raw_request("HEAD", "/api/v1/plcs/0/devices/Q1")
                  + raw_request("GET", "/api/v1/plcs/0/devices/R100?count=3"))
        head = recv_response(s, head_only=True)
        events = recv_response(s, head_only=True)
        missing = recv_response(s, head_only=True)
        got = recv_response(s)
    assert head.status == 200 and head.body == b"", head
    assert head.header("Content-Type") == "application/json"
    assert int(head.header("Content-Length")) == len(got.body), (head, got)
    assert events.status == 200 and events.header("Content-Type") == "text/event-stream", events
    assert events.header("Content-Length") is None, events  # a stream's length is never known
    assert missing.status == 404 and int(missing.header("Content-Length")) > 0, missing
    assert got.status == 200 and got.json()["names"] == ["R100", "R101", "R102"], got
    r = request(fbs.http, "HEAD", "/healthz")
    assert r.status == 200 and r.body == b"", r
    # A HEAD of a stream is refused as its GET would be.
    r = request(fbs.http, "HEAD", "/api/v1/plcs/0/events?device=Q1")
    assert r.status == 404 and r.body == b"", r


# --- The Host check (DNS rebinding) ------------------------------------------------------------


@pytest.mark.parametrize("host", ["evil.example", "evil.example:{port}", "localhost.evil.example",
                                  "127.0.0.1.nip.io:{port}", "plc",
                                  # Names, not addresses the system reads (they were served).
                                  "[evil.example]", "[evil.example]:{port}", "999.999.999.999",
                                  "1.2.3.4.5.6", "....", "[]"])
def test_a_host_that_is_not_the_consoles_is_421(fbs, host):
    host = host.format(port=fbs.http)
    name = host.rsplit(":", 1)[0] if host.count(":") == 1 else host
    for method, path, body in [("GET", "/api/v1/plcs/0/devices/R180", None),
                               ("PUT", "/api/v1/plcs/0/devices/R180", {"values": [18]}),
                               ("GET", "/", None)]:
        r = request(fbs.http, method, path, json_body=body, headers={"Host": host})
        assert_error(r, 421, f"'{name}'", "http.hosts")
    assert holding(fbs.client(), 180) == [0]


@pytest.mark.parametrize("host", ["localhost:{port}", "LocalHost", "[::1]:{port}", "[::1]",
                                  "127.0.0.1:{port}", "127.0.0.1", "10.1.2.3:{port}",
                                  "[::ffff:127.0.0.1]:{port}", "[fe80::1]",
                                  # IPv4 as the system reads it, as curl sends what it is given.
                                  "127.1:{port}", "0177.0.0.1"])
def test_an_ip_literal_or_localhost_host_is_served(fbs, host):
    # Only the header says so: the connection is to 127.0.0.1 all the same.
    r = get(fbs.http, "/api/v1/plcs/0", headers={"Host": host.format(port=fbs.http)})
    assert r.status == 200 and r.json()["id"] == "0", r


def test_a_target_in_absolute_form_is_served_for_the_host_it_names(fbs):
    # RFC 9112 §3.2.2: taken (it was 400), its host checked, not the Host header's.
    def raw(target, host):
        with connect(fbs.http) as s:
            s.sendall(f"GET {target} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
                      .encode())
            return recv_response(s)
    r = raw(f"http://127.0.0.1:{fbs.http}/api/v1/plcs/0?x=1", "evil.example")
    assert r.status == 200 and r.json()["id"] == "0", r
    assert raw(f"HTTP://localhost:{fbs.http}", "evil.example").status == 200  # the overview
    r = raw("http://evil.example/api/v1/plcs/0", f"127.0.0.1:{fbs.http}")
    assert_error(r, 421, "'evil.example'")
    assert_error(raw("http:///api/v1/plcs/0", "127.0.0.1"), 400, "host[:port]")
    assert_error(raw("http://user@127.0.0.1/api/v1/plcs/0", "127.0.0.1"), 400, "host[:port]")
    assert_error(raw("http://127.0.0.1#frag", "127.0.0.1"), 400, "host[:port]")


@pytest.mark.parametrize("host", ["::1", "127.0.0.1:80:90", "user@127.0.0.1", "127.0.0.1#x"])
def test_a_host_that_is_no_host_and_port_is_400(fbs, host):
    # RFC 9112 §3.2: they were taken for names and answered 421, one quoted cut.
    assert_error(get(fbs.http, "/api/v1/plcs/0", headers={"Host": host}), 400, "host[:port]")


def test_a_request_without_host_is_served(fbs):
    with connect(fbs.http) as s:
        s.sendall(b"GET /healthz HTTP/1.0\r\n\r\n")
        r = recv_response(s)
        assert r.status == 200 and r.json()["status"] == "ok", r


def test_http_hosts_names_the_hosts_a_console_answers_to(start_http):
    plc = start_http(http_extra=", hosts: [gateway.example]")
    for host in ["gateway.example:{port}", "GATEWAY.Example", "gateway.example",
                 "localhost:{port}", "127.0.0.1:{port}"]:
        r = get(plc.http, "/api/v1/plcs/0", headers={"Host": host.format(port=plc.http)})
        assert r.status == 200, (host, r)
    r = put(plc.http, "/api/v1/plcs/0/devices/R1", {"values": [5]},
            headers={"Host": f"Gateway.example:{plc.http}"})
    assert r.status == 200, r
    assert holding(plc.client(), 1) == [5]
    for host in ["other.example", "sub.gateway.example", "gateway.example.evil"]:
        assert_error(get(plc.http, "/healthz", headers={"Host": host}), 421, f"'{host}'")


# --- Path segments ------------------------------------------------------------------------------


def test_a_percent_encoded_slash_stays_in_its_segment(fbs):
    assert_error(get(fbs.http, "/api/v1/plcs/0/devices/a%2Fb"), 404, "device 'a/b'")
    assert_error(get(fbs.http, "/api/v1/plcs/0%2F1"), 404, "'0/1'")
    assert devices(fbs.http, "%52100").json()["names"] == ["R100"]


# --- No CORS ----------------------------------------------------------------------------------


def test_no_cors_headers_for_another_origin(fbs):
    origin = {"Origin": "http://evil.example"}
    replies = [
        get(fbs.http, "/api/v1/plcs", headers=origin),
        get(fbs.http, "/api/v1/plcs/0/devices/R100", headers=origin),
        request(fbs.http, "OPTIONS", "/api/v1/plcs/0/devices/R100",
                headers={**origin, "Access-Control-Request-Method": "PUT",
                         "Access-Control-Request-Headers": "content-type"}),
        request(fbs.http, "PUT", "/api/v1/plcs/0/devices/R100", body="values=1",
                headers={**origin, "Content-Type": "application/x-www-form-urlencoded"}),
    ]
    for r in replies:
        assert not [h for h in r.headers if h.startswith("access-control-")], r
    assert [r.status for r in replies] == [200, 200, 405, 415], replies
    assert_error(replies[2], 405, "not allowed")


# --- Simulator --------------------------------------------------------------------------------


def sim(port):
    r = get(port, "/api/v1/plcs/0/simulator")
    assert r.status == 200, r
    return r.json()


def sim_put(port, body):
    return put(port, "/api/v1/plcs/0/simulator", body)


def settings(state):
    """What a refused PUT must leave as it was."""
    return (state["time_scale"], state["frozen"], state["pending_steps"],
            [{k: v for k, v in ch.items() if k not in ("true_temperature_c", "heater_power")}
             for ch in state["channels"]])


def test_simulator_state_has_time_and_32_channels(fbs):
    s = sim(fbs.http)
    assert set(s) == {"time_scale", "frozen", "pending_steps", "simulated_s", "channels"}, s
    assert (s["time_scale"], s["frozen"], s["pending_steps"]) == (1, False, 0), s
    assert [ch["channel"] for ch in s["channels"]] == list(range(32))
    for ch in s["channels"]:
        assert set(ch) == {"channel", "true_temperature_c", "heater_power", "ambient_c", "k_c",
                           "tau_s", "dead_time_s", "noise_c", "faults"}, ch
        assert ch["faults"] == {"sensor_broken": False, "heater_open": False,
                                "heater_shorted": False, "reading_frozen": False}, ch
        assert 0 <= ch["heater_power"] <= 1, ch
    # The plant's defaults (docs/simulator-and-plant.md).
    ch0 = s["channels"][0]
    assert (ch0["ambient_c"], ch0["k_c"], ch0["tau_s"], ch0["dead_time_s"]) == (25, 400, 120, 5)


def test_freeze_and_step_run_exactly_the_scans_asked(start_http):
    plc = start_http()
    c = plc.client()
    r = sim_put(plc.http, {"frozen": True})
    assert r.status == 200 and r.json()["frozen"] is True, r
    assert holding(c, 1, unit=SIM_UNIT) == [1]
    time.sleep(0.05)
    before = plc_state(plc.http)
    time.sleep(0.15)
    assert plc_state(plc.http)["scans"] == before["scans"]
    assert before["time"]["frozen"] is True
    r = sim_put(plc.http, {"step": 10})
    assert r.status == 200, r
    after = wait_for(lambda: (lambda p: p if p["time"]["pending_steps"] == 0 else None)(
        plc_state(plc.http)), what="pending_steps 0")
    assert after["scans"] == before["scans"] + 10, (before, after)
    assert after["time"]["simulated_s"] == pytest.approx(before["time"]["simulated_s"] + 0.1)
    time.sleep(0.1)
    assert plc_state(plc.http)["scans"] == after["scans"]
    # Thawed, it scans again, and the simulator unit says so.
    assert sim_put(plc.http, {"frozen": False}).json()["frozen"] is False
    wait_for(lambda: plc_state(plc.http)["scans"] > after["scans"] + 5, what="scanning again")
    assert holding(c, 1, unit=SIM_UNIT) == [0]
    # Frozen over Modbus: the API sees it.
    assert not c.write_register(1, 1, slave=SIM_UNIT).isError()
    wait_for(lambda: sim(plc.http)["frozen"] is True, what="frozen over Modbus")


def test_time_scale_and_channels_agree_with_the_simulator_unit(start_http):
    plc = start_http()
    c = plc.client()
    r = sim_put(plc.http, {"time_scale": 50})
    assert r.status == 200 and r.json()["time_scale"] == 50, r
    assert plc_state(plc.http)["time"]["scale"] == 50
    assert holding(c, 0, unit=SIM_UNIT) == [50]
    assert not c.write_register(0, 7, slave=SIM_UNIT).isError()
    wait_for(lambda: sim(plc.http)["time_scale"] == 7, what="time scale 7")
    # A fault set through the API shows in the unit's fault bits (channel c at 100 + 10c,
    # b1 heater open) ...
    r = sim_put(plc.http, {"channels": [{"channel": 3, "faults": {"heater_open": True}}]})
    assert r.status == 200, r
    faults = r.json()["channels"][3]["faults"]
    assert faults == {"sensor_broken": False, "heater_open": True, "heater_shorted": False,
                      "reading_frozen": False}, faults
    assert sim(plc.http)["channels"][3]["faults"]["heater_open"] is True
    assert not any(ch["faults"]["heater_open"] for ch in sim(plc.http)["channels"] if
                   ch["channel"] != 3)
    wait_for(lambda: holding(c, 130, unit=SIM_UNIT) == [0b0010], what="fault bits 0010")
    # ... and one set through the unit shows in the API (b0 sensor broken, b3 reading frozen).
    assert not c.write_register(150, 0b1001, slave=SIM_UNIT).isError()
    wait_for(lambda: sim(plc.http)["channels"][5]["faults"] == {
        "sensor_broken": True, "heater_open": False, "heater_shorted": False,
        "reading_frozen": True}, what="channel 5 faults")
    r = sim_put(plc.http, {"channels": [{"channel": 3, "faults": {"heater_open": False}},
                                        {"channel": 5, "faults": {"sensor_broken": False}}]})
    assert r.status == 200, r
    wait_for(lambda: holding(c, 130, unit=SIM_UNIT) == [0], what="channel 3 cleared")
    wait_for(lambda: holding(c, 150, unit=SIM_UNIT) == [0b1000], what="channel 5 b3 only")
    # Parameters: ambient in 0.1 degC at +1, K at +2.
    r = sim_put(plc.http, {"channels": [{"channel": 2, "ambient_c": 40.5, "k_c": 300}]})
    assert r.status == 200, r
    ch2 = r.json()["channels"][2]
    assert (ch2["ambient_c"], ch2["k_c"]) == (40.5, 300), ch2
    wait_for(lambda: holding(c, 121, 2, unit=SIM_UNIT) == [405, 3000], what="ambient and K")


@pytest.mark.parametrize(
    "body,needles",
    [
        ({"time_scale": 0, "frozen": True}, ["time_scale", "1", "10000"]),
        ({"time_scale": 10001}, ["time_scale"]),
        ({"time_scale": "fast"}, ["time_scale"]),
        ({"frozen": "yes"}, ["frozen", "true or false"]),
        ({"frozen": 1}, ["frozen"]),
        ({"step": 65536, "frozen": True}, ["step", "65535"]),
        ({"step": -1}, ["step"]),
        ({"step": 1.5}, ["step"]),
        ({"bogus": 1, "frozen": True}, ["bogus", "unknown key"]),
        ({"channels": [{"channel": 32, "faults": {"heater_open": True}}]}, ["channel", "31"]),
        ({"channels": [{"channel": -1}]}, ["channel"]),
        ({"channels": [{"faults": {"heater_open": True}}]}, ["channel"]),
        ({"channels": [{"channel": 1, "faults": {"heater_open": True}},
                       {"channel": 2, "faults": {"melted": True}}], "frozen": True},
         ["melted", "unknown fault"]),
        ({"channels": [{"channel": 1, "faults": {"heater_open": 1}}]}, ["heater_open",
                                                                         "true or false"]),
        ({"channels": [{"channel": 1, "faults": True}]}, ["faults"]),
        ({"channels": [{"channel": 1, "ambient_c": 5000}]}, ["ambient_c"]),
        ({"channels": [{"channel": 1, "tau_s": 0}], "time_scale": 5}, ["tau_s"]),
        ({"channels": [{"channel": 1, "noise_c": -1}]}, ["noise_c"]),
        ({"channels": [{"channel": 1, "k_c": "hot"}]}, ["k_c"]),
        ({"channels": [{"channel": 1, "colour": "red"}]}, ["colour", "unknown key"]),
        ({"channels": {"channel": 1}}, ["channels", "list"]),
        ({"channels": [1]}, ["channels"]),
    ],
)
def test_simulator_refusals_apply_nothing(fbs, body, needles):
    before = settings(sim(fbs.http))
    assert_error(sim_put(fbs.http, body), 400, *needles)
    assert settings(sim(fbs.http)) == before
    assert plc_state(fbs.http)["time"]["frozen"] is False


def test_simulator_body_must_be_a_json_object(fbs):
    for body in ["[]", "{", '"frozen"']:
        r = request(fbs.http, "PUT", "/api/v1/plcs/0/simulator", body=body,
                    headers={"Content-Type": "application/json"})
        assert_error(r, 400, "not a JSON object")


# --- Communication faults ---------------------------------------------------------------------

COMM = "/api/v1/plcs/0/comm-faults"
# Every key of a GET (docs/communication-faults.md): the fields, `active`, `summary`, `figures`.
COMM_KEYS = {"active", "delay_ms", "drop_every", "drop_probability", "seed", "exception",
             "offline", "refuse_connections", "disconnect_after", "reset", "garble", "stop",
             "unit", "function", "from", "count", "summary", "figures"}
COMM_FIGURES = {"delayed", "dropped", "refused", "silenced", "disconnected", "garbled"}
COMM_OFF = {"active": False, "delay_ms": 0, "drop_every": 0, "drop_probability": 0, "seed": 1,
            "exception": 0, "offline": False, "refuse_connections": False,
            "disconnect_after": None, "reset": False, "garble": "none", "stop": False, "unit": 0,
            "function": 0, "from": None, "count": 0,
            "summary": {"faults": [], "scope": "every request"}}


def comm(port):
    r = get(port, COMM)
    assert r.status == 200, r
    return r.json()


def comm_put(port, body, **kw):
    return put(port, COMM, body, **kw)


def comm_delete(port, headers=None):
    """A DELETE as a script sends it: no body, no Content-Type."""
    return request(port, "DELETE", COMM, headers=headers)


def fields(state):
    """A GET's answer without what the faults did (the figures grow as requests come)."""
    return {k: v for k, v in state.items() if k != "figures"}


def read_r(client, address):
    """A pymodbus read of one holding register (R`address`) -> (response, seconds it took)."""
    start = time.monotonic()
    r = client.read_holding_registers(address, 1, slave=1)
    return r, time.monotonic() - start


def test_comm_faults_get_says_every_field_off(fbs):
    s = comm(fbs.http)
    assert set(s) == COMM_KEYS, s
    assert fields(s) == COMM_OFF, s
    assert set(s["figures"]) == COMM_FIGURES, s
    assert all(isinstance(v, int) and v >= 0 for v in s["figures"].values()), s
    head = request(fbs.http, "HEAD", COMM)
    assert head.status == 200 and head.body == b"", head
    assert int(head.header("Content-Length")) == len(get(fbs.http, COMM).body)


def test_comm_faults_put_then_get_and_the_get_put_back(start_http):
    plc = start_http()
    body = {"delay_ms": [100, 300], "drop_probability": 0.25, "seed": 7, "exception": 6,
            "offline": True, "refuse_connections": True, "disconnect_after": 3, "reset": True,
            "garble": "crc", "stop": True, "unit": 1, "function": 3, "from": "R100",
            "count": 10}
    r = comm_put(plc.http, body)
    assert r.status == 200, r
    put_answer = r.json()
    s = comm(plc.http)
    assert fields(put_answer) == fields(s)
    assert {k: s[k] for k in body} == body, s
    assert s["active"] is True
    assert s["drop_every"] == 0
    assert s["summary"] == {
        "faults": ["delay 100-300 ms (seed 7)", "drop with probability 0.25 (seed 7)",
                   "exception 06h", "offline", "refuse connections",
                   "disconnect after 3 request(s) (reset)", "garble crc", "stop"],
        "scope": "unit 1, function 03h, R100-R109"}, s["summary"]
    # What a GET said is taken back as it is (active, summary and figures are ignored).
    r = comm_put(plc.http, s)
    assert r.status == 200, r
    assert fields(r.json()) == fields(s)
    # A PUT replaces the whole set: what it leaves out is off.
    r = comm_put(plc.http, {"delay_ms": 300, "from": "R5"})
    assert r.status == 200, r
    s = r.json()
    assert fields(s) == {**COMM_OFF, "active": True, "delay_ms": 300, "from": "R5", "count": 1,
                         "summary": {"faults": ["delay 300 ms"], "scope": "R5"}}, s
    r = comm_put(plc.http, s)
    assert r.status == 200 and fields(r.json()) == fields(s), r
    # The GET of no fault goes back too; {} and DELETE switch everything off.
    assert comm_put(plc.http, {}).json()["active"] is False
    r = comm_put(plc.http, comm(plc.http))
    assert r.status == 200 and fields(r.json()) == COMM_OFF, r
    assert comm_put(plc.http, {"drop_every": 2, "disconnect_after": 0}).status == 200
    r = comm_delete(plc.http)
    assert r.status == 200 and fields(r.json()) == COMM_OFF, r
    assert fields(comm(plc.http)) == COMM_OFF
    log = plc.daemon.log_text()
    assert "comm fault on: delay 100-300 ms (seed 7) (unit 1, function 03h, R100-R109)" in log
    assert "comm fault off: drop every 2nd request" in log


def test_comm_faults_count_without_from_is_ignored(fbs):
    try:
        for body in ({"count": 5}, {"count": 0}, {"count": 5, "from": None}):
            r = comm_put(fbs.http, body)
            assert r.status == 200, (body, r)
            assert fields(r.json()) == COMM_OFF, (body, r)
        r = comm_put(fbs.http, {"from": "R200", "count": 5, "unit": 1})
        assert r.status == 200, r
        assert (r.json()["from"], r.json()["count"]) == ("R200", 5)
        assert r.json()["summary"]["scope"] == "unit 1, R200-R204"
        assert r.json()["active"] is False  # a scope alone is no fault
    finally:
        assert comm_delete(fbs.http).status == 200


@pytest.mark.parametrize(
    "body,needles",
    [
        ({"bogus": 1, "delay_ms": 5}, ["bogus", "unknown key", "delay_ms"]),
        ({"delay": 300}, ["delay", "unknown key"]),
        ({"delay_ms": [300, 100]}, ["delay_ms", "min at most max"]),
        ({"delay_ms": -1}, ["delay_ms", "0 to 60000"]),
        ({"delay_ms": "x"}, ["delay_ms", "0 to 60000"]),
        ({"delay_ms": 60001}, ["delay_ms", "60000"]),
        ({"delay_ms": 1.5}, ["delay_ms"]),
        ({"delay_ms": [1, 2, 3]}, ["delay_ms", "[min, max]"]),
        ({"drop_every": 2, "drop_probability": 0.5}, ["drop_every", "drop_probability"]),
        ({"drop_probability": 1.5}, ["drop_probability", "0 to 1"]),
        ({"drop_every": 65536}, ["drop_every", "65535"]),
        ({"exception": 256}, ["exception", "255"]),
        ({"exception": "04"}, ["exception"]),
        ({"offline": 1}, ["offline", "true or false"]),
        ({"reset": True}, ["reset", "disconnect_after"]),
        ({"garble": "foo"}, ["garble", "crc", "short", "gap"]),
        ({"garble": True}, ["garble"]),
        ({"from": "Q5"}, ["from", "Q5", "R100"]),
        ({"from": "R99999"}, ["from", "R99999"]),
        ({"from": "R4167", "count": 2}, ["from", "R4167-R4168", "outside"]),
        ({"from": "R100", "count": 0}, ["count", "1 to 65535"]),
        ({"from": ""}, ["from"]),
        ({"from": 100}, ["from"]),
        ({"unit": 256}, ["unit", "255"]),
        ({"function": -1}, ["function"]),
        ({"seed": 4294967296}, ["seed"]),
    ],
)
def test_comm_fault_refusals_are_400_and_change_nothing(fbs, body, needles):
    # A fault on a register no other test reads, to see that a refused PUT leaves it.
    r = comm_put(fbs.http, {"delay_ms": 5, "from": "R4000"})
    assert r.status == 200, r
    try:
        before = fields(r.json())
        assert_error(comm_put(fbs.http, body), 400, *needles)
        assert fields(comm(fbs.http)) == before
    finally:
        assert comm_delete(fbs.http).status == 200


def test_comm_faults_body_must_be_a_json_object(fbs):
    for body in ["[]", "{", '"offline"', "null", ""]:
        r = request(fbs.http, "PUT", COMM, body=body, headers={"Content-Type": "application/json"})
        assert_error(r, 400, "not a JSON object")
    assert fields(comm(fbs.http)) == COMM_OFF


@pytest.mark.parametrize("content_type", [None, "text/plain", "application/x-www-form-urlencoded",
                                          "text/json"])
def test_a_comm_fault_put_that_is_not_json_is_415(fbs, content_type):
    headers = {} if content_type is None else {"Content-Type": content_type}
    r = request(fbs.http, "PUT", COMM, body='{"offline": true}', headers=headers)
    assert_error(r, 415, "Content-Type: application/json")
    assert comm(fbs.http)["offline"] is False


def test_a_comm_fault_delete_needs_no_body_nor_content_type(fbs):
    try:
        assert comm_put(fbs.http, {"delay_ms": 5, "from": "R4001"}).json()["active"] is True
        with connect(fbs.http) as s:
            s.sendall(b"DELETE " + COMM.encode() + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
            r = recv_response(s)
        assert r.status == 200 and fields(r.json()) == COMM_OFF, r
        # A DELETE of nothing on is answered the same.
        r = comm_delete(fbs.http)
        assert r.status == 200 and fields(r.json()) == COMM_OFF, r
    finally:
        comm_delete(fbs.http)


def test_comm_fault_writes_need_the_token(start_http):
    plc = start_http(http_extra=", token: s3cret")
    for r in (comm_put(plc.http, {"offline": True}), comm_delete(plc.http)):
        assert_error(r, 401, "Authorization: Bearer")
        assert r.header("WWW-Authenticate") == "Bearer", r
    for auth in ["Bearer nope", "Basic czNjcmV0", "s3cret"]:
        assert_error(comm_put(plc.http, {"offline": True}, headers={"Authorization": auth}), 401,
                     "token")
        assert_error(comm_delete(plc.http, headers={"Authorization": auth}), 401, "token")
    assert comm(plc.http)["offline"] is False  # reads need no token
    auth = {"Authorization": "Bearer s3cret"}
    r = comm_put(plc.http, {"offline": True}, headers=auth)
    assert r.status == 200 and r.json()["offline"] is True, r
    assert_error(comm_delete(plc.http), 401, "Authorization: Bearer")
    assert comm(plc.http)["offline"] is True
    r = comm_delete(plc.http, headers=auth)
    assert r.status == 200 and r.json()["offline"] is False, r


def test_a_read_only_console_refuses_comm_fault_writes_with_403(start_http):
    plc = start_http(http_extra=", read_only: true")
    assert_error(comm_put(plc.http, {"offline": True}), 403, "read-only", "http.read_only")
    assert_error(comm_delete(plc.http), 403, "read-only")
    assert fields(comm(plc.http)) == COMM_OFF


def test_comm_faults_put_through_the_api_reach_modbus(start_http):
    plc = start_http(extra="init: {R0: 11, R100: 22}\n")
    c = plc.client()
    assert holding(c, 0) == [11]
    # Exception 04 on every request; DELETE answers again.
    r = comm_put(plc.http, {"exception": 4})
    assert r.status == 200 and r.json()["summary"]["faults"] == ["exception 04h"], r
    rr, _ = read_r(c, 0)
    assert rr.isError() and rr.exception_code == 4, rr
    assert comm(plc.http)["figures"]["refused"] >= 1
    # The simulator unit is never subject, and says a fault is on (comm.status b0, register
    # 40; comm.exception, register 25).
    assert holding(c, 40, unit=SIM_UNIT)[0] & 1 == 1
    assert holding(c, 25, unit=SIM_UNIT) == [4]
    assert comm_delete(plc.http).status == 200
    assert holding(c, 0) == [11]
    assert holding(c, 40, unit=SIM_UNIT)[0] & 1 == 0
    # A scope: R100-R109 answer 300 ms late, R0 at once; the figures count the delays.
    assert comm_put(plc.http, {"delay_ms": 300, "from": "R100", "count": 10}).status == 200
    rr, took = read_r(c, 100)
    assert not rr.isError() and rr.registers == [22] and took >= 0.28, (rr, took)
    rr, took = read_r(c, 0)
    assert not rr.isError() and took < 0.1, (rr, took)
    assert comm(plc.http)["figures"]["delayed"] >= 1
    # Switched through the simulator unit, the API says so (FC06 on comm.exception).
    assert not c.write_register(25, 6, slave=SIM_UNIT).isError()
    s = wait_for(lambda: (lambda j: j if j["exception"] == 6 else None)(comm(plc.http)),
                 what="exception 6 in the API")
    assert (s["delay_ms"], s["from"], s["count"]) == (300, "R100", 10), s
    rr, _ = read_r(c, 105)
    assert rr.isError() and rr.exception_code == 6, rr
    assert comm_delete(plc.http).status == 200
    rr, took = read_r(c, 100)
    assert not rr.isError() and took < 0.1, (rr, took)


# --- Events -----------------------------------------------------------------------------------


class EventStream:
    """A Server-Sent Events response read from a raw socket."""

    def __init__(self, port, path, timeout=TIMEOUT):
        self.sock = connect(port, timeout=timeout)
        self.sock.sendall(raw_request("GET", path))
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(4096)
            assert chunk, f"closed before the stream's head: {head!r}"
            head += chunk
        head, _, self.buf = head.partition(b"\r\n\r\n")
        lines = head.decode("latin-1").split("\r\n")
        assert lines[0].startswith("HTTP/1.1 200"), lines
        self.headers = {k.strip().lower(): v.strip()
                        for k, _, v in (line.partition(":") for line in lines[1:])}
        assert self.headers["content-type"] == "text/event-stream", self.headers

    def next(self, name, timeout=2.0):
        """The data (JSON) of the next event called `name`, skipping others and comments."""
        deadline = time.monotonic() + timeout
        while True:
            while b"\n\n" in self.buf:
                block, _, self.buf = self.buf.partition(b"\n\n")
                event, data = None, None
                for line in block.decode().split("\n"):
                    if line.startswith("event: "):
                        event = line[len("event: "):]
                    elif line.startswith("data: "):
                        data = line[len("data: "):]
                    else:
                        assert line.startswith(":"), block
                if event == name:
                    return json.loads(data)
            left = deadline - time.monotonic()
            if left <= 0:
                pytest.fail(f"no '{name}' event within {timeout} s")
            self.sock.settimeout(left)
            try:
                chunk = self.sock.recv(65536)
            except socket.timeout:
                continue
            assert chunk, "the stream ended"
            self.buf += chunk

    def close(self):
        self.sock.close()


def test_events_carry_values_when_they_change(fbs):
    c = fbs.client()
    assert not c.write_registers(160, [5, 6], slave=1).isError()
    stream = EventStream(fbs.http, "/api/v1/plcs/0/events?device=R160&count=2")
    try:
        first = stream.next("values")
        assert first == {"device": "R160", "names": ["R160", "R161"], "words": [1, 1],
                         "values": [5, 6]}, first
        state = stream.next("plcs")
        assert [p["id"] for p in state["plcs"]] == ["0"], state
        t0 = time.monotonic()
        assert not c.write_register(160, 4321, slave=1).isError()
        changed = stream.next("values", timeout=1.0)
        assert changed["values"] == [4321, 6], changed
        assert time.monotonic() - t0 < 1.0
        assert not c.write_register(161, 7, slave=1).isError()
        assert stream.next("values", timeout=1.0)["values"] == [4321, 7]
    finally:
        stream.close()


def test_what_an_event_streams_client_sends_is_dropped_and_costs_nothing(start_http):
    """A client of an event stream has nothing more to say; 4 MB it sends anyway are read and
    dropped, and the stream goes on (kept, they once filled the connection's buffer, after which
    the daemon spun on reads into no room: a core for as long as the client stayed)."""
    plc = start_http()
    c = plc.client()
    stream = EventStream(plc.http, "/api/v1/plcs/0/events?device=R160")
    try:
        stream.next("values")
        stream.sock.sendall(b"x" * (4 << 20))  # more than the kernel's buffers hold
        assert cpu_over(plc.daemon.proc.pid, 1.0) < 0.3
        assert not c.write_register(160, 99, slave=1).isError()
        assert stream.next("values", timeout=2.0)["values"] == [99]
    finally:
        stream.close()


def test_events_of_every_plc_carry_their_state(fbs):
    stream = EventStream(fbs.http, "/api/v1/events")
    try:
        first = stream.next("plcs")
        assert [p["id"] for p in first["plcs"]] == ["0"], first
        assert first["plcs"][0]["profile"] == "fbs", first
        second = stream.next("plcs", timeout=2.0)
        assert second["plcs"][0]["scans"] > first["plcs"][0]["scans"], (first, second)
    finally:
        stream.close()


# --- Traffic and clients -----------------------------------------------------------------------

ISO_MS = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$")


def peer_of(client):
    """The "address:port" the daemon sees a pymodbus client as."""
    host, port = client.socket.getsockname()[:2]
    return f"{host}:{port}"


def traffic(port, count=None, plc="0"):
    q = "" if count is None else f"?count={count}"
    r = get(port, f"/api/v1/plcs/{plc}/traffic{q}")
    assert r.status == 200, r
    body = r.json()
    assert set(body) == {"clients", "exchanges"}, body
    return body


def test_traffic_lists_the_requests_decoded(start_http):
    plc = start_http(modbus_extra=", write_protect: [R200-R209]")
    assert traffic(plc.http) == {"clients": [], "exchanges": []}
    c = plc.client()
    peer = peer_of(c)
    assert holding(c, 100, 10) == [0] * 10
    refused = c.write_register(205, 7, slave=1)
    assert refused.isError() and refused.exception_code == 2, refused
    assert holding(c, 100, 1, unit=SIM_UNIT) == [0]
    body = traffic(plc.http)
    ex = body["exchanges"]
    assert len(ex) == 3, ex
    for e in ex:
        assert set(e) == {"at", "client", "protocol", "unit", "function", "devices", "error"}, e
        assert ISO_MS.match(e["at"]), e
        assert (e["client"], e["protocol"]) == (peer, "modbus-tcp"), e
    # Oldest first, each as the master asked it.
    assert [(e["unit"], e["function"], e["devices"], e["error"]) for e in ex] == [
        (1, "03h", "R100-R109", ""),
        (1, "06h", "R205", "02h"),
        (SIM_UNIT, "03h", "simulator unit, register 100", ""),
    ], ex
    assert [e["at"] for e in ex] == sorted(e["at"] for e in ex)
    # The client that made them, counted.
    clients = body["clients"]
    assert len(clients) == 1, clients
    assert {k: clients[0][k] for k in ("peer", "protocol", "requests", "refusals")} == {
        "peer": peer, "protocol": "modbus-tcp", "requests": 3, "refusals": 1}, clients
    assert clients[0]["last"] == ex[-1]["at"], (clients, ex)
    # count: the last ones.
    assert [e["function"] for e in traffic(plc.http, 2)["exchanges"]] == ["06h", "03h"]
    assert traffic(plc.http, 1)["exchanges"] == ex[-1:]
    assert traffic(plc.http, 256)["exchanges"] == ex
    # An address the PLC does not map is said so.
    assert c.read_holding_registers(9999, 1, slave=1).isError()
    last = traffic(plc.http, 1)["exchanges"][0]
    assert (last["devices"], last["error"]) == ("address 9999 (not mapped)", "02h"), last
    # 17h reads one range and writes another, refused or not; the simulator unit has registers
    # only, so a request of another table names the unit alone.
    assert not c.readwrite_registers(read_address=100, read_count=2, write_address=110,
                                     write_registers=[1, 2, 3], slave=1).isError()
    refused = c.readwrite_registers(read_address=100, read_count=1, write_address=205,
                                    write_registers=[1], slave=1)
    assert refused.isError(), refused
    c.read_coils(0, 8, slave=SIM_UNIT)
    c.read_input_registers(0, 1, slave=SIM_UNIT)
    # A count of 0 is refused, and said.
    with socket.create_connection(("127.0.0.1", plc.daemon.port), timeout=3) as s:
        pdu = struct.pack(">BHHHHBH", 0x17, 100, 0, 110, 1, 2, 9)
        s.sendall(struct.pack(">HHHB", 1, 0, len(pdu) + 1, 1) + pdu)
        assert s.recv(64)[7:] == b"\x97\x03"
    assert [(e["function"], e["devices"], e["error"]) for e in traffic(plc.http, 5)["exchanges"]] \
        == [("17h", "read R100-R101, write R110-R112", ""),
            ("17h", "read R100, write R205", "02h"),
            ("01h", "simulator unit", "01h"),
            ("04h", "simulator unit", "01h"),
            ("17h", "read nothing, write R110", "03h")]
    # So is a count of 0 of any other function (it showed no devices at all).
    with socket.create_connection(("127.0.0.1", plc.daemon.port), timeout=3) as s:
        for function in (0x01, 0x03, 0x10):
            pdu = struct.pack(">BHH", function, 100, 0) + (b"\x00" if function == 0x10 else b"")
            s.sendall(struct.pack(">HHHB", 2, 0, len(pdu) + 1, 1) + pdu)
            assert s.recv(64)[7:] == bytes([function | 0x80, 3])
    assert [(e["function"], e["devices"], e["error"]) for e in traffic(plc.http, 3)["exchanges"]] \
        == [("01h", "nothing", "03h"), ("03h", "nothing", "03h"), ("10h", "nothing", "03h")]


@pytest.mark.parametrize("count", ["0", "257", "abc", "-1", ""])
def test_traffic_count_out_of_range_is_400(fbs, count):
    assert_error(get(fbs.http, f"/api/v1/plcs/0/traffic?count={count}"), 400, "count", "256")


def test_the_traffic_keeps_the_last_256(start_http):
    plc = start_http()
    c = plc.client()
    for n in range(260):
        assert not c.read_holding_registers(n, 1, slave=1).isError()
    ex = traffic(plc.http, 256)["exchanges"]
    assert [e["devices"] for e in ex] == [f"R{n}" for n in range(4, 260)]
    assert len(traffic(plc.http)["exchanges"]) == 100
    assert traffic(plc.http)["clients"][0]["requests"] == 260


def test_a_plcs_clients_are_listed_while_connected(start_http):
    plc = start_http()
    c = ModbusTcpClient("127.0.0.1", port=plc.daemon.port, timeout=3, retries=1)
    assert c.connect()
    try:
        peer = peer_of(c)
        for n in range(4):
            assert not c.read_holding_registers(n, 1, slave=1).isError()
        assert c.read_holding_registers(9999, 1, slave=1).isError()
        p = plc_state(plc.http)
        assert isinstance(p["lateness_p99_us"], int) and isinstance(p["lateness_max_us"], int), p
        assert 0 <= p["lateness_p99_us"] <= p["lateness_max_us"], p
        clients = p["clients"]
        assert len(clients) == 1, clients
        one = clients[0]
        assert set(one) == {"peer", "protocol", "requests", "refusals", "last"}, one
        assert (one["peer"], one["protocol"], one["requests"], one["refusals"]) == (
            peer, "modbus-tcp", 5, 1), one
        assert ISO_MS.match(one["last"]), one
        assert get(plc.http, "/api/v1/plcs").json()["plcs"][0]["clients"] == clients
        # A second client is listed beside it, in the order they first asked.
        d = plc.client()
        assert not d.read_coils(0, 8, slave=1).isError()
        listed = plc_state(plc.http)["clients"]
        assert [x["peer"] for x in listed] == [peer, peer_of(d)], listed
        assert (listed[1]["requests"], listed[1]["refusals"]) == (1, 0), listed
    finally:
        c.close()
    # Gone when its connection closes; its requests stay in the traffic, the client "gone".
    wait_for(lambda: [x["peer"] for x in plc_state(plc.http)["clients"]] == [peer_of(d)],
             timeout=2.0, what=f"{peer} no longer listed")
    ex = traffic(plc.http)["exchanges"]
    assert ex[0]["client"] != peer and ex[0]["client"].endswith("(gone)"), ex[0]
    assert ex[-1]["client"] == peer_of(d), ex[-1]


# --- /healthz and /metrics --------------------------------------------------------------------


def test_healthz_is_ok(fbs):
    r = get(fbs.http, "/healthz")
    assert r.status == 200, r
    assert r.json() == {"status": "ok", "plcs": [
        {"id": "0", "scanning": True, "frozen": False, "running": True}]}


def test_healthz_is_503_while_the_scans_cannot_keep_up(tmp_path):
    """docs/console.md, /healthz: at a time scale no host can keep up with (a 10 ms scan in
    0.1 microsecond of real time) the scans fall more than a second behind and the schedule
    skips ahead, again and again: 503, not scanning (it answered 200, the scans having run just
    before the request), the lateness counting the seconds behind; 200 again two seconds after
    the time scale is one a host keeps up with."""
    hp, mp = free_port(), free_port()
    d = spawn(tmp_path, single_config(hp, extra="persistence: {enabled: false}\n"
                                                "time_scale: 100000\n"), [hp, mp],
              modbus_port=mp)
    try:
        # One skip is a pause the scans came out of; the second is scans that cannot keep up.
        wait_for(lambda: d.log_text().count("skipping ahead") >= 2, timeout=10.0,
                 what="the schedule skipped ahead twice")
        r = get(hp, "/healthz")
        assert r.status == 503, r
        assert r.json()["plcs"][0]["scanning"] is False, r.json()
        late = get(hp, "/api/v1/plcs").json()["plcs"][0]["lateness_max_us"]
        assert late >= 1_000_000, late
        # The simulator unit's time scale (holding register 0 of unit 247) back to 1.
        c = d.client()
        assert not c.write_register(0, 1, slave=247).isError()
        wait_for(lambda: get(hp, "/healthz").status == 200, timeout=5.0,
                 what="200 again two seconds after")
    finally:
        d.stop()


def test_healthz_stays_200_through_one_pause(tmp_path):
    """A process stopped for 1.5 s, with scans too costly to catch up in one round (1,500 rungs),
    skips ahead once and goes on keeping its schedule: no fault (a readiness probe would have
    failed after every pause of the virtual machine)."""
    hp, mp = free_port(), free_port()
    rungs = ", ".join(["'ORG M0'", "'OUT M1'"] * 1500)
    d = spawn(tmp_path, single_config(hp, extra="persistence: {enabled: false}\n"
                                                f"program: {{il: [{rungs}]}}\n"), [hp, mp],
              modbus_port=mp)
    try:
        assert get(hp, "/healthz").status == 200
        d.proc.send_signal(signal.SIGSTOP)
        time.sleep(1.5)
        d.proc.send_signal(signal.SIGCONT)
        wait_for(lambda: "skipping ahead" in d.log_text(), timeout=5.0,
                 what="the schedule skipped ahead")
        r = get(hp, "/healthz")
        assert r.status == 200, (r, d.log_text())
        assert d.log_text().count("skipping ahead") == 1, d.log_text()
    finally:
        d.stop()


METRIC_NAME = r"[a-zA-Z_:][a-zA-Z0-9_:]*"
LABEL = r'[a-zA-Z_][a-zA-Z0-9_]*="(?:[^"\\\n]|\\[\\"n])*"'
SAMPLE = re.compile(
    rf"^({METRIC_NAME})(?:\{{((?:{LABEL})(?:,{LABEL})*)?\}})? "
    r"([-+]?(?:[0-9]+(?:\.[0-9]*)?(?:[eE][-+]?[0-9]+)?|NaN|Inf))$"
)
TYPE = re.compile(rf"^# TYPE ({METRIC_NAME}) (counter|gauge|histogram|summary|untyped)$")
HELP = re.compile(rf"^# HELP ({METRIC_NAME}) .+$")


def parse_metrics(text):
    """{(name, labels as a sorted tuple): value}; fails on any line that is not Prometheus'
    text format 0.0.4, and on a sample whose family has no # TYPE before it."""
    assert text.endswith("\n"), text[-100:]
    typed = set()
    samples = {}
    for line in text.split("\n")[:-1]:
        if line.startswith("#"):
            m = TYPE.match(line)
            if m:
                assert m.group(1) not in typed, f"two TYPE lines for {m.group(1)}"
                typed.add(m.group(1))
                if m.group(2) == "histogram":  # its samples are NAME_bucket, _sum and _count
                    typed.update(m.group(1) + s for s in ("_bucket", "_sum", "_count"))
            else:
                assert HELP.match(line), line
            continue
        m = SAMPLE.match(line)
        assert m, f"not a Prometheus sample: {line!r}"
        name, labels, value = m.groups()
        assert name in typed, f"{name} has no # TYPE before it"
        pairs = tuple(sorted(re.findall(r'([a-zA-Z_][a-zA-Z0-9_]*)="((?:[^"\\]|\\.)*)"',
                                        labels or "")))
        assert len({k for k, _ in pairs}) == len(pairs), line
        key = (name, pairs)
        assert key not in samples, f"duplicate sample {line!r}"
        samples[key] = float(value)
    return samples


def test_metrics_count_scans_and_modbus_requests(fbs):
    c = fbs.client()
    before = parse_metrics(get(fbs.http, "/metrics").body.decode())
    fc3 = ("plcemu_requests_total",
           (("function", "03"), ("plc", "0"), ("protocol", "modbus-tcp")))
    n = 7
    for _ in range(n):
        holding(c, 0)
    r = get(fbs.http, "/metrics")
    assert r.status == 200, r
    assert r.header("Content-Type").startswith("text/plain; version=0.0.4"), r
    m = parse_metrics(r.body.decode())
    assert m[("plcemu_scans_total", (("plc", "0"),))] > 0
    assert m[fc3] >= before.get(fc3, 0) + n, (before.get(fc3), m.get(fc3))
    assert m[("plcemu_running", (("plc", "0"),))] == 1
    assert m[("plcemu_frozen", (("plc", "0"),))] == 0
    assert ("plcemu_simulated_seconds", (("plc", "0"),)) in m
    temps = [k for k in m if k[0] == "plcemu_plant_temperature_celsius"]
    assert len(temps) == 32, temps
    # An exception reply is counted by its code: 02 for an unmapped address.
    bad = c.read_holding_registers(4500, 1, slave=1)
    assert bad.isError()
    m = parse_metrics(get(fbs.http, "/metrics").body.decode())
    assert m[("plcemu_request_errors_total", (("code", "02"), ("function", "03"), ("plc", "0"),
                                              ("protocol", "modbus-tcp")))] >= 1
    assert request(fbs.http, "HEAD", "/metrics").body == b""


# --- Loops ------------------------------------------------------------------------------------


def start_config_file(start_plcemud, name, *args):
    """config/<name> as it is, but for its ports: Modbus on a free port (--port), the console on
    another (--http-port) -> Plc."""
    hp = free_port()
    d = start_plcemud((REPO / "config" / name).read_text(), "--http-port", str(hp), *args)
    wait_listening(d, [hp])
    return Plc(d, hp)


def loops(port, plc="0"):
    r = get(port, f"/api/v1/plcs/{plc}/loops")
    assert r.status == 200, r
    body = r.json()
    assert set(body) == {"loops", "simulated_s"}, body
    assert isinstance(body["simulated_s"], float), body
    return body["loops"]


def flags(loop):
    return [(a["name"], a["device"], a["bit"], a["on"]) for a in loop["alarms"]]


def test_a_program_without_loops_has_none(fbs):
    assert loops(fbs.http) == []
    assert request(fbs.http, "HEAD", "/api/v1/plcs/0/loops").status == 200


def test_loops_of_default_yaml_are_its_ten_tpctl_points(start_plcemud):
    plc = start_config_file(start_plcemud, "default.yaml", "--time-scale", "10")
    # The PVs are there once the temperature modules have read every channel (execute code 56h
    # in D0, the modules' working registers).
    ls = wait_for(lambda: [lp for lp in loops(plc.http) if lp["pv"]], timeout=5,
                  what="the loops' PVs")
    assert [lp["name"] for lp in ls] == [f"TPCTL point {i} (channel {i})" for i in range(10)]
    p3 = ls[3]
    assert (p3["channel"], p3["unit"], p3["scale"], p3["output_full"]) == (3, "°C", 0.1, 16383), p3
    assert p3["pv"]["device"] == "R3", p3
    assert p3["pv"]["value"] == pytest.approx(p3["pv"]["raw"] * 0.1), p3
    assert p3["sv"] == {"device": "R103", "raw": 1500, "value": 150.0}, p3
    assert p3["output"] == {"device": "R203", "raw": 0, "value": 0, "percent": 0}, p3
    assert [(q["name"], q["device"], q["unit"]) for q in p3["parameters"]] == [
        ("Kc", "R123", "1-9999"), ("Ki", "R133", "0.01 repeats/min"), ("Td", "R143", "0.01 min"),
        ("in-zone offset", "R113", "0.1 °C")], p3
    assert p3["parameters"][3]["value"] == 50, p3
    assert flags(p3) == [("in zone", "R300", 3, False), ("warning", "R302", 3, False),
                         ("over temperature", "R305", 3, False), ("heater open", "R307", 3, False)]
    assert p3["manual"] is None and p3["tuning"] is None, p3
    assert p3["true_temperature_c"] == pytest.approx(25.0, abs=0.5), p3
    # What the loops say is the PLC's image: point 3's set point written over Modbus (just above
    # the ambient 25 °C, so that its PV is in zone), then the loops started as a SCADA does.
    c = plc.client()
    assert not c.write_register(103, 260, slave=1).isError()
    p3 = loops(plc.http)[3]
    assert p3["sv"]["raw"] == 260 and p3["sv"]["value"] == pytest.approx(26.0), p3
    assert put(plc.http, "/api/v1/plcs/0/devices/WM800", {"values": [1023]}).status == 200
    assert put(plc.http, "/api/v1/plcs/0/devices/M0", {"values": [1]}).status == 200

    def running():
        ls = loops(plc.http)
        return ls if flags(ls[3])[0][3] and ls[0]["output"]["raw"] > 0 else None

    ls = wait_for(running, timeout=10, what="point 3 in zone and point 0 heating")
    assert holding(c, 300)[0] & 0b1111 == 0b1000  # in zone: point 3 alone (bit 3 of WR+0)
    assert not flags(ls[0])[0][3]
    out = ls[0]["output"]
    assert out["device"] == "R200" and out["percent"] == pytest.approx(100 * out["raw"] / 16383)
    # The first execution wrote the default gains into PR, IR, DR.
    assert [q["value"] for q in ls[0]["parameters"]] == [110, 17, 50, 50], ls[0]
    assert holding(c, 120) == [110]


def test_loop_history_keeps_a_sample_a_simulated_second_once_the_loops_are_watched(
        start_plcemud):
    plc = start_config_file(start_plcemud, "default.yaml")
    assert sim_put(plc.http, {"frozen": True}).status == 200
    c = plc.client()
    assert not c.write_register(103, 260, slave=1).isError()  # point 3's SV: 26.0 °C

    def history():
        r = get(plc.http, "/api/v1/plcs/0/loops/history")
        assert r.status == 200, r
        return r.json()

    def stepped(n):
        before = plc_state(plc.http)["scans"]
        assert sim_put(plc.http, {"step": n}).status == 200
        wait_for(lambda: plc_state(plc.http)["scans"] == before + n, what=f"{n} scans")

    # Not watched yet: scans leave nothing behind (a process of many PLCs pays nothing).
    stepped(300)
    h = history()  # from now on it is watched
    assert h["every_s"] == 1
    assert [x["name"] for x in h["loops"]] == [f"TPCTL point {i} (channel {i})" for i in range(10)]
    assert all(x["samples"] == [] for x in h["loops"]), h
    stepped(501)  # 5.01 simulated seconds of 10 ms scans
    h = history()
    p3 = h["loops"][3]["samples"]
    assert len(p3) == 6, p3
    ts = [s[0] for s in p3]
    assert [round(b - a, 6) for a, b in zip(ts, ts[1:])] == [1.0] * 5, ts
    assert ts[-1] <= h["simulated_s"] < ts[-1] + 1, (ts, h["simulated_s"])
    # [t, pv, sv, output %]: in the loop's units, as /loops gives them.
    lp = loops(plc.http)[3]
    t, pv, sv, out = p3[-1]
    assert sv == pytest.approx(26.0) and sv == lp["sv"]["value"], (p3[-1], lp)
    assert pv == pytest.approx(lp["pv"]["value"], abs=0.2), (p3[-1], lp)
    assert out == pytest.approx(lp["output"]["percent"]), (p3[-1], lp)
    assert request(plc.http, "HEAD", "/api/v1/plcs/0/loops/history").status == 200
    assert request(plc.http, "PUT", "/api/v1/plcs/0/loops/history", json_body={}).status == 405


def test_loops_of_vb_pid_yaml_are_its_pid_with_its_tuning_bit(start_plcemud):
    plc = start_config_file(start_plcemud, "vb-pid.yaml")
    ls = loops(plc.http)
    assert len(ls) == 1, ls
    lp = ls[0]
    assert (lp["pv"]["device"], lp["sv"]["device"], lp["output"]["device"]) == (
        "D101", "D100", "D102"), lp
    assert lp["sv"] == {"device": "D100", "raw": 1500, "value": 1500}, lp
    # D201 = H0031 at start: bit 4, auto-tuning, is on until M0 runs the PID and tuning ends.
    assert lp["tuning"] == {"name": "auto-tuning", "device": "D201", "bit": 4, "on": True}, lp
    assert lp["manual"] is None, lp
    # MV in the program's own units: no percentage.
    assert lp["output_full"] == 0 and "percent" not in lp["output"], lp
    assert [q["device"] for q in lp["parameters"]] == ["D200", "D203", "D204", "D206"], lp
    assert lp["parameters"][0]["value"] == 2000, lp
    assert flags(lp)[0] == ("PV rose", "D224", 0, False), lp
    assert not plc.client().write_register(201, 0x21, slave=1).isError()
    assert loops(plc.http)[0]["tuning"]["on"] is False


def test_loops_of_vb_tpid_yaml_have_a_manual_bit_and_a_full_scale(start_plcemud):
    plc = start_config_file(start_plcemud, "vb-tpid.yaml")
    ls = loops(plc.http)
    assert [lp["name"] for lp in ls] == ["TPID channel 0 (D10)"], ls
    lp = ls[0]
    assert lp["output_full"] == 1000 and lp["output"]["device"] == "D110", lp
    assert lp["output"]["percent"] == pytest.approx(lp["output"]["raw"] / 10), lp
    assert lp["manual"] == {"name": "manual", "device": "D103", "bit": 0, "on": False}, lp
    assert lp["tuning"] == {"name": "auto-tuning", "device": "D104", "bit": 0, "on": False}, lp
    assert (lp["pv"]["device"], lp["scale"], lp["unit"]) == ("D10", 0.1, "°C"), lp
    assert lp["sv"] == {"device": "D0", "raw": 2450, "value": 245.0}, lp
    assert [q["device"] for q in lp["parameters"]] == [f"D{7000 + i}" for i in range(6)], lp
    assert flags(lp) == [("limitation alarm", "D106", 0, False),
                         ("deviation alarm", "D107", 0, False)], lp
    assert put(plc.http, "/api/v1/plcs/0/devices/D103", {"values": [1]}).status == 200
    assert loops(plc.http)[0]["manual"]["on"] is True


def test_a_tpid_with_n_in_a_register_has_the_loops_it_runs(start_plcemud):
    text = (REPO / "config" / "vb-tpid.yaml").read_text()
    text, subs = re.subn(r"(?m)^(  - TPID: \{.*)n: K1\}$", r"\1n: D500}", text)
    assert subs == 1
    text = text.replace("program:\n", "program:\n  - MOV: {en: M9002, s: K1, d: D500}\n", 1)
    hp = free_port()
    d = start_plcemud(text, "--http-port", str(hp))
    wait_listening(d, [hp])
    assert devices(hp, "D500").json()["values"] == [1]
    assert [lp["name"] for lp in loops(hp)] == ["TPID channel 0 (D10)"]


def test_metrics_have_each_loops_pv_sv_and_output(start_plcemud):
    plc = start_config_file(start_plcemud, "default.yaml")
    wait_for(lambda: all(lp["pv"] for lp in loops(plc.http)), timeout=5, what="the loops' PVs")
    m = parse_metrics(get(plc.http, "/metrics").body.decode())
    for i in range(10):
        labels = (("loop", f"TPCTL point {i} (channel {i})"), ("plc", "0"))
        assert m[("plcemu_loop_sv", labels)] == 150, i
        assert ("plcemu_loop_pv", labels) in m, i
        assert m[("plcemu_loop_output_percent", labels)] == 0, i
    assert len([k for k in m if k[0].startswith("plcemu_loop_")]) == 30
    # Text of the exposition itself, as a scraper reads it.
    text = get(plc.http, "/metrics").body.decode()
    line = r'(?m)^plcemu_loop_sv\{plc="0",loop="TPCTL point 0 \(channel 0\)"\} 150(\.0)?$'
    assert re.search(line, text), text


# --- Keep-alive and pipelining -----------------------------------------------------------------


def test_keep_alive_serves_several_requests_on_one_connection(fbs):
    with connect(fbs.http) as s:
        s.sendall(raw_request("GET", "/healthz"))
        first = recv_response(s)
        assert first.status == 200 and first.header("Connection") is None, first
        s.sendall(raw_request("GET", "/api/v1/plcs/0"))
        second = recv_response(s)
        assert second.status == 200 and second.json()["id"] == "0", second
        s.sendall(json_put_request("/api/v1/plcs/0/devices/R170", [17]))
        assert recv_response(s).status == 200
    # With http.client too: one socket for both.
    conn = http.client.HTTPConnection("127.0.0.1", fbs.http, timeout=TIMEOUT)
    try:
        conn.request("GET", "/healthz")
        assert conn.getresponse().read() and conn.sock is not None
        sock = conn.sock
        conn.request("GET", "/api/v1/plcs/0/devices/R170")
        r = conn.getresponse()
        assert json.loads(r.read())["values"] == [17]
        assert conn.sock is sock
    finally:
        conn.close()


def test_pipelined_requests_are_answered_in_order(fbs):
    with connect(fbs.http) as s:
        s.sendall(json_put_request("/api/v1/plcs/0/devices/R171", [77])
                  + raw_request("GET", "/api/v1/plcs/0/devices/R171")
                  + raw_request("GET", "/api/v1/plcs/0/devices/Q1")
                  + json_put_request("/api/v1/plcs/0/devices/R171", [78])
                  + raw_request("GET", "/healthz"))
        replies = [recv_response(s) for _ in range(5)]
    assert [r.status for r in replies] == [200, 200, 404, 200, 200], replies
    assert replies[0].json()["values"] == [77]
    assert replies[1].json()["values"] == [77]
    assert replies[3].json()["values"] == [78]
    assert replies[4].json()["status"] == "ok"
    # Many more than are served in one turn, in one send.
    n = 150
    with connect(fbs.http) as s:
        s.sendall(b"".join(raw_request("GET", f"/api/v1/plcs/0/devices/R{k}") for k in range(n)))
        names = [recv_response(s).json()["names"] for _ in range(n)]
    assert names == [[f"R{k}"] for k in range(n)]


def test_connection_close_is_honoured(fbs):
    with connect(fbs.http) as s:
        s.sendall(raw_request("GET", "/healthz", headers=["Connection: close"])
                  + raw_request("GET", "/healthz"))
        r = recv_response(s)
        assert r.status == 200 and r.header("Connection") == "close", r
        assert closed_by_server(s)


# --- Bounded clients ---------------------------------------------------------------------------


def test_a_stalled_half_request_is_closed_after_the_frame_timeout(start_http):
    plc = start_http(http_extra=", frame_timeout_ms: 300")
    with connect(plc.http) as s:
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n")
        t0 = time.monotonic()
        # Others are served meanwhile.
        assert get(plc.http, "/healthz").status == 200
        assert closed_by_server(s, within=3.0)
        elapsed = time.monotonic() - t0
    assert 0.25 <= elapsed < 2.0, elapsed
    assert plc.daemon.wait_log("request not completed within http.frame_timeout_ms")
    # A request that takes its time in pieces, but completes in time, is answered.
    with connect(plc.http) as s:
        s.sendall(b"GET /healthz HTTP/1.1\r\n")
        time.sleep(0.1)
        s.sendall(b"Host: 127.0.0.1\r\n\r\n")
        assert recv_response(s).status == 200


def test_requests_sent_a_few_bytes_at_a_time_are_cut_where_they_end(fbs):
    """A connection's requests arrive in pieces of any size: a 6 KB head and its body a few
    bytes per segment, with the next request's first bytes in the last segment, are one write
    and then the next request (each byte read once: docs/console.md, "Limits")."""
    c = fbs.client()
    assert not c.write_registers(146, [45], slave=1).isError()
    pad = [f"X-Pad-{i:03}: {'a' * 40}" for i in range(120)]
    first = json_put_request("/api/v1/plcs/0/devices/R146", [9], pad)
    assert len(first) > 6000
    stream = first + raw_request("GET", "/api/v1/plcs/0/devices/R146")
    with connect(fbs.http) as s:
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        for i in range(0, len(stream), 9):
            s.sendall(stream[i:i + 9])
            if i % 900 == 0:
                time.sleep(0.002)  # the daemon reads what came so far
        assert recv_response(s).status == 200
        r = recv_response(s)
        assert r.status == 200 and json.loads(r.body)["values"] == [9], r
    assert holding(c, 146) == [9]


def test_a_head_near_the_limit_is_answered_alike_or_refused_never_swallowed(fbs):
    """Beast counts the head limit from the request line's end when a head comes in one piece
    and from its start when it comes in pieces, so a head a few bytes over 8 KiB may be served
    or refused (431) by how it arrived; either way the requests behind it are answered or the
    connection closed (the answer once came from a second reading that disagreed with the
    first, and the requests behind it were swallowed on a connection left open)."""
    statuses = set()
    for size in range(8180, 8232, 4):
        head = raw_request("GET", "/healthz", headers=["X-Pad: " + "a" * (size - 60)])
        stream = head + raw_request("GET", "/healthz") + raw_request("GET", "/healthz")
        for pieces in ((stream,), (stream[:6], stream[6:])):
            with connect(fbs.http) as s:
                for p in pieces:
                    s.sendall(p)
                    time.sleep(0.02)
                first = recv_response(s)
                statuses.add(first.status)
                if first.status == 431:
                    assert closed_by_server(s)
                else:
                    assert first.status == 200, (len(head), len(pieces), first)
                    assert [recv_response(s).status for _ in range(2)] == [200, 200], len(head)
    assert statuses == {200, 431}
    # Well over the limit it is 431 however it comes.
    big = raw_request("GET", "/healthz", headers=["X-Pad: " + "a" * 9000])
    for pieces in ((big,), (big[:6], big[6:])):
        with connect(fbs.http) as s:
            for p in pieces:
                s.sendall(p)
                time.sleep(0.05)
            assert recv_response(s).status == 431
            assert closed_by_server(s)


def test_a_chunked_request_over_64_kib_as_sent_is_413(fbs):
    """A body within the 24 KiB limit sent in one-byte chunks is 72 KB on the wire: refused with
    413 as a request too large as sent (it was closed without an answer)."""
    body = b"".join(b"1\r\n%c\r\n" % c for c in b"x" * 12000) + b"0\r\n\r\n"
    raw = raw_request("PUT", "/api/v1/plcs/0/devices/R148", b"",
                      ["Content-Type: application/json"]).replace(
        b"Content-Length: 0", b"Transfer-Encoding: chunked") + body
    with connect(fbs.http) as s:
        try:
            s.sendall(raw)
        except (BrokenPipeError, ConnectionResetError):
            pass  # refused before it was all sent
        r = recv_response(s)
    assert_error(r, 413, "65536 bytes as sent")


def test_a_request_that_expects_100_continue_gets_it_before_its_body(fbs):
    """RFC 9110 §10.1.1: a PUT sent with `Expect: 100-continue` waits for the interim answer
    before its body (curl waits a second for it, then sends the body anyway); it comes once the
    head is read, and the final answer after the body. A body too large gets its 413 at once
    instead; HTTP/1.0 has no such expectation."""
    c = fbs.client()
    assert not c.write_registers(147, [45], slave=1).isError()
    body = json.dumps({"values": [11]}).encode()
    put_head = json_put_request("/api/v1/plcs/0/devices/R147", [11],
                                ["Expect: 100-continue"])[:-len(body)]
    with connect(fbs.http) as s:
        s.sendall(put_head)
        interim = recv_until(s, b"\r\n\r\n")
        assert interim == b"HTTP/1.1 100 Continue\r\n\r\n", interim
        s.sendall(body)
        assert recv_response(s).status == 200
        # The next request on the connection has its own.
        s.sendall(put_head.replace(b"100-continue", b"100-Continue"))
        assert s.recv(4096) == b"HTTP/1.1 100 Continue\r\n\r\n"
        s.sendall(body)
        assert recv_response(s).status == 200
    assert holding(c, 147) == [11]
    too_large = raw_request("PUT", "/api/v1/plcs/0/devices/R147", b"",
                            ["Content-Type: application/json", "Expect: 100-continue"]).replace(
        b"Content-Length: 0", b"Content-Length: 99999")
    assert status_of(fbs.http, too_large) == 413
    with connect(fbs.http, timeout=0.5) as s:
        s.sendall(put_head.replace(b"HTTP/1.1", b"HTTP/1.0"))
        with pytest.raises(socket.timeout):
            s.recv(4096)
        s.settimeout(TIMEOUT)
        s.sendall(body)
        assert s.recv(4096).startswith(b"HTTP/1.1 200 OK\r\n")


def test_max_clients_refuses_one_more_while_the_others_work(start_http):
    plc = start_http(http_extra=", max_clients: 2")
    a, b = connect(plc.http), connect(plc.http)
    try:
        for s in (a, b):
            s.sendall(raw_request("GET", "/healthz"))
            assert recv_response(s).status == 200
        with connect(plc.http) as third:
            try:
                third.sendall(raw_request("GET", "/healthz"))
            except (BrokenPipeError, ConnectionResetError):
                pass
            assert closed_by_server(third)
        assert plc.daemon.wait_log("http.max_clients")
        for s in (a, b):
            s.sendall(raw_request("GET", "/api/v1/plcs/0"))
            assert recv_response(s).status == 200
    finally:
        a.close()
    # A place freed is a place taken.
    def served():
        try:
            return get(plc.http, "/healthz", timeout=1.0).status == 200
        except (ConnectionError, OSError, http.client.HTTPException):
            return False
    wait_for(served, what="a new client served once one left")
    b.close()


def test_a_slow_event_reader_does_not_slow_modbus(start_http):
    plc = start_http()
    c = plc.client()
    # Two clients that open a stream of 1000 changing values and never read it.
    slow = [connect(plc.http, rcvbuf=4096) for _ in range(2)]
    try:
        for s in slow:
            s.sendall(raw_request("GET", "/api/v1/plcs/0/events?device=R0&count=1000"))
        worst = 0.0
        answered = 0
        deadline = time.monotonic() + 2.0
        i = 0
        while time.monotonic() < deadline:
            i += 1
            t = time.monotonic()
            # Every write changes the watched values: a new event of ~10 KB each 50 ms.
            assert not c.write_registers(0, [i & 0xFFFF] * 100, slave=1).isError()
            assert holding(c, 0) == [i & 0xFFFF]
            worst = max(worst, time.monotonic() - t)
            answered += 1
        assert worst < 0.5, worst
        assert answered > 20, answered
        assert get(plc.http, "/healthz").status == 200
    finally:
        for s in slow:
            s.close()


# --- Pages ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "path,content_type",
    [
        ("/", "text/html; charset=utf-8"),
        ("/plcs/0/devices", "text/html; charset=utf-8"),
        ("/plcs/0/loops", "text/html; charset=utf-8"),
        ("/plcs/0/plant", "text/html; charset=utf-8"),
        ("/plcs/0/traffic", "text/html; charset=utf-8"),
        ("/static/console.js", "text/javascript; charset=utf-8"),
        ("/static/console.css", "text/css; charset=utf-8"),
    ],
)
def test_pages_are_served_with_a_strict_csp(fbs, path, content_type):
    r = get(fbs.http, path)
    assert r.status == 200, r
    assert r.header("Content-Type") == content_type
    csp = r.header("Content-Security-Policy")
    assert "default-src 'self'" in csp and "script-src 'self'" in csp, csp
    assert "unsafe-inline" not in csp and "*" not in csp, csp
    assert r.header("X-Content-Type-Options") == "nosniff"


@pytest.mark.parametrize("view", ["devices", "loops", "plant", "traffic"])
def test_a_page_of_an_unknown_plc_is_the_page_as_a_404(fbs, view):
    # docs/console.md, "Pages": a browser shows the page, which says what the API says.
    r = get(fbs.http, f"/plcs/9/{view}")
    assert r.status == 404, r
    assert r.header("Content-Type") == "text/html; charset=utf-8"
    assert "script-src 'self'" in r.header("Content-Security-Policy")
    assert r.body == get(fbs.http, f"/plcs/0/{view}").body
    assert_error(get(fbs.http, "/api/v1/plcs/9"), 404, "'9'", "there are: 0")
    # A view that is not one stays a JSON 404.
    assert_error(get(fbs.http, "/plcs/9/nothing"), 404, "nothing at")


# --- OpenAPI ----------------------------------------------------------------------------------


def openapi(port):
    r = get(port, "/api/v1/openapi.json")
    assert r.status == 200, r
    return r.json()


def test_openapi_document_describes_every_endpoint(fbs):
    doc = openapi(fbs.http)
    assert doc["openapi"].startswith("3."), doc["openapi"]
    assert doc["info"]["title"] and doc["info"]["version"], doc["info"]
    missing = [p for p in CONTRACT_PATHS if p not in doc["paths"]]
    assert not missing, missing
    schemes = doc["components"]["securitySchemes"]
    bearer = [n for n, s in schemes.items()
              if s.get("type") == "http" and s.get("scheme") == "bearer"]
    assert bearer, schemes
    error = doc["components"]["schemas"]["Error"]
    assert error["required"] == ["error"] and error["properties"]["error"]["type"] == "string"
    text = json.dumps(doc)
    for path, item in doc["paths"].items():
        for method, op in item.items():
            if method == "parameters":
                continue
            assert op.get("responses"), (path, method)
            if method == "put":
                assert any(bearer[0] in req for req in op["security"]), (path, op)
                assert "application/json" in op["requestBody"]["content"], (path, op)
                for status in ("400", "401", "403", "404", "413", "415"):
                    assert status in op["responses"], (path, status)
    # Every $ref resolves.
    for ref in re.findall(r'"\$ref": "#/([^"]+)"', text):
        node = doc
        for part in ref.split("/"):
            node = node[part]


def test_every_documented_path_answers_for_a_real_plc(fbs):
    doc = openapi(fbs.http)
    for template, item in doc["paths"].items():
        path = (template.replace("{plc}", "0").replace("{device}", "R100")
                .replace("{file}", "console.js"))
        head = request(fbs.http, "HEAD", path)
        assert head.status == 200 and head.body == b"", (path, head)
        if "get" in item and not path.endswith("events"):
            assert get(fbs.http, path).status == 200, path
        if path.endswith("events"):
            EventStream(fbs.http, path).close()


# --- Configuration ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text,line,col,needle",
    [
        ("profile: fbs\nhttp: {port: 70000}\n", 2, 14, "http.port: 70000 is out of range 0..65535"),
        ('profile: fbs\nhttp: {token: ""}\n', 2, 15, "http.token: expected 1 to 256 printable"),
        ("profile: fbs\nhttp: {token: a b}\n", 2, 15, "http.token: expected 1 to 256 printable"),
        ("profile: fbs\nhttp: {allow: [bad]}\n", 2, 16, "http.allow: expected a CIDR range"),
        ("profile: fbs\nhttp: {allow: 10.0.0.0/8}\n", 2, 15, "http.allow: expected a list"),
        ("profile: fbs\nhttp: {bogus: 1}\n", 2, 8, "unknown key 'bogus'"),
        ("profile: fbs\nhttp: {unknown_unit: silent}\n", 2, 8, "unknown key 'unknown_unit'"),
        ("profile: fbs\nhttp: {read_only: maybe}\n", 2, 19, "http.read_only"),
        ("profile: fbs\nhttp: {frame_timeout_ms: 5}\n", 2, 26, "http.frame_timeout_ms"),
        ("profile: fbs\nhttp: {bind: localhost}\n", 2, 14, "http.bind: expected a numeric"),
        ("profile: fbs\nhttp: {hosts: [bad_name!]}\n", 2, 16,
         "http.hosts: expected a host name such as gateway.example, got 'bad_name!'"),
        ("profile: fbs\nhttp: {hosts: [gateway.example, '']}\n", 2, 33, "http.hosts"),
        ("profile: fbs\nhttp: {hosts: x}\n", 2, 15, "http.hosts: expected a list"),
        ("profile: vb\nhttp: {port: 70000}\n", 2, 14, "http.port: 70000 is out of range"),
        ("http: {bogus: 1}\nplcs:\n  - {profile: fbs}\n", 1, 8, "unknown key 'bogus'"),
        ("plcs:\n  - profile: fbs\n    http: {port: -1}\n", 3, 18, "http.port"),
    ],
)
def test_check_config_refuses_bad_http_keys_at_their_position(tmp_path, text, line, col, needle):
    p = tmp_path / "http.yaml"
    p.write_text(text)
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2, r.stderr
    assert f"{p}:{line}:{col}: " in r.stderr, r.stderr
    assert needle in r.stderr, r.stderr
    assert r.stdout == ""


@pytest.mark.parametrize("profile", ["fbs", "vb"])
def test_check_config_takes_every_http_key(tmp_path, profile):
    p = tmp_path / "http.yaml"
    p.write_text(
        f"profile: {profile}\n"
        "http:\n"
        "  enabled: true\n"
        "  bind: 127.0.0.1\n"
        "  port: 18020\n"
        "  allow: [127.0.0.0/8, '::1']\n"
        "  read_only: false\n"
        "  token: s3cret\n"
        "  max_clients: 4\n"
        "  idle_timeout_s: 60\n"
        "  frame_timeout_ms: 500\n"
        "  hosts: [gateway.example, plc-1.local, 192.0.2.7]\n"
    )
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 0, r.stderr
    assert "ok" in r.stdout
