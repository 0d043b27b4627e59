#pragma once
// Test support: a plain TCP client of a listener under test, the test running the listener's
// event loop while it waits (for at most 2 s).

#include <array>
#include <asio.hpp>
#include <chrono>
#include <cstddef>
#include <functional>
#include <string>

namespace plcemu::testing {

/// Runs `io` until `done()` holds or 2 s passed.
template <typename Done>
void run_until(asio::io_context& io, Done done) {
    using namespace std::chrono_literals;
    io.restart();
    const auto end = std::chrono::steady_clock::now() + 2s;
    while (!done() && std::chrono::steady_clock::now() < end) io.run_for(10ms);
}

/// Reads from `s` until `n` bytes came, the peer closed or 2 s passed; returns what came.
inline std::string read_bytes(asio::io_context& io, asio::ip::tcp::socket& s, std::size_t n) {
    std::string got(n, '\0');
    std::size_t have = 0;
    bool eof = false;
    std::function<void()> next = [&] {
        s.async_read_some(asio::buffer(got.data() + have, n - have),
                          [&](const asio::error_code& ec, std::size_t k) {
                              have += k;
                              if (ec) eof = true;
                              if (!ec && have < n) next();
                          });
    };
    next();
    run_until(io, [&] { return have == n || eof; });
    if (have < n && !eof) {  // timed out: the read must end before its buffers do
        s.cancel();
        run_until(io, [&] { return eof; });
    }
    got.resize(have);
    return got;
}

/// True when the peer closed `s` within 2 s.
inline bool closed(asio::io_context& io, asio::ip::tcp::socket& s) {
    std::array<char, 16> b{};
    bool done = false;
    bool eof = false;
    s.async_read_some(asio::buffer(b), [&](const asio::error_code& ec, std::size_t) {
        done = true;
        eof = ec == asio::error::eof || ec == asio::error::connection_reset;
    });
    run_until(io, [&] { return done; });
    if (!done) {  // timed out: the read must end before its buffer does
        s.cancel();
        run_until(io, [&] { return done; });
    }
    return eof;
}

}  // namespace plcemu::testing
