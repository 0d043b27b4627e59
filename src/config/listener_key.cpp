#include "plcemu/config/listener_key.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <array>
#include <filesystem>
#include <system_error>

namespace plcemu::config {

namespace {

// The address in the form inet_ntop writes it, or empty when it does not parse. An IPv4-mapped
// IPv6 address (::ffff:127.0.0.1) is the IPv4 address it maps: bound, it takes that address's
// port (the kernel refuses the second of the two), so they are one listener.
std::string canonical_address(const std::string& a) {
    std::array<unsigned char, 16> bin{};
    std::array<char, INET6_ADDRSTRLEN> text{};
    for (const int family : {AF_INET, AF_INET6}) {
        if (::inet_pton(family, a.c_str(), bin.data()) != 1) continue;
        const unsigned char* address = bin.data();
        int shown = family;
        if (family == AF_INET6 &&
            IN6_IS_ADDR_V4MAPPED(reinterpret_cast<const in6_addr*>(address))) {
            address += 12;
            shown = AF_INET;
        }
        if (::inet_ntop(shown, address, text.data(), text.size()) != nullptr) return text.data();
    }
    return {};
}

}  // namespace

std::string tcp_listener_key(const TcpConfig& tcp) {
    const std::string a = canonical_address(tcp.bind);
    return (a.empty() ? tcp.bind : a) + ":" + std::to_string(tcp.port);
}

bool any_address(const std::string& bind) {
    const std::string a = canonical_address(bind);
    return a == "0.0.0.0" || a == "::";
}

std::string serial_line_key(const std::string& device) {
    namespace fs = std::filesystem;
    std::error_code ec;
    // weakly_canonical resolves the part of the path that exists and normalises the rest.
    fs::path p = fs::weakly_canonical(device, ec);
    if (!ec) return p.string();
    return fs::path(device).lexically_normal().string();
}

std::string state_file_path(const Config& config, const std::string& state_directory) {
    std::string name = default_state_file(config);
    if (name.front() == '/') return name;
    std::string dir = state_directory.substr(0, state_directory.find(':'));
    if (dir.empty()) {
        const auto slash = config.path.rfind('/');
        if (slash == std::string::npos) {
            dir.assign(1, '.');
        } else if (slash == 0) {
            dir.assign(1, '/');
        } else {
            dir.assign(config.path, 0, slash);
        }
    }
    if (dir.back() != '/') dir += '/';
    dir += name;
    return dir;
}

std::string state_file_key(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path p = fs::absolute(path, ec);
    if (ec) return fs::path(path).lexically_normal().string();
    // weakly_canonical follows every link that leads somewhere; a dangling last link (to a state
    // file not made yet) is followed here, as the kernel would, up to its limit of 40.
    for (int links = 0; links < 40; ++links) {
        fs::path w = fs::weakly_canonical(p, ec);
        if (ec) break;
        if (!fs::is_symlink(fs::symlink_status(w, ec)) || ec) return w.string();
        const fs::path target = fs::read_symlink(w, ec);
        if (ec) return w.string();
        p = target.is_absolute() ? target : w.parent_path() / target;
    }
    return p.lexically_normal().string();
}

}  // namespace plcemu::config
