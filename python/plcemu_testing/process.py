"""One plcemud process under test: its directory, config file and log; start, stop, restart,
reload. What the process serves (one PLC, or the PLCs of a `plcs:` config) is its subclass's
(plc.py, plcs.py)."""

import os
import re
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

from .errors import DaemonError

START_TIMEOUT_S = 10.0
STOP_TIMEOUT_S = 5.0
RELOAD_TIMEOUT_S = 30.0


def free_port(taken=(), kind="tcp"):
    """A TCP (or `kind` "udp": UDP) port on 127.0.0.1 that nothing listens on at the moment of
    the call, and not one of `taken`."""
    while True:
        with socket.socket(type=socket.SOCK_DGRAM if kind == "udp" else socket.SOCK_STREAM) as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        if port not in taken:
            return port


def find_plcemud(*roots):
    """The plcemud binary: $PLCEMUD, else `plcemud` on PATH, else the newest build*/plcemud
    under one of `roots` (a source tree)."""
    env = os.environ.get("PLCEMUD")
    if env:
        if not os.access(env, os.X_OK):
            raise DaemonError(f"PLCEMUD={env} is not an executable file")
        return str(Path(env).resolve())
    on_path = shutil.which("plcemud")
    if on_path:
        return on_path
    built = [p for root in roots if root for p in Path(root).glob("build*/plcemud")
             if os.access(p, os.X_OK)]
    if built:
        return str(max(built, key=lambda p: p.stat().st_mtime))
    raise DaemonError("plcemud not found: set PLCEMUD to the binary, put it on PATH, or build it "
                      "in the source tree (build*/plcemud)")


class Process:
    """A plcemud run on `workdir`/`name`.yaml from `workdir`, its output in `workdir`/`name`.log.

    A subclass says which ports it listens on and what to do around a start: `_set_config`
    (write the config, read what it needs of it), `_args` (extra arguments), `_ports` (the TCP
    ports to wait for), `_connect` and `_disconnect` (its clients), `_new_ports` (other ports
    when one was taken during a restart), `_snapshot`/`_restore` (undo a rejected reload),
    `_reload_done` (the log says the reload is through) and `_reloaded` (read the new map)."""

    def __init__(self, binary, workdir, name):
        self.binary = str(binary)
        self.workdir = Path(workdir)
        self.workdir.mkdir(parents=True, exist_ok=True)
        self.config_path = self.workdir / f"{name}.yaml"
        self.log_path = self.workdir / f"{name}.log"
        self.proc = None
        self.exit_code = None

    def _start(self):
        env = {k: v for k, v in os.environ.items() if k != "STATE_DIRECTORY"}
        # The daemon stops (SIGTERM) when this process dies, even by SIGKILL, when no code of
        # ours runs to stop it: plcemud sets a parent-death signal on itself (Linux
        # PR_SET_PDEATHSIG) and checks that this pid is still its parent. Not prctl in a
        # preexec_fn: Python code between fork and exec can deadlock when other threads hold
        # locks (a test's server threads), and it rules out subprocess's vfork/posix_spawn path.
        # The kernel sends it when the *thread* that started the daemon ends: start daemons
        # from a thread that outlives them (pytest's main thread does).
        env["PLCEMUD_PARENT_PID"] = str(os.getpid())
        args = [self.binary, "-c", str(self.config_path), *self._args()]
        with open(self.log_path, "ab") as log:  # appended across restarts
            self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=log,
                                         stderr=subprocess.STDOUT, cwd=self.workdir, env=env)
        self.exit_code = None
        waiting = list(self._ports())
        deadline = time.monotonic() + START_TIMEOUT_S
        while waiting:
            if self.proc.poll() is not None:
                raise DaemonError(f"plcemud exited with {self.proc.returncode} before listening "
                                  f"on port {waiting[0]}\nargs: {args}\n--- log ---\n{self.log}")
            try:
                socket.create_connection(("127.0.0.1", waiting[0]), timeout=0.2).close()
                waiting.pop(0)
                continue
            except OSError:
                pass
            if time.monotonic() > deadline:
                self.stop(kill=True)
                raise DaemonError(f"plcemud did not listen on port {waiting[0]} within "
                                  f"{START_TIMEOUT_S} s\n--- log ---\n{self.log}")
            time.sleep(0.05)
        self._connect()

    @property
    def log(self):
        """Everything the daemon wrote (stdout and stderr) so far, across restarts."""
        try:
            return self.log_path.read_text(errors="replace")
        except FileNotFoundError:
            return ""

    @property
    def running(self):
        return self.proc is not None and self.proc.poll() is None

    def stop(self, kill=False):
        """SIGTERM (SIGKILL with kill=True), up to 5 s, then SIGKILL; returns the exit code."""
        self._disconnect()
        if self.proc is None:
            return self.exit_code
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL if kill else signal.SIGTERM)
            try:
                self.proc.wait(timeout=STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.exit_code = self.proc.returncode
        self.proc = None
        return self.exit_code

    def restart(self, kill=False):
        """Stops the daemon (SIGTERM, or SIGKILL with kill=True) and starts it again with the
        same config and state files, on the same ports if they are still free. Returns the
        first daemon's exit code; the clients are new connected ones."""
        code = self.stop(kill=kill)
        try:
            self._start()
        except DaemonError:
            if self.proc is not None and self.proc.poll() is None:
                raise
            self.proc = None
            self._new_ports()  # someone took a port in between
            self._start()
        return code

    def reload(self, config=None):
        """Writes `config` (if given) over the daemon's config file, sends SIGHUP and waits for
        "reload: done" in the log. A rejected config raises DaemonError with the daemon's
        reasons (the daemon goes on with the previous one, and so does this object)."""
        if not self.running:
            raise DaemonError("reload: plcemud is not running")
        previous = self.config_path.read_text(), self._snapshot()
        if config is not None:
            self._set_config(config)
        try:
            self._reload()
        except DaemonError:
            self.config_path.write_text(previous[0])
            self._restore(previous[1])
            raise
        self._reloaded()

    def _reload(self):
        start = self.log_path.stat().st_size
        self.proc.send_signal(signal.SIGHUP)
        deadline = time.monotonic() + RELOAD_TIMEOUT_S
        while True:
            with open(self.log_path, "rb") as f:
                f.seek(start)
                new = f.read().decode(errors="replace")
            if self._reload_done(new):
                break
            if re.search(r"still running (the|its) previous", new) or not self.running:
                raise DaemonError(f"reload rejected:\n{new}")
            if time.monotonic() > deadline:
                raise DaemonError(f"no 'reload: done' within {RELOAD_TIMEOUT_S} s:\n{new}")
            time.sleep(0.02)

    def _reload_done(self, new_log):
        """True when `new_log` (the log since SIGHUP) says the whole reload is done."""
        return "reload: done" in new_log
