#pragma once
// HTTP as listeners name it (`http:`): the console, the REST API, /healthz and /metrics.

#include "plcemu/listener/protocol.hpp"
#include "stream.hpp"

namespace plcemu::http {

/// HTTP/1.1 on TCP (docs/console.md).
inline constexpr listener::ProtocolKind kHttp{"http", &make_stream, nullptr, nullptr};

}  // namespace plcemu::http
