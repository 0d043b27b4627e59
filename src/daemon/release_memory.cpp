#include "daemon/release_memory.hpp"

#include <malloc.h>

namespace plcemu::daemon {

void release_freed_memory() noexcept { ::malloc_trim(0); }

}  // namespace plcemu::daemon
