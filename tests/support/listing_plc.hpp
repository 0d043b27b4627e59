#pragma once
// Test support: a PLC whose program is an instruction list, written inline in its config
// (`program: {il: [...]}`), and the refusal of such a program.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/config_errors.hpp"
#include "support/plc_rig.hpp"

namespace plcemu::testing {

/// The config of a PLC of `profile` running `lines`, read as il.yaml: "profile: …", `head`
/// (whole lines), then the program. Statement i (from 0) stands at il.yaml:(4 + lines of
/// head + i):8.
inline std::string listing_config(const std::string& profile,
                                  const std::vector<std::string>& lines,
                                  const std::string& head = "") {
    std::string yaml = "profile: " + profile + "\n" + head + "program:\n  il:\n";
    for (const auto& l : lines) {
        std::string quoted;
        for (const char c : l) quoted += c == '\'' ? std::string("''") : std::string(1, c);
        yaml += "    - '" + quoted + "'\n";
    }
    return yaml;
}

/// A PLC running an instruction list.
struct ListingPlc : PlcRig {
    ListingPlc(const std::string& profile,
               const std::vector<std::string>& lines,
               const std::string& head = "")
        : PlcRig(listing_config(profile, lines, head), "il.yaml") {}
};

/// Checks (GoogleTest) that `lines` are refused at il.yaml:`line`:`col` (line 1 is the first
/// statement's) with a message containing `needle`.
inline void expect_listing_error(const std::string& profile,
                                 const std::vector<std::string>& lines,
                                 int line,
                                 int col,
                                 const std::string& needle) {
    expect_config_error(config_failure([&] { ListingPlc p(profile, lines); }), "il.yaml", line + 3,
                        col, needle);
}

}  // namespace plcemu::testing
