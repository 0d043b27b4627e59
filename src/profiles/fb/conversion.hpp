#pragma once
// How an FB temperature point's sample becomes a raw value (R3968+p) and a reading (FB manual
// FUN72/FUN73, R4016–R4023; docs/profile-fb.md, "Conversion"): the emulated module's side (a
// sensed temperature → raw count, or resistance → 0.1 °C) and the PLC's side (raw × m × F / 1024,
// RTD × F / 1024, averaging, °F, broken-sensor thresholds).

#include <cstdint>

#include "plcemu/image/image.hpp"

namespace plcemu::profiles::fb {

/// Sensor codes (FUN72/FUN73 operand Tp).
namespace tp {
inline constexpr int kK = 0;         ///< K thermocouple, FB-2AK4
inline constexpr int kJ = 1;         ///< J thermocouple, FB-2AJ4
inline constexpr int kPt100 = 2;     ///< 3-wire Pt100, FB-2AH4
inline constexpr int kPt1000 = 3;    ///< 3-wire Pt1000, FB-2AT4
inline constexpr int kPt100Hi = 4;   ///< Pt100 up to 286 °C, FB-2AH4-3
inline constexpr int kPt1000Hi = 5;  ///< Pt1000 up to 286 °C, FB-2AT4-3
inline constexpr int kLast = 5;      ///< largest code
}  // namespace tp

/// Range and polarity codes (operand Pl): 0 0~10 V, 1 0~5 V, 2 −10~10 V, 3 −5~5 V.
inline constexpr int kLastPl = 3;

/// True for Tp 0 and 1.
constexpr bool thermocouple(int sensor) { return sensor == tp::kK || sensor == tp::kJ; }

/// The live conversion registers: R4009, R4016–R4023.
struct Factors {
    bool fahrenheit = false;         ///< R4009 low byte 1
    std::uint16_t k_positive = 248;  ///< R4016
    std::uint16_t k_negative = 286;  ///< R4017
    std::uint16_t j_positive = 240;  ///< R4018
    std::uint16_t j_negative = 280;  ///< R4019
    bool jis = false;                ///< R4020 high byte 1
    std::uint16_t pt100 = 1024;      ///< R4022
    std::uint16_t pt1000 = 1024;     ///< R4023

    /// The registers as the image holds them now.
    static Factors read(const image::Image& img);
};

// ---- thermocouples (Tp 0, 1)

/// Full-scale raw count of a range: 4095 unipolar (Pl 0, 1), 2047 bipolar (Pl 2, 3); a broken
/// thermocouple reads it (upscale burnout).
int full_scale_raw(int pl);
/// The emulated module's raw count for a sensed temperature: round(T × 1024 / (m × Fnom)),
/// Fnom the register's default, clamped to the range's counts.
int thermocouple_raw(double celsius, int sensor, int pl);
/// °C reading of the sum of `n` raw counts: trunc(Σraw × m × F / (1024 × n)), m and F chosen by
/// Pl and the sign of the sum (the FB manual's printed formulas, literally).
int thermocouple_celsius(long long sum, int n, int sensor, int pl, const Factors& f);
/// A whole-degree °C reading in the display unit: trunc((9 × C + 160) / 5) in °F.
int thermocouple_display(int celsius, const Factors& f);
/// The broken-thermocouple rule on a reading in the display unit: above 900 °C / 1700 °F on
/// the 10 V ranges (Pl 0, 2), above 450 °C / 870 °F on the 5 V ones.
bool thermocouple_broken(int display, int pl, const Factors& f);

// ---- RTDs (Tp 2–5)

/// The measuring range of an RTD module, °C (the ADC saturates at its ends).
struct RtdRange {
    double lo = 0.0;  ///< °C
    double hi = 0.0;  ///< °C
};
/// The range for a sensor code, span (Pl 0/2 10 V, 1/3 5 V) and standard.
RtdRange rtd_range(int sensor, int pl, bool jis);
/// Nominal resistance at 0 °C: 100 Ω (Pt100) or 1000 Ω (Pt1000).
double rtd_r0(int sensor);
/// The module's sample, 0.1 °C: the sensor's resistance R0(1 + αT) plus `lead_ohm`, less the
/// compensation `compensation_ohm`, back to a temperature, clamped to the range, rounded.
int rtd_sample(
    double celsius, double lead_ohm, double compensation_ohm, int sensor, int pl, bool jis);
/// The °C reading (0.1 °C) of the sum of `n` samples: trunc(Σ × F / (1024 × n)), F = R4022
/// (Pt100) or R4023 (Pt1000).
int rtd_celsius10(long long sum, int n, int sensor, const Factors& f);
/// A 0.1 °C reading in the display unit: trunc((9 × C10 + 1600) / 5) in °F.
int rtd_display(int celsius10, const Factors& f);
/// The raw value R3968+p of an RTD reading: its place in the range on 0–4095.
int rtd_raw(int celsius10, int sensor, int pl, bool jis);
/// The broken-RTD rule: above 900.0 in the display unit.
bool rtd_broken(int display10);
/// What a broken RTD reads (7FFFh).
inline constexpr int kRtdBroken = 32767;

/// Readings averaged per R4015: 1, 2, 4, 8 or 16 (above 4 taken as 4).
int averaged_samples(std::uint16_t r4015);

/// The line-resistance compensation of point `point` per R4020 (low byte 1 R, 2 D) and R4021,
/// Ω; 0 when the table is off or its entry is outside the area.
double compensation_ohm(const image::Image& img, int point);

}  // namespace plcemu::profiles::fb
