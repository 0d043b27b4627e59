#include "profiles/vb/model.hpp"

namespace plcemu::profiles::vb {

namespace {

bool digit(char c) { return c >= '0' && c <= '9'; }
bool upper(char c) { return c >= 'A' && c <= 'Z'; }

}  // namespace

bool valid_model(std::string_view m) {
    std::size_t i = 0;
    auto at = [&](std::size_t k) { return k < m.size() ? m[k] : '\0'; };
    if (at(i++) != 'V') return false;
    if (at(i) != 'B' && at(i) != 'H') return false;
    ++i;
    if (digit(at(i))) ++i;  // series: VB2, VB1
    if (at(i++) != '-') return false;
    const std::size_t points = i;
    while (digit(at(i))) ++i;
    if (i == points) return false;
    if (at(i++) != 'M') return false;
    while (i < m.size() && upper(m[i])) ++i;  // output type: R relay, T transistor, …
    return i == m.size();
}

}  // namespace plcemu::profiles::vb
