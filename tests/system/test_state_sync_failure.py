"""A state file whose sync to disk fails, for real (docs/operations.md, "Retentive memory";
docs/console.md, "Health and metrics").

msync does not fail on a healthy file system, so the test compiles a tiny LD_PRELOAD shim (with
`cc`) that interposes msync alone: while the control file named by PLCEMU_TEST_MSYNC_FAIL exists,
msync returns -1 with errno EIO (and appends a byte to the file named by PLCEMU_TEST_MSYNC_HITS,
so the test knows how many failures it injected); otherwise it calls the real msync
(dlsym(RTLD_NEXT)). Checked: every failed sync is counted in
plcemu_state_syncs_total{outcome="failed"}, an episode of failures is logged once when it begins
and once when syncing works again, Modbus is served throughout, and a clean stop exits 0.

Wire addresses (docs/profile-fbs.md): Rn is holding register n; R0-R2999 are retentive.
"""

import os
import re
import shutil
import signal
import subprocess
import time
import urllib.request
from pathlib import Path

import pytest

from conftest import PLCEMUD, free_port, port_open

SYNC_MS = 100
R100 = 100
# How long a step may take (the shim's first failure, the counters moving) before the test fails
# saying which step did not happen; only a failing run waits this long.
EFFECT_TIMEOUT_S = 10.0
# Failed syncs seen before the log is checked for one line only (0.8 s at SYNC_MS).
FAILURES_PER_EPISODE = 8

FAILED_LINE = "sync failed ("  # persistence.cpp, SyncThread::synced: "...: sync failed (EIO text)"
RECOVERED_LINE = ": syncing again"

SHIM_SOURCE = r"""
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

typedef int (*msync_fn)(void*, size_t, int);

/* True when PLCEMU_TEST_MSYNC_ONLY is unset, or names part of the path of the file mapped at
   addr (/proc/self/maps): one PLC's state file fails, the others' do not. */
static int chosen(void* addr) {
    const char* only = getenv("PLCEMU_TEST_MSYNC_ONLY");
    if (only == NULL) return 1;
    FILE* maps = fopen("/proc/self/maps", "re");
    if (maps == NULL) return 0;
    char line[4096];
    int hit = 0;
    while (fgets(line, sizeof line, maps) != NULL) {
        unsigned long lo = 0, hi = 0;
        if (sscanf(line, "%lx-%lx", &lo, &hi) != 2) continue;
        if ((unsigned long)addr >= lo && (unsigned long)addr < hi) {
            hit = strstr(line, only) != NULL;
            break;
        }
    }
    fclose(maps);
    return hit;
}

int msync(void* addr, size_t length, int flags) {
    const char* control = getenv("PLCEMU_TEST_MSYNC_FAIL");
    if (control != NULL && access(control, F_OK) == 0 && chosen(addr)) {
        const char* hits = getenv("PLCEMU_TEST_MSYNC_HITS");
        if (hits != NULL) {
            int fd = open(hits, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
            if (fd >= 0) {
                (void)!write(fd, "x", 1);
                close(fd);
            }
        }
        errno = EIO;
        return -1;
    }
    msync_fn real = (msync_fn)dlsym(RTLD_NEXT, "msync");
    if (real == NULL) {
        errno = ENOSYS;
        return -1;
    }
    return real(addr, length, flags);
}
"""


def build_shim(tmp_path: Path) -> Path:
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler `cc` on PATH to build the msync LD_PRELOAD shim "
                    "(scripts/install-deps.sh installs g++, which brings gcc and cc)")
    src = tmp_path / "msync_shim.c"
    src.write_text(SHIM_SOURCE)
    so = tmp_path / "msync_shim.so"
    r = subprocess.run([cc, "-shared", "-fPIC", "-O1", "-o", str(so), str(src), "-ldl"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, f"cannot build the msync shim:\n{r.stdout}{r.stderr}"
    return so


def syncs(http_port: int) -> dict:
    """{"ok": n, "failed": n} from /metrics."""
    with urllib.request.urlopen(f"http://127.0.0.1:{http_port}/metrics", timeout=3) as r:
        assert r.status == 200
        text = r.read().decode()
    found = dict(re.findall(r'^plcemu_state_syncs_total\{outcome="(ok|failed)"\} (\d+)$', text,
                            re.MULTILINE))
    assert set(found) == {"ok", "failed"}, f"no plcemu_state_syncs_total samples in:\n{text}"
    return {k: int(v) for k, v in found.items()}


def hits(path: Path) -> int:
    try:
        return path.stat().st_size
    except FileNotFoundError:
        return 0


def wait_until(predicate, timeout, on_timeout):
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(on_timeout())
        time.sleep(0.05)


def lines_with(d, needle):
    return [line for line in d.log_text().splitlines() if needle in line]


def write_read(client, value):
    w = client.write_register(R100, value, slave=1)
    assert not w.isError(), w
    rr = client.read_holding_registers(R100, count=1, slave=1)
    assert not rr.isError(), rr
    assert rr.registers == [value]


def preload_shim(tmp_path, monkeypatch):
    """Builds the shim and puts it in the daemons' environment; returns (shim, preload, control
    file, hits file, the LD_PRELOAD there was before)."""
    shim = build_shim(tmp_path)
    control = tmp_path / "msync-fails"
    hits_file = tmp_path / "msync-hits"
    # conftest's _spawn builds the daemon's environment from os.environ (PATH and all) and
    # passes env= itself, so the preload goes through os.environ (restored after the test).
    inherited = os.environ.get("LD_PRELOAD")
    preload = " ".join(p for p in (str(shim), inherited) if p)
    monkeypatch.setenv("LD_PRELOAD", preload)
    # A sanitizer build refuses to start when its runtime is not first in the library list.
    asan = os.environ.get("ASAN_OPTIONS", "")
    monkeypatch.setenv("ASAN_OPTIONS", f"{asan}:verify_asan_link_order=0" if asan
                       else "verify_asan_link_order=0")
    monkeypatch.setenv("PLCEMU_TEST_MSYNC_FAIL", str(control))
    monkeypatch.setenv("PLCEMU_TEST_MSYNC_HITS", str(hits_file))
    return shim, preload, control, hits_file, inherited


def test_failed_syncs_are_counted_logged_once_per_episode_and_do_not_stop_the_daemon(
        start_plcemud, tmp_path, monkeypatch):
    shim, preload, control, hits_file, inherited = preload_shim(tmp_path, monkeypatch)
    hp = free_port()
    d = start_plcemud(
        "profile: fbs\n"
        "modbus: {tcp: {bind: 127.0.0.1}}\n"
        f"http: {{bind: 127.0.0.1, port: {hp}}}\n"
        f"persistence: {{sync_ms: {SYNC_MS}}}\n",
        name="plc",
    )
    wait_until(lambda: port_open(hp), 10, lambda: f"no console on {hp}\n{d.log_text()}")
    state = tmp_path / "plc.state"
    assert state.is_file(), d.log_text()

    maps = Path(f"/proc/{d.proc.pid}/maps")
    if maps.exists() and str(shim) not in maps.read_text():
        pytest.fail(f"LD_PRELOAD={preload} was not honoured by {PLCEMUD} (a static binary?): "
                    f"the msync shim is not mapped, so no sync failure can be injected")

    # Healthy: syncs succeed and are counted, nothing failed.
    base = wait_until(lambda: (m := syncs(hp))["ok"] >= 2 and m, EFFECT_TIMEOUT_S,
                      lambda: f"no successful sync counted: {syncs(hp)}\n{d.log_text()}")
    assert base["failed"] == 0, base
    assert hits(hits_file) == 0
    c = d.client()
    write_read(c, 1111)

    for episode in (1, 2):
        # --- msync fails (EIO) while the control file exists ---------------------------------
        before = syncs(hp)
        control.touch()
        wait_until(
            lambda: hits(hits_file) > 0, EFFECT_TIMEOUT_S,
            lambda: f"the msync shim never failed a call within {EFFECT_TIMEOUT_S} s although it "
                    f"is mapped: msync is not interposed (sanitizer interceptor or static libc "
                    f"in {PLCEMUD}?); counters {before} -> {syncs(hp)}")
        wait_until(
            lambda: syncs(hp)["failed"] > before["failed"], EFFECT_TIMEOUT_S,
            lambda: f"daemon bug: the shim failed {hits(hits_file)} msync calls but "
                    f"plcemu_state_syncs_total{{outcome=\"failed\"}} stayed at "
                    f"{syncs(hp)['failed']}\n{d.log_text()}")
        wait_until(
            lambda: syncs(hp)["failed"] >= before["failed"] + FAILURES_PER_EPISODE,
            FAILURES_PER_EPISODE * SYNC_MS / 1000 + EFFECT_TIMEOUT_S,
            lambda: f"failed syncs not counted every period: {before} -> {syncs(hp)}")
        during = syncs(hp)
        assert during["ok"] <= before["ok"] + 1, (before, during)  # one sync may have been running

        # However many syncs failed, one line says so (with the file and errno's text).
        failed = lines_with(d, FAILED_LINE)
        assert len(failed) == episode, \
            f"{during['failed'] - before['failed']} failed syncs in episode {episode} logged " \
            f"{len(failed) - (episode - 1)} lines (expected 1):\n{d.log_text()}"
        assert str(state) in failed[-1] and "Input/output error" in failed[-1], failed[-1]
        assert len(lines_with(d, RECOVERED_LINE)) == episode - 1, d.log_text()

        # Modbus keeps being served; the write sits in memory (and the page cache).
        write_read(c, 2000 + episode)
        assert d.proc.poll() is None, d.log_text()

        # --- msync works again ---------------------------------------------------------------
        control.unlink()
        stopped = syncs(hp)
        wait_until(lambda: syncs(hp)["ok"] >= stopped["ok"] + 3, EFFECT_TIMEOUT_S,
                   lambda: f"syncs did not succeed again: {stopped} -> {syncs(hp)}\n"
                           f"{d.log_text()}")
        after = syncs(hp)
        # Every injected failure was counted, and none after the file went (one may have been
        # in flight when it was removed).
        assert after["failed"] == hits(hits_file), (after, hits(hits_file))
        assert after["failed"] <= stopped["failed"] + 1, (stopped, after)
        recovered = wait_until(lambda: len(lines_with(d, RECOVERED_LINE)) >= episode and
                               lines_with(d, RECOVERED_LINE), 2,
                               lambda: f"no recovery line logged:\n{d.log_text()}")
        assert len(recovered) == episode, d.log_text()
        assert str(state) in recovered[-1], recovered[-1]
        assert len(lines_with(d, FAILED_LINE)) == episode, d.log_text()
        write_read(c, 3000 + episode)

    assert d.stop(signal.SIGTERM) == 0, d.log_text()
    assert len(lines_with(d, FAILED_LINE)) == 2 and len(lines_with(d, RECOVERED_LINE)) == 2, \
        d.log_text()

    # What was written while syncs failed was kept: a restart (without the shim) reads it back.
    if inherited:
        monkeypatch.setenv("LD_PRELOAD", inherited)
    else:
        monkeypatch.delenv("LD_PRELOAD")
    d2 = start_plcemud(Path(d.config_path).read_text(), name="plc")
    rr = d2.client().read_holding_registers(R100, count=1, slave=1)
    assert not rr.isError() and rr.registers == [3002], rr
    assert d2.stop() == 0, d2.log_text()


def test_one_failing_file_is_its_own_episode_beside_healthy_ones(
        start_plcs, tmp_path, monkeypatch):
    # One sync thread syncs every PLC's file: one disk failing under one PLC is logged once, for
    # that file, and the other files' good syncs do not end its episode (they once did: two lines
    # a period, the recovery naming the healthy file).
    _, _, control, hits_file, _ = preload_shim(tmp_path, monkeypatch)
    monkeypatch.setenv("PLCEMU_TEST_MSYNC_ONLY", "two-line-a.state")
    hp = free_port()
    d = start_plcs(
        f"http: {{bind: 127.0.0.1, port: {hp}}}\n"
        "plcs:\n"
        "  - name: line-a\n"
        "    profile: fbs\n"
        f"    modbus: {{tcp: {{bind: 127.0.0.1, port: {free_port()}}}}}\n"
        f"    persistence: {{sync_ms: {SYNC_MS}}}\n"
        "  - name: line-b\n"
        "    profile: fbs\n"
        f"    modbus: {{tcp: {{bind: 127.0.0.1, port: {free_port()}}}}}\n"
        f"    persistence: {{sync_ms: {SYNC_MS}}}\n",
        [hp], name="two")
    wait_until(lambda: port_open(hp), 10, lambda: f"no console on {hp}\n{d.log_text()}")
    base = syncs(hp)
    control.touch()
    wait_until(lambda: hits(hits_file) >= FAILURES_PER_EPISODE, EFFECT_TIMEOUT_S,
               lambda: f"line-a's syncs did not fail: {hits(hits_file)}\n{d.log_text()}")
    during = syncs(hp)
    # line-b went on syncing; line-a's failures were all counted.
    assert during["ok"] >= base["ok"] + FAILURES_PER_EPISODE - 2, (base, during)
    assert during["failed"] >= FAILURES_PER_EPISODE - 1, during
    failed = lines_with(d, FAILED_LINE)
    assert len(failed) == 1 and "two-line-a.state" in failed[0], d.log_text()
    assert lines_with(d, RECOVERED_LINE) == [], d.log_text()
    control.unlink()
    wait_until(lambda: lines_with(d, RECOVERED_LINE), EFFECT_TIMEOUT_S,
               lambda: f"no recovery line logged:\n{d.log_text()}")
    time.sleep(3 * SYNC_MS / 1000)  # further good syncs of both files: no more lines
    recovered = lines_with(d, RECOVERED_LINE)
    assert len(recovered) == 1 and "two-line-a.state" in recovered[0], d.log_text()
    assert len(lines_with(d, FAILED_LINE)) == 1, d.log_text()
    assert d.stop(signal.SIGTERM) == 0, d.log_text()


def told(d, line, summary):
    """(lines naming a file, files counted in summary lines) of the log so far."""
    counted = sum(int(m.group(1)) for m in re.finditer(
        rf"persistence: (\d+) more {summary} in the last 2 s", d.log_text()))
    return len(lines_with(d, line)), counted


def test_a_disk_failing_under_many_files_is_a_few_lines_and_a_count(
        start_plcs, tmp_path, monkeypatch):
    # One disk under every PLC's state file: its failure begins an episode for each file at once.
    # Five files are named each way in 2 s, the rest counted in one line (5,000 PLCs logged
    # 10,000 lines for one hiccup). Each PLC copies the calendar's second into R100 (retentive),
    # so that each file has a page to write every second.
    _, _, control, hits_file, _ = preload_shim(tmp_path, monkeypatch)
    count = 30
    hp = free_port()
    d = start_plcs(
        f"http: {{bind: 127.0.0.1, port: {hp}}}\n"
        "plcs:\n" + "".join(
            f"  - {{name: p{i}, profile: fbs, persistence: {{sync_ms: {SYNC_MS}}},"
            f" modbus: {{tcp: {{bind: 127.0.0.1, port: 0}}}},"
            f" program: [{{MOV: {{en: M1926, s: R4128, d: R100}}}}]}}\n" for i in range(count)),
        [hp], name="many")
    wait_until(lambda: syncs(hp)["ok"] >= 2 * count, EFFECT_TIMEOUT_S,
               lambda: f"no syncs counted: {syncs(hp)}\n{d.log_text()}")
    # Each file told once failing and once syncing again, by name or in a count; a window of
    # 2 s names five at most.
    for change, line, summary in ((control.touch, FAILED_LINE, "state files failing to sync"),
                                  (control.unlink, RECOVERED_LINE, "state files syncing again")):
        change()
        wait_until(lambda: sum(told(d, line, summary)) == count, EFFECT_TIMEOUT_S,
                   lambda: f"{summary}: not told of every file: {syncs(hp)}\n{d.log_text()}")
        named, counted = told(d, line, summary)
        assert counted >= count - 10 and named <= 10, d.log_text()
    assert d.stop(signal.SIGTERM) == 0, d.log_text()
