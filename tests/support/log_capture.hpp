#pragma once
// Test support: the default logger's output captured while an object lives, to count what the
// code under test said.

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <sstream>
#include <string>

namespace plcemu::testing {

class LogCapture {
public:
    /// Captures the default logger's output under `logger`, from `level` up.
    explicit LogCapture(std::string logger, spdlog::level::level_enum level = spdlog::level::info)
        : logger_(std::move(logger)),
          previous_(spdlog::default_logger()) {
        auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log_);
        auto captured = std::make_shared<spdlog::logger>(logger_, sink);
        captured->set_level(level);
        spdlog::set_default_logger(captured);
    }
    ~LogCapture() {
        spdlog::set_default_logger(previous_);
        spdlog::drop(logger_);  // its sink writes to log_, which goes with this object
    }
    LogCapture(const LogCapture&) = delete;
    LogCapture& operator=(const LogCapture&) = delete;

    /// Everything logged so far.
    std::string log() const { return log_.str(); }

    /// How often `needle` was logged.
    std::size_t count(const std::string& needle) const {
        const std::string text = log_.str();
        std::size_t n = 0;
        for (auto at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1))
            ++n;
        return n;
    }

private:
    std::string logger_;
    std::ostringstream log_;
    std::shared_ptr<spdlog::logger> previous_;
};

}  // namespace plcemu::testing
