// The FBs Modbus slave map (FBs manual 13-50/51; docs/profile-fbs.md, "Modbus map").

#include <algorithm>
#include <string>
#include <utility>

#include "profiles/fbs/map.hpp"

#include "profiles/fatek/map_rows.hpp"

namespace plcemu::profiles::fbs {

namespace {

using image::Area;
using image::Range;
using modbus::AddressMap;
using modbus::MapRow;
using modbus::Resolution;
using modbus::Status;
using modbus::Table;

// FATEK user remap registers (manual 13-50/51).
constexpr std::uint32_t kRemapKey = 3968;  // = A55Ah enables the coil/holding remap
constexpr std::uint16_t kRemapMagic = 0xA55A;
constexpr std::uint32_t kCoilRemap = 3969;     // wire start, M start, count
constexpr std::uint32_t kDiscreteMap = 3972;   // wire start, M start, count
constexpr std::uint32_t kInputRegMap = 3975;   // wire start, R start, count
constexpr std::uint32_t kHoldingRemap = 3978;  // wire start, R start, count

// R4168–R4999 exist in the image only to keep R numbers equal to indices.
constexpr Range kRGap{Area::R, 4168, 5000 - 4168};

class FbsMap final : public AddressMap {
public:
    FbsMap() {
        rows_ = fatek::map_rows();
        read_only_ = fatek::read_only();
    }

    const std::vector<MapRow>& rows() const override { return rows_; }

    std::vector<std::string> dynamic_notes() const override {
        return {
            "coils (01 05 15) when R3968=A55Ah: wire R3969.., count R3971 -> M(R3970)..",
            "holding registers (03 06 16 22 23) when R3968=A55Ah: wire R3978.., count R3980 -> "
            "R(R3979)..",
            "discrete inputs (02): wire R3972.., count R3974 -> M(R3973)..; count 0: exception 01",
            "input registers (04): wire R3975.., count R3977 -> R(R3976)..; count 0: exception 01",
        };
    }

    const std::vector<Range>& read_only() const override { return read_only_; }

    Resolution resolve(const image::Image& img,
                       Table table,
                       std::uint16_t addr,
                       std::uint16_t qty) const noexcept override {
        const std::uint16_t* r = img.words(Area::R);
        switch (table) {
            case Table::Coils:
                if (r[kRemapKey] == kRemapMagic) {
                    return user(img, kCoilRemap, Area::M, addr, qty, Status::IllegalDataAddress);
                }
                return fixed(img, table, addr, qty);
            case Table::HoldingRegisters:
                if (r[kRemapKey] == kRemapMagic) {
                    return user(img, kHoldingRemap, Area::R, addr, qty, Status::IllegalDataAddress);
                }
                return fixed(img, table, addr, qty);
            // FBs manual 13-51: FC02/FC04 with a count of 0 are not served at all.
            case Table::DiscreteInputs:
                return user(img, kDiscreteMap, Area::M, addr, qty, Status::IllegalFunction);
            case Table::InputRegisters:
                return user(img, kInputRegMap, Area::R, addr, qty, Status::IllegalFunction);
        }
        return {};
    }

private:
    Resolution fixed(const image::Image& img,
                     Table table,
                     std::uint16_t addr,
                     std::uint16_t qty) const noexcept {
        return modbus::resolve_rows(rows_, img, table, addr, qty);
    }

    // A map held in three registers: wire start, device start, count. `empty` is the answer
    // when the count is 0.
    static Resolution user(const image::Image& img,
                           std::uint32_t reg,
                           Area area,
                           std::uint16_t addr,
                           std::uint16_t qty,
                           Status empty) noexcept {
        const std::uint16_t* r = img.words(Area::R);
        const std::uint32_t wire_start = r[reg];
        const std::uint32_t dev_start = r[reg + 1];
        const std::uint32_t count = r[reg + 2];
        if (count == 0) return {empty, {}};
        if (addr < wire_start || std::uint32_t{addr} + qty > wire_start + count) return {};
        const Range dev{area, dev_start + (addr - wire_start), qty};
        if (!img.layout().contains(dev) || dev.overlaps(kRGap)) return {};
        return {Status::Ok, dev};
    }

    std::vector<MapRow> rows_;
    std::vector<Range> read_only_;
};

}  // namespace

engine::Tags map_tags() {
    engine::Tags t{{{Area::R, kRemapKey, 1},
                    "Modbus map: A55Ah switches coils and holding registers to the user maps",
                    engine::Number::Unsigned}};
    const std::pair<std::uint32_t, const char*> maps[] = {
        {kCoilRemap, "coil user map (M)"},
        {kDiscreteMap, "discrete input map (M)"},
        {kInputRegMap, "input register map (R)"},
        {kHoldingRemap, "holding register user map (R)"}};
    const char* const kWords[] = {"wire start", "device start", "count"};
    for (const auto& [reg, what] : maps) {
        for (std::uint32_t w = 0; w < 3; ++w) {
            t.push_back({{Area::R, reg + w, 1},
                         std::string("Modbus map: ") + what + " " + kWords[w],
                         engine::Number::Unsigned});
        }
    }
    return t;
}

const AddressMap& map() {
    static const FbsMap map;
    return map;
}

}  // namespace plcemu::profiles::fbs
