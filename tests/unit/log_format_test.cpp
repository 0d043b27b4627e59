// The daemon's log lines (docs/operations.md, "Logging"): whatever a message quotes is escaped,
// so a config key with U+202E cannot reorder the terminal line that reports it.

#include "daemon/log_format.hpp"

#include <gtest/gtest.h>
#include <spdlog/details/log_msg.h>

#include <string>

namespace plcemu::daemon {
namespace {

std::string line_of(const std::string& message) {
    const spdlog::details::log_msg msg("plcemud", spdlog::level::warn, message);
    spdlog::memory_buf_t out;
    log_formatter()->format(msg, out);
    return std::string(out.data(), out.size());
}

TEST(LogFormat, TheMessageIsEscapedAndTheLineEndsOnce) {
    const std::string line = line_of("unknown key 'a\u202Eb\nc\x1b[2J\xff' in config");
    EXPECT_NE(line.find(" warning unknown key 'a\\u202Eb\\nc\\x1B[2J\\xFF' in config\n"),
              std::string::npos)
        << line;
    EXPECT_EQ(line.find('\n'), line.size() - 1);
}

TEST(LogFormat, TextAlreadyEscapedAndPlainUnicodeAreKept) {
    const std::string line = line_of("key 'a\\u202Eb' at 20 °C…");
    EXPECT_NE(line.find(" key 'a\\u202Eb' at 20 °C…\n"), std::string::npos) << line;
}

}  // namespace
}  // namespace plcemu::daemon
