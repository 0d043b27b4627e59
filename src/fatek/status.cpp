// 40 (gist system status) and 53 (detailed system status): the RUN bit, and the PLC's sizes
// from its layout (docs/profile-fbs.md, "FATEK protocol").

#include "command.hpp"

namespace plcemu::fatek::handlers {

namespace {

using image::Area;

// Status byte 1: bit 0 RUN; the other bits (battery, ladder checksum, ROM pack, WDT, ID,
// emergency stop) are never set by the emulator.
std::uint32_t status_1(const Target& plc) { return plc.engine.running() ? 0x01 : 0x00; }

// What 53 says of the main unit: its type, I/O points code and OS version (the manual's
// example), the ladder size, and the analog words (R3840-R3903 in, R3904-R3967 out).
constexpr std::uint32_t kUnitType = 0x01;
constexpr std::uint32_t kIoPointsCode = 0x02;
constexpr std::uint32_t kOsVersion = 0x40;
constexpr std::uint32_t kLadderSize = 0x8000;
constexpr std::uint32_t kAnalogWords = 64;

}  // namespace

Error gist_status(std::span<const std::uint8_t> data, Target& plc, Reply& reply) noexcept {
    if (!data.empty()) return Error::Format;
    reply.hex(status_1(plc), 2);
    reply.hex(0, 4);  // status bytes 2 and 3: reserved
    return Error::None;
}

Error detailed_status(std::span<const std::uint8_t> data, Target& plc, Reply& reply) noexcept {
    if (!data.empty()) return Error::Format;
    const image::Layout& l = plc.engine.image().layout();
    reply.hex(status_1(plc), 2);
    reply.hex(kUnitType, 2);
    reply.hex(kIoPointsCode, 2);
    reply.hex(kOsVersion, 2);
    reply.hex(kLadderSize, 4);
    reply.hex(l.size_of(Area::X), 4);
    reply.hex(l.size_of(Area::Y), 4);
    reply.hex(kAnalogWords, 4);
    reply.hex(kAnalogWords, 4);
    reply.hex(l.size_of(Area::M), 4);
    reply.hex(l.size_of(Area::S), 4);
    reply.hex(0, 4);  // L relays: none
    reply.hex(l.size_of(Area::R), 4);
    reply.hex(l.size_of(Area::D), 4);
    reply.hex(l.size_of(Area::T), 4);
    reply.hex(l.size_of(Area::C), 4);
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
