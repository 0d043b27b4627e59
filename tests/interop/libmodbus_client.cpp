// Interoperability check with libmodbus' master API: round trips of FC 01 02 03 04 05 06 15 16
// 22 23 and 11h, and each exception plcemud sends, against a running daemon. (libmodbus cannot
// receive FC08 or 2Bh replies: those are checked with pymodbus and raw frames.)
// Run by tests/system/test_interop.py; exits 1 with a message on the first mismatch.
//
// Usage: libmodbus_client tcp HOST PORT
//        libmodbus_client rtu DEVICE BAUD PARITY   (parity N, E or O; 8 data bits, 1 stop bit)
// The daemon must serve station 1 with the user maps DI 0.. -> M100.. and IR 0.. -> R200...

#include <modbus/modbus.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace {

using Ctx = std::unique_ptr<modbus_t, decltype(&modbus_free)>;

int failures = 0;

void fail(const std::string& what) {
    std::fprintf(stderr, "MISMATCH: %s\n", what.c_str());
    ++failures;
}

std::string hex(const std::vector<std::uint16_t>& v) {
    std::string s;
    for (auto x : v) {
        char b[8];
        std::snprintf(b, sizeof b, "%04X ", x);
        s += b;
    }
    return s;
}

// A call that must succeed.
bool ok(int rc, const char* what) {
    if (rc < 0) {
        fail(std::string(what) + ": " + modbus_strerror(errno));
        return false;
    }
    return true;
}

// A call that must fail with Modbus exception `code`.
void expect_exception(int rc, int code, const char* what) {
    if (rc >= 0) {
        fail(std::string(what) + ": succeeded, expected exception " + std::to_string(code));
    } else if (errno != MODBUS_ENOBASE + code) {
        fail(std::string(what) + ": " + modbus_strerror(errno) + ", expected exception " +
             std::to_string(code));
    }
}

void expect_words(modbus_t* ctx,
                  int addr,
                  const std::vector<std::uint16_t>& want,
                  const char* what) {
    std::vector<std::uint16_t> got(want.size());
    if (!ok(modbus_read_registers(ctx, addr, static_cast<int>(want.size()), got.data()), what)) {
        return;
    }
    if (got != want) fail(std::string(what) + ": read " + hex(got) + "expected " + hex(want));
}

void expect_bits(
    modbus_t* ctx, int addr, const std::vector<std::uint8_t>& want, bool input, const char* what) {
    std::vector<std::uint8_t> got(want.size());
    const int n = static_cast<int>(want.size());
    const int rc = input ? modbus_read_input_bits(ctx, addr, n, got.data())
                         : modbus_read_bits(ctx, addr, n, got.data());
    if (!ok(rc, what)) return;
    if (got != want) fail(std::string(what) + ": bits differ");
}

// Sends a raw PDU for unit 1 and returns the reply PDU (empty and errno set on failure).
std::vector<std::uint8_t> raw(modbus_t* ctx, std::vector<std::uint8_t> pdu) {
    pdu.insert(pdu.begin(), 1);  // unit
    if (modbus_send_raw_request(ctx, pdu.data(), static_cast<int>(pdu.size())) < 0) return {};
    std::vector<std::uint8_t> rsp(MODBUS_MAX_ADU_LENGTH);
    const int n = modbus_receive_confirmation(ctx, rsp.data());
    if (n < 0) return {};
    const int header = modbus_get_header_length(ctx);
    const int trailer = header == 1 ? 2 : 0;  // RTU: CRC
    return {rsp.begin() + header, rsp.begin() + n - trailer};
}

// Sends a raw request and checks that the reply is exception `code` to it.
void expect_raw_exception(modbus_t* ctx,
                          const std::vector<std::uint8_t>& pdu,
                          int code,
                          const char* what) {
    const auto rsp = raw(ctx, pdu);
    if (rsp.empty()) {
        fail(std::string(what) + ": " + modbus_strerror(errno));
    } else if (rsp.size() != 2 || rsp[0] != (pdu[0] | 0x80) || rsp[1] != code) {
        fail(std::string(what) + ": reply is not exception " + std::to_string(code));
    }
}

void check(modbus_t* ctx, bool tcp) {
    // 06, 03
    ok(modbus_write_register(ctx, 10, 0x1234), "FC06 R10");
    expect_words(ctx, 10, {0x1234}, "FC03 R10");
    // 16, 03 on D0-D2 (register 6000)
    const std::uint16_t d[3] = {1, 2, 3};
    ok(modbus_write_registers(ctx, 6000, 3, d), "FC16 D0-D2");
    expect_words(ctx, 6000, {1, 2, 3}, "FC03 D0-D2");
    // 05, 01 on M0 (coil 2000)
    ok(modbus_write_bit(ctx, 2000, 1), "FC05 M0");
    ok(modbus_write_bit(ctx, 2001, 0), "FC05 M1");
    expect_bits(ctx, 2000, {1, 0}, false, "FC01 M0-M1");
    // 15, 01 on Y0-Y2
    const std::uint8_t y[3] = {1, 0, 1};
    ok(modbus_write_bits(ctx, 0, 3, y), "FC15 Y0-Y2");
    expect_bits(ctx, 0, {1, 0, 1}, false, "FC01 Y0-Y2");
    // 22: (0x1234 AND 00FFh) OR (5600h AND NOT 00FFh) = 5634h
    ok(modbus_mask_write_register(ctx, 10, 0x00FF, 0x5600), "FC22 R10");
    expect_words(ctx, 10, {0x5634}, "FC03 after FC22");
    // 23: the write lands before the read
    const std::uint16_t w[1] = {0x0BAD};
    std::uint16_t r[2] = {0, 0};
    if (ok(modbus_write_and_read_registers(ctx, 11, 1, w, 10, 2, r), "FC23")) {
        if (r[0] != 0x5634 || r[1] != 0x0BAD) fail("FC23: read " + hex({r[0], r[1]}));
    }
    // 02: DI 0.. -> M100..
    ok(modbus_write_bit(ctx, 2100, 1), "FC05 M100");
    ok(modbus_write_bit(ctx, 2101, 0), "FC05 M101");
    expect_bits(ctx, 0, {1, 0}, true, "FC02 DI0-DI1");
    // 04: IR 0.. -> R200..
    ok(modbus_write_register(ctx, 200, 4242), "FC06 R200");
    std::uint16_t ir = 0;
    if (ok(modbus_read_input_registers(ctx, 0, 1, &ir), "FC04 IR0") && ir != 4242) {
        fail("FC04 IR0: read " + std::to_string(ir));
    }
    // 11h: slave ID = station, run indicator ON, then text
    std::uint8_t id[MODBUS_MAX_PDU_LENGTH] = {};
    const int n = modbus_report_slave_id(ctx, sizeof id, id);
    if (ok(n, "FC11h")) {
        const std::string text(reinterpret_cast<const char*>(id + 2),
                               static_cast<std::size_t>(n > 2 ? n - 2 : 0));
        if (id[0] != 1 || id[1] != 0xFF || text.rfind("FATEK FBs-24MC", 0) != 0) {
            fail("FC11h: id " + std::to_string(id[0]) + " run " + std::to_string(id[1]) +
                 " text '" + text + "'");
        }
    }
    // Exceptions
    std::uint16_t buf[130];
    expect_exception(modbus_read_registers(ctx, 4500, 1, buf), 2, "FC03 unmapped R4500");
    expect_exception(modbus_write_register(ctx, 3850, 1), 2, "FC06 read-only IR R3850");
    expect_exception(modbus_write_bit(ctx, 1000, 1), 2, "FC05 X0 (input)");
    // Requests the API refuses to build go out raw; the reply must be the exception.
    expect_raw_exception(ctx, {0x03, 0x00, 0x00, 0x00, 126}, 3, "FC03 126 registers");
    expect_raw_exception(ctx, {0x05, 0x07, 0xD0, 0x12, 0x34}, 3, "FC05 value 1234h");
    expect_raw_exception(ctx, {0x10, 0x00, 0x00, 0x00, 0x02, 0x03, 0, 1, 2}, 3,
                         "FC16 byte count 3 for 2 registers");
    expect_raw_exception(ctx, {0x41}, 1, "FC41h");
    expect_raw_exception(ctx, {0x07}, 1, "FC07 (not implemented)");
    expect_raw_exception(ctx, {0x08, 0x00, 0x01, 0x00, 0x00}, 1, "FC08 subfunction 01");
    if (tcp) {
        modbus_set_slave(ctx, 9);
        expect_exception(modbus_read_registers(ctx, 0, 1, buf), 0x0B, "unit 9 over TCP");
        modbus_set_slave(ctx, 255);
        expect_words(ctx, 10, {0x5634}, "unit 255 over TCP");
        modbus_set_slave(ctx, 1);
    } else {
        // Broadcast: applied, not answered (libmodbus does not wait for a reply).
        // libmodbus 3.1.6 still waits for a reply to a broadcast: a timeout is the expected
        // outcome there, an answer of any kind is a mismatch.
        modbus_set_slave(ctx, 0);
        modbus_set_response_timeout(ctx, 0, 500000);
        const int rc = modbus_write_register(ctx, 12, 0x0B0B);
        if (rc < 0 && errno != ETIMEDOUT) {
            fail(std::string("broadcast FC06 R12: ") + modbus_strerror(errno));
        }
        modbus_set_response_timeout(ctx, 2, 0);
        modbus_set_slave(ctx, 1);
        expect_words(ctx, 12, {0x0B0B}, "FC03 after broadcast");
    }
}

}  // namespace

int main(int argc, char** argv) {
    const std::string mode = argc > 1 ? argv[1] : "";
    modbus_t* raw_ctx = nullptr;
    if (mode == "tcp" && argc == 4) {
        raw_ctx = modbus_new_tcp(argv[2], std::atoi(argv[3]));
    } else if (mode == "rtu" && argc == 5) {
        raw_ctx = modbus_new_rtu(argv[2], std::atoi(argv[3]), argv[4][0], 8, 1);
    } else {
        std::fprintf(stderr, "usage: libmodbus_client tcp HOST PORT | rtu DEVICE BAUD PARITY\n");
        return 2;
    }
    Ctx ctx(raw_ctx, &modbus_free);
    if (!ctx) {
        std::fprintf(stderr, "libmodbus: %s\n", modbus_strerror(errno));
        return 1;
    }
    modbus_set_slave(ctx.get(), 1);
    modbus_set_response_timeout(ctx.get(), 2, 0);
    if (modbus_connect(ctx.get()) < 0) {
        std::fprintf(stderr, "connect: %s\n", modbus_strerror(errno));
        return 1;
    }
    check(ctx.get(), mode == "tcp");
    modbus_close(ctx.get());
    if (failures > 0) {
        std::fprintf(stderr, "%d mismatch(es)\n", failures);
        return 1;
    }
    std::printf("libmodbus %s: all round trips and exceptions as expected\n", mode.c_str());
    return 0;
}
