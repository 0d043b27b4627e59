"""The pytest kit's FATEK master, `plc.fatek` (docs/testing.md, "The FATEK protocol"): device
names as the FATEK protocol writes them, values of every width, RUN/STOP, errors with their
code, silence as a timeout, UDP, and several PLCs sharing one FATEK listener."""

import pytest

from plcemu_testing import DaemonError, DeviceError, Fatek, FatekError, FatekTimeout

FBS = {"profile": "fbs", "fatek": {"tcp": {}}, "persistence": {"enabled": False}}


def test_reads_and_writes_what_modbus_sees(plcemud):
    plc = plcemud({**FBS, "init": {"R0": [1234, 0, 65535], "M0": [1, 0, 1],
                                   "R10": [0x5678, 0x1234], "CTR200": [0x86A0, 1]}})
    plc.freeze()
    fatek = plc.fatek
    assert fatek.read("R0", 3) == [1234, 0, 65535]
    assert fatek.read("M0", 3) == fatek.read_bits("M0", 3) == [1, 0, 1]
    assert fatek.read("DR10") == [0x12345678]  # R11:R10
    assert fatek.read("DRC200") == [100000]  # C200, a 32-bit counter
    assert fatek.read("WM0") == [0b101]
    fatek.write("R100", [1, 2])
    fatek.write("Y0", [1, 0, 1])
    fatek.write("DD10", 0x0001ABCD)  # D11:D10
    assert plc.read("R100", 2) == [1, 2]
    assert plc.read_bits("Y0", 3) == [1, 0, 1]
    assert plc.read("D10", 2) == [0xABCD, 1]
    plc.write("R300", list(range(100)))  # more than one 46 request takes (64 words)
    assert fatek.read("R300", 100) == list(range(100))
    fatek.write_bits("M100", [1] * 300)  # more than one 45 request takes (256 discretes)
    assert plc.read_bits("M100", 301) == [1] * 300 + [0]


def test_run_stop_and_status(plcemud):
    plc = plcemud(FBS)
    fatek = plc.fatek
    assert fatek.status()["running"] is True
    fatek.stop()
    assert fatek.status() == {"running": False, "emergency_stop": False, "s1": 0, "s2": 0,
                              "s3": 0}
    fatek.run()
    assert fatek.status()["running"] is True


def test_errors_carry_the_fatek_code(plcemud):
    plc = plcemud(FBS)
    fatek = plc.fatek
    with pytest.raises(FatekError) as e:
        fatek.read("R4200")
    assert e.value.code == 0xA and "R04200" in str(e.value) and "illegal address" in str(e.value)
    with pytest.raises(FatekError) as e:
        fatek.write("X0", 1)  # an input, not disabled
    assert e.value.code == 3
    with pytest.raises(DeviceError):
        fatek.read_bits("R0")
    # request() returns the code rather than raising it; 4E has none.
    assert fatek.request(0x4F) == (4, "")
    assert fatek.request("4E", "HELLO") == (0, "HELLO")
    # Another station is silent: a timeout, and the line still works afterwards.
    fatek.station = 9
    with pytest.raises(FatekTimeout):
        fatek.read("R0")
    fatek.station = plc.station
    assert fatek.read("R0") == [0]


def test_over_udp(plcemud):
    plc = plcemud({"profile": "fbs", "fatek": {"udp": {}}, "init": {"D0": 100}})
    assert plc.fatek.read("D0") == [100]
    plc.fatek.write("D1", 5)
    assert plc.read("D1") == [5]


def test_a_config_without_fatek_says_so(plcemud):
    plc = plcemud({"profile": "fbs"})
    with pytest.raises(DaemonError, match="no fatek.tcp or fatek.udp listener"):
        plc.fatek.read("R0")


def test_plcs_sharing_a_fatek_listener_answer_their_own_station(plcemud):
    shared = {"tcp": {}}
    plcs = plcemud({"plcs": [
        {"name": "a", "profile": "fbs", "station": 1, "fatek": shared, "init": {"R0": 11}},
        {"name": "b", "profile": "fbs", "station": 2, "fatek": shared, "init": {"R0": 22}},
    ]})
    assert plcs["a"].fatek.read("R0") == [11]
    assert plcs["b"].fatek.read("R0") == [22]
    plcs["b"].fatek.write("R1", 5)
    assert plcs["b"].read("R1") == [5] and plcs["a"].read("R1") == [0]
    # One listener: the same port, each client at its PLC's station.
    a, b = plcs["a"].fatek, plcs["b"].fatek
    assert a.line.sock.getpeername() == b.line.sock.getpeername()
    assert (a.station, b.station) == (1, 2)
    plcs.restart()  # new clients on the same listener
    assert plcs["a"].fatek is not a and isinstance(plcs["a"].fatek, Fatek)
    assert plcs["a"].fatek.read("R0") == [11] and plcs["b"].fatek.read("R0") == [22]
