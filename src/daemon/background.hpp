#pragma once
// The daemon's threads beside the event loop (the reload's preparation, freeing replaced PLCs,
// syncing state files) yield to it.

namespace plcemu::daemon {

/// Lowers the calling thread's scheduling priority below the event loop's (its nice value 10
/// above the process's, at most 19): work that may take seconds of a core must not take it from
/// the scans and the clients (docs/architecture.md, "Threads"). Failing, it changes nothing.
void yield_to_the_loop() noexcept;

}  // namespace plcemu::daemon
