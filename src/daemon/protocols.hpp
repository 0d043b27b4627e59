#pragma once
// The protocols a listener may name (docs/architecture.md, "How to add a protocol"): each
// protocol's folder offers its kind; this list is the one place that gathers them.

#include <span>
#include <string_view>

#include "plcemu/listener/protocol.hpp"

namespace plcemu::daemon {

/// Every protocol the daemon serves.
std::span<const listener::ProtocolKind> protocols();

/// The protocol named `name`; throws std::logic_error for a name no protocol has.
const listener::ProtocolKind& protocol(std::string_view name);

}  // namespace plcemu::daemon
