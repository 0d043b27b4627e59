#pragma once
// Test support: what a test of a serial transport on a pty needs around the code under test —
// the log captured (to count what was said), a temporary directory with a pluggable pty in it,
// and the event loop run until a condition holds.

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <asio.hpp>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>

#include "support/log_capture.hpp"
#include "support/pluggable_pty.hpp"

namespace plcemu::testing {

class PtyLoop {
public:
    /// Captures the default logger's output under `logger` and plugs a pty in at
    /// <temporary directory>/tty.
    explicit PtyLoop(std::string logger)
        : capture_(std::move(logger)) {
        char dir[] = "/tmp/plcemu-pty-test-XXXXXX";
        if (::mkdtemp(dir) == nullptr) throw std::runtime_error("mkdtemp failed");
        dir_ = dir;
        pty_ = std::make_unique<PluggablePty>(dir_ + "/tty");
    }
    ~PtyLoop() {
        pty_.reset();
        ::rmdir(dir_.c_str());
    }
    PtyLoop(const PtyLoop&) = delete;
    PtyLoop& operator=(const PtyLoop&) = delete;

    /// The pty.
    PluggablePty& pty() { return *pty_; }

    /// Runs the loop, `step` at a time, until `done` or `limit`; true when `done`.
    template <class Pred>
    bool run_until(Pred done,
                   std::chrono::milliseconds limit,
                   std::chrono::milliseconds step = std::chrono::milliseconds(10)) {
        const auto end = std::chrono::steady_clock::now() + limit;
        while (!done()) {
            if (std::chrono::steady_clock::now() > end) return false;
            io.restart();
            io.run_for(step);
        }
        return true;
    }

    /// Everything logged so far.
    std::string log() const { return capture_.log(); }

    /// How often `needle` was logged.
    std::size_t count(const std::string& needle) const { return capture_.count(needle); }

    /// CPU time of the calling thread so far, in seconds.
    static double cpu_seconds() {
        rusage ru{};
        ::getrusage(RUSAGE_THREAD, &ru);
        return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
               static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e6;
    }

    asio::io_context io;  ///< the loop the code under test runs on

private:
    LogCapture capture_;
    std::string dir_;
    std::unique_ptr<PluggablePty> pty_;
};

}  // namespace plcemu::testing
