#include "serial_line.hpp"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace plcemu::modbus {

namespace {

speed_t speed_of(int baud) {
    switch (baud) {
        case 300:
            return B300;
        case 600:
            return B600;
        case 1200:
            return B1200;
        case 2400:
            return B2400;
        case 4800:
            return B4800;
        case 9600:
            return B9600;
        case 19200:
            return B19200;
        case 38400:
            return B38400;
        case 57600:
            return B57600;
        case 115200:
            return B115200;
        case 230400:
            return B230400;
        case 460800:
            return B460800;
        case 921600:
            return B921600;
        default:
            throw std::system_error(EINVAL, std::generic_category(),
                                    "rtu: unsupported baud rate " + std::to_string(baud));
    }
}

[[noreturn]] void fail(int fd, const std::string& what) {
    const int err = errno;
    if (fd >= 0) ::close(fd);
    throw std::system_error(err, std::generic_category(), what);
}

}  // namespace

std::string describe(const RtuOptions& o) {
    std::string s = o.device + " " + std::to_string(o.baud) + " " + std::to_string(o.data_bits);
    s += o.parity;
    s += std::to_string(o.stop_bits);
    if (o.echo) s += " (echo dropped)";
    return s;
}

int open_serial_line(const RtuOptions& o, const std::string& name) {
    const int fd = ::open(o.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) fail(fd, name + ": cannot open " + o.device);
    termios tio{};
    if (::tcgetattr(fd, &tio) != 0) fail(fd, name + ": " + o.device + " is not a serial device");
    ::cfmakeraw(&tio);
    tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
    tio.c_cflag |= CLOCAL | CREAD | (o.data_bits == 7 ? CS7 : CS8);
    if (o.stop_bits == 2) tio.c_cflag |= CSTOPB;
    tio.c_iflag &= ~static_cast<tcflag_t>(INPCK | IGNPAR | PARMRK | IXON | IXOFF | IXANY);
    if (o.parity != 'N') {
        tio.c_cflag |= PARENB;
        if (o.parity == 'O') tio.c_cflag |= PARODD;
        // A character with a parity error is dropped; the frame's CRC then fails: silence.
        tio.c_iflag |= INPCK | IGNPAR;
    }
    tio.c_cc[VMIN] = 1;
    tio.c_cc[VTIME] = 0;
    const speed_t speed = speed_of(o.baud);
    if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0) {
        fail(fd, name + ": " + o.device + ": cannot set " + std::to_string(o.baud) + " baud");
    }
    if (::tcsetattr(fd, TCSANOW, &tio) != 0) {
        // The C library answers EINVAL when the device took none of the changes asked for: a
        // pty opened again (a reload, the next start) already has the speed, the one setting
        // it takes. That is a line that did not take every setting, said below, not one that
        // cannot be used.
        const int error = errno;
        termios had{};
        if (error != EINVAL || ::tcgetattr(fd, &had) != 0 || ::cfgetispeed(&had) != speed ||
            ::cfgetospeed(&had) != speed) {
            errno = error;
            fail(fd, name + ": cannot configure " + o.device);
        }
    }
    // tcsetattr succeeds when any part of the request was applied: say what was not.
    termios now{};
    constexpr tcflag_t kLine = CSIZE | PARENB | PARODD | CSTOPB;
    if (::tcgetattr(fd, &now) == 0 &&
        ((now.c_cflag & kLine) != (tio.c_cflag & kLine) || ::cfgetispeed(&now) != speed)) {
        spdlog::warn("{}: {} did not take every line setting of {} {}{}{} (a pty ignores them)",
                     name, o.device, o.baud, o.data_bits, o.parity, o.stop_bits);
    }
    // Whatever was waiting from before we opened the line is not a request to us.
    ::tcflush(fd, TCIOFLUSH);
    return fd;
}

}  // namespace plcemu::modbus
