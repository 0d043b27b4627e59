#include "profiles/fb/control_loop.hpp"

#include <array>
#include <string>

#include "profiles/fb/conversion.hpp"

namespace plcemu::profiles::fb {

namespace control {

std::uint16_t default_kc(int sensor, int pl) {
    // FB manual FUN73: "0~10V … 60", "0~5V … 30", "-10~10V … 120", "-5~5V … 60". The RTD
    // modules are bipolar: 120 on a 10 V span, 60 on a 5 V one.
    static constexpr std::array<std::uint16_t, 4> kThermocouple{60, 30, 120, 60};
    if (thermocouple(sensor)) return kThermocouple[static_cast<std::size_t>(pl)];
    return pl == 0 || pl == 2 ? 120 : 60;
}

double full_scale(int sensor, int pl, bool fahrenheit, bool jis) {
    // Pb = 100 % / Kc of the converter's full scale: 1000/500/2000/1000 °C for thermocouples,
    // the measuring range in 0.1 °C for RTDs (docs/profile-fb.md, "FUN73 TSTC").
    static constexpr std::array<double, 4> kThermocouple{1000.0, 500.0, 2000.0, 1000.0};
    double fs = 0.0;
    if (thermocouple(sensor)) {
        fs = kThermocouple[static_cast<std::size_t>(pl)];
    } else {
        const RtdRange r = rtd_range(sensor, pl, jis);
        fs = (r.hi - r.lo) * 10.0;
    }
    return fahrenheit ? fs * 1.8 : fs;
}

int over_temperature_scale(int sensor) {
    // FB manual FUN73: R4008 "单位为度" (whole degrees); RTD readings are in 0.1°.
    return thermocouple(sensor) ? 1 : 10;
}

// FB manual FUN73/FUN86: OR 0–4095, Kc/Ti/Td up to 999, R4007 from 300 s, R4008 whole degrees
// from 50, R4005 codes 0 → 2 s, 1 → 4 s, 2 → 8 s, ≥ 3 → 1 s; a broken point's reading is a
// temperature that counts for over-temperature; Os < 0 is never in zone.
const fatek::LoopRules kRules{kFullScale, kGainCeiling, 300, 50, {2, 4, 8, 1}, true, true};

}  // namespace control

using namespace control;

engine::Loop point_loop(const image::Image& img,
                        const fatek::LoopBlocks& blocks,
                        std::string_view mnemonic,
                        int i,
                        const image::Device& pv,
                        int sensor) {
    const auto k = static_cast<std::uint32_t>(i);
    auto at = [k](const image::Device& block) {
        image::Device d = block;
        d.index += k;
        return d;
    };
    const int channel = blocks.first + i;
    engine::Loop l;
    l.name = std::string(mnemonic) + " point " + std::to_string(i) + " (channel " +
             std::to_string(channel) + ")";
    l.channel = channel;  // point p is plant channel p (docs/profile-fb.md, "Plant and simulator")
    const image::Device reading = at(pv);
    if (img.layout().contains({reading.area, reading.index, 1})) l.pv = reading;
    l.sv = at(blocks.sv);
    l.output = at(blocks.out);
    // FB manual FUN73: thermocouple readings in whole degrees, RTD ones in 0.1°; R4009 low byte 1
    // makes them °F. SV and Os are in the readings' unit.
    const bool tenths = !thermocouple(sensor);
    l.scale = tenths ? 0.1 : 1.0;
    l.unit = Factors::read(img).fahrenheit ? "°F" : "°C";
    l.output_full = kFullScale;
    l.parameters = {{"Kc", at(blocks.pr), "1-999"},
                    {"Ti", at(blocks.ir), "0.01 repeats/min"},
                    {"Td", at(blocks.dr), "0.01 min"},
                    {"in-zone offset", at(blocks.os), (tenths ? "0.1 " : "") + l.unit}};
    // The status block (TPCTL's WR, TSTC's WR+8): +0/1 in zone, +2/3 over-temperature or heater
    // open, +5/6 over-temperature, +7/8 heater open; bit i % 16 of the word of points 0-15 or
    // 16-31 counted from the loop's first.
    const auto half = static_cast<std::uint32_t>(i / 16);
    const auto bit = static_cast<std::uint8_t>(i % 16);
    auto flag = [&](const char* name, std::uint32_t word) {
        image::Device w = blocks.status;
        w.index += word + half;
        return engine::LoopFlag{name, w, bit};
    };
    l.alarms = {flag("in zone", 0), flag("warning", 2), flag("over temperature", 5),
                flag("heater open", 7)};
    return l;
}

ControlLoop::ControlLoop(const fatek::LoopBlocks& blocks)
    : blocks_(blocks),
      loop_(&kRules, blocks, 1.0, false, 1) {}

void ControlLoop::reset() {
    loop_ = fatek::TemperatureLoop(&kRules, blocks_, 1.0, false, 1);
    prev_en_ = false;
}

bool ControlLoop::run(
    engine::ScanContext& ctx, bool en, bool heating, const Points& points, const LoopSource& src) {
    image::Image& img = ctx.image;
    const bool rising = en && !prev_en_;
    prev_en_ = en;
    // R4005 is read when EN rises: a change while EN = 1 waits for the next (note 1).
    if (rising) loop_.latch_timing(img);
    if (!en) {
        loop_.stop(img);
        return false;
    }
    // "At the first execution the system gives every point the default Kc, Ti and Td": the
    // points whose PR is still 0.
    loop_.first_execution(img, {default_kc(src.sensor, src.pl), kDefaultTi, kDefaultTd});
    // "PID only really starts once every point has been measured" (FUN86: and FUN85 enabled).
    std::array<fatek::LoopInput, fatek::kLoopMaxPoints> in{};
    for (int i = 0; i < blocks_.points; ++i) {
        const int p = blocks_.first + i;
        const Point& pt = points.at[static_cast<std::size_t>(p)];
        if (!src.measuring || !pt.read_once) {
            loop_.stop(img);
            return false;
        }
        const auto at = src.pv.index + static_cast<std::uint32_t>(i);
        in[static_cast<std::size_t>(i)] = {static_cast<std::int16_t>(img.word(src.pv.area, at)),
                                           pt.broken};
    }
    const Factors f = Factors::read(img);
    loop_.set_gain(kFullScale / full_scale(src.sensor, src.pl, f.fahrenheit, f.jis));
    loop_.set_over_scale(over_temperature_scale(src.sensor));
    return loop_.run(ctx, heating, in);
}

}  // namespace plcemu::profiles::fb
