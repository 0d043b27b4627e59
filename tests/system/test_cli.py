"""The command line (issue point 8), configuration errors (docs/configuration.md, Configuration)
and logging (point 9): --check-config, --print-map [--format csv], --port, --time-scale, --version,
--help, signals, exit statuses, the start-up summary and connection log lines."""

import csv
import io
import http.client
import re
import signal
import socket
import subprocess
import time

import pytest

from conftest import BASE_CONFIG, PLCEMUD, REPO, free_port, port_open, run_plcemud

# FBs manual 13-50/51: the table as (5-digit range, 6-digit range, wire range, function codes).
MANUAL = [
    ("00001-00256", "000001-000256", "0-255", "01 05 15"),
    ("01001-01256", "001001-001256", "1000-1255", "01"),
    ("02001-04002", "002001-004002", "2000-4001", "01 05 15"),
    ("06001-07000", "006001-007000", "6000-6999", "01 05 15"),
    ("09001-09256", "009001-009256", "9000-9255", "01 05 15"),
    ("09501-09756", "009501-009756", "9500-9755", "01 05 15"),
    ("40001-44168", "400001-404168", "0-4167", "03 06 16"),
    ("45001-45999", "405001-405999", "5000-5998", "03 06 16"),
    ("46001-48999", "406001-408999", "6000-8998", "03 06 16"),
    ("49001-49256", "409001-409256", "9000-9255", "03 06 16"),
    ("49501-49700", "409501-409700", "9500-9699", "03 06 16"),
    ("49701-49812", "409701-409812", "9700-9811", "03 06 16"),
]
FATEK = ["Y0-Y255", "X0-X255", "M0-M2001", "S0-S999", "T0-T255", "C0-C255", "R0-R4167",
         "R5000-R5998", "D0-D2998", "T0-T255", "C0-C199", "C200-C255"]


def write(tmp_path, text, name="c.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p


# --check-config -----------------------------------------------------------------------------


def test_check_config_valid_exits_0(tmp_path):
    p = write(tmp_path, "{profile: fbs}\n")
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 0, r.stderr
    assert "ok" in r.stdout


@pytest.mark.parametrize(
    "text,line,col,needle",
    [
        ("profile: fbs\nstation: 300\n", 2, 10, "station"),
        ("profile: fbs\nmodbus:\n  tcp:\n    prot: 1\n", 4, 5, "unknown key 'prot'"),
        ("profile: fbs\nscan_ms: fast\n", 2, 10, "expected an integer"),
        ("profile: fbs\nprogram:\n  - MOV: {s: R1, d: Q7}\n", 3, 21, "MOV.d"),
        ("profile: fbs\ninit:\n  R8071: [1, 2]\n", 3, 3, "outside"),
        # A bit device takes 0 or 1 (2 and -1 were taken as ON without a word).
        ("profile: fbs\ninit:\n  M0: [1, 2, 0]\n", 3, 11, "init.M0: 2 is out of range 0..1"),
        ("profile: fbs\ninit:\n  Y5: -1\n", 3, 7, "init.Y5: -1 is out of range 0..1"),
        ("model: FBs-24MC\n", 1, 1, "'profile' is required"),
    ],
)
def test_check_config_error_names_file_line_col_and_exits_2(tmp_path, text, line, col, needle):
    p = write(tmp_path, text)
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2
    assert f"{p}:{line}:{col}: " in r.stderr, r.stderr
    assert needle in r.stderr
    assert r.stdout == ""


def test_check_config_missing_file_exits_2(tmp_path):
    r = run_plcemud("-c", tmp_path / "nope.yaml", "--check-config")
    assert r.returncode == 2
    assert "nope.yaml" in r.stderr and "cannot open" in r.stderr


def test_example_yaml_passes_check_config():
    r = run_plcemud("-c", REPO / "config" / "example.yaml", "--check-config")
    assert r.returncode == 0, r.stderr


def test_default_yaml_passes_check_config():
    """config/default.yaml runs the manual's FUN86 example (needs TPCTL)."""
    r = run_plcemud("-c", REPO / "config" / "default.yaml", "--check-config")
    assert r.returncode == 0, r.stderr


# --print-map --------------------------------------------------------------------------------


def test_print_map_csv_has_one_row_per_range_of_the_manual():
    r = run_plcemud("--print-map", "--format", "csv")
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    assert set(rows[0]) >= {"table", "modbus_5digit", "modbus_6digit", "wire", "fatek",
                            "function_codes", "access"}
    plc_rows = [row for row in rows if "unit" not in row["table"]]  # simulator unit rows apart
    assert len(plc_rows) == len(MANUAL)
    for row, (five, six, wire, codes), fatek in zip(plc_rows, MANUAL, FATEK):
        assert row["modbus_5digit"] == five
        assert row["modbus_6digit"] == six
        assert row["wire"] == wire
        assert row["fatek"].startswith(fatek), row
        assert row["function_codes"].startswith(codes), row
    assert plc_rows[1]["access"] == "read-only"  # X
    assert plc_rows[0]["access"] == "read/write"  # Y
    assert "R3840-R3903" in plc_rows[6]["access"] and "R4136-R4138" in plc_rows[6]["access"]
    assert "M1920-M1927" in plc_rows[2]["access"]


def test_print_map_text_matches_the_manual(tmp_path):
    p = write(tmp_path, "profile: fbs\nmodel: FBs-32MC\nstation: 3\n")
    r = run_plcemud("-c", p, "--print-map")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert "FBs-32MC" in r.stdout and "station 3" in r.stdout
    for (five, six, wire, codes), fatek in zip(MANUAL, FATEK):
        matching = [ln for ln in lines if re.search(rf"\s{five}\s+{six}\s+{wire}\s", ln)]
        assert len(matching) == 1, f"{five}: {matching}"
        assert fatek in matching[0] and codes in matching[0]
    # The image-held maps and the exception rule are told too.
    assert "R3968" in r.stdout and "R3972" in r.stdout and "R3975" in r.stdout
    assert "exception 02" in r.stdout and "exception 01" in r.stdout


def test_print_map_with_a_bad_config_exits_2(tmp_path):
    p = write(tmp_path, "profile: fbs\nstation: x\n")
    r = run_plcemud("-c", p, "--print-map")
    assert r.returncode == 2
    assert f"{p}:2:10: " in r.stderr


# --version, --help, bad arguments -----------------------------------------------------------


def test_version():
    r = run_plcemud("--version")
    assert r.returncode == 0
    assert re.fullmatch(r"plcemud \d+\.\d+\.\d+\S*\n", r.stdout), r.stdout


def test_help_lists_every_option():
    r = run_plcemud("--help")
    assert r.returncode == 0
    for opt in ("-c", "--check-config", "--print-map", "--format", "--port", "--time-scale",
                "--version", "--help"):
        assert opt in r.stdout
    assert run_plcemud("-h").stdout == r.stdout


@pytest.mark.parametrize(
    "args",
    [["--bogus"], ["--port"], ["--port", "x"], ["--port", "70000"], ["--time-scale", "0"],
     ["--format", "xml"], []],
)
def test_bad_arguments_exit_2(tmp_path, args):
    p = write(tmp_path, BASE_CONFIG)
    extra = ["-c", str(p)] if args else []
    r = run_plcemud(*args, *extra) if args else run_plcemud()
    assert r.returncode == 2, r
    assert "Usage" in r.stderr


# Running: overrides, log, signals -----------------------------------------------------------


def test_bad_config_exits_2_without_opening_the_port(tmp_path):
    port = free_port()
    p = write(tmp_path, f"profile: fbs\nmodbus: {{tcp: {{bind: 127.0.0.1, port: {port}}}}}\n"
                        "program:\n  - MOV: {s: R1, d: R99999}\n")
    proc = subprocess.Popen([PLCEMUD, "-c", str(p)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    seen_open = False
    deadline = time.monotonic() + 10
    while proc.poll() is None and time.monotonic() < deadline:
        seen_open = seen_open or port_open(port)
        time.sleep(0.01)
    out, err = proc.communicate(timeout=10)
    assert proc.returncode == 2
    assert not seen_open
    assert f"{p}:4:21: " in err, err
    assert not (tmp_path / "c.state").exists(), "a state file was created for a bad config"


def test_port_override(start_plcemud):
    config_port = free_port()
    d = start_plcemud(
        f"profile: fbs\nmodbus: {{tcp: {{bind: 127.0.0.1, port: {config_port}}}}}\n"
    )
    assert d.port != config_port
    assert port_open(d.port)
    assert not port_open(config_port)
    assert f"listening on tcp 127.0.0.1:{d.port}" in d.log_text()


def test_http_port_override_turns_a_disabled_console_on_and_takes_0(start_plcemud):
    # docs/console.md: --http-port turns the console on where the config has none or turns it
    # off; 0 is any free port, said in the log, as `http.port: 0` (it was refused).
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n"
                      "http: {enabled: false, port: 1}\n", "--http-port", "0")
    assert d.wait_log("listening on http 127.0.0.1:"), d.log_text()
    port = int(re.search(r"listening on http 127\.0\.0\.1:(\d+)", d.log_text()).group(1))
    assert port not in (0, 1) and port_open(port)


@pytest.mark.parametrize("check", [[], ["--check-config"]])
def test_overrides_are_checked_as_if_the_file_said_them(tmp_path, check):
    # The command line's ports are applied before the loader checks the listeners: a console
    # --http-port makes shared must agree (b's token and read_only were dropped, a's console
    # served both), and a port taken twice by one PLC is refused (FATEK went unserved).
    plcs = write(tmp_path, "plcs:\n"
                 f"  - {{name: a, profile: fbs, modbus: {{tcp: {{port: {free_port()}}}}},"
                 f" http: {{port: {free_port()}}}}}\n"
                 f"  - {{name: b, profile: fbs, station: 2, modbus: {{tcp: {{port: {free_port()}}}}},"
                 f" http: {{port: {free_port()}, token: s3cretTOKEN, read_only: true}}}}\n")
    r = run_plcemud("-c", plcs, "--http-port", free_port(), *check, timeout=20)
    assert r.returncode == 2, r
    assert "plcs[1] (b): http.read_only: differs from plcs[0] (a)'s" in r.stderr, r.stderr
    r = run_plcemud("-c", plcs, "--http-port", "0", *check, timeout=20)
    assert r.returncode == 2 and "--http-port 0: with plcs:" in r.stderr, r
    fatek = free_port()
    one = tmp_path / "one.yaml"
    one.write_text(f"profile: fbs\npersistence: {{enabled: false}}\n"
                   f"modbus: {{tcp: {{bind: 127.0.0.1, port: {free_port()}}}}}\n"
                   f"fatek: {{tcp: {{bind: 127.0.0.1, port: {fatek}}}}}\n")
    r = run_plcemud("-c", one, "--port", fatek, *check, timeout=20)
    assert r.returncode == 2, r
    assert f"fatek.tcp.port: {fatek} is also this PLC's modbus.tcp port (--port)" in r.stderr, \
        r.stderr
    # A clash an override makes says so: the error stands at the file's key, which holds another
    # number.
    r = run_plcemud("-c", one, "--http-port", fatek, *check, timeout=20)
    assert r.returncode == 2, r
    assert f"http.port (--http-port): {fatek} is also this PLC's fatek.tcp port" in r.stderr, \
        r.stderr


def test_http_port_turns_on_the_console_the_file_turned_off_with_its_settings(start_plcemud):
    # Never a console more open than the one written: its read_only and token hold.
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n"
                      "http: {enabled: false, token: s3cretTOKEN, read_only: true}\n",
                      "--http-port", "0")
    assert d.wait_log("listening on http 127.0.0.1:"), d.log_text()
    port = int(re.search(r"listening on http 127\.0\.0\.1:(\d+)", d.log_text()).group(1))
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
    conn.request("PUT", "/api/v1/plcs/0/devices/R100", body=b'{"values": [42]}',
                 headers={"Content-Type": "application/json"})
    reply = conn.getresponse()
    assert reply.status in (401, 403), (reply.status, reply.read())
    conn.close()


def sample_coil(client, addr, seconds):
    values = set()
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and len(values) < 2:
        values.add(client.read_coils(addr, 1, slave=1).bits[0])
        time.sleep(0.005)
    return values


def test_time_scale_override_speeds_up_the_simulated_clock(start_plcemud):
    """time_scale (docs/configuration.md, Configuration): the config says 0.001 (one scan every
    100 real seconds); --time-scale 600 makes the 60 s clock M1923 toggle every 50 real ms."""
    cfg = BASE_CONFIG + "scan_ms: 100\ntime_scale: 0.001\n"
    slow = start_plcemud(cfg)
    fast = start_plcemud(cfg, "--time-scale", "600")
    assert "time scale 600" in fast.log_text()
    assert "time scale 0.001" in slow.log_text()
    assert sample_coil(fast.client(), 3923, 10.0) == {True, False}
    # At 0.001 only the first scan has run: M1921 (0.1 s clock) and M1923 stay as they were.
    assert len(sample_coil(slow.client(), 3921, 0.5)) == 1
    assert len(sample_coil(slow.client(), 3923, 0.5)) == 1


def test_start_up_summary_and_connection_log(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "model: FBs-60MN\nstation: 9\nscan_ms: 20\n")
    # The summary is logged just after the listener opens: a client may get in first.
    assert d.wait_log("time scale"), d.log_text()
    log = d.log_text()
    assert re.search(r"plcemud \S+: profile fbs, model FBs-60MN, station 9, scan 20 ms, "
                     r"time scale 1\b", log), log
    assert f"listening on tcp 127.0.0.1:{d.port}" in log
    c = d.client()
    local = c.socket.getsockname()
    peer = f"127.0.0.1:{local[1]}"
    assert d.wait_log(f"tcp: {peer} connected"), d.log_text()
    c.close()
    assert d.wait_log(f"tcp: {peer} disconnected"), d.log_text()


def test_refused_requests_logged_at_debug(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "log: {level: debug}\n")
    c = d.client()
    assert c.read_holding_registers(4500, 1, slave=1).isError()
    assert d.wait_log("exception 02h"), d.log_text()
    quiet = start_plcemud(BASE_CONFIG)
    qc = quiet.client()
    assert qc.read_holding_registers(4500, 1, slave=1).isError()
    time.sleep(0.2)
    assert "exception 02h" not in quiet.log_text()


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signals_stop_cleanly_with_exit_0(start_plcemud, sig):
    d = start_plcemud(BASE_CONFIG)
    c = d.client()
    assert not c.read_holding_registers(0, 1, slave=1).isError()
    assert d.stop(sig) == 0, d.log_text()
    log = d.log_text()
    assert ("SIGTERM" if sig == signal.SIGTERM else "SIGINT") in log
    assert "stopped after" in log
    assert not port_open(d.port)


@pytest.mark.parametrize("section,kind", [
    ("modbus", "tcp"), ("fatek", "fatek tcp"), ("http", "http")])
def test_listen_failure_exits_nonzero_with_message(tmp_path, section, kind):
    """A port already in use: a clear error naming the listener and its section, not a hang."""
    with socket.socket() as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.bind(("127.0.0.1", 0))
        s.listen()
        busy = s.getsockname()[1]
        listeners = {
            "modbus": f"modbus: {{tcp: {{bind: 127.0.0.1, port: {busy}}}}}\n",
            "fatek": f"modbus: {{tcp: {{bind: 127.0.0.1, port: {free_port()}}}}}\n"
                     f"fatek: {{tcp: {{bind: 127.0.0.1, port: {busy}}}}}\n",
            "http": f"modbus: {{tcp: {{bind: 127.0.0.1, port: {free_port()}}}}}\n"
                    f"http: {{bind: 127.0.0.1, port: {busy}}}\n",
        }
        p = write(tmp_path, "profile: fbs\npersistence: {enabled: false}\n" + listeners[section])
        r = run_plcemud("-c", p)
    assert r.returncode == 1, r
    where = section + ".tcp" if section != "http" else "http"
    assert f"cannot listen on {kind} 127.0.0.1:{busy} ({where})" in r.stderr, r.stderr
    assert "in use" in r.stderr, r.stderr


# duplicates and long values in --check-config ------------------------------------------------


@pytest.mark.parametrize(
    "text,line,col,needle",
    [
        ("profile: fbs\ninit:\n  D7: 1\n  D7: 2\n", 4, 3,
         "init: duplicate device 'D7' (first at line 3)"),
        ("profile: fbs\ninit:\n  D7: 1\n  D07: 2\n", 4, 3,
         "init: duplicate device 'D07' (first at line 3 as 'D7')"),
        ("profile: fbs\nplant:\n  channels:\n    1: {k: 100}\n    01: {k: 200}\n", 5, 5,
         "plant.channels: duplicate channel '01' (first at line 4 as '1')"),
    ],
    ids=["init-same-key", "init-alias", "plant-channel-alias"],
)
def test_check_config_refuses_a_device_or_channel_named_twice(tmp_path, text, line, col, needle):
    """docs/configuration.md, "Configuration": a key given twice is an error, however init and plant.channels
    spell it."""
    p = write(tmp_path, text)
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2, r.stderr
    assert f"{p}:{line}:{col}: {needle}" in r.stderr, r.stderr
    assert r.stdout == ""


def test_check_config_never_echoes_a_whole_huge_or_multiline_value(tmp_path):
    p = write(tmp_path, "profile: fbs\nstation: " + "x" * (1 << 20) + "\n")
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2
    assert len(r.stderr.encode()) < 1000, r.stderr[:2000]
    assert f"{p}:2:10: station: expected an integer, got '{'x' * 40}…'" in r.stderr, r.stderr
    p = write(tmp_path, 'profile: fbs\nmodel: "FBs\\nplcemud: fake line"\n')
    r = run_plcemud("-c", p, "--check-config")
    assert r.returncode == 2
    assert f"{p}:2:8: model: expected an FBs model such as FBs-24MC, got 'FBs\\nplcemud" in r.stderr
    assert "\nplcemud: fake line" not in r.stderr, r.stderr
