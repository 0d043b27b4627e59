#include "support/modbus_oracle.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <modbus/modbus.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>

#include "plcemu/modbus/function_handler.hpp"

namespace {

// libmodbus 3.1 sleeps its response timeout before some exception replies (to let the rest of
// a bad request arrive on a serial line, then flush it): 13 µs or more per exception even with
// the timeout at 1 µs, which would make the oracle the slowest part of a fuzz input. While it
// answers for the oracle, that sleep returns at once; every other nanosleep of the process
// (the libraries' and the tests') is the C library's.
bool g_in_modbus_reply = false;

}  // namespace

extern "C" int nanosleep(const struct timespec* req, struct timespec* rem) {
    if (g_in_modbus_reply) return 0;
    using Fn = int (*)(const struct timespec*, struct timespec*);
    static const Fn next = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "nanosleep"));
    if (next == nullptr) {
        errno = ENOSYS;
        return -1;
    }
    return next(req, rem);
}

namespace plcemu::testing {

namespace {

using modbus::Span;
using modbus::Status;
using modbus::Table;

// What the listener's unit table says about routing, read when it serves a request.
struct Routing {
    std::uint8_t station = 0;    // the station now (R4055 may have changed it)
    std::uint8_t simulator = 0;  // the simulator unit's ID, 0: none
};

// The PLC's side, through the project's API: every call the oracle makes to it is here, so a
// change of that API is adapted in this one function. `before(routing)` runs before the request
// is served, with the routing the unit table applies to it.
template <class Before>
std::size_t plc_serve(PlcSide plc,
                      Framing framing,
                      std::span<const std::uint8_t> adu,
                      std::span<std::uint8_t> out,
                      Before&& before) {
    const listener::Seat& seat = plc.tcp.units().seats().front();
    before(
        Routing{*seat.station, seat.simulator != nullptr ? seat.simulator_unit : std::uint8_t{0}});
    if (framing == Framing::Tcp) return plc.tcp.answer(adu, out);
    const auto reply = plc.rtu.serve({modbus::RtuVerdict::Ok, adu});
    std::copy(reply.begin(), reply.end(), out.begin());
    return reply.size();
}

std::uint16_t be16(std::span<const std::uint8_t> p, std::size_t i) {
    return static_cast<std::uint16_t>(p[i] << 8 | p[i + 1]);
}

// The PDU length libmodbus 3.1.6 frames a request of function `fc` to (its receive reads the
// function's fixed part, then the byte count it gives), or 0 for a code it does not know
// (it answers 01 to any length).
std::size_t framed_length(std::span<const std::uint8_t> pdu) {
    switch (pdu[0]) {
        case 0x01:
        case 0x02:
        case 0x03:
        case 0x04:
        case 0x05:
        case 0x06:
            return 5;
        case 0x0F:
        case 0x10:
            return pdu.size() >= 6 ? 6u + pdu[5] : 6;
        case 0x16:
            return 7;
        case 0x17:
            return pdu.size() >= 10 ? 10u + pdu[9] : 10;
        default:
            return 0;
    }
}

// One table's window of a request: the wire addresses, and the PLC's memory behind them.
struct Window {
    bool used = false;
    Table table = Table::HoldingRegisters;
    std::uint16_t addr = 0;
    std::uint16_t qty = 0;
    bool write = false;
    Span span;  // status Ok: resolved
};

bool is_bits(Table t) { return t == Table::Coils || t == Table::DiscreteInputs; }

// The libmodbus mapping's fields for one table.
struct Fields {
    int* start;
    int* nb;
    std::uint8_t* bits;
    std::uint16_t* words;
};

Fields fields(modbus_mapping_t& m, Table t) {
    switch (t) {
        case Table::Coils:
            return {&m.start_bits, &m.nb_bits, m.tab_bits, nullptr};
        case Table::DiscreteInputs:
            return {&m.start_input_bits, &m.nb_input_bits, m.tab_input_bits, nullptr};
        case Table::HoldingRegisters:
            return {&m.start_registers, &m.nb_registers, nullptr, m.tab_registers};
        default:
            return {&m.start_input_registers, &m.nb_input_registers, nullptr,
                    m.tab_input_registers};
    }
}

// Memory of one part of a span, in bytes, and the wire element it starts at.
struct Extent {
    const std::uint8_t* begin;
    const std::uint8_t* end;
    std::size_t element;
    std::size_t bytes_per_element;
};

Extent extent(const Span& s, std::size_t k, std::uint16_t qty) {
    const modbus::Window& w = s.parts[k];
    const std::size_t first = s.first[k];
    const std::size_t last = k + 1 < s.n ? s.first[k + 1] : qty;
    const std::size_t per = w.words != nullptr ? 2 : (w.packed ? 16 : 1);
    const auto* b = w.words != nullptr ? reinterpret_cast<const std::uint8_t*>(w.words) : w.bits;
    return {b, b + (last - first) * per, first, per};
}

// True when two windows reach one device through two wire addresses (libmodbus' mapping has
// one cell per address, so a write to one would not show at the other).
bool aliased(const Window& a, const Window& b) {
    for (std::size_t i = 0; i < a.span.n; ++i) {
        for (std::size_t j = 0; j < b.span.n; ++j) {
            if (&a == &b && i == j) continue;
            const Extent x = extent(a.span, i, a.qty);
            const Extent y = extent(b.span, j, b.qty);
            if (x.end <= y.begin || y.end <= x.begin) continue;
            const auto wire_gap = (static_cast<long>(a.addr) + static_cast<long>(x.element)) -
                                  (static_cast<long>(b.addr) + static_cast<long>(y.element));
            const auto mem_gap = x.begin - y.begin;
            if (x.bytes_per_element != y.bytes_per_element ||
                mem_gap != wire_gap * static_cast<long>(x.bytes_per_element)) {
                return true;
            }
        }
    }
    return false;
}

// Calls `f(part, first, count)` for each part of a window's span: elements `first` to
// `first + count` of the request, in the part's memory from its element 0.
template <class F>
void for_each_part(const Window& w, F&& f) {
    for (std::size_t k = 0; k < w.span.n; ++k) {
        const std::size_t first = w.span.first[k];
        const std::size_t last = k + 1 < w.span.n ? w.span.first[k + 1] : w.qty;
        f(w.span.parts[k], first, last - first);
    }
}

// Values of one window as the PLC's memory holds them, into libmodbus' mapping starting at
// wire address `start`.
void copy_in(const Window& w, modbus_mapping_t& m, int start) {
    const Fields f = fields(m, w.table);
    const auto at = static_cast<std::size_t>(static_cast<int>(w.addr) - start);
    for_each_part(w, [&](const modbus::Window& p, std::size_t first, std::size_t count) {
        if (is_bits(w.table)) {
            for (std::size_t j = 0; j < count; ++j) f.bits[at + first + j] = p.bits[j] != 0;
        } else {
            for (std::size_t j = 0; j < count; ++j) f.words[at + first + j] = p.word(j);
        }
    });
}

// What `pdu` reads and writes: its windows resolved through `unit` (the PLC's map) and their
// values in `m`. Returns why the request is not compared, if it is not; `refused` tells that the
// PLC's map refuses a window (libmodbus then gets no mapping for that table, and must refuse it
// as the PLC does).
std::optional<OracleCase> plan(std::span<const std::uint8_t> pdu,
                               bool broadcast,
                               modbus::Unit& unit,
                               modbus_mapping_t& m,
                               std::array<Window, 2>& windows,
                               bool& refused) {
    for (Table t :
         {Table::Coils, Table::DiscreteInputs, Table::HoldingRegisters, Table::InputRegisters}) {
        *fields(m, t).nb = 0;
    }
    const std::uint8_t fc = pdu[0];
    if (fc >= 0x80) return OracleCase::FunctionAbove7F;
    if (fc == 0x08 || fc == 0x11 || fc == 0x2B) return OracleCase::Identity;
    if (fc == 0x07) return OracleCase::ReadExceptionStatus;
    const std::size_t framed = framed_length(pdu);
    if (framed == 0) return std::nullopt;  // a code neither serves: 01 from both
    if (pdu.size() != framed) return OracleCase::LengthNotFramed;

    const std::uint16_t addr = be16(pdu, 1);
    const std::uint16_t qty = be16(pdu, 3);
    const std::uint8_t bytes = pdu.size() > 5 ? pdu[5] : 0;
    Table table = Table::HoldingRegisters;
    bool write = true;
    switch (fc) {
        case 0x01:
        case 0x02:
            table = fc == 0x01 ? Table::Coils : Table::DiscreteInputs;
            write = false;
            break;
        case 0x03:
        case 0x04:
            table = fc == 0x03 ? Table::HoldingRegisters : Table::InputRegisters;
            write = false;
            break;
        case 0x05:
        case 0x0F:
            table = Table::Coils;
            break;
        default:
            break;
    }
    // A table the unit does not serve at all is 01 whatever the address (the map's rule).
    if (unit.resolve(table, addr, 1, write).status == Status::IllegalFunction)
        return OracleCase::TableNotServed;
    auto want = [&](Window& w, std::uint16_t a, std::uint16_t n, bool wr) {
        w.used = true;
        w.write = wr;
        w.table = table;
        w.addr = a;
        w.qty = n;
        w.span = modbus::resolve_span(unit, table, a, n, wr);
        if (w.span.status != Status::Ok) refused = true;
    };
    auto within = [](unsigned v, unsigned hi) { return v >= 1 && v <= hi; };
    switch (fc) {
        case 0x01:
        case 0x02:
            if (within(qty, MODBUS_MAX_READ_BITS)) want(windows[0], addr, qty, false);
            break;
        case 0x03:
        case 0x04:
            if (within(qty, MODBUS_MAX_READ_REGISTERS)) want(windows[0], addr, qty, false);
            break;
        case 0x05:
            want(windows[0], addr, 1, true);
            if (qty != 0 && qty != 0xFF00 && refused) return OracleCase::Fc05ValueFirst;
            break;
        case 0x06:
        case 0x16:
            want(windows[0], addr, 1, true);
            break;
        case 0x0F:
            if (within(qty, MODBUS_MAX_WRITE_BITS) && bytes * 8u >= qty) {
                if (bytes != (qty + 7u) / 8u) return OracleCase::Fc0FByteCount;
                want(windows[0], addr, qty, true);
            }
            break;
        case 0x10:
            if (within(qty, MODBUS_MAX_WRITE_REGISTERS) && bytes == qty * 2u)
                want(windows[0], addr, qty, true);
            break;
        default: {  // 0x17
            if (broadcast) return OracleCase::BroadcastFc17;
            const std::uint16_t waddr = be16(pdu, 5);
            const std::uint16_t wqty = be16(pdu, 7);
            if (within(qty, MODBUS_MAX_WR_READ_REGISTERS) &&
                within(wqty, MODBUS_MAX_WR_WRITE_REGISTERS) && pdu[9] == wqty * 2u) {
                want(windows[0], addr, qty, false);
                want(windows[1], waddr, wqty, true);
            }
            break;
        }
    }
    if (!windows[0].used) return std::nullopt;  // quantities libmodbus refuses before addresses
    if (!refused) {
        if (write && aliased(windows[0], windows[0])) return OracleCase::AliasedWindow;
        if (windows[1].used &&
            (aliased(windows[1], windows[1]) || aliased(windows[0], windows[1]))) {
            return OracleCase::AliasedWindow;
        }
    }
    // One run of cells from the lowest address the windows name (FC 17h's two may be far apart:
    // the cells between are never read); none when the map refuses a window.
    int start = windows[0].addr;
    int end = windows[0].addr + windows[0].qty;
    if (windows[1].used) {
        start = std::min<int>(start, windows[1].addr);
        end = std::max<int>(end, windows[1].addr + windows[1].qty);
    }
    const Fields f = fields(m, table);
    *f.start = start;
    *f.nb = refused ? 0 : end - start;
    if (refused) return std::nullopt;
    for (const Window& w : windows) {
        if (w.used) copy_in(w, m, start);
    }
    return std::nullopt;
}

// After both answered: each window written, as the PLC's devices and libmodbus' cells have it.
// Empty when equal. (A refused request had no mapping, and a read changes nothing on either
// side: the fuzz harnesses check that the image did not change.)
std::string compare_windows(const std::array<Window, 2>& windows, modbus_mapping_t& m) {
    std::string diff;
    for (const Window& w : windows) {
        if (!w.used || !w.write || w.span.status != Status::Ok) continue;
        const Fields f = fields(m, w.table);
        if (*f.nb == 0) return {};
        const auto at = static_cast<std::size_t>(static_cast<int>(w.addr) - *f.start);
        for_each_part(w, [&](const modbus::Window& p, std::size_t first, std::size_t count) {
            for (std::size_t j = 0; j < count && diff.empty(); ++j) {
                const std::size_t i = at + first + j;
                const unsigned ours = is_bits(w.table) ? (p.bits[j] != 0 ? 1u : 0u) : p.word(j);
                const unsigned theirs = is_bits(w.table) ? f.bits[i] : f.words[i];
                if (ours == theirs) continue;
                char s[160];
                std::snprintf(s, sizeof s,
                              "the request left address %u (table %d) at %u in the PLC and at "
                              "%u in libmodbus' mapping",
                              static_cast<unsigned>(w.addr + first + j), static_cast<int>(w.table),
                              ours, theirs);
                diff = s;
            }
        });
        if (!diff.empty()) return diff;
    }
    return {};
}

}  // namespace

ModbusOracle& ModbusOracle::get() {
    static ModbusOracle o;
    return o;
}

ModbusOracle::ModbusOracle() {
    int sv[2];
    if (socketpair(AF_UNIX, SOCK_STREAM, 0, sv) != 0) {
        std::perror("modbus oracle: socketpair");
        std::abort();
    }
    ours_ = sv[0];
    theirs_ = sv[1];
    fcntl(theirs_, F_SETFL, fcntl(theirs_, F_GETFL) | O_NONBLOCK);
    tcp_ = modbus_new_tcp("127.0.0.1", 502);
    rtu_ = modbus_new_rtu("/dev/null", 9600, 'E', 8, 1);
    // Every address a request can name, plus what FC 17h's two windows may reach beyond 65535.
    constexpr int kCells = 0x10000 + 256;
    map_ = modbus_mapping_new_start_address(0, kCells, 0, kCells, 0, kCells, 0, kCells);
    if (tcp_ == nullptr || rtu_ == nullptr || map_ == nullptr) {
        std::fprintf(stderr, "modbus oracle: libmodbus: %s\n", modbus_strerror(errno));
        std::abort();
    }
    for (modbus_t* ctx : {tcp_, rtu_}) {
        modbus_set_socket(ctx, ours_);
        modbus_set_response_timeout(ctx, 0, 1);
    }
}

ModbusOracle::Result ModbusOracle::serve(PlcSide plc,
                                         modbus::Unit& unit,
                                         Framing framing,
                                         std::span<const std::uint8_t> adu,
                                         std::span<std::uint8_t> out) {
    const std::size_t header = framing == Framing::Tcp ? 7 : 1;
    const std::size_t trailer = framing == Framing::Rtu ? 2 : 0;
    const bool whole = adu.size() >= header + 1 + trailer;
    const auto pdu = whole ? adu.subspan(header, adu.size() - header - trailer)
                           : std::span<const std::uint8_t>{};
    const std::uint8_t unit_id = whole ? adu[header - 1] : 0;
    const bool broadcast = framing == Framing::Rtu && unit_id == 0;

    // The transport's rules and the routing come before anything a request asks; then what the
    // request reads and writes, resolved through the PLC's map before it is served, and the same
    // values in libmodbus' mapping. `skip` is set once a reason not to compare is known.
    std::array<Window, 2> windows{};  // FC 17h: read, then write
    bool refused = false;             // a window the PLC's map refuses
    std::optional<OracleCase> skip;
    std::uint8_t station = 0;
    Result res;
    res.size = plc_serve(plc, framing, adu, out, [&](const Routing& routing) {
        station = routing.station;
        const bool to_plc = unit_id == routing.station || broadcast ||
                            (framing == Framing::Tcp && (unit_id == 0 || unit_id == 0xFF));
        if (!whole) {
            skip = OracleCase::LengthNotFramed;
        } else if (framing == Framing::Tcp && (adu[2] != 0 || adu[3] != 0)) {
            skip = OracleCase::ProtocolId;
        } else if (!to_plc) {
            skip = routing.simulator != 0 && unit_id == routing.simulator
                       ? OracleCase::SimulatorUnit
                       : OracleCase::NotThePlc;
        } else {
            skip = plan(pdu, broadcast, unit, *map_, windows, refused);
        }
    });
    const std::span<const std::uint8_t> ours(out.data(), res.size);
    if (!skip && res.size > 0 && framed_length(pdu) != 0 && res.size == header + 2 + trailer &&
        ours[header] == (pdu[0] | 0x80) && ours[header + 1] == 0x01) {
        // 01 to a code libmodbus serves, on tables the unit serves: the profile refuses it.
        skip = OracleCase::ProfileFunction;
    } else if (!skip && res.size > header + trailer && framed_length(pdu) == 0 &&
               ours[header] == pdu[0]) {
        // A normal reply to a code libmodbus does not know: the profile adds it.
        skip = OracleCase::ProfileFunction;
    }
    if (skip) {
        ++counts_[static_cast<std::size_t>(*skip)];
        res.how = *skip;
        return res;
    }

    // libmodbus' side: the request copied into a buffer longer than any frame (modbus_reply
    // reads the address and quantity fields of any request, even a one-byte PDU).
    std::array<std::uint8_t, 2 * MODBUS_MAX_ADU_LENGTH> req{};
    std::copy(adu.begin(), adu.end(), req.begin());
    modbus_t* ctx = framing == Framing::Tcp ? tcp_ : rtu_;
    if (framing == Framing::Rtu) modbus_set_slave(ctx, station);
    g_in_modbus_reply = true;
    modbus_reply(ctx, req.data(), static_cast<int>(adu.size()), map_);
    g_in_modbus_reply = false;
    std::array<std::uint8_t, 2 * MODBUS_MAX_ADU_LENGTH> theirs_buf{};
    const ssize_t got = recv(theirs_, theirs_buf.data(), theirs_buf.size(), MSG_DONTWAIT);
    const std::size_t n = got > 0 ? static_cast<std::size_t>(got) : 0;
    const std::span<const std::uint8_t> theirs(theirs_buf.data(), n);

    auto hex = [](std::span<const std::uint8_t> b) {
        std::string s;
        char x[4];
        for (std::uint8_t c : b) {
            std::snprintf(x, sizeof x, " %02x", c);
            s += x;
        }
        return s.empty() ? std::string(" (nothing)") : s;
    };
    if (!std::equal(ours.begin(), ours.end(), theirs.begin(), theirs.end())) {
        res.mismatch = "the PLC and libmodbus answer differently";
    } else {
        res.mismatch = compare_windows(windows, *map_);
    }
    if (!res.mismatch.empty()) {
        res.mismatch += "\n  request:  " + hex(adu) + "\n  PLC:      " + hex(ours) +
                        "\n  libmodbus:" + hex(theirs);
    }
    const OracleCase how = refused ? OracleCase::ComparedRefused : OracleCase::Compared;
    ++counts_[static_cast<std::size_t>(how)];
    res.how = how;
    return res;
}

namespace {

struct CaseText {
    const char* name;
    const char* why;
};

constexpr std::array<CaseText, kOracleCases> kCaseTexts{{
    {"compared", "answered by both from the same values: replies and writes identical"},
    {"compared-refused",
     "the PLC's map refuses the window (a gap, a read-only or write-protected range, a special "
     "device): libmodbus, given no mapping there, refuses it identically"},
    {"not-the-plc",
     "a unit the PLC does not answer as: routing is the dispatcher's, libmodbus "
     "answers any unit"},
    {"simulator-unit", "the simulator-control unit: its writes run scans"},
    {"identity",
     "FC 08, 11h, 2Bh: the PLC's own diagnostics and identity (libmodbus: 01, or "
     "its own name)"},
    {"fc07", "FC 07: libmodbus 3.1.6 sends no reply at all, the PLC answers 01"},
    {"fc-above-7f",
     "a function code of 80h or more: libmodbus adds 80h and wraps to a normal "
     "code, the PLC sets the high bit"},
    {"protocol-id", "MBAP protocol ID not 0: the TCP transport closes the connection"},
    {"length",
     "a PDU length libmodbus would not have framed (it frames by function code, the "
     "PLC by the MBAP length or the RTU frame): the PLC answers 03"},
    {"table-not-served", "a table the unit does not serve: the PLC answers 01"},
    {"profile-function",
     "a function code the profile adds (libmodbus: 01) or refuses (the PLC: "
     "01)"},
    {"fc05-value-first",
     "FC 05 with a value other than 0000h/FF00h at a refused address: the PLC answers 03 as the "
     "protocol's order says, libmodbus 02"},
    {"fc0f-byte-count",
     "FC 0Fh with a byte count above ceil(quantity / 8): the PLC answers 03, "
     "libmodbus takes it"},
    {"broadcast-fc17",
     "FC 17h broadcast: the PLC ignores it (it has a read part), libmodbus "
     "writes"},
    {"aliased",
     "a window reaching one device through two addresses (libmodbus has a cell per "
     "address)"},
}};

}  // namespace

const char* ModbusOracle::name(OracleCase c) {
    return kCaseTexts[static_cast<std::size_t>(c)].name;
}

const char* ModbusOracle::why(OracleCase c) { return kCaseTexts[static_cast<std::size_t>(c)].why; }

std::string ModbusOracle::summary() const {
    std::string s;
    for (std::size_t i = 0; i < kOracleCases; ++i) {
        if (counts_[i] == 0) continue;
        s += "oracle: " + std::string(kCaseTexts[i].name) + ": " + std::to_string(counts_[i]) +
             " (" + kCaseTexts[i].why + ")\n";
    }
    return s;
}

}  // namespace plcemu::testing
