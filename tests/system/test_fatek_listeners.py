"""The FATEK protocol's listeners (docs/configuration.md, `fatek.*`; FBs manual, Appendix 2
FATEK Communication Protocol) through the real daemon: what a hostile or careless master sends,
the access rules the Modbus listener has (allow, max_clients, idle timeout, read_only), and the
configs that are refused."""

import csv
import io
import json
import re
import signal
import socket
import time
import urllib.request
from pathlib import Path

from conftest import free_port, free_ports, run_plcemud
from plcemu_testing.fatek import Fatek, frame

GIST = frame(1, 0x40)  # gist status of station 1
RUNNING = frame(1, 0x40, "0010000")  # its reply: RUN


def config(listeners, extra=""):
    return ("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\npersistence: {enabled: false}\n"
            f"fatek:\n{listeners}{extra}")


def tcp_config(port, extra_tcp=""):
    return config(f"  tcp: {{bind: 127.0.0.1, port: {port}{extra_tcp}}}\n")


def closed_by_server(fatek, timeout=3.0):
    """True when the daemon closes the client's TCP connection within `timeout`."""
    sock = fatek.line.sock
    sock.settimeout(timeout)
    try:
        return sock.recv(1) == b""
    except ConnectionResetError:
        return True
    except socket.timeout:
        return False


# --- what a master sends


def test_garbage_and_stray_etx_are_skipped_up_to_the_next_stx(start_plcemud):
    port = free_port()
    start_plcemud(tcp_config(port))
    with Fatek.tcp(port) as fatek:
        fatek.send(b"hello\x03\x03\xff\x00 0140C7\x03")  # no STX: nothing is a frame
        assert fatek.receive(timeout=0.5) is None
        # An STX starts a frame again, abandoning a partial one.
        assert fatek.exchange(b"\x020146\x02" + GIST[1:]) == RUNNING
        assert fatek.exchange(GIST) == RUNNING


def test_a_frame_of_600_bytes_without_etx_is_dropped(start_plcemud):
    # 500 data characters at most: a longer run without ETX is no frame and gets no reply,
    # and the connection answers the next frame.
    port = free_port()
    start_plcemud(tcp_config(port))
    with Fatek.tcp(port) as fatek:
        assert fatek.exchange(b"\x02014E" + b"A" * 600 + b"\x03", timeout=0.5) is None
        assert fatek.exchange(GIST) == RUNNING
        # 500 characters is still a frame: the loop-back echoes them.
        longest = frame(1, 0x4E, "B" * 500)
        assert fatek.exchange(longest) == longest


def test_pipelined_and_split_frames_are_answered_in_order(start_plcemud):
    port = free_port()
    start_plcemud(tcp_config(port))
    with Fatek.tcp(port) as fatek:
        fatek.send(GIST + frame(1, 0x4E, "X") + GIST)
        assert [fatek.receive(), fatek.receive(), fatek.receive()] == [
            RUNNING, frame(1, 0x4E, "X"), RUNNING]
        for byte in GIST:  # one byte per segment
            fatek.send(bytes([byte]))
            time.sleep(0.01)
        assert fatek.receive() == RUNNING


def test_a_half_open_client_holds_up_nobody(start_plcemud):
    port = free_port()
    start_plcemud(tcp_config(port))
    with Fatek.tcp(port) as slow, Fatek.tcp(port) as other:
        slow.send(GIST[:4])  # half a frame, then silence
        assert other.exchange(GIST) == RUNNING
        assert slow.receive(timeout=0.3) is None
        slow.send(GIST[4:])  # the rest: the frame is whole and answered
        assert slow.receive() == RUNNING


# --- a serial line


def test_serial_line_abandons_a_partial_frame_after_1_s(start_plcemud, pty):
    # On a serial line a frame stalled for 1 s is dropped: its rest then belongs to no frame.
    d = start_plcemud(config(f"  serial: {{device: {pty.slave}}}\n"))
    with Fatek.serial(pty.master) as line:
        deadline = time.monotonic() + 5  # the line opens at start
        while line.exchange(GIST, timeout=0.2) != RUNNING:
            assert time.monotonic() < deadline, d.log_text()
        line.send(GIST[:4])
        time.sleep(1.5)
        line.send(GIST[4:])
        assert line.receive(timeout=0.5) is None
        line.send(GIST[:4])
        time.sleep(0.3)  # a shorter pause keeps the frame
        line.send(GIST[4:])
        assert line.receive() == RUNNING


def test_a_serial_line_that_echoes_gets_one_answer_a_request(start_plcemud, pty):
    """A reply echoed back to the PLC reads as command 40 with data, answered with error 4,
    whose echo is answered again, for ever. With `echo: true` the echo is dropped."""
    from rtu_pty import echoing

    d = start_plcemud(config(f"  serial: {{device: {pty.slave}, echo: true}}\n"))
    with Fatek.serial(pty.master) as line:
        deadline = time.monotonic() + 5  # the line opens at start
        while line.exchange(GIST, timeout=0.2) != RUNNING:
            assert time.monotonic() < deadline, d.log_text()
    time.sleep(0.3)
    got = echoing(pty.master, GIST, seconds=1.0)
    assert got == RUNNING, got


def test_plcs_on_one_serial_line_answer_their_own_station(plcemud, pty):
    line = {"serial": {"device": pty.slave}}
    plcs = plcemud({"plcs": [
        {"name": "a", "profile": "fbs", "station": 1, "simulator": {"unit": 201},
         "fatek": line, "init": {"R0": 11}},
        {"name": "b", "profile": "fbs", "station": 2, "simulator": {"unit": 202},
         "fatek": line, "init": {"R0": 22}},
    ]})
    with Fatek.serial(pty.master) as master:
        deadline = time.monotonic() + 5
        while master.exchange(GIST, timeout=0.2) != RUNNING:
            assert time.monotonic() < deadline, plcs.log
        assert master.exchange(frame(1, 0x46, "01R00000")) == frame(1, 0x46, "0000B")
        assert master.exchange(frame(2, 0x46, "01R00000")) == frame(2, 0x46, "00016")
        assert master.exchange(frame(3, 0x46, "01R00000"), timeout=0.5) is None
        # Station 0 reaches both, and neither answers.
        assert master.exchange(frame(0, 0x47, "01R000010007"), timeout=0.5) is None
    assert plcs["a"].read("R1") == [7] and plcs["b"].read("R1") == [7]


# --- access rules


def test_allow_list_closes_other_peers_at_accept(start_plcemud):
    port = free_port()
    d = start_plcemud(tcp_config(port, ", allow: [127.0.0.2/32]"))
    with Fatek.tcp(port, source="127.0.0.2") as allowed:
        assert allowed.exchange(GIST) == RUNNING
        with Fatek.tcp(port, source="127.0.0.3") as refused:
            assert closed_by_server(refused)
        assert d.wait_log("127.0.0.3"), d.log_text()
        assert allowed.exchange(GIST) == RUNNING


def test_udp_allow_list_ignores_other_peers(start_plcemud):
    port = free_port()
    start_plcemud(config(f"  udp: {{bind: 127.0.0.1, port: {port}, allow: [127.0.0.2]}}\n"))
    with Fatek.udp(port, source="127.0.0.2") as allowed, \
            Fatek.udp(port, source="127.0.0.3") as refused:
        assert allowed.exchange(GIST) == RUNNING
        assert refused.exchange(GIST, timeout=0.5) is None


def test_answers_a_udp_listener_cannot_hold_are_counted_dropped(start_plcemud):
    # docs/communication-faults.md: 256 answers held at most; the rest dropped, and the
    # counters say so (they counted all 300 delayed, 256 of them answered).
    port, http = free_ports(2)
    start_plcemud(config(f"  udp: {{bind: 127.0.0.1, port: {port}}}\n",
                         f"faults: {{delay_ms: 1500}}\nhttp: {{port: {http}}}\n"))
    with Fatek.udp(port) as peer:
        for i in range(300):
            peer.send(GIST)
            if i % 25 == 24:
                time.sleep(0.03)  # read as they come: a socket's buffer holds fewer than 300
        answers = 0
        # Held 1.5 s from each request: the 300 are sent well within it, slow machine or not.
        while peer.receive(timeout=2.5) == RUNNING:
            answers += 1
    assert answers == 256
    figures = json.loads(urllib.request.urlopen(
        f"http://127.0.0.1:{http}/api/v1/plcs/0/comm-faults", timeout=5).read())["figures"]
    # 44 dropped, unless the kernel dropped some datagrams before the daemon read them.
    assert figures["delayed"] == 256 and 0 < figures["dropped"] <= 44, figures


def ignored_datagrams(start_plcemud):
    """A daemon whose UDP listener has ignored 40 datagrams from outside its allow list."""
    port = free_port()
    d = start_plcemud(config(f"  udp: {{bind: 127.0.0.1, port: {port}, allow: [127.0.0.2]}}\n"))
    with Fatek.udp(port, source="127.0.0.3") as refused:
        for _ in range(40):
            refused.send(GIST)
    assert d.wait_log("not in the allow list"), d.log_text()
    return d


def test_ignored_datagrams_are_summed_up_when_the_window_ends(start_plcemud):
    # A few are logged one by one, the rest summed up at the window's end (10 s) even when no
    # datagram follows: the summary must not wait for the next one.
    d = ignored_datagrams(start_plcemud)
    assert d.wait_log("35 more datagrams ignored (not in the allow list) in the last", 16), \
        d.log_text()
    assert d.log_text().count("ignored a datagram from 127.0.0.3") == 5, d.log_text()


def test_ignored_datagrams_are_summed_up_at_the_stop(start_plcemud):
    # Or when the listener closes (the stop, a reload that reopens it) before that.
    d = ignored_datagrams(start_plcemud)
    time.sleep(0.3)
    assert d.stop() == 0
    assert "35 more datagrams ignored (not in the allow list) in the last 0 s" in d.log_text(), \
        d.log_text()


def test_a_udp_port_in_use_names_the_listener_and_its_section(tmp_path):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", 0))
        port = taken.getsockname()[1]
        cfg = tmp_path / "c.yaml"
        cfg.write_text(config(f"  udp: {{bind: 127.0.0.1, port: {port}}}\n").replace(
            "modbus: {tcp: {bind: 127.0.0.1}}", f"modbus: {{tcp: {{bind: 127.0.0.1, port: {free_port()}}}}}"))
        r = run_plcemud("-c", cfg, timeout=20)
    assert r.returncode == 1, r
    assert f"cannot listen on fatek udp 127.0.0.1:{port} (fatek.udp)" in r.stderr, r.stderr


def test_a_reload_to_a_udp_port_in_use_is_refused_and_the_old_one_serves_on(start_plcemud):
    # docs/operations.md, "Reload": as for a TCP port in use. It was applied, the old socket
    # closed and the new one never opened: the PLC left without its UDP listener.
    old = free_port()
    d = start_plcemud(config(f"  udp: {{bind: 127.0.0.1, port: {old}}}\n"))
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", 0))
        port = taken.getsockname()[1]
        Path(d.config_path).write_text(
            Path(d.config_path).read_text().replace(f"port: {old}}}", f"port: {port}}}"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("configuration rejected"), d.log_text()
    assert f"cannot listen on fatek udp 127.0.0.1:{port} (fatek.udp): Address already in use" \
        in d.log_text(), d.log_text()
    with Fatek.udp(old) as client:
        assert client.exchange(GIST) == RUNNING


def test_a_reload_to_a_udp_address_not_here_is_refused_and_the_old_one_serves_on(start_plcemud):
    # The same port on an address no interface has: the probe was skipped for a port the
    # daemon's own listener holds, and the reload left the PLC without its UDP listener.
    port = free_port()
    d = start_plcemud(config(f"  udp: {{bind: 127.0.0.1, port: {port}}}\n"))
    Path(d.config_path).write_text(
        Path(d.config_path).read_text().replace("udp: {bind: 127.0.0.1", "udp: {bind: 192.0.2.1"))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("configuration rejected"), d.log_text()
    assert f"cannot listen on fatek udp 192.0.2.1:{port} (fatek.udp)" in d.log_text()
    with Fatek.udp(port) as client:
        assert client.exchange(GIST) == RUNNING


def test_max_clients_refuses_extra_connections_and_keeps_the_others(start_plcemud):
    port = free_port()
    d = start_plcemud(tcp_config(port, ", max_clients: 2"))
    with Fatek.tcp(port) as a, Fatek.tcp(port) as b:
        assert a.exchange(GIST) == RUNNING and b.exchange(GIST) == RUNNING
        with Fatek.tcp(port) as extra:
            peer = "127.0.0.1:%d" % extra.line.sock.getsockname()[1]
            assert closed_by_server(extra)
        assert a.exchange(GIST) == RUNNING and b.exchange(GIST) == RUNNING
    # The lines name the listener's protocol, as its `listening on` line does (the Modbus
    # listener's are "tcp: ...").
    assert d.wait_log(f"fatek tcp: {peer} refused: 2 clients already connected "
                      "(fatek.tcp.max_clients)"), d.log_text()
    assert re.search(r"fatek tcp: 127\.0\.0\.1:\d+ connected", d.log_text()), d.log_text()


def test_idle_connections_are_closed_busy_ones_kept(start_plcemud):
    port = free_port()
    start_plcemud(tcp_config(port, ", idle_timeout_s: 1"))
    with Fatek.tcp(port) as idle, Fatek.tcp(port) as busy:
        assert idle.exchange(GIST) == RUNNING
        start, closed_at = time.monotonic(), None
        while time.monotonic() - start < 3.5:
            assert busy.exchange(GIST) == RUNNING  # a request every 0.2 s keeps it open
            if closed_at is None and closed_by_server(idle, timeout=0.2):
                closed_at = time.monotonic() - start
            elif closed_at is not None:
                time.sleep(0.2)
        assert closed_at is not None, "the idle connection was never closed"
        assert closed_at >= 0.9  # not before its timeout


def test_noise_is_no_request_a_client_sending_only_noise_is_idle(start_plcemud):
    """Bytes that are no frame are dropped unanswered and do not keep a connection alive: a
    client trickling noise is closed as an idle one is, and cannot hold a listener's slots."""
    port = free_port()
    start_plcemud(tcp_config(port, ", idle_timeout_s: 1"))
    with Fatek.tcp(port) as noisy:
        sock = noisy.line.sock
        start, closed_at = time.monotonic(), None
        while closed_at is None and time.monotonic() - start < 3.5:
            try:
                sock.sendall(b"A")  # a byte every 0.2 s, never an STX
            except OSError:
                closed_at = time.monotonic() - start
                break
            if closed_by_server(noisy, timeout=0.2):
                closed_at = time.monotonic() - start
        assert closed_at is not None, "a connection sending only noise was kept open"
        assert closed_at >= 0.9  # not before its timeout


def test_read_only_listener_refuses_writes_with_error_3(start_plcemud):
    port = free_port()
    d = start_plcemud(tcp_config(port, ", read_only: true") + "init: {R100: 7, M10: 0}\n")
    with Fatek.tcp(port) as fatek:
        assert fatek.exchange(frame(1, 0x47, "01R001000001")) == frame(1, 0x47, "3")
        assert fatek.exchange(frame(1, 0x45, "01M00101")) == frame(1, 0x45, "3")
        assert fatek.exchange(frame(1, 0x49, "01R001000002")) == frame(1, 0x49, "3")
        assert fatek.exchange(frame(1, 0x42, "3M0010")) == frame(1, 0x42, "3")  # set
        assert fatek.exchange(frame(1, 0x41, "0")) == frame(1, 0x41, "3")  # STOP
        assert fatek.status()["running"] is True
        assert fatek.exchange(frame(1, 0x46, "01R00100")) == frame(1, 0x46, "00007")
    modbus = d.client()  # nothing was written; Modbus still may
    assert modbus.read_holding_registers(100, 1, slave=1).registers == [7]
    assert modbus.read_coils(2010, 1, slave=1).bits[0] is False
    assert not modbus.write_register(100, 9, slave=1).isError()


# --- configs that are refused


def test_vb_refuses_the_fatek_section_at_its_line(tmp_path):
    path = tmp_path / "vb.yaml"
    path.write_text("profile: vb\nfatek:\n  tcp: {bind: 127.0.0.1, port: 45500}\n")
    r = run_plcemud("--check-config", "-c", path)
    assert r.returncode == 2, r
    assert re.search(r"vb\.yaml:2:\d+: .*fatek", r.stderr), r.stderr


def test_fatek_on_the_modbus_port_is_a_clear_error(tmp_path):
    port = free_port()
    path = tmp_path / "clash.yaml"
    path.write_text(f"profile: fbs\nmodbus: {{tcp: {{bind: 127.0.0.1, port: {port}}}}}\n"
                    f"fatek:\n  tcp: {{bind: 127.0.0.1, port: {port}}}\n"
                    "persistence: {enabled: false}\n")
    r = run_plcemud("-c", path, timeout=10)
    # Refused at load, at the FATEK listener's line, naming both (one port, one protocol).
    assert r.returncode == 2, r
    assert re.search(rf"clash\.yaml:4:\d+: .*fatek\.tcp.*{port}.*modbus\.tcp", r.stderr), r.stderr


# --- the listings


def test_print_map_names_each_range_as_fatek_frames_do(tmp_path, start_plcemud):
    path = tmp_path / "fbs.yaml"
    path.write_text("profile: fbs\ninit: {R5000: 4660, C200: 0}\n")
    r = run_plcemud("--print-map", "--format", "csv", "-c", path)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    by_wire = {row["wire"]: row["fatek_protocol"] for row in rows}
    assert by_wire["0-4167"] == "R00000-R04167"
    assert by_wire["5000-5998"] == "R05000-R05998"
    assert by_wire["9700-9811"] == "DRC0200-DRC0255"
    assert by_wire["1000-1255"] == "X0000-X0255"
    # A name the listing gives reaches the device its Modbus address does.
    port = free_port()
    d = start_plcemud(tcp_config(port) + "init: {R5000: 4660}\n")
    with Fatek.tcp(port) as fatek:
        assert fatek.exchange(frame(1, 0x46, "01R05000")) == frame(1, 0x46, "01234")
    assert d.client().read_holding_registers(5000, 1, slave=1).registers == [0x1234]
    # A family that does not speak the protocol has no such column.
    vb = tmp_path / "vb.yaml"
    vb.write_text("profile: vb\n")
    r = run_plcemud("--print-map", "--format", "csv", "-c", vb)
    assert r.returncode == 0 and "fatek_protocol" not in r.stdout.splitlines()[0]


# --- RUN/STOP and disabled discretes are a master's, not the config's


def test_stop_and_disabled_discretes_survive_a_reload(start_plcemud):
    # A reload builds the PLC anew from its config; what a master did to it (STOP, a disabled
    # output set by hand) stays, as on a PLC whose program is downloaded in STOP.
    port = free_port()
    text = tcp_config(port) + "program:\n  - MOV: {en: M1926, s: K7, d: R10}\n"
    d = start_plcemud(text)
    with Fatek.tcp(port) as fatek:
        assert fatek.exchange(frame(1, 0x41, "0")) == frame(1, 0x41, "0")  # STOP
        assert fatek.exchange(frame(1, 0x42, "1Y0005")) == frame(1, 0x42, "0")  # disable Y5
        assert fatek.exchange(frame(1, 0x42, "3Y0005")) == frame(1, 0x42, "0")  # set it
        assert fatek.exchange(frame(1, 0x47, "01R000100000")) == frame(1, 0x47, "0")
    Path(d.config_path).write_text(text + "# reloaded\n")
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    with Fatek.tcp(port) as fatek:
        assert fatek.exchange(GIST) == frame(1, 0x40, "0000000")  # still STOP
        assert fatek.exchange(frame(1, 0x43, "01Y0005")) == frame(1, 0x43, "01")  # disabled
        assert fatek.exchange(frame(1, 0x44, "01Y0005")) == frame(1, 0x44, "01")  # kept ON
        time.sleep(0.3)  # scans go on; the program does not run in STOP
        assert fatek.exchange(frame(1, 0x46, "01R00010")) == frame(1, 0x46, "00000")
        assert fatek.exchange(frame(1, 0x41, "1")) == frame(1, 0x41, "0")  # RUN
        time.sleep(0.3)
        assert fatek.exchange(frame(1, 0x46, "01R00010")) == frame(1, 0x46, "00007")
        assert fatek.exchange(GIST) == RUNNING


def test_the_program_reads_a_disabled_relay_as_the_master_set_it(start_plcemud):
    # docs/profile-fbs.md, "FATEK protocol": the program does not change a disabled discrete, so
    # the rung after an OUT to it sees the master's value (M6 follows the forced M5; X0 is OFF).
    port = free_port()
    d = start_plcemud(tcp_config(port) + "program: {il: ['ORG X0', 'OUT M5', 'ORG M5',"
                                         " 'OUT M6']}\n")
    with Fatek.tcp(port) as fatek:
        assert fatek.exchange(frame(1, 0x42, "1M0005")) == frame(1, 0x42, "0")  # disable M5
        assert fatek.exchange(frame(1, 0x42, "3M0005")) == frame(1, 0x42, "0")  # set it
        time.sleep(0.2)  # scans
        assert fatek.exchange(frame(1, 0x44, "02M0005")) == frame(1, 0x44, "011"), d.log_text()


# --- a reload keeps what it does not change


def udp_inode(port):
    """The inode of the UDP socket bound to `port` (/proc/net/udp), or None."""
    for line in Path("/proc/net/udp").read_text().splitlines()[1:]:
        fields = line.split()
        if int(fields[1].split(":")[1], 16) == port:
            return int(fields[9])
    return None


def test_a_reload_keeps_an_unchanged_serial_line_and_udp_listener_open(start_plcs, pty,
                                                                      tmp_path):
    # docs/operations.md, "Reload": a PLC's UDP listener and serial line go on through a reload
    # that leaves their settings alone, as its TCP listener does: a frame half received on the
    # line before the SIGHUP is answered when its rest comes after, the datagram socket is the
    # same one. A changed line setting opens the line again.
    tcp_a, tcp_b = free_ports(2)
    udp = free_port()
    a = (f"  - {{name: a, profile: fbs, persistence: {{enabled: false}},"
         f" modbus: {{tcp: {{bind: 127.0.0.1, port: {tcp_a}}}}},"
         f" fatek: {{serial: {{device: {pty.slave}, baud: BAUD}},"
         f" udp: {{bind: 127.0.0.1, port: {udp}}}}}}}\n")
    b = (f"  - {{name: b, profile: fbs, persistence: {{enabled: false}},"
         f" modbus: {{tcp: {{bind: 127.0.0.1, port: {tcp_b}}}}}, init: {{R100: SETPOINT}}}}\n")
    text = "plcs:\n" + a + b
    d = start_plcs(text.replace("BAUD", "9600").replace("SETPOINT", "1"), [tcp_a, tcp_b])
    with Fatek.serial(pty.master) as line, Fatek.udp(udp) as datagrams:
        deadline = time.monotonic() + 5  # the line opens at start
        while line.exchange(GIST, timeout=0.2) != RUNNING:
            assert time.monotonic() < deadline, d.log_text()
        assert datagrams.exchange(GIST) == RUNNING
        inode = udp_inode(udp)
        assert inode is not None

        line.send(GIST[:4])  # half a frame; the line abandons it after 1 s of silence
        time.sleep(0.1)
        Path(d.config_path).write_text(text.replace("BAUD", "9600").replace("SETPOINT", "2"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: applied to 1 of 2 PLCs"), d.log_text()
        line.send(GIST[4:])
        assert line.receive() == RUNNING, d.log_text()
        assert udp_inode(udp) == inode
        assert datagrams.exchange(GIST) == RUNNING
        log = d.log_text()
        assert log.count("listening on fatek serial") == 1, log
        assert log.count("listening on fatek udp") == 1, log

        # A new speed is the line opened again with it; the UDP listener stays.
        Path(d.config_path).write_text(text.replace("BAUD", "19200").replace("SETPOINT", "2"))
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: applied to 1 of 2 PLCs", timeout=5), d.log_text()
        deadline = time.monotonic() + 5
        while d.log_text().count("listening on fatek serial") < 2:
            assert time.monotonic() < deadline, d.log_text()
            time.sleep(0.05)
        assert "19200" in d.log_text().split("listening on fatek serial")[-1].splitlines()[0]
        assert udp_inode(udp) == inode

        # A new path to the same device (a by-id link for the tty) is the line opened by it:
        # kept, it went on by the old path, and a lost line came back on the wrong device.
        link = tmp_path / "by-id-link"
        link.symlink_to(pty.slave)
        Path(d.config_path).write_text(text.replace("BAUD", "19200").replace("SETPOINT", "2")
                                       .replace(f"device: {pty.slave}", f"device: {link}"))
        d.proc.send_signal(signal.SIGHUP)
        deadline = time.monotonic() + 5
        while d.log_text().count("listening on fatek serial") < 3:
            assert time.monotonic() < deadline, d.log_text()
            time.sleep(0.05)
        assert str(link) in d.log_text().split("listening on fatek serial")[-1].splitlines()[0]


def test_a_line_whose_device_is_away_at_a_reload_comes_back_by_itself(start_plcs, tmp_path):
    # The device is a link (socat's, as udev's /dev/serial/by-id ones are); it goes away, a
    # reload comes while it is away (its name now resolves elsewhere, so the line is opened
    # anew and cannot be), and the device comes back: the line is tried with back-off and
    # answers without another reload (it stayed dead until one).
    from rtu_pty import PtyPair

    pair = PtyPair(tmp_path)
    tcp = free_port()
    text = ("plcs:\n"
            f"  - {{name: a, profile: fbs, persistence: {{enabled: false}},"
            f" modbus: {{tcp: {{bind: 127.0.0.1, port: {tcp}}}}},"
            f" fatek: {{serial: {{device: {pair.slave}}}}}}}\n")
    d = start_plcs(text, [tcp])
    try:
        with Fatek.serial(pair.master) as line:
            deadline = time.monotonic() + 5
            while line.exchange(GIST, timeout=0.2) != RUNNING:
                assert time.monotonic() < deadline, d.log_text()
        pair.stop()
        assert d.wait_log("lost ("), d.log_text()
        d.proc.send_signal(signal.SIGHUP)
        assert d.wait_log("reload: applied to 0 of 1 PLCs"), d.log_text()
        pair = PtyPair(tmp_path)
        with Fatek.serial(pair.master) as line:
            deadline = time.monotonic() + 10
            while line.exchange(GIST, timeout=0.2) != RUNNING:
                assert time.monotonic() < deadline, d.log_text()
    finally:
        pair.stop()
