"""The FATEK protocol (FBs manual, Appendix 2 FATEK Communication Protocol; docs/profile-fbs.md,
"FATEK protocol") through the real daemon: the acceptance scenarios byte for byte over TCP, UDP
and a serial pty pair, the frame checksum of the kit's client against the manual's worked
examples, and one image shared with Modbus.

Frames are written as in the manual: `<STX>` is the byte 02h, `<ETX>` 03h, the rest ASCII.
"""

import threading
import time

from conftest import free_port
from plcemu_testing.fatek import Fatek, checksum, frame, parse

NO_REPLY_S = 0.5  # what "no reply" waits, as a master's timeout would

# The start state: station 1 in RUN, every device 0 but these (R0-R2 = 1234, 0, 65535; M0, M2,
# X0, X3 ON; T0 value 5, C0 value 7, C200 value 100000 = 000186A0h, low word first). No program
# changes them, and the scans are frozen after the start.
START = """\
profile: fbs
modbus: {tcp: {bind: 127.0.0.1}}
persistence: {enabled: false}
init:
  R0: [1234, 0, 65535]
  R10: [0x5678, 0x1234]
  D0: 100
  M0: [1, 0, 1]
  X0: [1, 0, 0, 1]
  TMR0: 5
  CTR0: 7
  CTR200: [0x86A0, 1]
"""

# (step, request, expected reply; None: no reply) - run in order on one connection.
SCENARIOS = [
    ("1 gist status (40)", "<STX>0140C7<ETX>", "<STX>0140001000018<ETX>"),
    ("2 read R0-R2 (46)", "<STX>014603R0000072<ETX>", "<STX>0146004D20000FFFFAF<ETX>"),
    ("3 read M0-M2 (44)", "<STX>014403M00003B<ETX>", "<STX>014401018D<ETX>"),
    ("4 read DR10 = R11:R10 (46, 32-bit)", "<STX>014601DR00010B5<ETX>",
     "<STX>0146012345678A1<ETX>"),
    ("5 read D0 (46)", "<STX>014601D0000062<ETX>", "<STX>014600064C7<ETX>"),
    ("6 write R100,R101 = 1,2 (47)", "<STX>014702R0010000010002F6<ETX>", "<STX>01470FE<ETX>"),
    ("6 read back R100-R101", "<STX>014602R0010072<ETX>", "<STX>014600001000280<ETX>"),
    ("7 write Y0-Y2 = 1,0,1 (45)", "<STX>014503Y0000101DA<ETX>", "<STX>01450FC<ETX>"),
    ("7 read back Y0-Y2", "<STX>014403Y000047<ETX>", "<STX>014401018D<ETX>"),
    ("8 set M1 (42 code 3)", "<STX>01423M00010A<ETX>", "<STX>01420F9<ETX>"),
    ("8 read WM0 (46, packed M0-M15)", "<STX>014601WM000092<ETX>", "<STX>014600007C4<ETX>"),
    ("9 disable Y5 (42 code 1)", "<STX>01421Y000518<ETX>", "<STX>01420F9<ETX>"),
    ("9 read enable/disable flags Y4-Y6 (43)", "<STX>014303Y00044A<ETX>",
     "<STX>014300108B<ETX>"),
    ("10 mixed read R0, M0, DR10, X3, RT0 (48)",
     "<STX>014805R00000M0000DR00010X0003RT00008B<ETX>",
     "<STX>0148004D211234567810005A4<ETX>"),
    ("11 read 32-bit counter C200 (46 DRC)", "<STX>014601DRC0200C9<ETX>",
     "<STX>01460000186A09D<ETX>"),
    ("12 mixed write R200=ABCDh, M10=1 (49)", "<STX>014902R00200ABCDM00101BF<ETX>",
     "<STX>0149000<ETX>"),
    ("12 mixed read back R200, M10 (48)", "<STX>014802R00200M001083<ETX>",
     "<STX>01480ABCD13A<ETX>"),
    ("13 loop-back (4E)", "<STX>014EABCDEFGB8<ETX>", "<STX>014EABCDEFGB8<ETX>"),
    ("14 STOP (41)", "<STX>01410F8<ETX>", "<STX>01410F8<ETX>"),
    ("14 gist status after STOP (40)", "<STX>0140C7<ETX>", "<STX>0140000000017<ETX>"),
    ("14 RUN (41)", "<STX>01411F9<ETX>", "<STX>01410F8<ETX>"),
    ("15 detailed status (53)", "<STX>0153CB<ETX>",
     "<STX>01530010102408000010001000040004007D203E800001F880FA00100010022<ETX>"),
    ("16 error 2: 46 count 65", "<STX>014641R0000074<ETX>", "<STX>01462FF<ETX>"),
    ("17 error 2: 46 count 00 (=256)", "<STX>014600R000006F<ETX>", "<STX>01462FF<ETX>"),
    ("18 error A: R4200 does not exist", "<STX>014601R0420076<ETX>", "<STX>0146A0E<ETX>"),
    ("19 error A: WX0003 not a multiple of 8", "<STX>014601WX0003A0<ETX>",
     "<STX>0146A0E<ETX>"),
    ("20 error A: F file register absent", "<STX>014601F0000064<ETX>", "<STX>0146A0E<ETX>"),
    ("21 error 4: unknown command 4F", "<STX>014FDD<ETX>", "<STX>014F411<ETX>"),
    ("22 error 4: 47 value count mismatch", "<STX>014702R001000001064<ETX>",
     "<STX>0147402<ETX>"),
    ("23 error 3: write X0 while enabled (45)", "<STX>014501X0000176<ETX>",
     "<STX>01453FF<ETX>"),
    ("24 error 2: 42 running code 5", "<STX>01425M00010C<ETX>", "<STX>01422FB<ETX>"),
    ("25 no reply: bad checksum", "<STX>014603R0000000<ETX>", None),
    ("25 no reply: other station 02", "<STX>024603R0000073<ETX>", None),
    ("25 no reply: broadcast write R5=7 (00)", "<STX>004701R0000500073C<ETX>", None),
    ("25 R5 after broadcast", "<STX>014601R0000575<ETX>", "<STX>014600007C4<ETX>"),
]


def wire(text: str) -> bytes:
    """A frame written with <STX>/<ETX> as the bytes on the wire."""
    return text.replace("<STX>", "\x02").replace("<ETX>", "\x03").encode("ascii")


def shown(data) -> str:
    return "no reply" if data is None else data.decode("ascii", "replace").replace(
        "\x02", "<STX>").replace("\x03", "<ETX>")


def freeze(d):
    """Stops the scans (simulator unit 247, register 1) so nothing changes between steps."""
    assert not d.client().write_register(1, 1, slave=247).isError()


def run_scenarios(fatek):
    for step, request, expected in SCENARIOS:
        reply = fatek.exchange(wire(request), timeout=NO_REPLY_S if expected is None else 3)
        want = None if expected is None else wire(expected)
        assert reply == want, f"step {step}: {request} -> {shown(reply)}, expected {expected}"


# --- the frame and its checksum, without the daemon


def test_checksum_is_the_worked_examples_plain_sum():
    # The manual's worked examples: the low byte of the sum of STX..data, in hex.
    assert frame(1, 0x40) == wire("<STX>0140C7<ETX>")
    assert checksum(wire("<STX>01400010000")) == b"18"
    assert frame(1, 0x46, "03R00012") == wire("<STX>014603R0001275<ETX>")
    assert checksum(wire("<STX>0146010A57FC40001")) == b"89"
    assert checksum(wire("<STX>01490")) == b"00"  # 100h: the sum wraps to 00
    assert parse(wire("<STX>0146010A57FC4000189<ETX>")) == (1, 0x46, "010A57FC40001")


def test_every_scenario_frame_but_the_bad_one_carries_its_checksum():
    # Guards the table above against a typo: every frame checks, except the one meant not to.
    bad = [step for step, request, expected in SCENARIOS
           for f in (request, expected) if f is not None
           and checksum(wire(f)[:-3]) != wire(f)[-3:-1]]
    assert bad == ["25 no reply: bad checksum"]


# --- the scenarios through the daemon


def test_scenarios_over_tcp(start_plcemud):
    port = free_port()
    d = start_plcemud(START + f"fatek:\n  tcp: {{bind: 127.0.0.1, port: {port}}}\n")
    freeze(d)
    with Fatek.tcp(port) as fatek:
        run_scenarios(fatek)
        # The connection outlived the silent steps and still answers.
        assert fatek.exchange(wire("<STX>0140C7<ETX>")) == wire("<STX>0140001000018<ETX>")


def test_scenarios_over_udp(start_plcemud):
    port = free_port()
    d = start_plcemud(START + f"fatek:\n  udp: {{bind: 127.0.0.1, port: {port}}}\n")
    freeze(d)
    with Fatek.udp(port) as fatek:
        run_scenarios(fatek)


def answering(fatek, timeout=5.0):
    """Waits until the line answers a gist status request (the serial port opens at start)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if fatek.exchange(frame(fatek.station, 0x40), timeout=0.2) is not None:
            return True
    return False


def test_scenarios_over_a_serial_line(start_plcemud, pty):
    # 9600 7E1 as the manual's serial port; a pty carries the bytes whatever the character
    # format, so the master end stays raw (docs/testing.md, "FATEK on a pty").
    d = start_plcemud(START + f"fatek:\n  serial: {{device: {pty.slave}, baud: 9600, "
                              "data_bits: 7, parity: E, stop_bits: 1}\n")
    freeze(d)
    with Fatek.serial(pty.master) as fatek:
        assert answering(fatek), d.log_text()
        run_scenarios(fatek)


# --- one image, two protocols


def test_fatek_and_modbus_masters_see_each_others_writes(start_plcemud):
    # A FATEK master writes R100-R109 (47) and reads R200-R209 (46) while a Modbus master
    # writes holding 200-209 (FC16) and reads holding 100-109 (FC03): FBs R0-R4167 are holding
    # registers 0-4167. Each request is served between two scans, so a block of ten is always
    # read whole (all ten equal) and never goes backwards.
    port = free_port()
    d = start_plcemud(START + f"fatek:\n  tcp: {{bind: 127.0.0.1, port: {port}}}\n")
    modbus = d.client()
    stop = threading.Event()
    seen = {"fatek": [], "modbus": []}
    last = {"fatek": 0, "modbus": 0}
    failures = []

    def fatek_master():
        try:
            with Fatek.tcp(port, timeout=3) as fatek:
                k = 0
                while not stop.is_set():
                    k += 1
                    fatek.write("R100", [k] * 10)
                    last["fatek"] = k
                    seen["fatek"].append(fatek.read("R200", 10))
        except Exception as e:  # noqa: BLE001 - reported by the main thread
            failures.append(repr(e))

    thread = threading.Thread(target=fatek_master)
    thread.start()
    try:
        k, deadline = 0, time.monotonic() + 3
        while time.monotonic() < deadline and not failures:
            k += 1
            assert not modbus.write_registers(200, [k] * 10, slave=1).isError()
            last["modbus"] = k
            r = modbus.read_holding_registers(100, 10, slave=1)
            assert not r.isError(), r
            seen["modbus"].append(r.registers)
    finally:
        stop.set()
        thread.join(10)
    assert not failures, failures
    for master, blocks in seen.items():
        assert all(len(set(b)) == 1 for b in blocks), f"{master} read a torn block"
        firsts = [b[0] for b in blocks]
        assert firsts == sorted(firsts), f"{master} saw the other's writes go backwards"
        assert len(set(firsts)) > 10, f"{master} saw too few of the other's writes: {firsts}"
    with Fatek.tcp(port) as fatek:
        assert fatek.read("R200", 10) == [last["modbus"]] * 10
        assert fatek.read("R100", 10) == [last["fatek"]] * 10
        # The same registers through both protocols.
        assert fatek.read("R0", 64) == modbus.read_holding_registers(0, 64, slave=1).registers
    assert modbus.read_holding_registers(100, 10, slave=1).registers == [last["fatek"]] * 10


def test_station_follows_r4055_after_the_scan(start_plcemud):
    # R4055 = 55xxh sets the station (FBs manual, R4055), through either protocol: the write is
    # answered as station 1, the next scan makes the PLC station 2 for FATEK and Modbus alike.
    port = free_port()
    d = start_plcemud(START + f"fatek:\n  tcp: {{bind: 127.0.0.1, port: {port}}}\n")
    with Fatek.tcp(port) as fatek:
        assert fatek.exchange(frame(1, 0x47, "01R040555502")) == frame(1, 0x47, "0")
        deadline = time.monotonic() + 3
        while fatek.exchange(frame(2, 0x40), timeout=0.1) is None:
            assert time.monotonic() < deadline, "station 2 never answered"
        assert fatek.exchange(frame(2, 0x40)) == frame(2, 0x40, "0010000")
        assert fatek.exchange(frame(1, 0x40), timeout=NO_REPLY_S) is None  # no longer station 1
        assert fatek.exchange(frame(2, 0x46, "01R04055")) == frame(2, 0x46, "00002")
    assert d.client().read_holding_registers(4055, 1, slave=2).registers == [2]


def test_disabling_frees_an_input_for_a_master_but_no_protected_discrete(start_plcemud):
    # Error 3 (Decision X1 in docs/profile-fbs.md, "FATEK protocol"): an input (X) is written
    # only while disabled; the read-only specials and a `write_protect` range refuse a write
    # disabled or not, through every write command (42 set, 45, 49).
    port = free_port()
    d = start_plcemud(START.replace("modbus: {tcp: {bind: 127.0.0.1}}",
                                    "modbus: {tcp: {bind: 127.0.0.1}, write_protect: [M100-M109]}")
                      + f"fatek:\n  tcp: {{bind: 127.0.0.1, port: {port}}}\n")
    freeze(d)
    with Fatek.tcp(port) as fatek:
        before = {name: fatek.exchange(frame(1, 0x44, "01" + name)) for name in ("M0100", "M1920")}
        for name in ("X0001", "M0100", "M1920"):
            assert fatek.exchange(frame(1, 0x42, "3" + name)) == frame(1, 0x42, "3"), name
            assert fatek.exchange(frame(1, 0x42, "1" + name)) == frame(1, 0x42, "0"), name
            assert fatek.exchange(frame(1, 0x43, "01" + name)) == frame(1, 0x43, "01"), name
        assert fatek.exchange(frame(1, 0x42, "3X0001")) == frame(1, 0x42, "0")
        assert fatek.exchange(frame(1, 0x44, "01X0001")) == frame(1, 0x44, "01")
        for name in ("M0100", "M1920"):
            assert fatek.exchange(frame(1, 0x42, "3" + name)) == frame(1, 0x42, "3"), name
            assert fatek.exchange(frame(1, 0x45, "01" + name + "1")) == frame(1, 0x45, "3"), name
            assert fatek.exchange(frame(1, 0x49, "01" + name + "1")) == frame(1, 0x49, "3"), name
            assert fatek.exchange(frame(1, 0x44, "01" + name)) == before[name], name
