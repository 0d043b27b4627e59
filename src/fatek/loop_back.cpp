// 4E: loop-back test. The reply's data are the request's, with no error code before them.

#include <algorithm>

#include "command.hpp"

namespace plcemu::fatek::handlers {

Error loop_back(std::span<const std::uint8_t> data, Target&, Reply& reply) noexcept {
    std::for_each(data.begin(), data.end(), [&](std::uint8_t c) { reply.put(c); });
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
