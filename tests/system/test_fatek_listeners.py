"""The FATEK protocol's listeners (docs/configuration.md, `fatek.*`; FBs manual, Appendix 2
FATEK Communication Protocol) through the real daemon: what a hostile or careless master sends,
the access rules the Modbus listener has (allow, max_clients, idle timeout, read_only), and the
configs that are refused."""

import re
import socket
import time

from conftest import free_port, run_plcemud
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


def test_max_clients_refuses_extra_connections_and_keeps_the_others(start_plcemud):
    port = free_port()
    start_plcemud(tcp_config(port, ", max_clients: 2"))
    with Fatek.tcp(port) as a, Fatek.tcp(port) as b:
        assert a.exchange(GIST) == RUNNING and b.exchange(GIST) == RUNNING
        with Fatek.tcp(port) as extra:
            assert closed_by_server(extra)
        assert a.exchange(GIST) == RUNNING and b.exchange(GIST) == RUNNING


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
    assert r.returncode != 0, r
    assert str(port) in r.stderr and "fatek" in r.stderr, r.stderr
