#pragma once
// Test support: run something that may refuse a config, and check where and why it refused.

#include <functional>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"

namespace plcemu::testing {

/// What a config refusal said, if there was one.
struct ConfigFailure {
    bool thrown = false;                  ///< a ConfigError was thrown
    config::Position pos;                 ///< its (first error's) position
    std::string what;                     ///< its (first error's) message
    std::vector<config::Diagnostic> all;  ///< every error it carried, the first included
    std::vector<std::string> lines;       ///< what the daemon prints for it, one per line
    bool stopped = false;                 ///< the loader stopped at config::Errors::kMax
};

/// One expected error: where, and a part of its message.
struct ExpectedError {
    int line;            ///< 1-based line
    int col;             ///< 1-based column
    std::string needle;  ///< found in its message
};

/// Runs `load` and catches the ConfigError it throws.
ConfigFailure config_failure(const std::function<void()>& load);

/// Checks (GoogleTest) that `f` is a refusal in `file` at line:col whose message starts with
/// "file:line:col: " and contains `needle`.
void expect_config_error(
    const ConfigFailure& f, const std::string& file, int line, int col, const std::string& needle);

/// Checks that `f` is a refusal in `file` with exactly the errors `expected`, in that order, each
/// printed as "file:line:col: …" containing its needle, and that it did not stop at the bound.
void expect_config_errors(const ConfigFailure& f,
                          const std::string& file,
                          const std::vector<ExpectedError>& expected);

}  // namespace plcemu::testing
