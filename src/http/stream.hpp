#pragma once
// HTTP/1.1 on a TCP listener seat: one session per connection, answering requests in order
// (keep-alive, pipelining) and, after an events request, carrying its stream.

#include <memory>

#include "plcemu/listener/protocol.hpp"

namespace plcemu::http {

/// The protocol of an `http:` listener.
std::unique_ptr<listener::StreamProtocol> make_stream(listener::ProtocolSetup setup);

}  // namespace plcemu::http
