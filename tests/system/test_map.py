"""The FBs Modbus map (FBs manual 13-50/51; docs/profile-fbs.md, "Modbus map") through Modbus
TCP against the real daemon: every row of the FBs manual's table read and written, the gaps,
read-only items, exceptions 01/02/03, the R3968/R3972/R3975 user maps, FC22 and FC23."""

import struct
import time

import pytest

from conftest import BASE_CONFIG, raw_request

ILLEGAL_FUNCTION = 1
ILLEGAL_ADDRESS = 2
ILLEGAL_VALUE = 3

# FBs manual 13-50/51: (manual 5-digit range, table, first wire, last wire, writable).
ROWS = [
    ("00001-00256 Y0-Y255", "coil", 0, 255, True),
    ("01001-01256 X0-X255", "coil", 1000, 1255, False),
    ("02001-04002 M0-M2001", "coil", 2000, 4001, True),
    ("06001-07000 S0-S999", "coil", 6000, 6999, True),
    ("09001-09256 T0-T255 status", "coil", 9000, 9255, True),
    ("09501-09756 C0-C255 status", "coil", 9500, 9755, True),
    ("40001-44168 R0-R4167", "reg", 0, 4167, True),
    ("45001-45999 R5000-R5998", "reg", 5000, 5998, True),
    ("46001-48999 D0-D2998", "reg", 6000, 8998, True),
    ("49001-49256 T0-T255 value", "reg", 9000, 9255, True),
    ("49501-49700 C0-C199 value", "reg", 9500, 9699, True),
    ("49701-49812 C200-C255 value", "reg", 9700, 9811, True),
]

# Registers the engine rewrites every scan: a write is accepted but does not stick.
ENGINE_KEPT = {4167}


def exc(resp):
    """The exception code of a pymodbus response, 0 when it is not an exception."""
    assert resp is not None
    return getattr(resp, "exception_code", 0) if resp.isError() else 0


def pdu_exception(reply):
    assert reply is not None, "no reply"
    if reply[0] & 0x80:
        return reply[1]
    return 0


@pytest.fixture
def plc(start_plcemud):
    d = start_plcemud(BASE_CONFIG)
    return d.client()


@pytest.mark.parametrize("row", ROWS, ids=[r[0] for r in ROWS])
def test_every_row_reads_and_writes_first_and_last(plc, row):
    _, table, first, last, writable = row
    mid = (first + last) // 2
    for a in (first, mid, last):
        if table == "coil":
            r = plc.read_coils(a, 1, slave=1)
            assert exc(r) == 0, f"read coil {a}"
            w = plc.write_coil(a, True, slave=1)
            if not writable:
                assert exc(w) == ILLEGAL_ADDRESS
                assert plc.read_coils(a, 1, slave=1).bits[0] is False
                continue
            assert exc(w) == 0, f"write coil {a}"
            assert plc.read_coils(a, 1, slave=1).bits[0] is True
            assert exc(plc.write_coils(a, [False], slave=1)) == 0
            assert plc.read_coils(a, 1, slave=1).bits[0] is False
        else:
            r = plc.read_holding_registers(a, 1, slave=1)
            assert exc(r) == 0, f"read register {a}"
            if a in ENGINE_KEPT:
                continue
            v = (0x1000 + a) & 0xFFFF
            assert exc(plc.write_register(a, v, slave=1)) == 0, f"write register {a}"
            assert plc.read_holding_registers(a, 1, slave=1).registers == [v]
            assert exc(plc.write_registers(a, [v ^ 0xFFFF], slave=1)) == 0
            assert plc.read_holding_registers(a, 1, slave=1).registers == [v ^ 0xFFFF]
    # The element after the last is a gap (except C199 -> C200, which continue each other).
    if last != 9699:
        if table == "coil":
            assert exc(plc.read_coils(last, 2, slave=1)) == ILLEGAL_ADDRESS
        else:
            assert exc(plc.read_holding_registers(last, 2, slave=1)) == ILLEGAL_ADDRESS


def test_rows_hold_distinct_devices(plc):
    """Each wire address is its own device: a pattern written over a whole row reads back."""
    for _, table, first, last, writable in ROWS:
        if not writable:
            continue
        if table == "coil":
            for a in range(first, last + 1, 1968):
                n = min(1968, last + 1 - a)
                bits = [(a + k) % 3 == 0 for k in range(n)]
                # M1920-M1927 are read-only: write around them.
                if a <= 3920 < a + n:
                    split = 3920 - a
                    assert exc(plc.write_coils(a, bits[:split], slave=1)) == 0
                    assert exc(plc.write_coils(3928, bits[split + 8 :], slave=1)) == 0
                else:
                    assert exc(plc.write_coils(a, bits, slave=1)) == 0
                got = plc.read_coils(a, n, slave=1).bits[:n]
                for k in range(n):
                    if not 3920 <= a + k <= 3927:
                        assert got[k] == bits[k], f"coil {a + k}"
        else:
            for a in range(first, last + 1, 123):
                n = min(123, last + 1 - a)
                vals = [(a + k) & 0xFFFF for k in range(n)]
                ro = [x for x in range(a, a + n) if 3840 <= x <= 3903 or 4136 <= x <= 4138]
                if ro:
                    continue  # the read-only items have their own test
                assert exc(plc.write_registers(a, vals, slave=1)) == 0, f"register {a}"
                got = plc.read_holding_registers(a, n, slave=1).registers
                for k in range(n):
                    if a + k not in ENGINE_KEPT and not 4049 <= a + k <= 4138:
                        assert got[k] == vals[k], f"register {a + k}"


@pytest.mark.parametrize("addr", [256, 999, 1256, 1999, 4002, 5999, 7000, 8999, 9256, 9499, 9756, 65535])
def test_coil_gaps_are_illegal_address(plc, addr):
    assert exc(plc.read_coils(addr, 1, slave=1)) == ILLEGAL_ADDRESS
    assert exc(plc.write_coil(addr, True, slave=1)) == ILLEGAL_ADDRESS
    assert exc(plc.write_coils(addr, [True], slave=1)) == ILLEGAL_ADDRESS


@pytest.mark.parametrize("addr", [4168, 4999, 5999, 8999, 9256, 9499, 9812, 65535])
def test_register_gaps_are_illegal_address(plc, addr):
    """Including R4168-R4999, R5999-R8071 and D2999-D3999, which exist but are not mapped."""
    assert exc(plc.read_holding_registers(addr, 1, slave=1)) == ILLEGAL_ADDRESS
    assert exc(plc.write_register(addr, 1, slave=1)) == ILLEGAL_ADDRESS
    assert exc(plc.write_registers(addr, [1], slave=1)) == ILLEGAL_ADDRESS


def test_request_touching_a_gap_is_refused_whole(plc):
    assert exc(plc.write_registers(4160, [7] * 8, slave=1)) == 0
    assert exc(plc.write_registers(4160, [9] * 9, slave=1)) == ILLEGAL_ADDRESS
    assert plc.read_holding_registers(4160, 2, slave=1).registers == [7, 7]
    assert exc(plc.read_holding_registers(4100, 100, slave=1)) == ILLEGAL_ADDRESS


@pytest.mark.parametrize(
    "name,table,addr",
    [
        ("X0", "coil", 1000),
        ("X255", "coil", 1255),
        ("M1920", "coil", 3920),
        ("M1927", "coil", 3927),
        ("IR R3840", "reg", 3840),
        ("IR R3903", "reg", 3903),
        ("R4136", "reg", 4136),
        ("R4138", "reg", 4138),
    ],
)
def test_read_only_items_refuse_writes_unchanged(plc, name, table, addr):
    """docs/profile-fbs.md, Modbus map: writes to read-only items get exception 02 and change
    nothing."""
    if table == "coil":
        before = plc.read_coils(addr, 1, slave=1).bits[0]
        if addr in (3920, 3927):
            before = None  # clocks move by themselves
        assert exc(plc.write_coil(addr, True, slave=1)) == ILLEGAL_ADDRESS
        assert exc(plc.write_coils(addr, [False], slave=1)) == ILLEGAL_ADDRESS
        if before is not None:
            assert plc.read_coils(addr, 1, slave=1).bits[0] == before
    else:
        before = plc.read_holding_registers(addr, 1, slave=1).registers[0]
        assert exc(plc.write_register(addr, 0x7777, slave=1)) == ILLEGAL_ADDRESS
        assert exc(plc.write_registers(addr, [0x7777], slave=1)) == ILLEGAL_ADDRESS
        assert exc(plc.mask_write_register(addr, 0, 0x7777, unit=1)) == ILLEGAL_ADDRESS
        rw = plc.readwrite_registers(
            read_address=0, read_count=1, write_address=addr, write_registers=[0x7777], unit=1
        )
        assert exc(rw) == ILLEGAL_ADDRESS
        after = plc.read_holding_registers(addr, 1, slave=1).registers[0]
        assert after == before and after != 0x7777


def test_read_only_scan_time_reads_scan_ms(plc):
    """R4136-R4138 hold the scan time in ms (the default 10 ms)."""
    assert plc.read_holding_registers(4136, 3, slave=1).registers == [10, 10, 10]


def test_special_relays_and_model_code(plc):
    """M1926 RUN is ON; R4167 is the FBs-24MC model code 0118h, kept even after a write."""
    assert plc.read_coils(3926, 1, slave=1).bits[0] is True
    assert plc.read_holding_registers(4167, 1, slave=1).registers == [0x0118]
    assert exc(plc.write_register(4167, 0, slave=1)) == 0
    deadline = time.monotonic() + 10  # the next scan puts it back
    while plc.read_holding_registers(4167, 1, slave=1).registers != [0x0118]:
        assert time.monotonic() < deadline, "R4167 not restored by the scan"
        time.sleep(0.005)


def test_32bit_counters_low_word_first(plc):
    """docs/profile-fbs.md, Modbus map: C200-C255 current values take 2 registers, low word
    first."""
    assert exc(plc.write_registers(9700, [0x5678, 0x1234], slave=1)) == 0
    assert plc.read_holding_registers(9700, 2, slave=1).registers == [0x5678, 0x1234]
    assert exc(plc.write_registers(9810, [0xCDEF, 0x89AB], slave=1)) == 0  # C255
    assert plc.read_holding_registers(9810, 2, slave=1).registers == [0xCDEF, 0x89AB]
    assert exc(plc.read_holding_registers(9811, 2, slave=1)) == ILLEGAL_ADDRESS


def test_quantity_limits_illegal_value(start_plcemud):
    """docs/profile-fbs.md, Modbus map: FC01/02 1-2000, FC03/04 1-125, FC15 1-1968, FC16 1-123,
    FC23 read 1-125 / write 1-121, byte counts consistent, FC05 0000h/FF00h; else exception 03."""
    d = start_plcemud(BASE_CONFIG + "init: {R3972: [0, 0, 2002], R3975: [0, 0, 3000]}\n")
    port = d.port

    def read(fc, addr, qty):
        return pdu_exception(raw_request(port, struct.pack(">BHH", fc, addr, qty)))

    for fc, start, limit in ((1, 2000, 2000), (2, 0, 2000), (3, 0, 125), (4, 0, 125)):
        assert read(fc, start, 0) == ILLEGAL_VALUE, fc
        assert read(fc, start, 1) == 0, fc
        assert read(fc, start, limit) == 0, fc
        assert read(fc, start, limit + 1) == ILLEGAL_VALUE, fc

    def fc15(qty, nbytes=None, extra=0):
        nbytes = (qty + 7) // 8 if nbytes is None else nbytes
        pdu = struct.pack(">BHHB", 15, 6000, qty, nbytes) + b"\x00" * (nbytes + extra)
        return pdu_exception(raw_request(port, pdu))

    assert fc15(1) == 0
    assert fc15(1000) == 0
    assert fc15(0, 0) == ILLEGAL_VALUE
    assert fc15(1969) == ILLEGAL_VALUE
    assert fc15(9, 1) == ILLEGAL_VALUE
    assert fc15(8, 2) == ILLEGAL_VALUE

    def fc16(qty, nbytes=None):
        nbytes = 2 * qty if nbytes is None else nbytes
        pdu = struct.pack(">BHHB", 16, 6000, qty, nbytes) + b"\x00\x01" * (nbytes // 2)
        return pdu_exception(raw_request(port, pdu))

    assert fc16(123) == 0
    assert fc16(0, 0) == ILLEGAL_VALUE
    # 124 registers do not fit a Modbus TCP frame (length field <= 254): the quantity field says
    # 124 over a byte count that fits.
    assert fc16(124, 240) == ILLEGAL_VALUE
    assert fc16(2, 2) == ILLEGAL_VALUE

    def fc23(rqty, wqty, nbytes=None):
        nbytes = 2 * wqty if nbytes is None else nbytes
        pdu = struct.pack(">BHHHHB", 23, 0, rqty, 6000, wqty, nbytes) + b"\x00\x02" * (nbytes // 2)
        return pdu_exception(raw_request(port, pdu))

    assert fc23(125, 121) == 0
    assert fc23(126, 1) == ILLEGAL_VALUE
    assert fc23(0, 1) == ILLEGAL_VALUE
    assert fc23(1, 122, 240) == ILLEGAL_VALUE
    assert fc23(1, 0, 0) == ILLEGAL_VALUE
    assert fc23(1, 2, 2) == ILLEGAL_VALUE

    for value in (0x0001, 0x00FF, 0xFFFF, 0xFF01):
        assert pdu_exception(raw_request(port, struct.pack(">BHH", 5, 2000, value))) == ILLEGAL_VALUE
    assert pdu_exception(raw_request(port, struct.pack(">BHH", 5, 2000, 0xFF00))) == 0


def test_unsupported_function_codes_illegal_function(daemon):
    """docs/profile-fbs.md, Modbus map: function codes the emulator does not implement get
    exception 01."""
    for fc in (0x07, 0x0B, 0x0C, 0x14, 0x15, 0x18, 0x41, 0x64):
        reply = raw_request(daemon.port, bytes([fc, 0, 0, 0, 1]))
        assert reply is not None and reply[0] == fc | 0x80 and reply[1] == ILLEGAL_FUNCTION, hex(fc)


def test_fc02_fc04_without_map_are_illegal_function(plc):
    """docs/profile-fbs.md, Modbus map: with R3974 / R3977 = 0 (the default) FC02 / FC04 are not
    served."""
    assert exc(plc.read_discrete_inputs(0, 1, slave=1)) == ILLEGAL_FUNCTION
    assert exc(plc.read_input_registers(0, 1, slave=1)) == ILLEGAL_FUNCTION


def test_fc02_fc04_user_maps(plc):
    """FBs manual 13-50/51: FC02 R3972.. (count R3974) -> M(R3973)..; FC04 R3975.. (count
    R3977) -> R(R3976).., set at run time by a master."""
    assert exc(plc.write_registers(3972, [100, 500, 16, 200, 4128, 11], slave=1)) == 0
    assert exc(plc.write_coils(2500, [True, False, True], slave=1)) == 0  # M500-M502
    bits = plc.read_discrete_inputs(100, 16, slave=1).bits
    assert bits[:3] == [True, False, True]
    assert exc(plc.read_discrete_inputs(99, 1, slave=1)) == ILLEGAL_ADDRESS
    assert exc(plc.read_discrete_inputs(115, 2, slave=1)) == ILLEGAL_ADDRESS
    regs = plc.read_input_registers(200, 11, slave=1).registers  # R4128-R4138
    assert 0 <= regs[0] <= 59 and 1 <= regs[4] <= 12  # calendar: second, month
    assert regs[8:] == [10, 10, 10]  # scan times
    assert exc(plc.read_input_registers(211, 1, slave=1)) == ILLEGAL_ADDRESS
    # The maps are independent of R3968, and a count of 0 switches them off again.
    assert exc(plc.write_register(3974, 0, slave=1)) == 0
    assert exc(plc.read_discrete_inputs(100, 1, slave=1)) == ILLEGAL_FUNCTION
    assert exc(plc.read_input_registers(200, 1, slave=1)) == 0


def test_r3968_remap_and_back(plc):
    """FBs manual 13-50/51: R3968 = A55Ah replaces the coil map (R3969-R3971) and the
    holding-register map (R3978-R3980); any other value restores the manual's table."""
    # Coils 0-9 -> M100-M109; registers 3968-3980 -> R3968-R3980 (so we can switch back) ...
    assert exc(plc.write_registers(3969, [0, 100, 10], slave=1)) == 0
    assert exc(plc.write_registers(3978, [3968, 3968, 13], slave=1)) == 0
    assert exc(plc.write_coil(0, True, slave=1)) == 0  # Y0 under the manual's table
    assert exc(plc.write_register(3968, 0xA55A, slave=1)) == 0
    # ... now coil 0 is M100 (OFF), and Y0 is unreachable.
    assert plc.read_coils(0, 1, slave=1).bits[0] is False
    assert exc(plc.write_coil(5, True, slave=1)) == 0  # M105
    assert exc(plc.read_coils(10, 1, slave=1)) == ILLEGAL_ADDRESS
    assert exc(plc.read_coils(2000, 1, slave=1)) == ILLEGAL_ADDRESS
    assert exc(plc.read_holding_registers(0, 1, slave=1)) == ILLEGAL_ADDRESS
    assert exc(plc.read_holding_registers(6000, 1, slave=1)) == ILLEGAL_ADDRESS
    assert plc.read_holding_registers(3968, 1, slave=1).registers == [0xA55A]
    assert exc(plc.read_holding_registers(3980, 2, slave=1)) == ILLEGAL_ADDRESS
    # Any other value: the manual's table again.
    assert exc(plc.write_register(3968, 0, slave=1)) == 0
    assert plc.read_coils(0, 1, slave=1).bits[0] is True  # Y0
    assert plc.read_coils(2105, 1, slave=1).bits[0] is True  # M105, written through the remap
    assert exc(plc.read_holding_registers(6000, 1, slave=1)) == 0


def test_fc22_mask_write(plc):
    assert exc(plc.write_register(6004, 0x0012, slave=1)) == 0
    r = plc.mask_write_register(6004, 0x00F2, 0x0025, unit=1)
    assert exc(r) == 0
    assert plc.read_holding_registers(6004, 1, slave=1).registers == [0x0017]


def test_fc23_read_write_different_areas(plc):
    assert exc(plc.write_registers(0, [0x1111, 0x2222], slave=1)) == 0
    r = plc.readwrite_registers(
        read_address=0, read_count=2, write_address=6000, write_registers=[0xAAAA, 0xBBBB], unit=1
    )
    assert exc(r) == 0
    assert r.registers == [0x1111, 0x2222]
    assert plc.read_holding_registers(6000, 2, slave=1).registers == [0xAAAA, 0xBBBB]
    # The write is done before the read.
    r = plc.readwrite_registers(
        read_address=6000, read_count=2, write_address=6001, write_registers=[0x0101], unit=1
    )
    assert r.registers == [0xAAAA, 0x0101]


def test_fc05_fc06_echo_and_fc08_echo(daemon):
    for pdu in (struct.pack(">BHH", 5, 2010, 0xFF00), struct.pack(">BHH", 6, 6010, 0xBEEF),
                bytes([0x08, 0, 0, 0x12, 0x34])):
        assert raw_request(daemon.port, pdu) == pdu


def test_device_identification(daemon):
    """docs/profile-fbs.md, Modbus map: 2Bh/0Eh: vendor FATEK, product code the model, revision the
    version."""
    reply = raw_request(daemon.port, bytes([0x2B, 0x0E, 0x01, 0x00]))
    assert reply[:2] == bytes([0x2B, 0x0E])
    count = reply[6]
    objects, k = {}, 7
    for _ in range(count):
        oid, n = reply[k], reply[k + 1]
        objects[oid] = reply[k + 2 : k + 2 + n].decode()
        k += 2 + n
    assert objects[0] == "FATEK"
    assert objects[1] == "FBs-24MC"
    assert objects[2]  # the emulator's version
    report = raw_request(daemon.port, bytes([0x11]))
    assert report[0] == 0x11 and b"FBs-24MC" in report
