#include "support/wire.hpp"

#include <algorithm>
#include <stdexcept>

#include "modbus/crc.hpp"
#include "support/modbus_oracle.hpp"

namespace plcemu::testing {

namespace {

listener::ProtocolSetup setup(std::vector<listener::Seat> seats) {
    return {std::move(seats), listener::UnknownUnit::Refuse, {}};
}

}  // namespace

Wire::Wire(modbus::Dispatcher& d,
           modbus::Unit& unit,
           const std::uint8_t& station,
           modbus::Unit* sim,
           std::uint8_t sim_unit)
    : Wire(std::vector<listener::Seat>{{"", &station, &d, &unit, sim_unit, sim}}) {
    oracle_ = true;
}

Wire::Wire(daemon::Plc& plc)
    : Wire(plc.dispatcher(), plc.unit(), plc.engine().station()) {}

Wire::Wire(std::vector<listener::Seat> seats)
    : tcp_(setup(seats)),
      rtu_(setup(seats)) {}

std::size_t Wire::serve(bool tcp, const std::vector<std::uint8_t>& adu) {
    if (!oracle_) {
        if (tcp) return tcp_.answer(adu, out_);
        const auto a = rtu_.serve({modbus::RtuVerdict::Ok, adu});
        std::copy(a.begin(), a.end(), out_.begin());
        return a.size();
    }
    auto r = ModbusOracle::get().serve({tcp_, rtu_}, *tcp_.units().seats().front().unit,
                                       tcp ? Framing::Tcp : Framing::Rtu, adu, out_);
    if (!r.mismatch.empty()) throw std::runtime_error("libmodbus oracle: " + r.mismatch);
    return r.size;
}

void Wire::set_unknown_unit(listener::UnknownUnit u) {
    tcp_.units().set_unknown_unit(u);
    rtu_.units().set_unknown_unit(u);
}

std::vector<std::uint8_t> Wire::reply(std::size_t n) const {
    return {out_.begin(), out_.begin() + static_cast<std::ptrdiff_t>(n)};
}

std::vector<std::uint8_t> Wire::tcp(std::uint8_t unit, const std::vector<std::uint8_t>& pdu) {
    ++tid_;
    std::vector<std::uint8_t> adu{static_cast<std::uint8_t>(tid_ >> 8),
                                  static_cast<std::uint8_t>(tid_ & 0xFF),
                                  0,
                                  0,
                                  static_cast<std::uint8_t>((pdu.size() + 1) >> 8),
                                  static_cast<std::uint8_t>((pdu.size() + 1) & 0xFF),
                                  unit};
    adu.insert(adu.end(), pdu.begin(), pdu.end());
    auto r = reply(serve(true, adu));
    if (r.empty()) return r;
    if (r.size() < 8 || r[0] != adu[0] || r[1] != adu[1] || r[2] != 0 || r[3] != 0 ||
        r[6] != unit || static_cast<std::size_t>(r[4] << 8 | r[5]) != r.size() - 6) {
        throw std::runtime_error("malformed MBAP reply");
    }
    return {r.begin() + 7, r.end()};
}

std::vector<std::uint8_t> Wire::rtu(std::uint8_t unit, const std::vector<std::uint8_t>& pdu) {
    std::vector<std::uint8_t> f{unit};
    f.insert(f.end(), pdu.begin(), pdu.end());
    const std::uint16_t crc = modbus::crc16(f.data(), f.size());
    f.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    f.push_back(static_cast<std::uint8_t>(crc >> 8));
    auto r = reply(serve(false, f));
    if (r.empty()) return r;
    if (r.size() < 4 || r[0] != unit) throw std::runtime_error("malformed RTU reply");
    const std::uint16_t got = static_cast<std::uint16_t>(r[r.size() - 2] | r[r.size() - 1] << 8);
    if (got != modbus::crc16(r.data(), r.size() - 2)) throw std::runtime_error("bad reply CRC");
    return {r.begin() + 1, r.end() - 2};
}

std::vector<std::uint8_t> read_pdu(std::uint8_t fc, std::uint16_t addr, std::uint16_t qty) {
    return {fc, static_cast<std::uint8_t>(addr >> 8), static_cast<std::uint8_t>(addr & 0xFF),
            static_cast<std::uint8_t>(qty >> 8), static_cast<std::uint8_t>(qty & 0xFF)};
}

std::vector<std::uint8_t> write_single_pdu(std::uint8_t fc, std::uint16_t addr, std::uint16_t v) {
    return read_pdu(fc, addr, v);
}

std::vector<std::uint8_t> write_registers_pdu(std::uint16_t addr,
                                              const std::vector<std::uint16_t>& values) {
    auto p = read_pdu(0x10, addr, static_cast<std::uint16_t>(values.size()));
    p.push_back(static_cast<std::uint8_t>(values.size() * 2));
    for (auto v : values) {
        p.push_back(static_cast<std::uint8_t>(v >> 8));
        p.push_back(static_cast<std::uint8_t>(v & 0xFF));
    }
    return p;
}

std::vector<std::uint8_t> write_coils_pdu(std::uint16_t addr, const std::vector<bool>& values) {
    auto p = read_pdu(0x0F, addr, static_cast<std::uint16_t>(values.size()));
    std::vector<std::uint8_t> bytes((values.size() + 7) / 8, 0);
    for (std::size_t i = 0; i < values.size(); ++i) {
        if (values[i]) bytes[i / 8] = static_cast<std::uint8_t>(bytes[i / 8] | (1u << (i % 8)));
    }
    p.push_back(static_cast<std::uint8_t>(bytes.size()));
    p.insert(p.end(), bytes.begin(), bytes.end());
    return p;
}

std::vector<std::uint16_t> reply_words(const std::vector<std::uint8_t>& pdu) {
    std::vector<std::uint16_t> w;
    if (pdu.size() < 2) return w;
    for (std::size_t i = 2; i + 1 < pdu.size(); i += 2) {
        w.push_back(static_cast<std::uint16_t>(pdu[i] << 8 | pdu[i + 1]));
    }
    return w;
}

std::vector<bool> reply_bits(const std::vector<std::uint8_t>& pdu, std::size_t qty) {
    std::vector<bool> b;
    for (std::size_t i = 0; i < qty && 2 + i / 8 < pdu.size(); ++i) {
        b.push_back((pdu[2 + i / 8] >> (i % 8)) & 1);
    }
    return b;
}

std::uint8_t exception_of(const std::vector<std::uint8_t>& pdu) {
    if (pdu.size() == 2 && (pdu[0] & 0x80)) return pdu[1];
    return 0;
}

}  // namespace plcemu::testing
