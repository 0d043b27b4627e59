#pragma once
// The FATEK protocol as listeners name it (`fatek.tcp`, `fatek.udp`, `fatek.serial`).

#include "plcemu/listener/protocol.hpp"
#include "serial.hpp"
#include "stream.hpp"

namespace plcemu::fatek {

/// FATEK's own protocol (FBs manual, Appendix 2 FATEK Communication Protocol) on TCP, UDP and
/// serial lines.
inline constexpr listener::ProtocolKind kFatek{"fatek", &make_stream, &make_datagram, &make_serial};

}  // namespace plcemu::fatek
