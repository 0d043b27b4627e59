#include "profiles/fb/conversion.hpp"

#include <algorithm>
#include <cmath>

#include "profiles/fb/special_registers.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::Area;
namespace sp = special;

constexpr long long kScale = 1024;  // the FB manual's "/ 1024"

bool bipolar(int pl) { return pl == 2 || pl == 3; }
bool ten_volt(int pl) { return pl == 0 || pl == 2; }

// m of the FB manual's formulas (R4016–R4019): × 2 for a bipolar range above 0, and on −10~10 V
// below 0; × 1 otherwise (docs/profile-fb.md, "Conversion").
int multiplier(int pl, bool negative) {
    if (!negative) return bipolar(pl) ? 2 : 1;
    return pl == 2 ? 2 : 1;
}

std::uint16_t factor(int sensor, bool negative, const Factors& f) {
    if (sensor == tp::kJ) return negative ? f.j_negative : f.j_positive;
    return negative ? f.k_negative : f.k_positive;
}

// α of R = R0 (1 + α T): DIN 0.00385, JIS 0.00392.
double alpha(bool jis) { return jis ? 0.00392 : 0.00385; }

bool pt1000(int sensor) { return sensor == tp::kPt1000 || sensor == tp::kPt1000Hi; }

// Integer division rounding toward zero, as the PLC's.
long long trunc_div(long long a, long long b) { return a / b; }

}  // namespace

Factors Factors::read(const image::Image& img) {
    const std::uint16_t* r = img.words(Area::R);
    Factors f;
    f.fahrenheit = (r[sp::kTempUnit] & 0xFFu) == 1;
    f.k_positive = r[sp::kFactorKPositive];
    f.k_negative = r[sp::kFactorKNegative];
    f.j_positive = r[sp::kFactorJPositive];
    f.j_negative = r[sp::kFactorJNegative];
    f.jis = (r[sp::kRtdStandard] >> 8) == 1;
    f.pt100 = r[sp::kFactorPt100];
    f.pt1000 = r[sp::kFactorPt1000];
    return f;
}

int full_scale_raw(int pl) { return bipolar(pl) ? 2047 : 4095; }

int thermocouple_raw(double celsius, int sensor, int pl) {
    const bool negative = celsius < 0.0;
    const Factors nominal;  // the module's own characteristic: the default factors
    const double per_count =
        static_cast<double>(multiplier(pl, negative) * factor(sensor, negative, nominal)) /
        static_cast<double>(kScale);
    const double raw = std::round(celsius / per_count);  // half away from zero
    const double lo = bipolar(pl) ? -2048.0 : 0.0;
    return static_cast<int>(std::clamp(raw, lo, static_cast<double>(full_scale_raw(pl))));
}

int thermocouple_celsius(long long sum, int n, int sensor, int pl, const Factors& f) {
    const bool negative = sum < 0;
    const long long num = sum * multiplier(pl, negative) * factor(sensor, negative, f);
    return static_cast<int>(trunc_div(num, kScale * std::max(n, 1)));
}

int thermocouple_display(int celsius, const Factors& f) {
    return f.fahrenheit ? static_cast<int>(trunc_div(9LL * celsius + 160, 5)) : celsius;
}

bool thermocouple_broken(int display, int pl, const Factors& f) {
    // FB manual FUN73: "大于 900°C 或 1700°F" (10 V), 450 °C or 870 °F (5 V); strictly above.
    if (ten_volt(pl)) return display > (f.fahrenheit ? 1700 : 900);
    return display > (f.fahrenheit ? 870 : 450);
}

RtdRange rtd_range(int sensor, int pl, bool jis) {
    // FB manual FUN73, measuring ranges of the FB-2AH(T)4 and FB-2AH(T)4-3.
    const bool high = sensor == tp::kPt100Hi || sensor == tp::kPt1000Hi;
    if (ten_volt(pl)) {
        if (high) return jis ? RtdRange{-48.2, 281.0} : RtdRange{-49.1, 286.2};
        return jis ? RtdRange{-48.9, 143.9} : RtdRange{-49.8, 146.6};
    }
    if (high) return jis ? RtdRange{5.4, 161.5} : RtdRange{5.5, 164.5};
    return jis ? RtdRange{-12.0, 82.1} : RtdRange{-12.3, 83.6};
}

double rtd_r0(int sensor) { return pt1000(sensor) ? 1000.0 : 100.0; }

int rtd_sample(
    double celsius, double lead_ohm, double compensation_ohm, int sensor, int pl, bool jis) {
    const double r0 = rtd_r0(sensor);
    const double a = alpha(jis);
    const double measured = r0 * (1.0 + a * celsius) + lead_ohm - compensation_ohm;
    const RtdRange range = rtd_range(sensor, pl, jis);
    const double t = std::clamp((measured / r0 - 1.0) / a, range.lo, range.hi);
    return static_cast<int>(std::lround(t * 10.0));
}

int rtd_celsius10(long long sum, int n, int sensor, const Factors& f) {
    const long long factor = pt1000(sensor) ? f.pt1000 : f.pt100;
    return static_cast<int>(trunc_div(sum * factor, kScale * std::max(n, 1)));
}

int rtd_display(int celsius10, const Factors& f) {
    return f.fahrenheit ? static_cast<int>(trunc_div(9LL * celsius10 + 1600, 5)) : celsius10;
}

int rtd_raw(int celsius10, int sensor, int pl, bool jis) {
    const RtdRange range = rtd_range(sensor, pl, jis);
    const double raw = std::round((celsius10 / 10.0 - range.lo) * 4095.0 / (range.hi - range.lo));
    return static_cast<int>(std::clamp(raw, 0.0, 4095.0));
}

bool rtd_broken(int display10) { return display10 > 9000; }

int averaged_samples(std::uint16_t r4015) { return 1 << std::min<int>(r4015, 4); }

double compensation_ohm(const image::Image& img, int point) {
    const std::uint16_t mode = img.word(Area::R, sp::kRtdStandard) & 0xFFu;
    if (mode != 1 && mode != 2) return 0.0;
    const Area area = mode == 1 ? Area::R : Area::D;
    const std::uint32_t at = std::uint32_t{img.word(Area::R, sp::kCompensationTable)} +
                             static_cast<std::uint32_t>(point);
    if (!img.layout().contains(image::Range{area, at, 1})) return 0.0;
    return img.word(area, at) / 10.0;  // 0.1 Ω, unsigned
}

}  // namespace plcemu::profiles::fb
