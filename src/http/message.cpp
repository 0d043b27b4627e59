#include "http/message.hpp"

#include <boost/beast/core/error.hpp>
#include <boost/beast/core/string.hpp>
#include <boost/beast/http.hpp>
#include <algorithm>
#include <iterator>
#include <optional>
#include <sstream>

namespace plcemu::http {

namespace beast = boost::beast;
namespace bhttp = boost::beast::http;

namespace {

using Parser = bhttp::request_parser<bhttp::string_body>;

// A parser with the limits of a request.
void configure(Parser& p) {
    p.header_limit(kMaxHead);
    p.body_limit(kMaxBody);
    p.eager(true);
}

// Feeds `bytes` to `p` until one message is whole; returns the bytes it took (those of a head
// not whole yet are not taken: they are given again with the next ones) and leaves the parser's
// error in `ec`, need_more while the message is not whole.
std::size_t feed(Parser& p, std::span<const std::uint8_t> bytes, beast::error_code& ec) {
    std::size_t used = 0;
    while (!p.is_done()) {
        const std::size_t n =
            p.put(boost::asio::const_buffer(bytes.data() + used, bytes.size() - used), ec);
        used += n;
        if (ec) return used;
        if (n == 0) {
            ec = bhttp::error::need_more;
            return used;
        }
    }
    return used;
}

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// Percent-decoding of a target's pieces (RFC 3986 §2.1; `+` as a space in a query). Beast reads
// the request but not its target, and the Boost here has no URL library: it is small enough.
bool decode(std::string_view in, std::string& out, bool query) {
    out.clear();
    for (std::size_t i = 0; i < in.size(); ++i) {
        const char c = in[i];
        if (c == '%') {
            if (i + 2 >= in.size()) return false;
            const int hi = hex_digit(in[i + 1]);
            const int lo = hex_digit(in[i + 2]);
            if (hi < 0 || lo < 0) return false;
            out.push_back(static_cast<char>(hi * 16 + lo));
            i += 2;
        } else if (query && c == '+') {
            out.push_back(' ');
        } else {
            out.push_back(c);
        }
    }
    return true;
}

// A Host header's value as RFC 9110 §7.2 has it: a name or address and an optional port of
// digits (an IPv6 address in brackets). Empty (no Host, HTTP/1.0) passes.
bool host_and_port(std::string_view h) {
    if (h.empty()) return true;
    std::size_t end = h.size();
    if (h.front() == '[') {
        end = h.find(']');
        if (end == std::string_view::npos) return false;
        ++end;
    } else {
        if (const auto colon = h.rfind(':'); colon != std::string_view::npos) end = colon;
        // A name or an IPv4 address has none of these (RFC 3986 §3.2.2: reg-name); "::1"
        // without brackets, "user@host" or "127.0.0.1:80:90" is no host[:port].
        if (h.substr(0, end).find_first_of(":@#/?[]\\ \t") != std::string_view::npos) return false;
    }
    if (end == h.size()) return true;
    const std::string_view port = h.substr(end);
    // RFC 3986 §3.2.3: the port is *DIGIT, so "host:" is a Host too.
    return port.size() <= 6 && port.front() == ':' &&
           port.find_first_not_of("0123456789", 1) == std::string_view::npos;
}

std::string field(const bhttp::request<bhttp::string_body>& m, bhttp::field f) {
    const auto it = m.find(f);
    return it == m.end() ? std::string() : std::string(it->value());
}

// True when a head of text has a line that ends in LF alone, which Beast refuses as what it
// met next ("bad version", "bad value"). Bytes that are no text (a TLS hello sent to the
// console's port) are not a head: Beast's words stay.
bool bare_lf_in_head(std::span<const std::uint8_t> b) {
    for (std::size_t i = 0; i < b.size(); ++i) {
        const std::uint8_t c = b[i];
        if (c == '\n') {
            if (i == 0 || b[i - 1] != '\r') return true;
            if (i >= 3 && b[i - 2] == '\n' && b[i - 3] == '\r') return false;  // the head's end
            continue;
        }
        if (c != '\r' && c != '\t' && (c < 0x20 || c > 0x7E)) return false;
    }
    return false;
}

}  // namespace

const std::string* Request::param(std::string_view name) const {
    for (const auto& [k, v] : query) {
        if (k == name) return &v;
    }
    return nullptr;
}

struct RequestCutter::State {
    std::optional<Parser> parser;  // the request being read; none before its first byte
    std::size_t taken = 0;         // the bytes of it the parser has taken
    beast::error_code error;       // the parser's error: it takes nothing more
    bool too_large = false;        // kMaxRequest bytes came and the request is not whole
    bool continued = false;        // its 100 Continue was sent
    bool bare_lf = false;          // a line of its head ended in LF alone (bare_lf_in_head)
};

RequestCutter::RequestCutter() = default;
RequestCutter::~RequestCutter() = default;

listener::Split RequestCutter::split(std::span<const std::uint8_t> buffered) noexcept {
    try {
        if (!state_) state_ = std::make_unique<State>();
        State& s = *state_;
        // Fewer bytes than were taken: not the bytes of the last call (a caller's mistake that
        // costs a parse from the start, not a wrong cut).
        if (s.parser && buffered.size() < s.taken) next();
        // Empty lines before a request line are ignored (RFC 9112 §2.2: a client may send a
        // CRLF after a request's body); they were a 400 "bad method".
        if (!s.parser || s.taken == 0) {
            std::size_t blank = 0;
            while (blank < buffered.size() &&
                   (buffered[blank] == '\r' || buffered[blank] == '\n')) {
                ++blank;
            }
            if (blank > 0) return {listener::Cut::Skip, blank, ""};
        }
        if (!s.parser) {
            configure(s.parser.emplace());
            s.taken = 0;
        }
        // A request that cannot be read is every byte buffered: take() says why.
        if (s.error || s.too_large) return {listener::Cut::Frame, buffered.size(), ""};
        if (s.parser->is_done()) return {listener::Cut::Frame, s.taken, ""};
        beast::error_code ec;
        s.taken += feed(*s.parser, buffered.subspan(s.taken), ec);
        const bool more = ec == bhttp::error::need_more;
        if (ec && !more) {
            s.error = ec;
            s.bare_lf = bare_lf_in_head(buffered);
            return {listener::Cut::Frame, buffered.size(), ""};
        }
        // Chunks' sizes, extensions and trailers are bytes too, which the body limit does not
        // count: the request as sent has a limit of its own.
        if (s.taken > kMaxRequest || (more && buffered.size() >= kMaxRequest)) {
            s.too_large = true;
            return {listener::Cut::Frame, buffered.size(), ""};
        }
        if (more) return {listener::Cut::Incomplete, 0, ""};
        return {listener::Cut::Frame, s.taken, ""};
    } catch (...) {
        return {listener::Cut::Bad, 0, "http: out of memory"};
    }
}

bool RequestCutter::take_continue() noexcept {
    if (!state_ || !state_->parser || state_->error || state_->continued) return false;
    const Parser& p = *state_->parser;
    if (!p.is_header_done() || p.is_done()) return false;
    const auto& m = p.get();
    const auto expect = m.find(bhttp::field::expect);
    // An HTTP/1.0 request's expectation is ignored (RFC 9110 §10.1.1).
    if (m.version() < 11 || expect == m.end() || !beast::iequals(expect->value(), "100-continue"))
        return false;
    state_->continued = true;
    return true;
}

void RequestCutter::next() noexcept {
    if (!state_) return;
    state_->parser.reset();
    state_->taken = 0;
    state_->error = {};
    state_->too_large = false;
    state_->continued = false;
    state_->bare_lf = false;
}

bool RequestCutter::take(Request& out, Refusal& refusal) {
    if (!state_ || !state_->parser) {
        refusal = {400, "not an HTTP/1.1 request: nothing was sent"};
        return false;
    }
    const State& s = *state_;
    if (s.too_large) {
        refusal = {413, "the request is larger than " + std::to_string(kMaxRequest) +
                            " bytes as sent (its chunks' sizes, extensions and trailers counted)"};
        return false;
    }
    if (s.error == bhttp::error::header_limit) {
        refusal = {431, "the request's head is larger than " + std::to_string(kMaxHead) + " bytes"};
        return false;
    }
    if (s.error == bhttp::error::body_limit) {
        refusal = {413, "the request's body is larger than " + std::to_string(kMaxBody) + " bytes"};
        return false;
    }
    if (s.error && s.bare_lf) {
        refusal = {400,
                   "not an HTTP/1.1 request: its lines end in LF alone, where HTTP ends them "
                   "in CR LF"};
        return false;
    }
    if (s.error || !s.parser->is_done()) {
        refusal = {400, "not an HTTP/1.1 request: " +
                            (s.error ? s.error.message() : std::string("it is not whole"))};
        return false;
    }
    Parser& p = *state_->parser;
    const auto& m = p.get();
    // RFC 9112 §3.2: an HTTP/1.1 request without Host, with more than one, or with a Host that
    // is no host[:port], is answered 400 (which of two would the Host check believe?). HTTP/1.0
    // has no Host to require.
    const std::size_t hosts = m.count(bhttp::field::host);
    if (hosts == 0 && m.version() >= 11) {
        refusal = {400, "an HTTP/1.1 request without a Host header"};
        return false;
    }
    if (hosts > 1) {
        refusal = {400, "more than one Host header"};
        return false;
    }
    if (!host_and_port(field(m, bhttp::field::host))) {
        refusal = {400, "the Host header is no host[:port]"};
        return false;
    }
    // RFC 9112 §6.1: a transfer coding it does not know is answered 501. Beast undoes chunked
    // alone, and would hand over a body still gzip'ed as though it were plain.
    if (const auto te = m.find(bhttp::field::transfer_encoding); te != m.end()) {
        const bhttp::token_list codings(te->value());
        const auto first = codings.begin();
        if (first == codings.end() || !beast::iequals(*first, "chunked") ||
            std::next(first) != codings.end()) {
            refusal = {501, "Transfer-Encoding other than chunked is not implemented"};
            return false;
        }
    }
    out.method = std::string(m.method_string());
    out.target = std::string(m.target());
    out.keep_alive = m.keep_alive();
    out.authorization = field(m, bhttp::field::authorization);
    out.content_type = field(m, bhttp::field::content_type);
    out.origin = field(m, bhttp::field::origin);
    out.host = field(m, bhttp::field::host);
    out.body = std::move(p.get().body());
    std::string_view target = out.target;
    std::string rooted;  // an absolute form's path when it has none ("http://h?x" is "/?x")
    // RFC 9112 §3.2.2: a server takes a target in absolute form (what a client sends through a
    // proxy), and the host it names, not the Host header's, is the one the request is for.
    if (beast::iequals(beast::string_view(target.data(), std::min<std::size_t>(target.size(), 7)),
                       "http://")) {
        target.remove_prefix(7);
        const std::size_t end = std::min(target.find_first_of("/?"), target.size());
        out.host = std::string(target.substr(0, end));
        target.remove_prefix(end);
        if (out.host.empty() || !host_and_port(out.host)) {
            refusal = {400, "the request target's host is no host[:port]"};
            return false;
        }
        if (target.empty() || target.front() == '?') {
            rooted = "/";
            rooted += target;
            target = rooted;
        }
    }
    if (target.empty() || target.front() != '/') {
        refusal = {400, "the request target must be a path starting with '/'"};
        return false;
    }
    const auto q = target.find('?');
    const std::string_view raw_path = target.substr(0, q);
    if (!decode(raw_path, out.path, false)) {
        refusal = {400, "bad percent-encoding in the path"};
        return false;
    }
    out.segments.clear();
    for (std::size_t i = 0; i < raw_path.size();) {
        const std::size_t j = std::min(raw_path.find('/', i), raw_path.size());
        if (j > i) {
            std::string seg;
            decode(raw_path.substr(i, j - i), seg, false);  // checked whole above
            out.segments.push_back(std::move(seg));
        }
        i = j + 1;
    }
    out.query.clear();
    if (q != std::string_view::npos) {
        std::string_view rest = target.substr(q + 1);
        while (!rest.empty()) {
            const auto amp = rest.find('&');
            const std::string_view pair = rest.substr(0, amp);
            rest = amp == std::string_view::npos ? std::string_view() : rest.substr(amp + 1);
            if (pair.empty()) continue;
            const auto eq = pair.find('=');
            std::string k;
            std::string v;
            if (!decode(pair.substr(0, eq), k, true) ||
                (eq != std::string_view::npos && !decode(pair.substr(eq + 1), v, true))) {
                refusal = {400, "bad percent-encoding in the query"};
                return false;
            }
            out.query.emplace_back(std::move(k), std::move(v));
        }
    }
    return true;
}

bool parse_request(std::span<const std::uint8_t> frame, Request& out, Refusal& refusal) {
    RequestCutter cutter;
    if (cutter.split(frame).cut == listener::Cut::Bad) throw std::bad_alloc();
    return cutter.take(out, refusal);
}

std::string serialize(const Response& r, bool keep_alive, bool head_only) {
    bhttp::response<bhttp::string_body> m;
    m.version(11);
    m.result(r.status);
    m.set(bhttp::field::server, "plcemud");
    m.set(bhttp::field::content_type, r.content_type);
    // Pages and values change with every scan; nothing is to be cached.
    m.set(bhttp::field::cache_control, "no-store");
    m.set("X-Content-Type-Options", "nosniff");
    for (const auto& [k, v] : r.headers) m.set(k, v);
    m.body() = r.body;
    m.keep_alive(keep_alive);
    if (!r.stream) m.prepare_payload();
    std::ostringstream o;
    if (head_only) {
        o << m.base();
    } else {
        o << m;
    }
    return o.str();
}

Response event_stream() {
    Response r;
    r.content_type = "text/event-stream";
    r.stream = true;
    return r;
}

}  // namespace plcemu::http
