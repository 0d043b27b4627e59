#include "profiles/vb/mbus_table.hpp"

#include <optional>

namespace plcemu::profiles::vb::mbus {

namespace {

using image::Area;

// Set words.
constexpr std::size_t kStation = 0;
constexpr std::size_t kCommand = 1;
constexpr std::size_t kLength = 2;
constexpr std::size_t kMasterType = 3;
constexpr std::size_t kMasterNumber = 4;
constexpr std::size_t kSlaveType = 5;
constexpr std::size_t kSlaveNumber = 6;

constexpr int kMaxStation = 247;
constexpr int kMaxLength = 64;
constexpr std::uint32_t kMaxSlaveNumber = 32767;

enum Command : std::uint16_t { kRead = 1, kWriteSeries = 2, kWriteOne = 3 };

// Slave device types (the 0xxxx, 1xxxx, 3xxxx, 4xxxx references).
enum SlaveType : std::uint16_t { kCoil = 0, kInput = 1, kInputRegister = 3, kHolding = 4 };

struct MasterType {
    std::uint16_t code;
    Area area;
};

// VB manual FNC149, S1+4: 1 X, 2 Y, 3 M, 4 S, 5 T contact, 6 C contact, 10 T value,
// 11 16-bit C value, 13 D.
constexpr std::array<MasterType, 9> kMasterTypes{{{1, Area::X},
                                                  {2, Area::Y},
                                                  {3, Area::M},
                                                  {4, Area::S},
                                                  {5, Area::T},
                                                  {6, Area::C},
                                                  {10, Area::TV},
                                                  {11, Area::CV},
                                                  {13, Area::D}}};

const MasterType* master_type(std::uint16_t code) {
    for (const auto& t : kMasterTypes) {
        if (t.code == code) return &t;
    }
    return nullptr;
}

bool slave_bits(std::uint16_t type) { return type == kCoil || type == kInput; }
bool known_slave(std::uint16_t type) {
    return slave_bits(type) || type == kInputRegister || type == kHolding;
}

// X20 is written 20 (an octal area's number as its digits); 8 or 9 make it no device.
std::optional<std::uint32_t> octal(std::uint16_t written) {
    std::uint32_t value = 0;
    std::uint32_t place = 1;
    for (std::uint16_t rest = written; rest > 0; rest /= 10) {
        const std::uint32_t digit = rest % 10;
        if (digit > 7) return std::nullopt;
        value += digit * place;
        place *= 8;
    }
    return value;
}

// Function codes (docs/profile-vb.md, "FNC149 MBUS": the manual names the data kinds only).
std::uint8_t function_of(std::uint16_t command, std::uint16_t slave) {
    const bool bits = slave == kCoil;
    switch (command) {
        case kRead:
            if (slave == kCoil) return 1;
            if (slave == kInput) return 2;
            return slave == kHolding ? 3 : 4;
        case kWriteSeries:
            return bits ? 15 : 16;
        default:
            return bits ? 5 : 6;
    }
}

}  // namespace

Checked check_set(const std::array<std::uint16_t, kSetWords>& set,
                  const image::Layout& layout,
                  const image::Naming& naming,
                  std::span<const image::Range> read_only) {
    Checked out;
    auto fail = [&out](Status s) {
        out.status = s;
        return out;
    };
    const std::uint16_t station = set[kStation];
    const std::uint16_t command = set[kCommand];
    const std::uint16_t slave = set[kSlaveType];
    if (station < 1 || station > kMaxStation) return fail(kNumberError);
    if (command < kRead || command > kWriteOne) return fail(kTypeError);
    // The length of a single write is ignored (VB manual FNC149, S1+3).
    const std::uint16_t length = set[kLength];
    if (command != kWriteOne && (length < 1 || length > kMaxLength)) return fail(kLengthError);
    const MasterType* master = master_type(set[kMasterType]);
    if (master == nullptr || !known_slave(slave)) return fail(kTypeError);
    if (command != kRead && (slave == kInput || slave == kInputRegister)) return fail(kTypeError);
    if (image::is_bit_area(master->area) != slave_bits(slave)) return fail(kKindMismatch);

    const std::uint32_t count = command == kWriteOne ? 1 : std::uint32_t{length};
    const bool octal_area = naming.radix[static_cast<std::size_t>(master->area)] == 8;
    const auto first =
        octal_area ? octal(set[kMasterNumber]) : std::optional<std::uint32_t>(set[kMasterNumber]);
    if (!first) return fail(kNumberError);
    const image::Range range{master->area, *first, count};
    if (!layout.contains(range)) return fail(kNumberError);
    // Type 11 is the 16-bit counters' values; a 32-bit counter's is not one word.
    if (master->area == Area::CV && range.end() > naming.first_32bit_counter) {
        return fail(kNumberError);
    }
    // File registers are "read only registers" (VB manual FNC149): no reply lands in them.
    if (command == kRead) {
        for (const auto& r : read_only) {
            if (range.overlaps(r)) return fail(kNumberError);
        }
    }
    const std::uint32_t address = set[kSlaveNumber];
    if (address + count - 1 > kMaxSlaveNumber) return fail(kNumberError);

    Transfer& t = out.transfer;
    t.station = static_cast<std::uint8_t>(station);
    t.read = command == kRead;
    t.function = function_of(command, slave);
    t.address = static_cast<std::uint16_t>(address);
    t.count = static_cast<std::uint16_t>(count);
    t.master = range;
    return out;
}

}  // namespace plcemu::profiles::vb::mbus
