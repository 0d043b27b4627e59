#pragma once
// Test support: a VB PLC running a program, stepped scan by scan, and the refusal of a program
// (the unit tests of the FX-style program entries and of the VB's own instructions share it).

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/image/image.hpp"
#include "support/config_errors.hpp"
#include "support/plc_rig.hpp"

namespace plcemu::testing {

/// A VB PLC built from `vb.yaml`: "profile: vb", then `head` (other keys, whole lines), then
/// "program:" and `program` (YAML list entries, one per line). With `storage` the image lives
/// there, as a state file's does.
struct VbPlc : PlcRig {
    explicit VbPlc(const std::string& program,
                   const std::string& head = "",
                   std::span<std::byte> storage = {},
                   daemon::Start start = daemon::Start::Retained)
        : PlcRig("profile: vb\n" + head + "program:\n" + program, "vb.yaml", storage, start) {}

    using PlcRig::d;
    /// `n` words from D `i` on.
    std::vector<std::uint16_t> d(std::uint32_t i, std::uint32_t n) {
        std::vector<std::uint16_t> out;
        for (std::uint32_t k = 0; k < n; ++k) out.push_back(word(image::Area::D, i + k));
        return out;
    }
    /// Sets D `i` and the following registers.
    void set_d(std::uint32_t i, std::initializer_list<std::uint16_t> values) {
        for (const auto v : values) set_word(image::Area::D, i++, v);
    }
};

/// Checks (GoogleTest) that a VB PLC running the one-line `program` is refused at vb.yaml:3:`col`
/// with a message containing `needle`.
inline void expect_program_error(const std::string& program, int col, const std::string& needle) {
    SCOPED_TRACE(program);
    expect_config_error(config_failure([&] { VbPlc p(program); }), "vb.yaml", 3, col, needle);
}

}  // namespace plcemu::testing
