#include "log_format.hpp"

#include <spdlog/pattern_formatter.h>

#include <string>
#include <string_view>

#include "plcemu/image/excerpt.hpp"

namespace plcemu::daemon {

namespace {

// %* : the message, escaped.
class EscapedMessage final : public spdlog::custom_flag_formatter {
public:
    void format(const spdlog::details::log_msg& msg,
                const std::tm& /*time*/,
                spdlog::memory_buf_t& dest) override {
        const std::string text = image::excerpt(
            std::string_view(msg.payload.data(), msg.payload.size()), std::string_view::npos);
        dest.append(text.data(), text.data() + text.size());
    }
    std::unique_ptr<custom_flag_formatter> clone() const override {
        return std::make_unique<EscapedMessage>();
    }
};

}  // namespace

std::unique_ptr<spdlog::formatter> log_formatter() {
    auto f = std::make_unique<spdlog::pattern_formatter>();
    f->add_flag<EscapedMessage>('*').set_pattern("%Y-%m-%d %H:%M:%S.%e %^%-5l%$ %*");
    return f;
}

}  // namespace plcemu::daemon
