"""What the daemon says must be true and safe to print (docs/operations.md, "Logging"): text a
config supplies is escaped in every log line (a key with U+202E cannot reorder the terminal line
that reports it), `--export-tags json` is valid JSON whatever bytes the file name holds, and the
descriptor-limit lines say what the limit allows."""

import json
import os
import resource
import socket
import subprocess

import pytest

from conftest import (BASE_CONFIG, PLCEMUD, free_ports, plcs_lines, raw_exchange, run_plcemud,
                      spawn_plcs)

RLO = "\u202e"  # RIGHT-TO-LEFT OVERRIDE
READ_R0 = b"\x03\x00\x00\x00\x01"


# --- control and bidi characters in the log


def test_a_key_with_a_right_to_left_override_is_logged_escaped(tmp_path):
    p = tmp_path / "plc.yaml"
    p.write_text(f"profile: fbs\nscan{RLO}_ms: 10\n", encoding="utf-8")
    for args in (("-c", p, "--check-config"), ("-c", p)):
        r = run_plcemud(*args)
        assert r.returncode == 2, r.stderr
        assert "unknown key 'scan\\u202E_ms' in config" in r.stderr, r.stderr
        assert RLO not in r.stderr


def test_controls_and_bidi_characters_are_escaped_in_any_log_line(tmp_path):
    # A serial device the config names, quoted by the error that stops the start: no quoting of
    # its own, the log line escapes it.
    p = tmp_path / "plc.yaml"
    p.write_bytes(
        b"profile: fbs\nmodbus: {tcp: {enabled: false}, rtu: {device: \"/nonexistent/tty"
        b"\\e[2J\\u2066\"}}\n"
    )
    r = subprocess.run([PLCEMUD, "-c", str(p)], capture_output=True, timeout=20)
    err = r.stderr.decode("utf-8")
    assert r.returncode != 0
    assert "/nonexistent/tty\\x1B[2J\\u2066" in err, err
    assert "\x1b" not in err and "\u2066" not in err


# --- --export-tags json and a file name that is not UTF-8


def test_export_tags_json_of_a_file_name_that_is_not_utf8_is_valid_json(tmp_path):
    name = os.fsencode(tmp_path) + b"/caf\xe9\xff.yaml"
    with open(name, "wb") as f:
        f.write(b"profile: fbs\nprogram:\n  - MOV: {en: M0, s: R1, d: R100}\n")
    r = subprocess.run(
        [PLCEMUD.encode(), b"-c", name, b"--export-tags", b"json"], capture_output=True, timeout=20
    )
    assert r.returncode == 0, r.stderr
    rows = json.loads(r.stdout.decode("utf-8"))
    r100 = next(row for row in rows if row["name"] == "R100")
    # Each byte that is not UTF-8 is U+FFFD (docs/configuration.md, "Tag export").
    assert "caf\ufffd\ufffd.yaml:3:" in r100["description"], r100


# --- the descriptor limit


def limited(soft, hard):
    def preexec():
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))

    return preexec


def test_a_limit_that_cannot_be_raised_is_not_said_to_be_raised_and_the_count_holds(start_plcemud):
    d = start_plcemud(BASE_CONFIG, preexec_fn=limited(64, 64))
    assert d.wait_log("listening on tcp"), d.log_text()
    log = d.log_text()
    assert "limit raised" not in log, log
    line = next(x for x in log.splitlines() if "descriptors but the limit is 64" in x)
    assert "cannot be raised (hard limit 64): about " in line, line
    clients = int(line.split("): about ")[1].split()[0])
    assert 0 < clients < 64, line
    # As many clients as the line says are served at once.
    socks = [socket.create_connection(("127.0.0.1", d.port), timeout=3) for _ in range(clients)]
    try:
        for i, s in enumerate(socks):
            assert raw_exchange(s, READ_R0, tid=i + 1)[0] == 3, i
    finally:
        for s in socks:
            s.close()


def test_a_limit_too_low_for_any_client_says_so(start_plcemud):
    d = start_plcemud(BASE_CONFIG, preexec_fn=limited(26, 26))
    assert d.wait_log("listening on tcp"), d.log_text()
    log = d.log_text()
    assert "limit raised" not in log, log
    assert "the limit is 26 and cannot be raised (hard limit 26): the daemon's own descriptors " \
           "leave none for clients" in log, log
    assert "clients beyond" not in log


def test_a_limit_raised_to_the_hard_limit_says_so(start_plcemud):
    d = start_plcemud(BASE_CONFIG, preexec_fn=limited(64, 100))
    assert d.wait_log("listening on tcp"), d.log_text()
    log = d.log_text()
    assert "descriptor limit raised from 64 to 100 (the hard limit) for modbus.tcp.max_clients 64" \
        in log, log
    assert "the limit is 100 and cannot be raised (hard limit 100): about " in log, log


def test_the_limit_lines_name_each_listeners_clients(start_plcemud):
    """The console's clients count beside Modbus's, and the lines say so (they once gave the sum
    as modbus.tcp.max_clients)."""
    hp = free_ports(1)[0]
    d = start_plcemud(BASE_CONFIG + f"http: {{bind: 127.0.0.1, port: {hp}, max_clients: 8}}\n",
                      preexec_fn=limited(64, 100))
    assert d.wait_log("listening on tcp"), d.log_text()
    log = d.log_text()
    # Each kind of listener once, in the order of their names, in both lines.
    assert "descriptor limit raised from 64 to 100 (the hard limit) for http.max_clients 8, " \
           "modbus.tcp.max_clients 64\n" in log, log
    assert "http.max_clients 8, modbus.tcp.max_clients 64 needs about 136 descriptors but the " \
           "limit is 100" in log, log


def test_a_start_of_hundreds_of_plcs_raises_the_limit_before_their_state_files(tmp_path):
    """Each PLC holds its state file, the file's lock and its listener: 400 PLCs need more
    than the usual soft limit of 1,024 before any listener is open, so the limit is raised
    first (the start used to fail with "Too many open files" at the 340th port or so)."""
    soft, hard = 1024, resource.getrlimit(resource.RLIMIT_NOFILE)[1]
    if hard != resource.RLIM_INFINITY and hard < 2000:
        pytest.skip(f"the hard descriptor limit here ({hard}) leaves nothing to raise")
    count = 400
    ports = free_ports(count)
    text = plcs_lines(ports, f"persistence: {{file: {tmp_path}/oven-{{i}}.state}}")
    d = spawn_plcs(tmp_path, text, ports, preexec_fn=limited(soft, hard))
    try:
        log = d.log_text()
        assert "descriptor limit raised from 1024 to " in log, log[-2000:]
        assert f"for modbus.tcp.max_clients of {count} listeners ({64 * count} clients), and " \
               f"{count - 1} more PLCs" in log, log[-2000:]
        assert "Too many open files" not in log
        # The last PLC answers from its own state file.
        with socket.create_connection(("127.0.0.1", ports[-1]), timeout=3) as s:
            assert raw_exchange(s, READ_R0)[0] == 3
        assert (tmp_path / f"oven-{count - 1}.state").stat().st_size > 0
    finally:
        d.stop()
