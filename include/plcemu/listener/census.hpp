#pragma once
// What the process counts beside its PLCs' requests, for the metrics an operator scrapes
// (docs/operations.md, "Health and metrics"): its listeners' connections, its reloads and its
// state-file syncs. The daemon owns it and fills it; views (HTTP's /metrics) only read it.

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace plcemu::listener {

/// One stream listener's connections.
struct ConnectionFigures {
    std::string protocol;        ///< "modbus-tcp", "fatek", "http"
    std::string endpoint;        ///< "0.0.0.0:502"
    std::uint64_t open = 0;      ///< connections open now
    std::uint64_t accepted = 0;  ///< connections accepted since the listener opened
    std::uint64_t refused = 0;   ///< closed at accept: not allowed, or max_clients reached
};

/// The clients every TCP listener of the process may hold together: what the descriptor limit
/// leaves once the daemon's own descriptors and a reload's files are counted. At it, listeners
/// stop accepting (connections wait in the backlog) until a client leaves, so that clients can
/// never take the descriptors a reload needs to read its config (docs/operations.md).
struct ClientRoom {
    long room = -1;  ///< clients allowed at once (-1: no limit)
    long open = 0;   ///< clients connected now
    bool full() const noexcept { return room >= 0 && open >= room; }
};

/// The process's figures.
struct Census {
    /// The stream listeners open now (the daemon answers it from its listeners).
    std::function<std::vector<ConnectionFigures>()> connections;
    std::uint64_t reloads_applied = 0;   ///< SIGHUP reloads applied
    std::uint64_t reloads_rejected = 0;  ///< SIGHUP reloads refused (the old config kept)
    // The state files are synced on a thread of their own.
    std::atomic<std::uint64_t> syncs{0};          ///< state-file syncs that reached the disk
    std::atomic<std::uint64_t> sync_failures{0};  ///< syncs the kernel refused (msync failed)
    std::atomic<std::uint64_t> pages_synced{0};   ///< state-file pages the syncs wrote to disk
};

}  // namespace plcemu::listener
