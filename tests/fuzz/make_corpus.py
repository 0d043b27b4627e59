#!/usr/bin/env python3
"""Writes the hand-made seed corpora of the request harnesses (tests/fuzz/corpus/fuzz_tcp_request
and fuzz_rtu_frame) and of the master's reply harness (fuzz_master_reply): a valid request of every function code docs/profile-fbs.md ("Modbus map")
lists, the quantity limits, refusals, and short sequences that set up the user remap or change
the station; and the seeds of fuzz_config_tree, each YAML seed of fuzz_config (kept as plain YAML
files) and each example config under config/ written in that harness's flow syntax
(python3-yaml). Run it after changing the seeds:
tests/fuzz/make_corpus.py
"""

import pathlib
import struct
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "system"))
from rtu_pty import crc16  # noqa: E402  (the system tests' RTU helpers, stdlib only)

HERE = pathlib.Path(__file__).resolve().parent
STATION = 1
SIM_UNIT = 247


def be16(*values):
    return b"".join(struct.pack(">H", v & 0xFFFF) for v in values)


def read(fc, addr, qty):
    return bytes([fc]) + be16(addr, qty)


def write_single(fc, addr, value):
    return bytes([fc]) + be16(addr, value)


def write_registers(addr, values):
    return bytes([0x10]) + be16(addr, len(values)) + bytes([2 * len(values)]) + be16(*values)


def write_coils(addr, bits):
    packed = bytearray((len(bits) + 7) // 8)
    for i, b in enumerate(bits):
        if b:
            packed[i // 8] |= 1 << (i % 8)
    return bytes([0x0F]) + be16(addr, len(bits)) + bytes([len(packed)]) + bytes(packed)


def mask_write(addr, and_mask, or_mask):
    return bytes([0x16]) + be16(addr, and_mask, or_mask)


def read_write(raddr, rqty, waddr, values):
    return (bytes([0x17]) + be16(raddr, rqty, waddr, len(values)) + bytes([2 * len(values)]) +
            be16(*values))


# name -> list of (unit, PDU); unit None means the station.
SEQUENCES = {
    # One valid request per function code.
    "fc01_read_y": [(None, read(0x01, 0, 16))],
    "fc01_read_x": [(None, read(0x01, 1000, 8))],
    "fc01_read_m": [(None, read(0x01, 2000, 2000))],
    "fc02_unmapped": [(None, read(0x02, 0, 8))],
    "fc03_read_r": [(None, read(0x03, 0, 125))],
    "fc03_read_d": [(None, read(0x03, 6000, 10))],
    "fc03_read_c32": [(None, read(0x03, 9700, 4))],
    "fc04_unmapped": [(None, read(0x04, 0, 1))],
    "fc05_set_m0": [(None, write_single(0x05, 2000, 0xFF00))],
    "fc05_bad_value": [(None, write_single(0x05, 2000, 0x1234))],
    "fc06_write_r100": [(None, write_single(0x06, 100, 1500))],
    "fc0f_write_y": [(None, write_coils(0, [1, 0, 1, 1, 0, 0, 1, 0, 1]))],
    "fc10_write_d": [(None, write_registers(6000, [1, 2, 3, 4]))],
    "fc16_mask_write": [(None, mask_write(100, 0x00F2, 0x0025))],
    "fc17_read_write": [(None, read_write(100, 4, 120, [10, 20, 30]))],
    "fc08_echo": [(None, bytes([0x08]) + be16(0, 0xA537))],
    "fc08_subfunction": [(None, bytes([0x08]) + be16(1, 0))],
    "fc11_report_id": [(None, bytes([0x11]))],
    "fc2b_basic_id": [(None, bytes([0x2B, 0x0E, 0x01, 0x00]))],
    "fc2b_regular_id": [(None, bytes([0x2B, 0x0E, 0x02, 0x00]))],
    "fc2b_one_object": [(None, bytes([0x2B, 0x0E, 0x04, 0x01]))],
    "fc_unknown": [(None, bytes([0x41, 0x00]))],
    # Quantity limits and refusals.
    "fc01_too_many": [(None, read(0x01, 2000, 2001))],
    "fc03_too_many": [(None, read(0x03, 0, 126))],
    "fc03_gap": [(None, read(0x03, 4160, 20))],
    "fc10_max": [(None, write_registers(6000, list(range(123))))],
    "fc0f_max": [(None, write_coils(2000, [1] * 1968))],
    "fc10_byte_count_wrong": [(None, bytes([0x10]) + be16(6000, 2) + bytes([3]) + be16(1, 2))],
    "fc05_write_x_refused": [(None, write_single(0x05, 1000, 0xFF00))],
    "fc06_write_ir_refused": [(None, write_single(0x06, 3840, 1))],
    "fc06_write_scan_time_refused": [(None, write_single(0x06, 4136, 1))],
    "fc06_write_protected_d100": [(None, write_single(0x06, 6100, 7))],
    "fc05_write_protected_m1000": [(None, write_single(0x05, 3000, 0xFF00))],
    # Unit IDs.
    "unit_255": [(255, read(0x03, 0, 2))],
    "unit_unknown": [(9, read(0x03, 0, 2))],
    "unit_simulator_read": [(SIM_UNIT, read(0x03, 0, 5))],
    "unit_simulator_step": [(SIM_UNIT, write_registers(1, [1, 3]))],
    "unit_simulator_faults": [(SIM_UNIT, write_registers(100, [0x0F, 250, 4000, 120, 5, 10]))],
    # Sequences that change what later requests mean.
    "remap_holding": [
        (None, write_registers(3968, [0xA55A, 100, 0, 50, 0, 0, 0, 0, 0, 0, 200, 5000, 20])),
        (None, read(0x03, 200, 20)),
        (None, read(0x01, 100, 50)),
    ],
    "user_map_inputs": [
        (None, write_registers(3972, [10, 800, 32, 20, 3840, 64])),
        (None, read(0x02, 10, 32)),
        (None, read(0x04, 20, 64)),
    ],
    "station_change": [
        (None, write_single(0x06, 4055, 0x5502)),
        (2, read(0x03, 4055, 1)),
        (1, read(0x03, 4055, 1)),
    ],
    "tpctl_start": [
        (None, write_coils(2800, [1] * 10)),
        (None, write_single(0x05, 2000, 0xFF00)),
        (None, read(0x03, 0, 10)),
        (None, read(0x03, 6000, 40)),
    ],
    "temperature_table_broken": [
        (None, write_registers(5000, [0xA556, 9, 10000, 20000, 0x0707, 0x0303])),
        (None, read(0x03, 0, 20)),
    ],
}


def tcp_stream(seq, control=0x01):
    out = bytearray([control])
    for tid, (unit, pdu) in enumerate(seq, start=1):
        unit = STATION if unit is None else unit
        out += be16(tid, 0, len(pdu) + 1) + bytes([unit]) + pdu
    return bytes(out)


def rtu_records(seq, control=0x01):
    out = bytearray([control])
    for unit, pdu in seq:
        body = bytes([STATION if unit is None else unit]) + pdu
        if len(body) > 255:
            return None
        out += bytes([len(body)]) + body
    return bytes(out)


def rtu_raw(chunks, control=0x81):
    """chunks: list of (pause in half characters, bytes)."""
    out = bytearray([control])
    for pause, data in chunks:
        out += bytes([len(data), pause]) + data
    return bytes(out)


def with_crc(frame):
    return frame + struct.pack("<H", crc16(frame))


def write(harness, name, data):
    d = HERE / "corpus" / harness
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data)


TREE_SPECIAL = set("{}[],:\n\"")


def tree_text(node, top=False):
    """A YAML document (every scalar a string) in fuzz_config_tree's flow syntax."""
    if isinstance(node, dict):
        sep = ",\n " if top else ", "
        return "{" + sep.join(f"{tree_text(k)}: {tree_text(v)}" for k, v in node.items()) + "}"
    if isinstance(node, list):
        return "[" + ", ".join(tree_text(v) for v in node) + "]"
    text = "" if node is None else str(node)
    if any(c in TREE_SPECIAL for c in text) or text != text.strip(" \t"):
        return '"' + text.replace('"', "") + '"'
    return text


def write_config_trees():
    import yaml  # python3-yaml, only for this

    for f in sorted((HERE / "corpus" / "fuzz_config").iterdir()):
        try:
            doc = yaml.load(f.read_text(), Loader=yaml.BaseLoader)
        except (yaml.YAMLError, UnicodeDecodeError):
            continue  # a seed of the YAML syntax itself
        write("fuzz_config_tree", f.name, (tree_text(doc, top=True) + "\n").encode())
    # Every example config of the repository: valid configs of every profile and instruction,
    # so the fuzzer starts from programs that build and scan.
    for f in sorted((HERE.parents[1] / "config").glob("*.yaml")):
        doc = yaml.load(f.read_text(), Loader=yaml.BaseLoader)
        write("fuzz_config_tree", "config_" + f.stem,
              (tree_text(doc, top=True) + "\n").encode())


def main():
    write_config_trees()
    for name, seq in SEQUENCES.items():
        write("fuzz_tcp_request", name, tcp_stream(seq))
        rec = rtu_records(seq)
        if rec is not None:
            write("fuzz_rtu_frame", name, rec)
    # TCP: edge cases of the framing itself.
    all_fcs = [s[0] for n, s in SEQUENCES.items() if n.startswith("fc")]
    write("fuzz_tcp_request", "pipelined_all_fcs", tcp_stream(all_fcs, control=0x03))
    write("fuzz_tcp_request", "silent_unknown_unit",
          tcp_stream([(9, read(0x03, 0, 2)), (None, read(0x03, 0, 2))], control=0x08))
    write("fuzz_tcp_request", "bad_protocol_closes",
          tcp_stream([(None, read(0x03, 0, 1))]) + be16(7, 1, 6) + bytes([1]) + read(0x03, 0, 1))
    write("fuzz_tcp_request", "bad_length_closes", b"\x00" + be16(1, 0, 255) + bytes([1, 3]))
    write("fuzz_tcp_request", "truncated_frame", tcp_stream([(None, read(0x03, 0, 1))])[:-2])
    write("fuzz_tcp_request", "length_too_short_pdu", b"\x00" + be16(1, 0, 2) + bytes([1, 3]))
    # RTU: broadcasts, other stations, and raw chunks through the framer.
    write("fuzz_rtu_frame", "broadcast_write",
          rtu_records([(0, write_registers(6000, [5, 6])), (None, read(0x03, 6000, 2))]))
    write("fuzz_rtu_frame", "broadcast_read_ignored", rtu_records([(0, read(0x03, 0, 1))]))
    write("fuzz_rtu_frame", "other_station", rtu_records([(7, read(0x03, 0, 1))]))
    good = with_crc(bytes([STATION]) + read(0x03, 0, 4))
    write("fuzz_rtu_frame", "raw_one_frame", rtu_raw([(0, good)]))
    write("fuzz_rtu_frame", "raw_split_chunks", rtu_raw([(0, good[:3]), (1, good[3:])]))
    write("fuzz_rtu_frame", "raw_two_frames_silence", rtu_raw([(0, good), (20, good)]))
    write("fuzz_rtu_frame", "raw_gap_in_frame", rtu_raw([(0, good[:3]), (5, good[3:])]))
    bad = bytearray(good)
    bad[-1] ^= 0xFF
    write("fuzz_rtu_frame", "raw_bad_crc", rtu_raw([(0, bytes(bad)), (20, good)]))
    write("fuzz_rtu_frame", "raw_too_long", rtu_raw([(0, bytes(200)), (0, bytes(100))]))

    master_replies()


MASTER_FCS = [1, 2, 3, 4, 5, 6, 15, 16]


def master_input(fc, addr, qty, station, reply, framed=False):
    """fuzz_master_reply: the request's header, then a reply PDU or raw chunks of RTU frames."""
    header = bytes([MASTER_FCS.index(fc)]) + be16(addr) + bytes([qty - 1, station - 1, framed])
    if not framed:
        return header + reply
    frame = with_crc(bytes([station]) + reply)
    return header + bytes([len(frame), 0]) + frame


def master_replies():
    """Replies a master gets: right ones of every function code, exceptions, wrong counts."""
    h = "fuzz_master_reply"
    cases = {
        "fc01_ok": (1, 0, 10, b"\x01\x02\x85\x02"),
        "fc02_ok": (2, 0, 3, b"\x02\x01\x05"),
        "fc03_ok": (3, 0, 2, b"\x03\x04\x12\x34\x00\x07"),
        "fc04_ok": (4, 100, 1, b"\x04\x02\xab\xcd"),
        "fc05_ok": (5, 7, 1, b"\x05\x00\x07\x00\x00"),
        "fc06_ok": (6, 7, 1, b"\x06\x00\x07\x00\x00"),
        "fc15_ok": (15, 0, 10, b"\x0f\x00\x00\x00\x0a"),
        "fc16_ok": (16, 1000, 5, b"\x10\x03\xe8\x00\x05"),
        "exception_0b": (16, 1000, 5, b"\x90\x0b"),
        "wrong_count": (3, 0, 2, b"\x03\x02\x12\x34"),
        "wrong_function": (3, 0, 1, b"\x04\x02\x12\x34"),
    }
    for name, (fc, addr, qty, reply) in cases.items():
        write(h, name, master_input(fc, addr, qty, 5, reply))
        write(h, "rtu_" + name, master_input(fc, addr, qty, 5, reply, framed=True))
    ok = with_crc(b"\x05\x03\x04\x12\x34\x00\x07")
    head = bytes([MASTER_FCS.index(3)]) + be16(0) + bytes([1, 4, 1])
    write(h, "rtu_split", head + bytes([3, 0]) + ok[:3] + bytes([len(ok) - 3, 1]) + ok[3:])
    write(h, "rtu_gap", head + bytes([3, 0]) + ok[:3] + bytes([len(ok) - 3, 5]) + ok[3:])
    write(h, "rtu_other_station", head + bytes([len(ok), 0]) + b"\x06" + ok[1:])


if __name__ == "__main__":
    main()
