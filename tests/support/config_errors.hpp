#pragma once
// Test support: run something that may refuse a config, and check where and why it refused.

#include <functional>
#include <string>

#include "plcemu/config/config.hpp"

namespace plcemu::testing {

/// What a config refusal said, if there was one.
struct ConfigFailure {
    bool thrown = false;   ///< a ConfigError was thrown
    config::Position pos;  ///< its position
    std::string what;      ///< its message
};

/// Runs `load` and catches the ConfigError it throws.
ConfigFailure config_failure(const std::function<void()>& load);

/// Checks (GoogleTest) that `f` is a refusal in `file` at line:col whose message starts with
/// "file:line:col: " and contains `needle`.
void expect_config_error(
    const ConfigFailure& f, const std::string& file, int line, int col, const std::string& needle);

}  // namespace plcemu::testing
