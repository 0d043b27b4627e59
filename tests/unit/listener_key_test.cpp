// What makes two PLCs' listeners one (docs/configuration.md, "Sharing a listener"): the bind
// address as the listener parses it, the serial device as the kernel finds it.

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

}  // namespace
}  // namespace plcemu::config
