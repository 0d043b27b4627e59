#pragma once
// Test support: a scripted outbound link for master instructions (FNC149 MBUS). It records each
// request; a test then completes it with a reply, an exception, a time-out or garbage, or lets
// a responder answer every request at once, as a slave faster than the scan would.

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <vector>

#include "plcemu/engine/outbound.hpp"

namespace plcemu::testing {

class FakeOutbound final : public engine::OutboundLink {
public:
    /// Answers every request when set (the answer is there at the next poll).
    std::function<engine::OutboundCompletion(const engine::OutboundRequest&)> responder;
    /// Every request submitted, in order.
    std::vector<engine::OutboundRequest> sent;
    /// Requests given up (abandon() with nothing in flight gives up none).
    int abandoned = 0;

    bool submit(const engine::OutboundRequest& r) noexcept override {
        if (busy_) return false;
        sent.push_back(r);
        busy_ = true;
        if (responder) ready_ = responder(r);
        return true;
    }
    std::optional<engine::OutboundCompletion> poll() noexcept override {
        if (!busy_ || !ready_) return std::nullopt;
        busy_ = false;
        auto c = ready_;
        ready_.reset();
        return c;
    }
    void abandon() noexcept override {
        if (busy_) ++abandoned;
        busy_ = false;
        ready_.reset();
    }

    /// True while a request waits for its completion.
    bool busy() const { return busy_; }
    /// Completes the request in flight with a reply carrying `values`.
    void reply(std::initializer_list<std::uint16_t> values = {}) { ready_ = make_reply(values); }
    /// Completes it with an exception reply.
    void exception(std::uint8_t code) {
        engine::OutboundCompletion c;
        c.status = engine::OutboundStatus::Exception;
        c.exception = code;
        ready_ = c;
    }
    /// Completes it with a time-out.
    void time_out() { ready_ = engine::OutboundCompletion{}; }
    /// Completes it with a reply that does not answer it.
    void garbage() {
        engine::OutboundCompletion c;
        c.status = engine::OutboundStatus::Malformed;
        ready_ = c;
    }

    /// A reply with `values`.
    static engine::OutboundCompletion make_reply(std::initializer_list<std::uint16_t> values) {
        engine::OutboundCompletion c;
        c.status = engine::OutboundStatus::Reply;
        std::size_t i = 0;
        for (auto v : values) c.values.at(i++) = v;
        return c;
    }

private:
    bool busy_ = false;
    std::optional<engine::OutboundCompletion> ready_;
};

}  // namespace plcemu::testing
