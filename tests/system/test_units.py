"""Unit IDs over TCP (docs/profile-fbs.md, "Modbus map"): the station, 0 and 255 are answered,
other units get exception 0Bh (or nothing, when configured); the station changes when a master
writes 55xxh to R4055."""

import socket
import struct
import time

from conftest import BASE_CONFIG, raw_exchange, raw_request

GATEWAY_TARGET_FAILED = 0x0B
READ_R0 = struct.pack(">BHH", 3, 0, 1)


def read_r0(port, unit):
    return raw_request(port, READ_R0, unit=unit)


def test_station_0_and_255_answered_others_0b(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "init: {R0: 4242}\n")
    # Modbus TCP implementation guide §4.4.1.2: over TCP, unit 0 addresses the device itself.
    for unit in (1, 0, 255):
        assert read_r0(d.port, unit) == bytes([3, 2]) + struct.pack(">H", 4242), unit
    for unit in (2, 17, 200, 247 + 1, 254):
        assert read_r0(d.port, unit) == bytes([0x83, GATEWAY_TARGET_FAILED]), unit
    # A write to another unit is refused and does not land.
    assert raw_request(d.port, struct.pack(">BHH", 6, 0, 1), unit=2) == bytes(
        [0x86, GATEWAY_TARGET_FAILED]
    )
    assert read_r0(d.port, 1) == bytes([3, 2]) + struct.pack(">H", 4242)


def test_pymodbus_sees_0b_as_exception(start_plcemud):
    d = start_plcemud(BASE_CONFIG)
    c = d.client()
    r = c.read_holding_registers(0, 1, slave=9)
    assert r.isError() and r.exception_code == GATEWAY_TARGET_FAILED
    assert not c.read_holding_registers(0, 1, slave=1).isError()
    assert not c.read_holding_registers(0, 1, slave=255).isError()


def test_configured_station(start_plcemud):
    d = start_plcemud(BASE_CONFIG + "station: 5\n")
    assert read_r0(d.port, 5)[0] == 3
    assert read_r0(d.port, 255)[0] == 3
    assert read_r0(d.port, 1) == bytes([0x83, GATEWAY_TARGET_FAILED])
    c = d.client()
    assert c.read_holding_registers(4055, 1, slave=5).registers == [5]


def test_unknown_unit_silent(start_plcemud):
    d = start_plcemud("profile: fbs\nmodbus: {tcp: {bind: 127.0.0.1, unknown_unit: silent}}\n")
    with socket.create_connection(("127.0.0.1", d.port), timeout=1.0) as s:
        assert raw_exchange(s, READ_R0, unit=3) is None  # nothing within the timeout
        # The connection stays usable: the next request to the station is answered.
        s.settimeout(3.0)
        assert raw_exchange(s, READ_R0, unit=1, tid=2)[0] == 3


def test_station_change_via_r4055(start_plcemud):
    """docs/profile-fbs.md, Scan cycle and special registers: R4055 low byte is the station, set
    by writing 55h in the high byte."""
    d = start_plcemud(BASE_CONFIG)
    c = d.client()
    assert c.read_holding_registers(4055, 1, slave=1).registers == [1]
    # Without 55h in the high byte the write is put back at the next scan.
    assert not c.write_register(4055, 0x0009, slave=1).isError()
    deadline = time.monotonic() + 5
    while c.read_holding_registers(4055, 1, slave=1).registers != [1]:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert read_r0(d.port, 9) == bytes([0x83, GATEWAY_TARGET_FAILED])

    assert not c.write_register(4055, 0x5507, slave=1).isError()
    deadline = time.monotonic() + 5
    while read_r0(d.port, 7)[0] != 3:
        assert time.monotonic() < deadline, "station 7 never answered"
        time.sleep(0.01)
    assert read_r0(d.port, 1) == bytes([0x83, GATEWAY_TARGET_FAILED])
    assert read_r0(d.port, 255)[0] == 3
    assert c.read_holding_registers(4055, 1, slave=7).registers == [7]
    # And back.
    assert not c.write_register(4055, 0x5501, slave=7).isError()
    deadline = time.monotonic() + 5
    while read_r0(d.port, 1)[0] != 3:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert read_r0(d.port, 7) == bytes([0x83, GATEWAY_TARGET_FAILED])
