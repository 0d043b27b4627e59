"""Retentive memory in the state file (docs/operations.md, "Retentive memory"; R4057 power-up
counter, docs/profile-fbs.md, "Scan cycle and special registers").

Wire addresses (FBs manual 13-50/51): Rn is holding register n (R0-R4167, R5000-R5998), Dn is
6000+n, Mn is coil 2000+n.
"""

import os
import random
import signal
import struct
import subprocess
import threading
import time
from pathlib import Path

import pytest
from pymodbus.client import ModbusTcpClient

from conftest import PLCEMUD, free_port, free_ports, port_open, run_plcemud, spawn_plcs

D0 = 6000
M0 = 2000
R4057 = 4057  # power-up counter


def config(state: Path, extra: str = "") -> str:
    return (
        "profile: fbs\n"
        "modbus: {tcp: {bind: 127.0.0.1}}\n"
        f"persistence: {{file: '{state}', sync_ms: 200}}\n" + extra
    )


def read(client, address, count=1):
    rr = client.read_holding_registers(address, count, slave=1)
    assert not rr.isError(), rr
    return rr.registers


def restart(start_plcemud, d, cfg):
    assert d.stop() == 0, d.log_text()
    return start_plcemud(cfg)


def header(state: Path) -> dict:
    """The fields of the state file header (docs/operations.md, "Retentive memory")."""
    raw = state.read_bytes()[:144]
    fields = struct.unpack("<8sIIII16IQQIIQQQQ", raw)
    return {
        "magic": fields[0],
        "version": fields[1],
        "area_size": list(fields[5:21]),
        "state": fields[23],
        "retentive_count": fields[24],
    }


def fnv1a64(data: bytes, h: int = 0xCBF29CE484222325) -> int:
    for b in data:
        h ^= b
        h = (h * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def bad_files(state: Path):
    return sorted(state.parent.glob(state.name + ".bad-*"))


# --- SIGKILL during a storm of acknowledged writes


class Writer(threading.Thread):
    """Writes random values to its own registers until the daemon dies; remembers the last
    acknowledged value of each register and the one write that may have been in flight."""

    def __init__(self, port, registers, seed):
        super().__init__(daemon=True)
        self.port = port
        self.registers = registers
        self.rng = random.Random(seed)
        self.acked = {}
        self.in_flight = {}
        self.count = 0
        self.started = threading.Event()

    def run(self):
        client = ModbusTcpClient("127.0.0.1", port=self.port, timeout=2, retries=0)
        if not client.connect():
            self.started.set()
            return
        self.started.set()
        try:
            while True:
                if self.rng.random() < 0.3:
                    # FC16: a few consecutive registers of this writer's set.
                    i = self.rng.randrange(len(self.registers) - 3)
                    regs = self.registers[i : i + 3]
                    if regs[-1] - regs[0] != 2:
                        continue
                    values = [self.rng.randrange(1, 65536) for _ in regs]
                    self.in_flight = dict(zip(regs, values))
                    rr = client.write_registers(regs[0], values, slave=1)
                else:
                    reg = self.rng.choice(self.registers)
                    value = self.rng.randrange(1, 65536)
                    self.in_flight = {reg: value}
                    rr = client.write_register(reg, value, slave=1)
                if rr.isError():
                    return
                self.acked.update(self.in_flight)
                self.in_flight = {}
                self.count += 1
        except Exception:  # noqa: BLE001 - the daemon was killed under us: that is the point
            return
        finally:
            client.close()


def test_sigkill_during_write_storm_keeps_every_acknowledged_write(start_plcemud, tmp_path):
    """docs/operations.md, Retentive memory: every acknowledged write to a retentive register
    survives kill -9."""
    state = tmp_path / "storm.state"
    cfg = config(state)
    d = start_plcemud(cfg)
    seed = random.randrange(1 << 30)
    rng = random.Random(seed)
    # Four writers, each on its own retentive block: D0-D99, D2800-D2899, R100-R199, R5000-R5099.
    blocks = [D0, D0 + 2800, 100, 5000]
    writers = [Writer(d.port, list(range(b, b + 100)), seed + k) for k, b in enumerate(blocks)]
    for w in writers:
        w.start()
    for w in writers:
        assert w.started.wait(5)
    time.sleep(rng.uniform(0.5, 1.5))
    d.proc.send_signal(signal.SIGKILL)
    d.proc.wait(timeout=5)
    for w in writers:
        w.join(timeout=10)
    acked = sum(w.count for w in writers)
    assert acked > 100, f"only {acked} acknowledged writes before the kill (seed {seed})"

    d2 = start_plcemud(cfg)
    assert "did not close it" in d2.log_text()
    c = d2.client()
    assert read(c, R4057) == [2]
    checked = 0
    for w in writers:
        for reg, value in w.acked.items():
            got = read(c, reg)[0]
            allowed = {value, w.in_flight.get(reg)}
            assert got in allowed, (
                f"register {reg}: last acknowledged {value}, in flight {w.in_flight.get(reg)}, "
                f"found {got} (seed {seed})"
            )
            checked += 1
    assert checked > 50
    print(f"{acked} acknowledged writes before kill -9; {checked} registers compared (seed {seed})")


# --- clean shutdown


def test_clean_shutdown_keeps_retentive_clears_the_rest_and_counts_starts(start_plcemud, tmp_path):
    """docs/operations.md, Retentive memory: retentive kept, the rest cleared, R4057 counts
    power-ups."""
    state = tmp_path / "clean.state"
    cfg = config(state)
    d = start_plcemud(cfg)
    c = d.client()
    assert read(c, R4057) == [1]
    assert not c.write_register(D0 + 100, 4242, slave=1).isError()        # D100: retentive
    assert not c.write_register(5000, 5555, slave=1).isError()            # R5000: retentive
    assert not c.write_register(3000, 3333, slave=1).isError()            # R3000: not retentive
    assert not c.write_coil(M0 + 800, True, slave=1).isError()            # M800: retentive
    assert not c.write_coil(M0 + 10, True, slave=1).isError()             # M10: not retentive
    d.close_clients()
    assert d.stop() == 0
    assert "closed" in d.log_text()
    assert header(state)["state"] == 2  # closed cleanly

    d = start_plcemud(cfg)
    assert "closed cleanly last time" in d.log_text()
    c = d.client()
    assert read(c, D0 + 100) == [4242]
    assert read(c, 5000) == [5555]
    assert read(c, 3000) == [0]
    assert c.read_coils(M0 + 800, 1, slave=1).bits[0] is True
    assert c.read_coils(M0 + 10, 1, slave=1).bits[0] is False
    assert read(c, R4057) == [2]
    assert header(state)["state"] == 1  # open while running
    d = restart(start_plcemud, d, cfg)
    assert read(d.client(), R4057) == [3]


def test_init_presets_do_not_overwrite_a_scadas_retained_writes(start_plcemud, tmp_path):
    """Decision (docs/operations.md): init reaches retentive devices only when the state file is new."""
    state = tmp_path / "init.state"
    cfg = config(state, "init: {R10: 111, R3000: 7}\n")
    d = start_plcemud(cfg)
    c = d.client()
    assert read(c, 10) == [111]
    assert read(c, 3000) == [7]
    c.write_register(10, 222, slave=1)
    c.write_register(3000, 9, slave=1)
    d = restart(start_plcemud, d, cfg)
    c = d.client()
    assert read(c, 10) == [222]   # retained value wins
    assert read(c, 3000) == [7]   # not retentive: cleared, preset again

    # persistence.init: always puts the preset back at every start.
    cfg_always = config(state).replace("sync_ms: 200}", "sync_ms: 200, init: always}")
    cfg_always += "init: {R10: 111}\n"
    d = restart(start_plcemud, d, cfg_always)
    assert read(d.client(), 10) == [111]


def test_a_device_that_becomes_retentive_takes_its_preset_at_the_restart(start_plcemud, tmp_path):
    """Decision (docs/operations.md): after the retentive ranges change, a device retentive now
    but not before was cleared, and takes its preset as a non-retentive one does; one retentive
    both before and now keeps its value."""
    state = tmp_path / "widen.state"
    presets = "init: {R10: 111, R3500: 42}\n"
    d = start_plcemud(config(state, presets))
    c = d.client()
    assert read(c, 3500) == [42]
    c.write_register(10, 222, slave=1)
    c.write_register(3500, 9, slave=1)
    widened = config(state, presets).replace("sync_ms: 200}",
                                             "sync_ms: 200, retentive: [R0-R3599]}")
    d = restart(start_plcemud, d, widened)
    c = d.client()
    assert "the retentive ranges changed" in d.log_text()
    assert read(c, 10) == [222]   # retentive before and now: retained
    assert read(c, 3500) == [42]  # cleared (not retentive before), then preset; was 0
    c.write_register(3500, 5, slave=1)
    d = restart(start_plcemud, d, widened)
    assert read(d.client(), 3500) == [5]  # retentive now: a retained write wins


# --- corrupted and mismatched files


def test_corrupted_state_file_is_moved_aside_and_a_fresh_one_used(start_plcemud, tmp_path):
    state = tmp_path / "corrupt.state"
    cfg = config(state)
    d = start_plcemud(cfg)
    d.client().write_register(D0 + 5, 55, slave=1)
    assert d.stop() == 0
    raw = bytearray(state.read_bytes())
    raw[4096 + 3000] ^= 0x10  # somewhere in the image, after a clean close
    state.write_bytes(bytes(raw))

    d = start_plcemud(cfg)
    log = d.log_text()
    assert "data checksum mismatch" in log
    bad = bad_files(state)
    assert len(bad) == 1, log
    assert f"moved to {bad[0]}" in log
    assert bad[0].read_bytes() == bytes(raw)  # kept as found
    c = d.client()
    assert read(c, D0 + 5) == [0]
    assert read(c, R4057) == [1]  # a fresh start


def test_garbage_state_file_is_moved_aside(start_plcemud, tmp_path):
    state = tmp_path / "garbage.state"
    state.write_bytes(b"this is not a state file\n" * 400)
    d = start_plcemud(config(state))
    assert "not a plcemu state file" in d.log_text()
    assert len(bad_files(state)) == 1
    assert read(d.client(), R4057) == [1]


def test_mismatched_state_file_is_moved_aside(start_plcemud, tmp_path):
    """A well-formed file for another layout (here: a D area of 8000) is never used."""
    state = tmp_path / "mismatch.state"
    cfg = config(state)
    d = start_plcemud(cfg)
    d.client().write_register(D0 + 7, 77, slave=1)
    assert d.stop() == 0
    raw = bytearray(state.read_bytes())
    d_index = 7  # Area::D
    struct.pack_into("<I", raw, 24 + 4 * d_index, 8000)
    count = struct.unpack_from("<I", raw, 108)[0]
    checksum = fnv1a64(bytes(raw[:136]))
    checksum = fnv1a64(bytes(raw[144 : 144 + 12 * count]), checksum)
    struct.pack_into("<Q", raw, 136, checksum)
    state.write_bytes(bytes(raw))

    d = start_plcemud(cfg)
    log = d.log_text()
    assert "does not match the configuration" in log, log
    assert "D area has 8000 devices, not 4000" in log
    assert len(bad_files(state)) == 1
    assert read(d.client(), D0 + 7) == [0]
    assert header(state)["area_size"][d_index] == 4000


def test_a_state_file_of_another_family_is_named_by_its_family(start_plcemud, tmp_path):
    """A config whose profile changed from fbs to vb finds the fbs image in its state file:
    moved aside, the message naming the family it holds (it gave its number: "number 0")."""
    state = tmp_path / "changed.state"
    d = start_plcemud(config(state))
    assert d.stop() == 0
    d = start_plcemud(config(state).replace("profile: fbs", "profile: vb"))
    log = d.log_text()
    assert "it holds the image of another PLC family (fbs), not of vb" in log, log
    assert len(bad_files(state)) == 1


def test_second_daemon_on_the_same_state_file_is_refused(start_plcemud, tmp_path):
    state = tmp_path / "shared.state"
    d = start_plcemud(config(state))
    other = tmp_path / "other.yaml"
    other.write_text(config(state).replace("bind: 127.0.0.1", "bind: 127.0.0.1, port: 0"))
    r = run_plcemud("-c", other)
    assert r.returncode == 1
    assert "in use by another process" in r.stderr
    assert not bad_files(state)
    assert read(d.client(), R4057) == [1]


def test_default_state_file_lives_in_the_systemd_state_directory(tmp_path):
    """systemd's StateDirectory= sets STATE_DIRECTORY; the fixture clears it, so run by hand."""
    state_dir = tmp_path / "var-lib-plcemu"
    state_dir.mkdir()
    cfg = tmp_path / "line1.yaml"
    cfg.write_text("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n")
    port = free_port()
    env = {**os.environ, "STATE_DIRECTORY": str(state_dir)}
    proc = subprocess.Popen([PLCEMUD, "-c", str(cfg), "--port", str(port)], env=env,
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 10
        while not port_open(port) and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert port_open(port)
        expected = state_dir / "line1.state"
        assert expected.exists()
        assert header(expected)["magic"] == b"PLCEMUST"
        assert not (tmp_path / "line1.state").exists()
    finally:
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=10)
    assert proc.returncode == 0, err
    assert f"state file {state_dir}/line1.state closed" in err


def test_default_state_file_lies_beside_the_config(start_plcemud):
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n")
    expected = Path(d.config_path).with_suffix(".state")
    assert expected.exists()


def test_persistence_can_be_disabled(start_plcemud, tmp_path):
    cfg = "profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\npersistence: {enabled: false}\n"
    d = start_plcemud(cfg)
    d.client().write_register(D0, 1, slave=1)
    assert not list(tmp_path.glob("*.state"))
    d = restart(start_plcemud, d, cfg)
    assert read(d.client(), D0) == [0]


# --- the sync thread beside the loop


def test_the_sync_thread_yields_to_the_event_loop(start_plcemud, tmp_path):
    """docs/architecture.md, Threads: the threads beside the event loop run at a nice value 10
    above the process's, the loop at the process's own."""
    d = start_plcemud(config(tmp_path / "nice.state"))
    pid = d.proc.pid

    def nice(tid):
        # /proc/PID/task/TID/stat: the 19th field, counted after the command's closing ")".
        stat = Path(f"/proc/{pid}/task/{tid}/stat").read_text()
        return int(stat[stat.rindex(")") + 2:].split()[16])

    process = os.nice(0)  # started with this test's own
    assert nice(pid) == process, "the main thread runs the loop"
    tasks = [int(t) for t in os.listdir(f"/proc/{pid}/task")]
    others = sorted(nice(t) for t in tasks if t != pid)
    assert min(process + 10, 19) in others, (process, others)


def test_a_reload_to_the_most_retentive_ranges_keeps_the_daemon(start_plcemud, tmp_path):
    # 256 ranges is what a config may list; R4057, which the family always keeps, is one more.
    # The state file refused the 257th at the reload's apply: the daemon stopped.
    state = tmp_path / "r.state"
    ranges = ", ".join(f"D{2 * i}" for i in range(256))
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n"
                      f"persistence: {{file: '{state}', retentive: [D0]}}\n")
    c = d.client()
    assert not c.write_register(D0 + 2, 77, slave=1).isError()
    Path(d.config_path).write_text(Path(d.config_path).read_text().replace(
        "retentive: [D0]", f"retentive: [{ranges}]"))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    time.sleep(0.5)
    assert d.proc.poll() is None, d.log_text()
    assert read(c, D0 + 2) == [77]
    d.stop()
    # And a start with them.
    d = start_plcemud(Path(d.config_path).read_text())
    assert read(d.client(), D0 + 2) == [77], d.log_text()


def test_a_reload_naming_the_same_state_file_otherwise_says_nothing_moves(start_plcemud,
                                                                        tmp_path):
    """`dir/./e.state` for `dir/e.state` is the file the daemon holds: a reload warned that the
    state file would become it at the next start. A key taken away said `-> ` and nothing."""
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1}}\n"
                      f"persistence: {{file: '{tmp_path}/e.state'}}\n")
    config = Path(d.config_path)
    config.write_text(config.read_text().replace(f"{tmp_path}/e.state", f"{tmp_path}/./e.state"))
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("reload: done"), d.log_text()
    assert "the state file becomes" not in d.log_text(), d.log_text()
    config.write_text("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1, port: %d}}\n" % d.port)
    d.proc.send_signal(signal.SIGHUP)
    assert d.wait_log("the state file becomes"), d.log_text()
    assert "e.state -> default" in d.log_text(), d.log_text()
    assert f"the state file becomes {tmp_path}/{config.stem}.state at the next start" in \
        d.log_text(), d.log_text()


@pytest.mark.parametrize("how", ["deleted", "moved", "linked"])
def test_a_state_file_taken_away_while_in_use_is_said_once(start_plcemud, tmp_path, how):
    # docs/operations.md, "Retentive memory": said at the next sync, once; the PLC runs on, and
    # the stop says the file is not where the next start looks.
    state = tmp_path / "gone.state"
    d = start_plcemud(config(state))
    c = d.client()
    assert not c.write_register(D0, 5, slave=1).isError()
    if how == "deleted":
        state.unlink()
    else:
        state.rename(tmp_path / "elsewhere.state")
        if how == "linked":  # a link to it, which a start never follows
            state.symlink_to(tmp_path / "elsewhere.state")
    assert d.wait_log("the state file was deleted or moved away while in use", 3), d.log_text()
    assert f"{state}: the state file was deleted" in d.log_text()
    time.sleep(0.6)  # three more syncs
    assert d.log_text().count("deleted or moved away") == 1, d.log_text()
    assert read(c, D0) == [5]
    assert not c.write_register(D0, 6, slave=1).isError()
    assert read(c, D0) == [6]
    assert d.stop() == 0
    assert f"state file {state} closed, but not at its path" in d.log_text(), d.log_text()


def test_a_state_file_taken_away_is_said_for_its_plc(tmp_path):
    # Among many PLCs the line names which one, as the PLC's other lines do.
    ports = free_ports(2)
    entries = "".join(
        f"  - {{name: {n}, profile: fbs, modbus: {{tcp: {{bind: 127.0.0.1, port: {p}}}}},\n"
        f"     persistence: {{file: {n}.state, sync_ms: 200}}}}\n"
        for n, p in zip("ab", ports))
    d = spawn_plcs(tmp_path, "plcs:\n" + entries, ports)
    try:
        (tmp_path / "b.state").unlink()
        assert d.wait_log("deleted or moved away while in use", 3), d.log_text()
        assert "plcs[1] (b): persistence: " in d.log_text(), d.log_text()
    finally:
        assert d.stop() == 0
