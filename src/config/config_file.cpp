#include "config/config_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "plcemu/config/reader.hpp"

namespace plcemu::config {

namespace {

// What a file that is not a regular one is, in the words of ls(1) and stat(1).
const char* kind_of(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "of another type";
}

std::string too_big(const std::string& what) {
    return what + " is larger than " + std::to_string(kMaxConfigBytes >> 20) + " MiB; refused";
}

// Closes the descriptor on every way out.
struct Descriptor {
    int fd;
    ~Descriptor() {
        if (fd >= 0) ::close(fd);
    }
};

}  // namespace

std::string read_config_file(const std::string& path, const std::string& what) {
    const Position at{path, 0, 0};
    // O_NONBLOCK: opening a FIFO nobody writes returns at once instead of waiting for a writer
    // (it is refused below); on a regular file the flag changes nothing.
    Descriptor f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
    if (f.fd < 0) {
        throw ConfigError(at, "cannot open " + what + ": " + std::strerror(errno));
    }
    struct stat st {};
    if (::fstat(f.fd, &st) != 0) {
        throw ConfigError(at, "cannot stat " + what + ": " + std::strerror(errno));
    }
    if (!S_ISREG(st.st_mode)) {
        throw ConfigError(at,
                          what + " is " + kind_of(st.st_mode) + ", not a regular file; refused");
    }
    if (static_cast<unsigned long long>(st.st_size) > kMaxConfigBytes)
        throw ConfigError(at, too_big(what));
    // The size stat gave may change while the file is read: the read itself stops one byte past
    // the limit.
    std::string text;
    text.resize(static_cast<std::size_t>(st.st_size) + 1);
    std::size_t got = 0;
    for (;;) {
        if (got == text.size()) {
            if (text.size() > kMaxConfigBytes) throw ConfigError(at, too_big(what));
            text.resize(std::min(kMaxConfigBytes + 1, text.size() * 2));
        }
        const ssize_t n = ::read(f.fd, text.data() + got, text.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            throw ConfigError(at, "cannot read " + what + ": " + std::strerror(errno));
        }
        if (n == 0) break;
        got += static_cast<std::size_t>(n);
    }
    text.resize(got);
    return text;
}

}  // namespace plcemu::config
