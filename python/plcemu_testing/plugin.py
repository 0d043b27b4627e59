"""The pytest side: the `plcemud` fixture, the daemons' logs in the report of a failed test, and
SIGTERM turned into an interrupt so that the fixture stops its daemons."""

import signal
import threading
from pathlib import Path

import pytest

from .errors import DaemonError
from .plc import Plc
from .plcs import Plcs, plcs_of
from .process import find_plcemud

_PLCS = pytest.StashKey[list]()
_SIGTERM = pytest.StashKey[object]()  # the SIGTERM handler before ours
LOG_TAIL = 20000  # characters of each daemon's log shown with a failure


@pytest.fixture
def plcemud(request, tmp_path):
    """A factory: plcemud(config) -> Plc, a daemon on a free port of 127.0.0.1 with its own
    state file in tmp_path; `config` is a dict, a path or YAML text. A `plcs:` config gives a
    Plcs instead: a free port per listener, a state file per PLC, `plcs["kiln"]` or `plcs[1]`
    a Plc-like PlcEntry. Every daemon still running at teardown is stopped with SIGTERM, and one
    that did not exit with 0 fails the test."""
    plcs = request.node.stash.setdefault(_PLCS, [])
    _interrupt_on_sigterm(request.config)
    try:
        binary = find_plcemud(request.config.rootpath, Path(__file__).resolve().parents[2])
    except DaemonError as e:
        pytest.fail(str(e), pytrace=False)

    def start(config, name=None):
        kind = Plc if plcs_of(config) is None else Plcs
        plc = kind(binary, tmp_path / (name or f"plcemud-{len(plcs)}"), config)
        plcs.append(plc)
        return plc

    yield start
    bad = []
    for plc in plcs:
        running = plc.proc is not None  # not stopped by the test itself
        died = running and plc.proc.poll() is not None
        code = plc.stop()
        if running and (died or code != 0):
            how = "exited by itself" if died else "stopped (SIGTERM)"
            bad.append(f"plcemud {plc.config_path} {how} with {code}\n--- log ---\n"
                       f"{plc.log[-LOG_TAIL:]}")
    if bad:
        pytest.fail("\n".join(bad), pytrace=False)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.failed:
        for i, plc in enumerate(item.stash.get(_PLCS, [])):
            report.sections.append((f"plcemud {i} log ({plc.workdir})", plc.log[-LOG_TAIL:]))


def _sigterm(signum, frame):
    raise KeyboardInterrupt("SIGTERM")


def _interrupt_on_sigterm(config):
    """From the first daemon on, SIGTERM (a CI runner's time-out) interrupts the session as
    Ctrl-C does: pytest then tears the fixtures down, which stops the daemons with their state
    saved. Only where SIGTERM still has its default action (a handler of someone else's is left
    alone) and from the main thread (the only one that may set one). A SIGKILL, or a SIGTERM
    during the teardown, leaves it to the daemon's parent-death signal (process.py)."""
    if _SIGTERM in config.stash or threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        return
    config.stash[_SIGTERM] = signal.signal(signal.SIGTERM, _sigterm)


def pytest_unconfigure(config):
    previous = config.stash.get(_SIGTERM, None)
    if previous is not None and signal.getsignal(signal.SIGTERM) is _sigterm:
        signal.signal(signal.SIGTERM, previous)
