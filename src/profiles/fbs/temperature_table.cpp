#include "profiles/fbs/temperature_table.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "profiles/fbs/model.hpp"
#include "profiles/fbs/special_registers.hpp"

namespace plcemu::profiles::fbs {

namespace temperature {

namespace {

struct ModuleInfo {
    int channels;
    int conversion_ms;  // normal scan rate
    bool rtd;
};

// docs/profile-fbs.md, "Temperature measurement": name codes 1 TC6, 2 RTD6, 3 TC16, 4 RTD16, 5 TC2;
// conversion times of manual 21.1.
std::optional<ModuleInfo> info(std::uint8_t name_code) {
    switch (name_code) {
        case 1:
            return ModuleInfo{6, 4000, false};
        case 2:
            return ModuleInfo{6, 2000, true};
        case 3:
            return ModuleInfo{16, 6000, false};
        case 4:
            return ModuleInfo{16, 4000, true};
        case 5:
            return ModuleInfo{2, 2000, false};
        default:
            return std::nullopt;
    }
}

}  // namespace

int channels_of(std::uint8_t name_code) {
    const auto i = info(name_code);
    return i ? i->channels : 0;
}

int conversion_ms(std::uint8_t name_code) {
    const auto i = info(name_code);
    return i ? i->conversion_ms : 0;
}

bool is_rtd(std::uint8_t name_code) {
    const auto i = info(name_code);
    return i && i->rtd;
}

bool sensor_range(std::uint8_t name_code, std::uint8_t sensor, double& lo_c, double& hi_c) {
    const auto i = info(name_code);
    if (!i) return false;
    // Manual 21.1.1 / 21.1.2, in the order of the module name codes.
    static constexpr double kTc[8][2] = {{-200, 900},  {-190, 1300}, {-190, 380}, {-190, 1000},
                                         {-200, 1000}, {350, 1800},  {0, 1800},   {0, 1700}};
    static constexpr double kRtd[4][2] = {{-200, 850}, {-200, 850}, {-200, 600}, {-200, 600}};
    if (i->rtd) {
        if (sensor >= 4) return false;
        lo_c = kRtd[sensor][0];
        hi_c = kRtd[sensor][1];
    } else {
        if (sensor >= 8) return false;
        lo_c = kTc[sensor][0];
        hi_c = kTc[sensor][1];
    }
    return true;
}

std::optional<image::Device> decode_register(std::uint16_t v) {
    if (v >= 10000 && v < 20000) return image::Device{image::Area::R, v - 10000u, false};
    if (v >= 20000 && v < 30000) return image::Device{image::Area::D, v - 20000u, false};
    return std::nullopt;
}

std::uint16_t encode_register(const image::Device& d) {
    return static_cast<std::uint16_t>((d.area == image::Area::D ? 20000u : 10000u) + d.index);
}

std::uint32_t main_unit_outputs(const config::Config& config) {
    // The modules follow the main unit on the expansion chain: their outputs come after the
    // main unit's (FBs-24MC: Y0-Y9, so the first module has Y10-Y17).
    switch (model_code(config.model).value_or(24) & 0xFF) {
        case 10:
            return 4;
        case 14:
            return 6;
        case 20:
            return 8;
        case 32:
            return 12;
        case 40:
            return 16;
        case 44:
            return 20;
        case 60:
            return 24;
        default:
            return 10;
    }
}

std::optional<image::Range> module_outputs(const config::Config& config) {
    const auto n = static_cast<std::uint32_t>(settings_of(config)->temperature.modules.size());
    if (n == 0) return std::nullopt;
    return image::Range{image::Area::Y, main_unit_outputs(config), 8 * n};
}

}  // namespace temperature

namespace {

namespace sp = special;
using namespace temperature;

constexpr std::int64_t kNsPerMs = 1'000'000;
// R4015's largest code: 2^4 = 16 readings.
constexpr int kMaxAverageCode = 4;

bool fits(const image::Image& img, const image::Device& d, std::uint32_t count) {
    return img.layout().contains({d.area, d.index, count});
}

}  // namespace

TemperatureTable::TemperatureTable(TemperatureOptions options, engine::SensorSource& sensors)
    : opt_(std::move(options)),
      sensors_(sensors) {}

TemperatureOptions TemperatureTable::options_of(const config::Config& config) {
    TemperatureOptions o;
    const auto settings = settings_of(config);
    const TemperatureConfig& t = settings->temperature;
    if (t.table) o.table = *t.table;
    o.installed = t.modules;
    o.fast = t.fast;
    o.main_unit_outputs = main_unit_outputs(config);
    return o;
}

void TemperatureTable::put(image::Image& img,
                           const image::Device& base,
                           std::uint32_t offset,
                           std::uint16_t v) const noexcept {
    const std::uint32_t i = base.index + offset;
    if (i < img.layout().size_of(base.area)) img.set_word(base.area, i, v);
}

void TemperatureTable::restart(const image::Image& img, std::int64_t now) noexcept {
    const auto& s = snapshot_;
    marker_ok_ = s[0] == kValidTable;
    n_ = s[1];
    readings_ = decode_register(s[2]);
    if (readings_ && !fits(img, *readings_, 1)) readings_.reset();
    wr_ = decode_register(s[3]);
    if (wr_ && !fits(img, *wr_, 4)) wr_.reset();
    modules_.clear();
    total_ = 0;
    mismatch_ = 0;
    ch_ = {};
    read_ = 0;
    broken_ = 0;
    start_ns_ = now;
    code_ = kIdle;
    if (!marker_ok_) return;
    if (n_ == 0 || n_ > kMaxModules) {
        code_ = kBadModuleCount;
        return;
    }
    for (std::uint16_t k = 0; k < n_; ++k) {
        const std::uint16_t w = s[4u + k];
        ModuleState m;
        m.name = static_cast<std::uint8_t>(w & 0xFF);
        m.sensor = static_cast<std::uint8_t>(w >> 8);
        m.channels = channels_of(m.name);
        m.first = total_;
        total_ += m.channels;
        // FBs manual §21.3.2: a table module that differs from the installed one sets bit k of
        // WR+0's low byte. No declared chain means the chain is what the table says.
        if (m.channels == 0) {
            m.mismatch = true;
        } else if (!opt_.installed.empty()) {
            m.mismatch = k >= opt_.installed.size() || opt_.installed[k].name_code != m.name;
        }
        if (m.mismatch) mismatch_ = static_cast<std::uint8_t>(mismatch_ | (1u << k));
        m.sensor_ok = sensor_range(m.name, m.sensor, m.lo_c, m.hi_c);
        if (m.channels > 0) {
            const std::int64_t conv =
                static_cast<std::int64_t>(conversion_ms(m.name)) * kNsPerMs / (opt_.fast ? 2 : 1);
            m.slot_ns = conv / m.channels;
        }
        modules_.push_back(m);
    }
    if (total_ > kMaxChannels) code_ = kTooManyChannels;
}

void TemperatureTable::convert(engine::ScanContext& ctx, ModuleState& m) noexcept {
    if (m.channels == 0 || m.slot_ns <= 0) return;
    image::Image& img = ctx.image;
    const std::int64_t due = (ctx.now.count() - start_ns_) / m.slot_ns;
    // After a long pause (a huge step) only the last rounds matter: they fill the averages.
    const std::int64_t keep = 16LL * m.channels;
    if (due - m.done > keep) {
        const std::int64_t skipped = due - m.done - keep;
        m.current = static_cast<int>((m.current + skipped) % m.channels);
        m.done += skipped;
    }
    const std::uint16_t* r = img.words(image::Area::R);
    // FB manual (FUN73 special registers): R4009's low byte decides, so 0101h reads °F.
    const bool fahrenheit = (r[sp::kTempUnit] & 0xFFu) == 1;
    // R4015 0…4: 1, 2, 4, 8, 16 readings (FB manual, FUN73); larger values count as 4.
    const int depth = 1 << std::min<int>(r[sp::kTempAverage], kMaxAverageCode);
    while (m.done < due) {
        const int g = m.first + m.current;
        ChannelState& c = ch_[static_cast<std::size_t>(g)];
        const std::uint32_t bit = 1u << g;
        read_ |= bit;
        std::uint16_t value = 0;
        const std::uint16_t installed = r[sp::kSensorInstalled + (g < 16 ? 0 : 1)];
        if (((installed >> (g % 16)) & 1u) == 0) {
            // R4010/R4011 bit 0: not installed, reads 0, no broken-line check.
            broken_ &= ~bit;
            c.count = 0;
        } else {
            bool broken = m.mismatch || !m.sensor_ok;
            double celsius = 0.0;
            if (!broken) {
                const engine::SensorSample s = sensors_.sense(g);
                // Only an open sensor is a broken line; beyond the range the module reads its
                // range's limit (docs/profile-fbs.md, "Temperature measurement").
                broken = s.broken || std::isnan(s.celsius);
                celsius = broken ? 0.0 : std::clamp(s.celsius, m.lo_c, m.hi_c);
            }
            if (broken) {
                // Open sensor, a module that is not the installed one, or an unknown sensor code.
                value = kBroken;
                broken_ |= bit;
                c.count = 0;
            } else {
                broken_ &= ~bit;
                constexpr int kRing = static_cast<int>(std::tuple_size_v<decltype(c.avg)>);
                c.avg[static_cast<std::size_t>(c.next)] = celsius;
                c.next = (c.next + 1) % kRing;
                c.count = std::min(c.count + 1, kRing);
                const int n = std::min(depth, c.count);
                double sum = 0.0;
                for (int i = 1; i <= n; ++i)
                    sum += c.avg[static_cast<std::size_t>((c.next - i + kRing) % kRing)];
                double x = sum / n;
                if (fahrenheit) x = x * 9.0 / 5.0 + 32.0;
                // Fast scan rate: 1° resolution, still in 0.1° units.
                const double tenths = opt_.fast ? std::round(x) * 10.0 : std::round(x * 10.0);
                const long v = std::lround(std::clamp(tenths, -32768.0, 32766.0));
                value = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
            }
        }
        put(img, *readings_, static_cast<std::uint32_t>(g), value);
        m.current = (m.current + 1) % m.channels;
        ++m.done;
    }
}

void TemperatureTable::inputs(engine::ScanContext& ctx) noexcept {
    // A power-up restarts the measurement (docs/profile-fbs.md, "Temperature measurement"):
    // the table is read anew and no earlier conversion counts.
    if (ctx.first_scan) have_snapshot_ = false;
    image::Image& img = ctx.image;
    const auto& layout = img.layout();
    if (opt_.table.index >= layout.size_of(opt_.table.area)) return;

    // The table is re-read every scan; only the words it occupies count as a change.
    std::array<std::uint16_t, 4 + kMaxModules> s{};
    const std::uint32_t avail = layout.size_of(opt_.table.area) - opt_.table.index;
    for (std::uint32_t i = 0; i < s.size() && i < avail; ++i) {
        s[i] = img.word(opt_.table.area, opt_.table.index + i);
    }
    const std::size_t used = 4u + std::min<std::size_t>(s[1], kMaxModules);
    for (std::size_t i = used; i < s.size(); ++i) s[i] = 0;
    if (!have_snapshot_ || s != snapshot_) {
        snapshot_ = s;
        have_snapshot_ = true;
        restart(img, ctx.now.count());
    }

    if (!wr_) return;  // nowhere to report anything
    const image::Device wr = *wr_;
    if (!marker_ok_) {
        put(img, wr, 0, 0);
        return;
    }
    if (code_ == kBadModuleCount) {
        put(img, wr, 0, static_cast<std::uint16_t>(kBadModuleCount << 8));
        put(img, wr, 1, 0);
        put(img, wr, 2, 0);
        put(img, wr, 3, static_cast<std::uint16_t>(n_ & 0xFF));
        return;
    }
    const auto wr3 = static_cast<std::uint16_t>((total_ & 0xFF) << 8 | (n_ & 0xFF));
    const bool readings_fit =
        readings_ && fits(img, *readings_, static_cast<std::uint32_t>(std::max(total_, 1)));
    if (code_ != kTooManyChannels && readings_fit) {
        for (auto& m : modules_) convert(ctx, m);
        code_ = total_ > 0 && (read_ & channel_mask()) == channel_mask() ? kRunning : kIdle;
    } else if (code_ != kTooManyChannels) {
        code_ = kIdle;  // the reading start is not a register: no measurement
    }
    const std::uint32_t broken = code_ != kTooManyChannels ? broken_ & channel_mask() : 0;
    const std::uint16_t bits[2] = {static_cast<std::uint16_t>(broken & 0xFFFFu),
                                   static_cast<std::uint16_t>(broken >> 16)};
    put(img, wr, 0, static_cast<std::uint16_t>(code_ << 8 | mismatch_));
    put(img, wr, 1, bits[0]);
    put(img, wr, 2, bits[1]);
    put(img, wr, 3, wr3);
    if (code_ == kTooManyChannels) return;
    for (std::size_t k = 0; k < modules_.size(); ++k) {
        const ModuleState& m = modules_[k];
        const auto base = static_cast<std::uint32_t>(4 + 4 * k);
        const auto first_y = static_cast<std::uint32_t>(opt_.main_unit_outputs + 8 * k);
        put(img, wr, base + 0,
            static_cast<std::uint16_t>(std::uint32_t{m.sensor} << 8 | (first_y & 0xFF)));
        put(img, wr, base + 1,
            static_cast<std::uint16_t>(static_cast<std::size_t>(m.channels & 0xFF) << 8 | k));
        std::uint16_t start = 0;
        if (readings_) {
            image::Device d = *readings_;
            d.index += static_cast<std::uint32_t>(m.first);
            start = encode_register(d);
        }
        put(img, wr, base + 2, start);
        put(img, wr, base + 3, static_cast<std::uint16_t>(m.current));
    }
}

engine::Tags temperature_tags(const config::Config& config, const image::Image& image) {
    using engine::Number;
    engine::Tags t;
    const auto table = settings_of(config)->temperature.table;
    if (!table) return t;
    const image::Layout& layout = image.layout();
    auto word = [&](std::uint32_t offset) -> std::uint16_t {
        const image::Range r{table->area, table->index + offset, 1};
        return layout.contains(r) ? image.word(r.area, r.start) : 0;
    };
    auto add = [&](const image::Device& base, std::uint32_t offset, const std::string& what,
                   Number number) {
        const image::Range r{base.area, base.index + offset, 1};
        if (layout.contains(r)) t.push_back({r, what, number});
    };
    const std::string sr = "temperature table SR+";
    add(*table, 0, sr + "0: A556h marks a valid table", Number::Unsigned);
    add(*table, 1, sr + "1: module count N, 1-8", Number::Unsigned);
    add(*table, 2, sr + "2: reading start (encoded: 10000+n = Rn, 20000+n = Dn)", Number::Unsigned);
    add(*table, 3, sr + "3: working register start (encoded)", Number::Unsigned);
    const std::uint32_t n = std::min<std::uint32_t>(word(1), kMaxModules);
    int total = 0;
    for (std::uint32_t k = 0; k < n; ++k) {
        std::string what = sr + std::to_string(4 + k);
        what += ": module " + std::to_string(k + 1);
        what += ", name code (low byte) and sensor type (high byte)";
        add(*table, 4 + k, what, Number::Unsigned);
        total += channels_of(static_cast<std::uint8_t>(word(4 + k) & 0xFF));
    }
    if (const auto readings = decode_register(word(2))) {
        for (int g = 0; g < std::min(total, kMaxChannels); ++g) {
            add(*readings, static_cast<std::uint32_t>(g),
                "temperature reading, channel " + std::to_string(g) + ", 0.1 degree",
                Number::Signed);
        }
    }
    if (const auto wr = decode_register(word(3))) {
        const std::string w = "temperature working register WR+";
        add(*wr, 0, w + "0: execute code (high byte), module mismatch bits (low byte)",
            Number::Unsigned);
        add(*wr, 1, w + "1: sensor-abnormal bits, channels 0-15", Number::Unsigned);
        add(*wr, 2, w + "2: sensor-abnormal bits, channels 16-31", Number::Unsigned);
        add(*wr, 3, w + "3: total channels (high byte), module count (low byte)", Number::Unsigned);
        const char* const kModule[] = {"sensor type (high byte), first Y (low byte)",
                                       "channel count (high byte), input register index (low byte)",
                                       "reading start (encoded)", "channel being converted"};
        for (std::uint32_t k = 0; k < n; ++k) {
            for (std::uint32_t i = 0; i < 4; ++i) {
                const std::uint32_t offset = 4 + 4 * k + i;
                add(*wr, offset,
                    w + std::to_string(offset) + ": module " + std::to_string(k + 1) + " " +
                        kModule[i],
                    Number::Unsigned);
            }
        }
    }
    return t;
}

std::unique_ptr<TemperatureTable> make_temperature_table(const config::Config& config,
                                                         engine::SensorSource& sensors) {
    return std::make_unique<TemperatureTable>(TemperatureTable::options_of(config), sensors);
}

}  // namespace plcemu::profiles::fbs
