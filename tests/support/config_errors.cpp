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
    }
    return f;
}

void expect_config_error(
    const ConfigFailure& f, const std::string& file, int line, int col, const std::string& needle) {
    ASSERT_TRUE(f.thrown) << "accepted";
    EXPECT_EQ(f.pos.file, file);
    EXPECT_EQ(f.pos.line, line) << f.what;
    EXPECT_EQ(f.pos.column, col) << f.what;
    const std::string prefix = file + ":" + std::to_string(line) + ":" + std::to_string(col) + ": ";
    EXPECT_EQ(f.what.rfind(prefix, 0), 0u) << f.what;
    EXPECT_NE(f.what.find(needle), std::string::npos) << f.what;
}

}  // namespace plcemu::testing
