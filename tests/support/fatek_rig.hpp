#pragma once
// Test support: one FBs PLC built from a config text behind the FATEK protocol of a TCP (or UDP)
// listener, seated as the daemon seats it, and frames written as the scenarios of
// docs/profile-fbs.md, "FATEK protocol" write them: "<STX>0140C7<ETX>" as "0140C7".

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "fatek/frame.hpp"
#include "fatek/stream.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/profiles/profile.hpp"

namespace plcemu::testing {

/// The frame STX + `text` + ETX.
inline std::string stx_etx(const std::string& text) { return "\x02" + text + "\x03"; }

/// The listener seat of a built PLC, as the daemon makes it (without a simulator unit or time
/// control: a test adds those it needs).
inline listener::Seat seat_of(daemon::Plc& plc) {
    listener::Seat s;
    s.station = &plc.engine().station();
    s.dispatcher = &plc.dispatcher();
    s.unit = &plc.unit();
    s.engine = &plc.engine();
    s.protected_ranges = &plc.unit().protected_ranges();
    s.id = "0";
    s.profile = plc.config().profile;
    s.model = plc.config().model;
    s.scan_ms = plc.config().scan_ms;
    s.naming = &profiles::of(plc.config()).naming();
    s.plant = &plc.plant();
    return s;
}

/// The setup of a listener with one PLC.
inline listener::ProtocolSetup setup_of(daemon::Plc& plc, bool read_only = false) {
    listener::ProtocolSetup s;
    s.seats = {seat_of(plc)};
    s.unknown_unit = listener::UnknownUnit::Refuse;
    s.read_only = read_only;
    return s;
}

/// An FBs PLC (station 1) on a FATEK listener.
struct FatekRig {
    explicit FatekRig(const std::string& config = "profile: fbs\n", bool read_only = false)
        : plc(config::parse_config(config, "fatek.yaml")),
          protocol(setup_of(plc, read_only)) {}

    /// Answers one whole frame (STX and ETX added); the reply without them is returned with
    /// them too, as the wire has it ("" when nothing was sent).
    std::string ask(const std::string& text) { return send(stx_etx(text)); }
    /// Answers `bytes` as one frame, exactly as given.
    std::string send(const std::string& bytes) {
        const std::size_t n = protocol.answer(
            {reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}, out);
        return {reinterpret_cast<const char*>(out.data()), n};
    }

    daemon::Plc plc;
    fatek::FatekStream protocol;
    std::array<std::uint8_t, fatek::kMaxFrame> out{};
};

}  // namespace plcemu::testing
