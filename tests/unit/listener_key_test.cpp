// What makes two PLCs' listeners one (docs/configuration.md, "Sharing a listener"): the bind
// address as the listener parses it, the serial device as the kernel finds it; and what makes
// two state files one.

#include "plcemu/config/listener_key.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace plcemu::config {
namespace {

TcpConfig tcp(const std::string& bind, std::uint16_t port) {
    TcpConfig t;
    t.bind = bind;
    t.port = port;
    return t;
}

TEST(ListenerKey, OneAddressWrittenTwoWaysIsOneListener) {
    EXPECT_EQ(tcp_listener_key(tcp("::1", 1502)), tcp_listener_key(tcp("0:0:0:0:0:0:0:1", 1502)));
    EXPECT_EQ(tcp_listener_key(tcp("fe80::0:1", 1502)), tcp_listener_key(tcp("FE80::1", 1502)));
    EXPECT_NE(tcp_listener_key(tcp("::1", 1502)), tcp_listener_key(tcp("::1", 1503)));
    EXPECT_NE(tcp_listener_key(tcp("127.0.0.1", 1502)), tcp_listener_key(tcp("127.0.0.2", 1502)));
    EXPECT_EQ(tcp_listener_key(tcp("127.0.0.1", 1502)), "127.0.0.1:1502");
}

TEST(ListenerKey, TheWildcardAddressHoweverWritten) {
    EXPECT_TRUE(any_address("0.0.0.0"));
    EXPECT_TRUE(any_address("::"));
    EXPECT_TRUE(any_address("0:0:0:0:0:0:0:0"));
    EXPECT_FALSE(any_address("::1"));
    EXPECT_FALSE(any_address("127.0.0.1"));
}

TEST(ListenerKey, ADeviceBySymlinkOrDoubledSlashIsOneLine) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "plcemu_listener_key_test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "ttyX").put('x');
    fs::create_symlink(dir / "ttyX", dir / "link");
    const std::string real = serial_line_key((dir / "ttyX").string());
    EXPECT_EQ(serial_line_key(dir.string() + "//ttyX"), real);
    EXPECT_EQ(serial_line_key((dir / "link").string()), real);
    EXPECT_EQ(serial_line_key(dir.string() + "/./ttyX"), real);
    // A device that is not there (yet) is compared as written, made lexically normal.
    EXPECT_EQ(serial_line_key("/nonexistent//dir/./ttyQ"), "/nonexistent/dir/ttyQ");
    EXPECT_NE(serial_line_key("/nonexistent/ttyQ"), serial_line_key("/nonexistent/ttyR"));
    fs::remove_all(dir);
}

// docs/configuration.md, "Several PLCs": one state file however written, whether it exists yet
// or not.
TEST(StateFileKey, OneFileSpelledTwoWaysOrByALinkIsOneFile) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "plcemu_state_file_key_test";
    fs::remove_all(dir);
    fs::create_directories(dir / "real");
    fs::create_directory_symlink(dir / "real", dir / "linked");
    const std::string real = (fs::canonical(dir) / "real" / "x.state").string();
    // x.state does not exist yet: the directory is resolved and the name appended.
    EXPECT_EQ(state_file_key((dir / "real" / "x.state").string()), real);
    EXPECT_EQ(state_file_key(dir.string() + "/real/./x.state"), real);
    EXPECT_EQ(state_file_key((dir / "linked" / "x.state").string()), real);
    // A link to it, dangling until the file is made, and one through another link.
    fs::create_symlink("x.state", dir / "real" / "y.state");
    fs::create_symlink(dir / "real" / "y.state", dir / "z.state");
    EXPECT_EQ(state_file_key((dir / "real" / "y.state").string()), real);
    EXPECT_EQ(state_file_key((dir / "z.state").string()), real);
    std::ofstream(dir / "real" / "x.state").put('x');
    EXPECT_EQ(state_file_key((dir / "z.state").string()), real);
    EXPECT_NE(state_file_key((dir / "real" / "w.state").string()), real);
    // Relative to the working directory, as the daemon opens it.
    const fs::path cwd = fs::current_path();
    fs::current_path(dir / "real");
    EXPECT_EQ(state_file_key("x.state"), real);
    EXPECT_EQ(state_file_key("./x.state"), real);
    fs::current_path(cwd);
    // A loop of links resolves to no file, and to no crash.
    fs::create_symlink("b.state", dir / "a.state");
    fs::create_symlink("a.state", dir / "b.state");
    EXPECT_NE(state_file_key((dir / "a.state").string()), real);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace plcemu::config
