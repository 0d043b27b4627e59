#include "http/stream.hpp"

#include <spdlog/spdlog.h>

#include <optional>
#include <string_view>

#include "http/message.hpp"
#include "http/router.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::http {

namespace {

class HttpSession final : public listener::Session {
public:
    HttpSession(listener::Outlet& outlet, listener::UnitTable& units)
        : outlet_(outlet),
          units_(units) {}

    listener::Split split(std::span<const std::uint8_t> buffered) const noexcept override {
        // A stream's client says nothing more; what it sends is not read as requests, and
        // dropped (kept, it would fill the connection's buffer).
        if (stream_) {
            return buffered.empty() ? listener::Split{}
                                    : listener::Split{listener::Cut::Skip, buffered.size(), ""};
        }
        return cutter_.split(buffered);
    }

    bool answer(std::span<const std::uint8_t> frame, std::vector<std::uint8_t>& out) override {
        if (stream_) return true;
        (void)frame;  // what the cutter read
        Request rq;
        Refusal refusal;
        std::string bytes;
        bool keep = true;
        try {
            const bool read = cutter_.take(rq, refusal);
            cutter_.next();
            if (!read) {
                // What follows a request that could not be read cannot be trusted.
                bytes = serialize(error(refusal.status, refusal.why), false);
                keep = false;
            } else {
                Routed routed = route(rq, units_);
                if (routed.stream) {
                    stream_ = std::move(routed.stream);
                    bytes = serialize(routed.response, false);
                    bool ended = false;
                    bytes += stream_->poll(units_, ended);
                    if (ended) {
                        keep = false;
                    } else {
                        outlet_.tick_every(kEventPeriod);
                    }
                } else {
                    keep = rq.keep_alive;
                    bytes = serialize(routed.response, keep, rq.method == "HEAD");
                }
            }
        } catch (const std::exception& e) {
            // Out of memory and the like: this request fails, the daemon does not.
            spdlog::warn("http: {} {} {}: {}", outlet_.peer(), rq.method,
                         image::excerpt(rq.target, 100), e.what());
            bytes = serialize(error(500, "internal error"), false);
            keep = false;
        }
        out.insert(out.end(), bytes.begin(), bytes.end());
        return keep;
    }

    void waiting(std::vector<std::uint8_t>& out) override {
        if (stream_ || !cutter_.take_continue()) return;
        constexpr std::string_view kContinue = "HTTP/1.1 100 Continue\r\n\r\n";
        out.insert(out.end(), kContinue.begin(), kContinue.end());
    }

    void tick() override {
        if (!stream_) return;
        bool ended = false;
        std::string events;
        try {
            events = stream_->poll(units_, ended);
        } catch (const std::exception& e) {
            spdlog::warn("http: {} event stream: {}", outlet_.peer(), e.what());
            ended = true;
        }
        if (!events.empty() &&
            !outlet_.send({reinterpret_cast<const std::uint8_t*>(events.data()), events.size()})) {
            return;  // closed: this session is gone
        }
        if (ended) outlet_.tick_every(std::chrono::milliseconds(0));
    }

private:
    listener::Outlet& outlet_;
    listener::UnitTable& units_;
    std::optional<Subscription> stream_;
    // Keeps its place in the request being read between reads: split() is const to the
    // connection, which may ask it twice over the same bytes, and the cutter answers alike.
    mutable RequestCutter cutter_;
};

class HttpProtocol final : public listener::StreamProtocol {
public:
    explicit HttpProtocol(listener::ProtocolSetup setup) {
        units_.assign(std::move(setup.seats));
        units_.set_read_only(setup.read_only);
    }
    std::size_t max_frame() const noexcept override { return kMaxRequest; }
    listener::Split split(std::span<const std::uint8_t>) const noexcept override {
        return {listener::Cut::Bad, 0, "http: no session"};
    }
    std::size_t answer(std::span<const std::uint8_t>, std::span<std::uint8_t>) noexcept override {
        return 0;
    }
    std::unique_ptr<listener::Session> open(listener::Outlet& outlet) override {
        return std::make_unique<HttpSession>(outlet, units_);
    }
    listener::UnitTable& units() noexcept override { return units_; }

private:
    listener::UnitTable units_;
};

}  // namespace

std::unique_ptr<listener::StreamProtocol> make_stream(listener::ProtocolSetup setup) {
    return std::make_unique<HttpProtocol>(std::move(setup));
}

}  // namespace plcemu::http
