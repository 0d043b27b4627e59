#pragma once
// HTTP/1.1 messages on a byte stream: where a request ends, what it says, and a response's bytes.
// Boost.Beast's parser and serializer do the work (docs/architecture.md, "HTTP"); they are used
// as codecs over bytes, because the connections are the listener seat's, on the daemon's loop.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "plcemu/listener/protocol.hpp"

namespace plcemu::http {

/// Largest request head (request line and headers).
inline constexpr std::size_t kMaxHead = std::size_t{8} * 1024;
/// Largest request body.
inline constexpr std::size_t kMaxBody = std::size_t{24} * 1024;
/// Largest request as sent: head, body, and a chunked body's sizes, extensions and trailers.
inline constexpr std::size_t kMaxRequest = std::size_t{64} * 1024;

/// A request as the handlers see it.
struct Request {
    std::string method;  ///< "GET"
    std::string target;  ///< as sent: "/api/v1/plcs/0/devices/R100?count=4"
    std::string path;    ///< the target's path, percent-decoded: "/api/v1/plcs/0/devices/R100"
    /// The path's segments, each decoded after the path was split at its slashes: an encoded
    /// slash (%2F) stays inside its segment. Empty segments are dropped.
    std::vector<std::string> segments;
    std::vector<std::pair<std::string, std::string>> query;  ///< decoded, in order
    std::string authorization;                               ///< the Authorization header
    std::string content_type;                                ///< the Content-Type header
    std::string origin;                                      ///< the Origin header
    std::string host;                                        ///< the Host header
    std::string body;                                        ///< the body, whole
    bool keep_alive = true;  ///< the connection may carry the next request

    /// The query parameter `name`, or null.
    const std::string* param(std::string_view name) const;
};

/// A response.
struct Response {
    unsigned status = 200;
    std::string content_type = "application/json";
    std::string body;
    std::vector<std::pair<std::string, std::string>> headers;  ///< besides the usual ones
    /// The body follows as a stream of events until the connection closes: no length is sent.
    bool stream = false;
};

/// A request that could not be read: the status that says why, and a message.
struct Refusal {
    unsigned status = 400;  ///< 400, 413 (body or request too large), 431 (head too large), 501
    std::string why;
};

/// Where requests end on one connection, reading each byte once: a head sent a byte at a time
/// costs what it costs in one piece (Beast's parser, kept between reads, resumes where it was).
class RequestCutter {
public:
    RequestCutter();
    ~RequestCutter();
    RequestCutter(const RequestCutter&) = delete;
    RequestCutter& operator=(const RequestCutter&) = delete;

    /// Where the first request of `buffered` ends: the bytes received and not yet served, which
    /// begin where that request begins and only grow from one call to the next until next().
    /// A request that cannot be read is a frame of every byte buffered, so that parse_request()
    /// says why and the connection is closed after the answer.
    listener::Split split(std::span<const std::uint8_t> buffered) noexcept;
    /// Reads the request split() cut; false with `refusal` set when it is not one (the
    /// connection is then closed). next() follows.
    bool take(Request& out, Refusal& refusal);
    /// True, once a request, when the request being read has its head and waits for a
    /// "100 Continue" before it sends its body (`Expect: 100-continue`, HTTP/1.1: RFC 9110
    /// §10.1.1).
    bool take_continue() noexcept;
    /// The request split() cut was taken: the next one begins after it.
    void next() noexcept;

private:
    struct State;
    std::unique_ptr<State> state_;
};

/// Reads `frame` as one whole request, as a fresh cutter would; false with `refusal` set when
/// it is not one.
bool parse_request(std::span<const std::uint8_t> frame, Request& out, Refusal& refusal);

/// The bytes of `response`; `keep_alive` false adds `Connection: close`. `head_only`: the
/// headers of a GET without its body (HEAD).
std::string serialize(const Response& response, bool keep_alive, bool head_only = false);

/// A response whose body follows as a stream of Server-Sent Events.
Response event_stream();

}  // namespace plcemu::http
