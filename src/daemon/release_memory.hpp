#pragma once
// Memory freed in bulk goes back to the system.

namespace plcemu::daemon {

/// Returns the free memory of every malloc arena to the system. A reload of thousands of PLCs
/// reads and builds hundreds of megabytes on a thread of its own and frees them; malloc keeps
/// what a thread's arena freed for that thread's next allocations, so without this the
/// process's RSS would stay at the reload's peak (docs/performance.md, "Many PLCs in one
/// process"). Takes each arena's lock in turn: for threads beside the loop only.
void release_freed_memory() noexcept;

}  // namespace plcemu::daemon
