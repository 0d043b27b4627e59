#include "plcemu/modbus/dispatcher.hpp"

#include <modbus/modbus.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "crc.hpp"

namespace plcemu::modbus {

namespace {

using ModbusPtr = std::unique_ptr<modbus_t, decltype(&modbus_free)>;

// Function codes.
constexpr std::uint8_t kReadCoils = 0x01;
constexpr std::uint8_t kReadDiscreteInputs = 0x02;
constexpr std::uint8_t kReadHolding = 0x03;
constexpr std::uint8_t kReadInput = 0x04;
constexpr std::uint8_t kWriteCoil = 0x05;
constexpr std::uint8_t kWriteRegister = 0x06;
constexpr std::uint8_t kDiagnostics = 0x08;
constexpr std::uint8_t kWriteCoils = 0x0F;
constexpr std::uint8_t kWriteRegisters = 0x10;
constexpr std::uint8_t kReportSlaveId = 0x11;
constexpr std::uint8_t kMaskWrite = 0x16;
constexpr std::uint8_t kReadWriteRegisters = 0x17;
constexpr std::uint8_t kEncapsulated = 0x2B;
constexpr std::uint8_t kReadDeviceId = 0x0E;

std::uint16_t be16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] << 8 | p[1]); }

// What a request asks for, once its format has been checked.
struct Request {
    Status status = Status::Ok;  // IllegalFunction or IllegalDataValue when malformed
    Table table = Table::HoldingRegisters;
    std::uint16_t addr = 0;
    std::uint16_t qty = 0;
    bool write = false;
};

bool in(std::uint16_t v, std::uint16_t lo, std::uint16_t hi) { return v >= lo && v <= hi; }

// SPEC §2 quantities and byte counts; a PDU of the wrong length is malformed (exception 03).
Request parse(const std::uint8_t* pdu, std::size_t n) {
    Request r;
    const std::uint8_t fc = pdu[0];
    auto bad = [&] {
        r.status = Status::IllegalDataValue;
        return r;
    };
    if (fc == kReadCoils || fc == kReadDiscreteInputs || fc == kReadHolding || fc == kReadInput ||
        fc == kWriteCoil || fc == kWriteRegister) {
        if (n != 5) return bad();
        r.addr = be16(pdu + 1);
        r.qty = be16(pdu + 3);
    }
    switch (fc) {
        case kReadCoils:
        case kReadDiscreteInputs:
            r.table = fc == kReadCoils ? Table::Coils : Table::DiscreteInputs;
            if (!in(r.qty, 1, 2000)) return bad();
            return r;
        case kReadHolding:
        case kReadInput:
            r.table = fc == kReadHolding ? Table::HoldingRegisters : Table::InputRegisters;
            if (!in(r.qty, 1, 125)) return bad();
            return r;
        case kWriteCoil:
            r.table = Table::Coils;
            if (r.qty != 0x0000 && r.qty != 0xFF00) return bad();
            r.qty = 1;
            r.write = true;
            return r;
        case kWriteRegister:
            r.table = Table::HoldingRegisters;
            r.qty = 1;
            r.write = true;
            return r;
        case kWriteCoils:
        case kWriteRegisters: {
            if (n < 6) return bad();
            r.addr = be16(pdu + 1);
            r.qty = be16(pdu + 3);
            r.write = true;
            const std::size_t bytes = pdu[5];
            if (fc == kWriteCoils) {
                r.table = Table::Coils;
                if (!in(r.qty, 1, 1968) || bytes != (r.qty + 7u) / 8u) return bad();
            } else {
                r.table = Table::HoldingRegisters;
                if (!in(r.qty, 1, 123) || bytes != r.qty * 2u) return bad();
            }
            if (n != 6 + bytes) return bad();
            return r;
        }
        case kMaskWrite:
            if (n != 7) return bad();
            r.table = Table::HoldingRegisters;
            r.addr = be16(pdu + 1);
            r.qty = 1;
            r.write = true;
            return r;
        default:
            r.status = Status::IllegalFunction;
            return r;
    }
}

}  // namespace

// libmodbus writes its replies to a descriptor (it has no buffer API in 3.1): it gets one end
// of a socket pair, and the reply is read back from the other end into the caller's buffer. A
// reply is one write of at most 260 bytes, so one read takes it whole.
struct Dispatcher::Contexts {
    ModbusPtr tcp{modbus_new_tcp("127.0.0.1", 502), &modbus_free};
    ModbusPtr rtu{modbus_new_rtu("/dev/null", 9600, 'N', 8, 1), &modbus_free};
    std::array<int, 2> pair{-1, -1};

    Contexts() {
        if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, pair.data()) !=
            0) {
            throw std::system_error(errno, std::generic_category(), "dispatcher: socketpair");
        }
        modbus_set_socket(tcp.get(), pair[0]);
        modbus_set_socket(rtu.get(), pair[0]);
    }
    ~Contexts() {
        // modbus_free does not close the socket it was given.
        ::close(pair[0]);
        ::close(pair[1]);
    }
    Contexts(const Contexts&) = delete;
    Contexts& operator=(const Contexts&) = delete;

    modbus_t* get(Transport t) const { return t == Transport::Tcp ? tcp.get() : rtu.get(); }

    /// Reads back what libmodbus wrote (0 when it wrote nothing).
    std::size_t take(ReplyBuffer out) const noexcept {
        const ssize_t n = ::recv(pair[1], out.data(), out.size(), MSG_DONTWAIT);
        return n > 0 ? static_cast<std::size_t>(n) : 0;
    }
};

Dispatcher::Dispatcher(Unit& plc, const std::uint8_t& station, Identity identity)
    : plc_(plc),
      station_(station),
      identity_(std::move(identity)),
      ctx_(std::make_unique<Contexts>()) {
    if (!ctx_->tcp || !ctx_->rtu) throw std::runtime_error("libmodbus: cannot create a context");
}

Dispatcher::~Dispatcher() = default;

void Dispatcher::set_simulator(Unit* sim, std::uint8_t unit_id) {
    sim_ = unit_id != 0 ? sim : nullptr;
    sim_unit_ = unit_id;
}

std::size_t Dispatcher::serve_tcp(std::span<const std::uint8_t> adu, ReplyBuffer out) noexcept {
    return serve(Transport::Tcp, adu, out);
}

std::size_t Dispatcher::serve_rtu(std::span<const std::uint8_t> frame, ReplyBuffer out) noexcept {
    return serve(Transport::Rtu, frame, out);
}

namespace {

// Frames a PDU like the request it answers, into `out`; for the replies libmodbus cannot build
// (FC 08, 11h, 17h, 2Bh, and exceptions for function codes of 80h and up). Returns the length.
std::size_t frame_pdu(Transport t,
                      const std::uint8_t* req,
                      const std::uint8_t* pdu,
                      std::size_t n,
                      ReplyBuffer out) noexcept {
    std::size_t len = 0;
    if (t == Transport::Tcp) {
        out[0] = req[0];
        out[1] = req[1];
        out[2] = 0;
        out[3] = 0;
        out[4] = static_cast<std::uint8_t>((n + 1) >> 8);
        out[5] = static_cast<std::uint8_t>((n + 1) & 0xFF);
        out[6] = req[6];
        len = 7;
    } else {
        out[0] = req[0];
        len = 1;
    }
    std::memcpy(out.data() + len, pdu, n);
    len += n;
    if (t == Transport::Rtu) {
        const std::uint16_t crc = crc16(out.data(), len);
        out[len++] = static_cast<std::uint8_t>(crc & 0xFF);
        out[len++] = static_cast<std::uint8_t>(crc >> 8);
    }
    return len;
}

}  // namespace

std::size_t Dispatcher::serve(Transport t,
                              std::span<const std::uint8_t> adu,
                              ReplyBuffer reply) noexcept {
    const std::size_t header = t == Transport::Tcp ? 7 : 1;
    const std::size_t trailer = t == Transport::Rtu ? 2 : 0;
    if (adu.size() < header + 1 + trailer) {
        ++stats_.ignored;
        return 0;
    }
    const std::uint8_t* req = adu.data();
    const std::uint8_t unit = req[header - 1];
    const std::uint8_t* pdu = req + header;
    const std::size_t n = adu.size() - header - trailer;
    const std::uint8_t fc = pdu[0];
    const bool broadcast = t == Transport::Rtu && unit == 0;
    modbus_t* ctx = ctx_->get(t);

    auto exception = [&](Status s) -> std::size_t {
        ++stats_.requests;
        // Refused requests are what a SCADA integrator hunts for; debug keeps them off by default.
        spdlog::debug("modbus: unit {} function {:02X}h address {} refused: exception {:02X}h{}",
                      unit, fc, n >= 3 ? be16(pdu + 1) : 0, static_cast<unsigned>(s),
                      broadcast ? " (broadcast, not sent)" : "");
        if (broadcast) return 0;  // a broadcast is never answered
        ++stats_.exceptions;
        // Set the high bit rather than add 80h as modbus_reply_exception does, which would wrap
        // a function code of 80h or more to a normal-looking reply.
        const std::array<std::uint8_t, 2> e{static_cast<std::uint8_t>(fc | 0x80),
                                            static_cast<std::uint8_t>(s)};
        return frame_pdu(t, req, e.data(), e.size(), reply);
    };

    Unit* target = nullptr;
    // Over TCP, 0 and 255 address the device itself (Modbus TCP implementation guide §4.4.1.2:
    // clients such as Node-RED's fall back to 0); over RTU, 0 is the broadcast address.
    if (unit == station_ || broadcast || (t == Transport::Tcp && (unit == 0xFF || unit == 0))) {
        target = &plc_;
    } else if (sim_ != nullptr && unit == sim_unit_) {
        target = sim_;
    } else {
        if (t == Transport::Tcp && unknown_unit_ == UnknownUnitPolicy::Exception) {
            return exception(Status::GatewayTargetFailed);
        }
        ++stats_.ignored;
        return 0;
    }

    std::array<std::uint8_t, 253> out{};
    switch (fc) {
        case kDiagnostics: {
            // Subfunction 00 (return query data) only.
            if (n < 3) return exception(Status::IllegalDataValue);
            if (be16(pdu + 1) != 0) return exception(Status::IllegalFunction);
            if (broadcast) return 0;
            ++stats_.requests;
            return frame_pdu(t, req, pdu, n, reply);
        }
        case kReportSlaveId: {
            if (n != 1) return exception(Status::IllegalDataValue);
            if (broadcast) return 0;
            const std::string text =
                identity_.vendor + " " + identity_.product + " plcemu " + identity_.revision;
            std::size_t k = 0;
            out[k++] = kReportSlaveId;
            out[k++] = 0;  // byte count, filled below
            // The slave ID is the station (a TCP request to unit 255 still names the PLC).
            out[k++] = target == &plc_ ? station_ : unit;
            out[k++] = 0xFF;  // run indicator: ON
            for (char c : text) {
                if (k >= 250) break;
                out[k++] = static_cast<std::uint8_t>(c);
            }
            out[1] = static_cast<std::uint8_t>(k - 2);
            ++stats_.requests;
            return frame_pdu(t, req, out.data(), k, reply);
        }
        case kEncapsulated: {
            if (n < 2 || pdu[1] != kReadDeviceId) return exception(Status::IllegalFunction);
            if (n != 4) return exception(Status::IllegalDataValue);
            const std::uint8_t code = pdu[2];
            std::uint8_t object = pdu[3];
            if (code < 1 || code > 4) return exception(Status::IllegalDataValue);
            if (broadcast) return 0;
            struct Object {
                std::uint8_t id;
                const std::string* value;
            };
            const std::string model_name = identity_.product;
            const std::array<Object, 4> objects{{{0x00, &identity_.vendor},
                                                 {0x01, &identity_.product},
                                                 {0x02, &identity_.revision},
                                                 {0x05, &model_name}}};
            const std::uint8_t last_id = code == 1 ? 0x02 : 0x7F;
            auto known = [&](std::uint8_t id) {
                for (const auto& o : objects) {
                    if (o.id == id) return true;
                }
                return false;
            };
            if (code == 4 && !known(object)) return exception(Status::IllegalDataAddress);
            if (code != 4 && (!known(object) || object > last_id)) object = 0;
            std::size_t k = 0;
            out[k++] = kEncapsulated;
            out[k++] = kReadDeviceId;
            out[k++] = code;
            out[k++] = 0x82;  // conformity: regular identification, stream and individual
            out[k++] = 0x00;  // more follows: no (everything fits in one PDU)
            out[k++] = 0x00;  // next object id
            const std::size_t count_at = k++;
            std::uint8_t count = 0;
            for (const auto& o : objects) {
                if (code == 4 ? o.id != object : (o.id < object || o.id > last_id)) continue;
                out[k++] = o.id;
                out[k++] = static_cast<std::uint8_t>(o.value->size());
                std::memcpy(out.data() + k, o.value->data(), o.value->size());
                k += o.value->size();
                ++count;
            }
            out[count_at] = count;
            ++stats_.requests;
            return frame_pdu(t, req, out.data(), k, reply);
        }
        case kReadWriteRegisters: {
            if (n < 10) return exception(Status::IllegalDataValue);
            const std::uint16_t raddr = be16(pdu + 1);
            const std::uint16_t rqty = be16(pdu + 3);
            const std::uint16_t waddr = be16(pdu + 5);
            const std::uint16_t wqty = be16(pdu + 7);
            const std::size_t bytes = pdu[9];
            const Window ww = target->resolve(Table::HoldingRegisters, waddr, wqty, true);
            const Window rw = target->resolve(Table::HoldingRegisters, raddr, rqty, false);
            if (ww.status == Status::IllegalFunction) return exception(Status::IllegalFunction);
            if (!in(rqty, 1, 125) || !in(wqty, 1, 121) || bytes != wqty * 2u || n != 10 + bytes) {
                return exception(Status::IllegalDataValue);
            }
            if (ww.status != Status::Ok) return exception(ww.status);
            if (rw.status != Status::Ok) return exception(rw.status);
            if (broadcast) return 0;  // has a read part: not a broadcast request
            for (std::size_t i = 0; i < wqty; ++i) ww.words[i] = be16(pdu + 10 + 2 * i);
            target->written(Table::HoldingRegisters, waddr, wqty);
            std::size_t k = 0;
            out[k++] = kReadWriteRegisters;
            out[k++] = static_cast<std::uint8_t>(rqty * 2);
            for (std::size_t i = 0; i < rqty; ++i) {
                out[k++] = static_cast<std::uint8_t>(rw.words[i] >> 8);
                out[k++] = static_cast<std::uint8_t>(rw.words[i] & 0xFF);
            }
            ++stats_.requests;
            return frame_pdu(t, req, out.data(), k, reply);
        }
        default:
            break;
    }

    const Request r = parse(pdu, n);
    if (r.status == Status::IllegalFunction) return exception(r.status);
    const Window w = target->resolve(r.table, r.addr, r.qty, r.write);
    if (w.status == Status::IllegalFunction) return exception(w.status);
    if (r.status != Status::Ok) return exception(r.status);
    if (w.status != Status::Ok) return exception(w.status);
    if (broadcast && !r.write) {
        ++stats_.ignored;  // broadcast reads are ignored
        return 0;
    }

    // A window onto the resolved range: libmodbus reads and writes the image in place.
    modbus_mapping_t m{};
    switch (r.table) {
        case Table::Coils:
            m.start_bits = r.addr;
            m.nb_bits = r.qty;
            m.tab_bits = w.bits;
            break;
        case Table::DiscreteInputs:
            m.start_input_bits = r.addr;
            m.nb_input_bits = r.qty;
            m.tab_input_bits = w.bits;
            break;
        case Table::HoldingRegisters:
            m.start_registers = r.addr;
            m.nb_registers = r.qty;
            m.tab_registers = w.words;
            break;
        case Table::InputRegisters:
            m.start_input_registers = r.addr;
            m.nb_input_registers = r.qty;
            m.tab_input_registers = w.words;
            break;
    }
    ++stats_.requests;
    modbus_reply(ctx, req, static_cast<int>(adu.size()), &m);
    // libmodbus writes nothing for a broadcast; drain the pair either way.
    const std::size_t len = ctx_->take(reply);
    if (r.write) target->written(r.table, r.addr, r.qty);
    return broadcast ? 0 : len;
}

}  // namespace plcemu::modbus
