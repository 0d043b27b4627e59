#include "mixed.hpp"

#include "command.hpp"

namespace plcemu::fatek {

namespace {

// Most items of a mixed request, and their most weight in words.
constexpr std::uint32_t kMaxItems = 64;
constexpr std::uint32_t kMaxWeight = 64;

}  // namespace

bool MixedItems::next(MixedItem& item) noexcept {
    if (at_ >= data_.size() || error_ != Error::None) return false;
    const NameParse p = parse_name(data_.subspan(at_));
    if (p.error != Error::None) {
        error_ = p.error;
        return false;
    }
    item.name = p.name;
    at_ += p.name.length;
    if (!values_) return true;
    const Width w = width_of(p.name.form);
    const std::size_t chars = chars_of(w);
    if (data_.size() - at_ < chars) {
        error_ = Error::Format;
        return false;
    }
    item.value = data_.subspan(at_, chars);
    at_ += chars;
    if (w != Width::Bit && !parse_hex(item.value)) {
        error_ = Error::Format;
        return false;
    }
    return true;
}

Error check_mixed(std::span<const std::uint8_t> data,
                  bool values,
                  const image::Layout& layout) noexcept {
    const auto count = read_count(data);
    if (!count) return Error::Format;
    MixedItems items(data, values);
    MixedItem it;
    std::uint32_t n = 0;
    std::uint32_t weight = 0;
    bool bad_bit = false;
    while (items.next(it)) {
        ++n;
        weight += width_of(it.name.form) == Width::Dword ? 2 : 1;
        bad_bit = bad_bit || (values && width_of(it.name.form) == Width::Bit &&
                              it.value[0] != '0' && it.value[0] != '1');
    }
    if (items.error() == Error::Format) return Error::Format;
    const bool unknown = items.error() == Error::Address;
    if (!unknown && n != *count) return Error::Format;
    if (*count == 0 || *count > kMaxItems || weight > kMaxWeight || bad_bit) return Error::Value;
    if (unknown) return Error::Address;
    MixedItems again(data, values);
    while (again.next(it)) {
        Run run;
        if (resolve(it.name, 1, layout, run) != Error::None) return Error::Address;
    }
    return Error::None;
}

}  // namespace plcemu::fatek
