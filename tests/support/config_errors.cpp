#include "support/config_errors.hpp"

#include <gtest/gtest.h>

namespace plcemu::testing {

ConfigFailure config_failure(const std::function<void()>& load) {
    ConfigFailure f;
    try {
        load();
    } catch (const config::ConfigError& e) {
        f.thrown = true;
        f.pos = e.position();
        f.what = e.what();
        f.all = e.errors();
        f.lines = e.lines();
        f.stopped = e.stopped();
    }
    return f;
}

void expect_config_error(
    const ConfigFailure& f, const std::string& file, int line, int col, const std::string& needle) {
    ASSERT_TRUE(f.thrown) << "accepted";
    EXPECT_EQ(f.pos.file.str(), file);
    EXPECT_EQ(f.pos.line, line) << f.what;
    EXPECT_EQ(f.pos.column, col) << f.what;
    const std::string prefix = file + ":" + std::to_string(line) + ":" + std::to_string(col) + ": ";
    EXPECT_EQ(f.what.rfind(prefix, 0), 0u) << f.what;
    EXPECT_NE(f.what.find(needle), std::string::npos) << f.what;
}

void expect_config_errors(const ConfigFailure& f,
                          const std::string& file,
                          const std::vector<ExpectedError>& expected) {
    ASSERT_TRUE(f.thrown) << "accepted";
    EXPECT_FALSE(f.stopped);
    std::string all;
    for (const auto& l : f.lines) all += l + "\n";
    ASSERT_EQ(f.all.size(), expected.size()) << all;
    ASSERT_EQ(f.lines.size(), expected.size()) << all;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        const auto& want = expected[i];
        const auto& got = f.all[i];
        EXPECT_EQ(got.pos.file.str(), file) << all;
        EXPECT_EQ(got.pos.line, want.line) << "error " << i << "\n" << all;
        EXPECT_EQ(got.pos.column, want.col) << "error " << i << "\n" << all;
        const std::string prefix =
            file + ":" + std::to_string(want.line) + ":" + std::to_string(want.col) + ": ";
        EXPECT_EQ(f.lines[i].rfind(prefix, 0), 0u) << all;
        EXPECT_NE(f.lines[i].find(want.needle), std::string::npos) << "error " << i << "\n" << all;
    }
    // The first error is the exception's own message, as a loader stopping at it would say.
    EXPECT_EQ(f.what, f.lines.front());
}

}  // namespace plcemu::testing
