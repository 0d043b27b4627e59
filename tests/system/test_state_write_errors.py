"""A state file on a disk whose writes fail for real (docs/operations.md, "Retentive memory").

The disk is an ext4 file system in a loop device whose backing file lives on a small tmpfs
(root only). To make the disk refuse the state file's writes, the test fills the tmpfs, punches
the file's blocks out of the backing file (`fallocate --punch-hole`, where `filefrag` says they
are) and fills the room that freed: a write of those blocks then needs room the tmpfs does not
have, and fails with an I/O error, as on a full thin-provisioned volume. Removing the fillers
gives the room back. A write-back that fails leaves its pages clean in the page cache and
reports the error once; checked here:
- syncs keep failing (one log line for the episode) while the disk refuses, and write the pages
  again for real once it takes them: the values are on the disk after the page cache is gone;
- a stop whose last sync fails exits 1, leaves the file marked open, and the next start recovers
  what the disk holds instead of moving the whole file aside.

Wire addresses (docs/profile-fbs.md): Rn is holding register n, Dn is 6000+n; R0-R2999 and
D0-D2999 are retentive.
"""

import os
import re
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest

FAILED_LINE = "sync failed ("        # persistence.cpp, SyncThread::synced
RECOVERED_LINE = ": syncing again"
CLOSE_FAILED_LINE = "the last sync failed"  # daemon.cpp, Host::close
D0 = 6000


def run(*args, check=True):
    r = subprocess.run(list(args), capture_output=True, text=True, timeout=60)
    if check and r.returncode != 0:
        pytest.skip(f"{' '.join(args)}: {r.stderr.strip() or r.stdout.strip()}")
    return r


@pytest.fixture
def failing_disk(tmp_path):
    """(mount point, tmpfs, loop device, backing file): ext4 on a loop device backed by a sparse
    file on an 8 MiB tmpfs."""
    if os.geteuid() != 0:
        pytest.skip("a loop device and mounts need root")
    for tool in ("losetup", "mkfs.ext4", "mount", "umount", "filefrag", "fallocate"):
        if shutil.which(tool) is None:
            pytest.skip(f"no {tool} (scripts/install-deps.sh installs util-linux and e2fsprogs)")
    tmpfs = tmp_path / "backing"
    disk = tmp_path / "disk"
    tmpfs.mkdir()
    disk.mkdir()
    run("mount", "-t", "tmpfs", "-o", "size=8m,mode=0700", "tmpfs", str(tmpfs))
    device = None
    try:
        image = tmpfs / "ext4.img"
        with open(image, "wb") as f:
            f.truncate(32 << 20)
        run("mkfs.ext4", "-q", "-F", "-b", "4096", "-O", "^has_journal", str(image))
        device = run("losetup", "-f", "--show", str(image)).stdout.strip()
        run("mount", device, str(disk))
        yield disk, tmpfs, device, image
    finally:
        # The tests take this fixture before start_plcemud, so their daemons are stopped (and
        # the disk free) by now; a lazy unmount all the same, so that nothing is left mounted.
        for mount in (disk, tmpfs):
            if run("umount", str(mount), check=False).returncode != 0:
                run("umount", "-l", str(mount), check=False)
            if mount == disk and device:
                run("losetup", "-d", device, check=False)


def fill(tmpfs: Path, name: str = "filler") -> Path:
    """Fills the tmpfs under the loop device's backing file."""
    path = tmpfs / name
    with open(path, "wb", buffering=0) as f:
        block = b"\0" * 4096
        try:
            while f.write(block):
                pass
        except OSError:
            pass
    return path


def refuse_writes(state: Path, image: Path, tmpfs: Path):
    """Makes the disk refuse every write of `state`'s pages: returns the fillers to remove to
    give the room back, and what the disk held at each page (offset in the backing file, bytes),
    in file order. (Whole extents are punched: a page punched alone out of a larger page of the
    tmpfs may still be there to write into.)"""
    fillers = [fill(tmpfs, "filler-1")]
    out = run("filefrag", "-v", "-b4096", str(state)).stdout
    held = []
    with open(image, "rb") as f:
        for m in re.finditer(r"^\s*\d+:\s+(\d+)\.\.\s*(\d+):\s+(\d+)\.\.\s*\d+:", out,
                             re.M):
            first, last, physical = int(m[1]), int(m[2]), int(m[3])
            for page in range(first, last + 1):
                offset = (physical + page - first) * 4096
                f.seek(offset)
                held.append((offset, f.read(4096)))
            run("fallocate", "--punch-hole", "--offset", str(physical * 4096), "--length",
                str((last - first + 1) * 4096), str(image))
    fillers.append(fill(tmpfs, "filler-2"))
    return fillers, held


def page_holding(state: Path, marker: bytes) -> int:
    """The page of the state file where `marker` is."""
    at = state.read_bytes().find(marker)
    assert at >= 0, f"{marker!r} not in {state}"
    return at // 4096


def remount(disk: Path, device: str, image: Path = None, pages=()):
    """Unmounts and mounts the disk again: its page cache is gone, as after a power loss.
    `pages` ((offset, bytes) in the backing file `image`) are put back on the disk meanwhile:
    the pages the disk kept."""
    run("umount", str(disk))
    if pages:
        with open(image, "r+b") as f:
            for offset, data in pages:
                f.seek(offset)
                f.write(data)
    run("mount", device, str(disk))


def config(disk: Path, sync_ms: int) -> str:
    return ("profile: fbs\n"
            "modbus: {tcp: {bind: 127.0.0.1}}\n"
            f"persistence: {{file: {disk / 'plc.state'}, sync_ms: {sync_ms}}}\n")


def write_block(c, address, value, count=100):
    w = c.write_registers(address, [value] * count, slave=1)
    assert not w.isError(), w


def read_block(c, address, count=100):
    rr = c.read_holding_registers(address, count=count, slave=1)
    assert not rr.isError(), rr
    return rr.registers


def count(d, needle):
    return sum(needle in line for line in d.log_text().splitlines())


def test_syncs_that_fail_are_retried_for_real_once_the_disk_takes_them(failing_disk,
                                                                       start_plcemud):
    disk, tmpfs, device, image = failing_disk
    d = start_plcemud(config(disk, 200), name="plc")
    c = d.client()
    time.sleep(0.6)  # the first syncs, on a healthy disk
    fillers, _ = refuse_writes(disk / "plc.state", image, tmpfs)
    for value in (21, 22, 23):
        for address in range(0, 3000, 100):
            write_block(c, address, value)
        write_block(c, D0, value)
        time.sleep(0.3)
    assert d.wait_log(FAILED_LINE, timeout=10), d.log_text()
    # While the disk refuses, every sync fails: one line for the episode, never a recovery
    # (a sync that found its pages clean after the failed write-back said "syncing again").
    time.sleep(1.5)
    assert count(d, FAILED_LINE) == 1, d.log_text()
    assert count(d, RECOVERED_LINE) == 0, d.log_text()

    for f in fillers:
        f.unlink()
    assert d.wait_log(RECOVERED_LINE, timeout=10), d.log_text()
    assert d.stop() == 0, d.log_text()
    assert re.search(r"info  state file \S+plc\.state closed$", d.log_text(), re.M), d.log_text()

    remount(disk, device)
    again = start_plcemud(config(disk, 200), name="plc")
    c = again.client()
    assert read_block(c, 0) == [23] * 100, d.log_text() + again.log_text()
    assert read_block(c, 2900) == [23] * 100
    assert read_block(c, D0) == [23] * 100
    assert "moved to" not in again.log_text(), again.log_text()


def test_a_stop_whose_last_sync_fails_exits_1_and_the_next_start_recovers_the_disks_values(
        failing_disk, start_plcemud):
    disk, tmpfs, device, image = failing_disk
    state = disk / "plc.state"
    first = start_plcemud(config(disk, 60000), name="plc")
    write_block(first.client(), 0, 0x4B4B)
    assert first.stop() == 0, first.log_text()  # R0-R99 on the disk, the file closed

    second = start_plcemud(config(disk, 60000), name="plc")
    r0_page = page_holding(state, b"KK" * 100)
    fillers, held = refuse_writes(state, image, tmpfs)
    write_block(second.client(), D0, 2222)
    assert second.stop() == 1, second.log_text()
    assert count(second, CLOSE_FAILED_LINE) == 1, second.log_text()
    assert " closed" not in second.log_text().split("stopped after")[-1], second.log_text()

    for f in fillers:
        f.unlink()
    # The disk kept the header (marked open at this start) and R0's page; it took none of the
    # stop's writes.
    remount(disk, device, image, [held[0], held[r0_page]])
    third = start_plcemud(config(disk, 60000), name="plc")
    c = third.client()
    # The file was left open: recovered as after a crash, R0-R99 as the disk holds them, not
    # moved aside as corrupted (its checksum, of values the disk never took, would not match).
    assert read_block(c, 0) == [0x4B4B] * 100, third.log_text()
    assert "moved to" not in third.log_text(), third.log_text()
    assert "did not close it" in third.log_text(), third.log_text()
