"""Communication faults (docs/communication-faults.md) seen by a Modbus master in the same
process: a `plcs:` config holding an `fbs` PLC ("press", station 5) and a `vb` PLC ("master")
whose FNC149 MBUS polls the press's R0-R9 into D2000-D2009 over the press's TCP listener
(docs/profile-vb.md, "FNC149 MBUS"). The press's faults are switched through its own
simulator unit (the kit's comm_fault) or the REST API; the master's working area S2 = D100
says what MBUS saw: S2+0 status (high byte) and station (low byte), S2+2 passes, S2+3 the last
exception code."""

import json
import time
import urllib.error
import urllib.request

import pytest

from conftest import free_port
from plcemu_testing import ModbusError

STATION = 5
R0 = list(range(1001, 1011))


def config(mbus_port):
    """Each PLC on a listener of its own (the ports as written are placeholders: the kit gives
    each listener a free port), each with its simulator unit there."""
    return {"plcs": [
        {"name": "press", "profile": "fbs", "station": STATION,
         "modbus": {"tcp": {"port": 1502}}, "persistence": {"enabled": False},
         "init": {"R0": R0}},
        {"name": "master", "profile": "vb",
         "modbus": {"tcp": {"port": 1503}}, "persistence": {"enabled": False},
         "mbus": {"tcp": {"host": "127.0.0.1", "port": mbus_port}},
         # One set: read 10 registers from station 5, 4xxxx 0 on, into D2000 on.
         "init": {"D1000": 1, "D1001": [STATION, 1, 10, 13, 2000, 4, 0]},
         "program": [{"MBUS": {"en": "M0", "s1": "D1000", "s2": "D100"}}]},
    ]}


def wait_for(predicate, timeout=2.0):
    deadline = time.monotonic() + timeout
    while True:
        v = predicate()
        if v or time.monotonic() > deadline:
            return v
        time.sleep(0.01)


@pytest.fixture
def pair(plcemud):
    """(plcs, press, master), MBUS on and its first read landed."""
    # The press's port is known once the kit has given it one: the master's mbus: names it at
    # a reload (which keeps every listener's port).
    plcs = plcemud(config(free_port()))
    press, master = plcs["press"], plcs["master"]
    assert press.port != master.port
    plcs.reload(config(press.port))
    assert f"(master): mbus: master via tcp 127.0.0.1:{press.port}" in plcs.log
    master.write_bits("M0", 1)
    assert wait_for(lambda: master.read("D2000", 10) == R0), master.read("D100", 4)
    assert master.read("D100") == [0]
    return plcs, press, master


def status(master):
    return master.read("D100")[0]


def api(plcs, method, body=None, path="comm-faults"):
    """A request to the press's REST API; (HTTP status, JSON body)."""
    url = f"{plcs.console_url}api/v1/plcs/press/{path}"
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, method=method,
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=5) as r:
            return r.status, json.load(r)
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"null")


def set_press_r0(plcs, values):
    """Writes the press's R0-R9 through the REST API, which no communication fault touches."""
    code, body = api(plcs, "PUT", {"values": values}, path="devices/R0")
    assert code == 200, body


def flows_again(plcs, master, values):
    """After the fault: a whole pass without a failure clears S2+0, and the press's new values
    land in D2000-D2009."""
    set_press_r0(plcs, values)
    assert wait_for(lambda: master.read("D2000", 10) == values), master.read("D100", 4)
    assert wait_for(lambda: status(master) == 0), hex(status(master))


# VB manual FNC149 status 6, "abnormal communication": an exception reply, its code in S2+3.
def test_exception_4_on_the_press_is_mbus_status_6_with_code_4(pair):
    plcs, press, master = pair
    press.comm_fault(exception=4)  # through the press's simulator unit
    assert wait_for(lambda: status(master) == (6 << 8 | STATION)), hex(status(master))
    assert master.read("D103") == [4]
    # While it answers with exceptions nothing lands: the press's values change, D2000 not.
    set_press_r0(plcs, [7] * 10)
    passes = master.read("D102")[0]
    assert wait_for(lambda: master.read("D102")[0] >= passes + 3), "MBUS keeps passing"
    assert master.read("D2000", 10) == R0
    assert status(master) == 6 << 8 | STATION
    press.clear_comm_faults()
    flows_again(plcs, master, [7] * 10)
    assert master.read("D103") == [4]  # the last exception's code stays until EN rises again


# Status 5, "no response": no reply within the D9129 time-out (0: 100 ms).
def test_offline_press_is_mbus_status_5_and_it_recovers(pair):
    plcs, press, master = pair
    started = time.monotonic()
    code, body = api(plcs, "PUT", {"offline": True})
    assert code == 200 and body["active"] and body["summary"]["faults"] == ["offline"], body
    assert press.comm_faults_on
    assert wait_for(lambda: status(master) == (5 << 8 | STATION)), hex(status(master))
    assert time.monotonic() - started >= 0.09  # the time-out had to pass
    set_press_r0(plcs, [8] * 10)
    passes = master.read("D102")[0]
    assert wait_for(lambda: master.read("D102")[0] >= passes + 2), "one pass per time-out"
    assert master.read("D2000", 10) == R0
    assert master.read("D103") == [0]  # no exception reply came
    code, body = api(plcs, "GET")
    assert code == 200 and body["figures"]["silenced"] >= 2, body
    code, body = api(plcs, "DELETE")
    assert code == 200 and not body["active"], body
    assert not press.comm_faults_on
    flows_again(plcs, master, [8] * 10)


# The faults are one PLC's: on the master they answer the master's own clients with exceptions
# and leave its MBUS polling alone; on the press they leave the master's clients alone.
def test_faults_belong_to_one_plc(pair):
    plcs, press, master = pair

    def master_d2000():
        url = f"{plcs.console_url}api/v1/plcs/master/devices/D2000?count=10"
        with urllib.request.urlopen(url, timeout=5) as r:
            return json.load(r)["values"]

    with master.comm_fault(exception=4):
        with pytest.raises(ModbusError, match="04h"):
            master.read("D2000")
        set_press_r0(plcs, [6] * 10)
        assert wait_for(lambda: master_d2000() == [6] * 10), master_d2000()
        assert not press.comm_faults_on
    with press.comm_fault(offline=True):
        assert wait_for(lambda: status(master) == (5 << 8 | STATION)), hex(status(master))
        for _ in range(20):
            t = time.monotonic()
            assert master.read("D2000", 10) == [6] * 10
            assert time.monotonic() - t < 0.05
    flows_again(plcs, master, [9] * 10)
