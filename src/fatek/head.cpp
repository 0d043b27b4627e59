#include "head.hpp"

#include "command.hpp"

namespace plcemu::fatek {

Head read_head(std::span<const std::uint8_t> data) noexcept {
    Head h;
    const auto count = read_count(data);
    if (!count) {
        h.error = Error::Format;
        return h;
    }
    h.count = *count;
    const NameParse p = parse_name(data.subspan(2));
    h.error = p.error;
    h.start = p.name;
    h.size = 2 + p.name.length;
    return h;
}

}  // namespace plcemu::fatek
