#include "master_pdu.hpp"

#include <algorithm>
#include <cstring>

#include "plcemu/modbus/limits.hpp"

namespace plcemu::modbus {

namespace {

constexpr std::uint8_t kReadCoils = 1;
constexpr std::uint8_t kReadDiscreteInputs = 2;
constexpr std::uint8_t kReadHolding = 3;
constexpr std::uint8_t kReadInput = 4;
constexpr std::uint8_t kWriteCoil = 5;
constexpr std::uint8_t kWriteRegister = 6;
constexpr std::uint8_t kWriteCoils = 15;
constexpr std::uint8_t kWriteRegisters = 16;
// The master asks for no more in a read than it may write (plcemu/modbus/limits.hpp), so that
// one table of values serves both directions.
constexpr std::uint16_t kMaxBits = kMaxWriteBits;
constexpr std::uint16_t kMaxRegisters = kMaxWriteRegisters;
// Function code, address, quantity (or value).
constexpr std::size_t kHeader = 5;

bool bit_function(std::uint8_t f) {
    return f == kReadCoils || f == kReadDiscreteInputs || f == kWriteCoils;
}

std::size_t bit_bytes(std::uint16_t quantity) { return (quantity + 7u) / 8u; }

}  // namespace

bool is_write(std::uint8_t function) noexcept {
    return function == kWriteCoil || function == kWriteRegister || function == kWriteCoils ||
           function == kWriteRegisters;
}

std::size_t encode_request(std::uint8_t function,
                           std::uint16_t address,
                           std::uint16_t quantity,
                           std::span<const std::uint16_t> values,
                           std::span<std::uint8_t> out) noexcept {
    if (out.size() < kHeader) return 0;
    out[0] = function;
    put_be16(&out[1], address);
    switch (function) {
        case kReadCoils:
        case kReadDiscreteInputs:
        case kReadHolding:
        case kReadInput: {
            const std::uint16_t max = bit_function(function) ? kMaxBits : kMaxRegisters;
            if (quantity < 1 || quantity > max) return 0;
            put_be16(&out[3], quantity);
            return kHeader;
        }
        case kWriteCoil:
            if (values.empty()) return 0;
            put_be16(&out[3], values[0] != 0 ? 0xFF00 : 0x0000);
            return kHeader;
        case kWriteRegister:
            if (values.empty()) return 0;
            put_be16(&out[3], values[0]);
            return kHeader;
        case kWriteCoils: {
            const std::size_t bytes = bit_bytes(quantity);
            if (quantity < 1 || quantity > kMaxBits || values.size() < quantity ||
                out.size() < kHeader + 1 + bytes) {
                return 0;
            }
            put_be16(&out[3], quantity);
            out[kHeader] = static_cast<std::uint8_t>(bytes);
            std::fill_n(&out[kHeader + 1], bytes, std::uint8_t{0});
            for (std::size_t i = 0; i < quantity; ++i) {
                if (values[i] != 0)
                    out[kHeader + 1 + i / 8] |= static_cast<std::uint8_t>(1u << (i % 8));
            }
            return kHeader + 1 + bytes;
        }
        case kWriteRegisters: {
            const std::size_t bytes = 2u * quantity;
            if (quantity < 1 || quantity > kMaxRegisters || values.size() < quantity ||
                out.size() < kHeader + 1 + bytes) {
                return 0;
            }
            put_be16(&out[3], quantity);
            out[kHeader] = static_cast<std::uint8_t>(bytes);
            for (std::size_t i = 0; i < quantity; ++i)
                put_be16(&out[kHeader + 1 + 2 * i], values[i]);
            return kHeader + 1 + bytes;
        }
        default:
            return 0;
    }
}

ReplyCheck check_reply(std::span<const std::uint8_t> request,
                       std::span<const std::uint8_t> reply,
                       std::span<std::uint16_t> values) noexcept {
    ReplyCheck out;
    if (request.size() < kHeader || reply.empty()) return out;
    const std::uint8_t function = request[0];
    if (reply[0] == (function | kExceptionBit)) {
        if (reply.size() == 2) {
            out.verdict = ReplyVerdict::Exception;
            out.exception = reply[1];
        }
        return out;
    }
    if (reply[0] != function) return out;
    switch (function) {
        case kReadCoils:
        case kReadDiscreteInputs:
        case kReadHolding:
        case kReadInput: {
            const std::uint16_t quantity = be16(&request[3]);
            const bool bits = bit_function(function);
            const std::size_t bytes = bits ? bit_bytes(quantity) : 2u * quantity;
            if (reply.size() != 2 + bytes || reply[1] != bytes || values.size() < quantity) {
                return out;
            }
            for (std::size_t i = 0; i < quantity; ++i) {
                values[i] = bits ? static_cast<std::uint16_t>(reply[2 + i / 8] >> (i % 8) & 1u)
                                 : be16(&reply[2 + 2 * i]);
            }
            out.verdict = ReplyVerdict::Ok;
            return out;
        }
        case kWriteCoil:
        case kWriteRegister:
        case kWriteCoils:
        case kWriteRegisters:
            // The reply echoes the address and the value (FC05/06) or the quantity (FC15/16).
            if (reply.size() == kHeader &&
                std::memcmp(reply.data(), request.data(), kHeader) == 0) {
                out.verdict = ReplyVerdict::Ok;
            }
            return out;
        default:
            return out;
    }
}

}  // namespace plcemu::modbus
