#pragma once
// The control half FUN73 TSTC and the FB's FUN86 TPCTL share (FB manual FUN73/FUN86;
// docs/profile-fb.md, "FUN73 TSTC" and "FUN86 TPCTL"): R4005 read when EN rises, the
// first-execution gains by range, PID only once every controlled point has been read, and the
// FATEK loop with the FB's figures and its error scaled by 4095 / the converter's full scale.

#include <cstdint>
#include <string_view>

#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/loops.hpp"
#include "profiles/fatek/temperature_loop.hpp"
#include "profiles/fb/points.hpp"

namespace plcemu::profiles::fb {

/// Facts of the FB's PID that tests and the docs refer to.
namespace control {
/// Full scale of the PID output OR+i (FUN73 "值为 0~4095"; FUN86 the same).
inline constexpr int kFullScale = 4095;
/// Kc, Ti and Td above this count as it.
inline constexpr int kGainCeiling = 999;
/// Default Ti (reset time 6 min) and Td (1 min).
inline constexpr std::uint16_t kDefaultTi = 17;
inline constexpr std::uint16_t kDefaultTd = 100;
/// The default Kc of a sensor code and range: thermocouples 60/30/120/60 for Pl 0–3, RTDs (bipolar
/// modules) 120 on a 10 V span and 60 on a 5 V one.
std::uint16_t default_kc(int sensor, int pl);
/// The converter's full scale in the reading's unit (°C/°F, or 0.1 °C/°F for RTDs): the PID's
/// error is scaled by 4095 / full scale.
double full_scale(int sensor, int pl, bool fahrenheit, bool jis);
/// What R4008 (whole degrees) is multiplied by before it is compared with a reading: 1 for
/// thermocouples (whole degrees), 10 for RTDs (0.1°).
int over_temperature_scale(int sensor);
/// The FB's figures for the FATEK loop.
extern const fatek::LoopRules kRules;
}  // namespace control

/// Where a loop's process values come from this scan.
struct LoopSource {
    image::Device pv;        ///< the PV of the loop's point i is the word at pv + i
    int sensor = 0;          ///< the measuring instruction's Tp (TPSNS: 0 K, 1 J)
    int pl = 0;              ///< its range
    bool measuring = false;  ///< the measuring instruction runs (TPSNS's EN for a TPCTL)
};

/// Point `i` of a TSTC's or TPCTL's loop as the console's faceplate shows it (docs/console.md,
/// "Loops"): named "<mnemonic> point i (channel first+i)", on plant channel first + i, PV the word
/// at pv + i (none when that lies outside the image), SV, OR (0–4095), Kc/Ti/Td/Os and the status
/// block's in-zone, warning, over-temperature and heater-open bits. `sensor` (Tp) and R4009 give
/// the readings' unit: whole degrees for thermocouples, 0.1° for RTDs, °C or °F.
engine::Loop point_loop(const image::Image& img,
                        const fatek::LoopBlocks& blocks,
                        std::string_view mnemonic,
                        int i,
                        const image::Device& pv,
                        int sensor);

/// One TSTC's or TPCTL's PID over points blocks.first…first+points−1.
class ControlLoop {
public:
    explicit ControlLoop(const fatek::LoopBlocks& blocks);

    /// Back to power-up (the first scan after a start).
    void reset();
    /// One scan. EN 0: outputs off, OR 0, the status block 0. EN 1: the first-execution gains,
    /// then PID while `src.measuring` and every point has been read since its measuring
    /// instruction's EN rose. Returns the alarm (AO1 / ALM; false while not running).
    bool run(engine::ScanContext& ctx,
             bool en,
             bool heating,
             const Points& points,
             const LoopSource& src);

private:
    fatek::LoopBlocks blocks_;
    fatek::TemperatureLoop loop_;
    bool prev_en_ = false;
};

}  // namespace plcemu::profiles::fb
