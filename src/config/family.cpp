#include "plcemu/config/family.hpp"

#include <algorithm>
#include <map>

namespace plcemu::config {

namespace {

// Built on first use: families register during static initialisation, in any order.
std::map<std::string_view, const Family*>& registry() {
    static std::map<std::string_view, const Family*> r;
    return r;
}

}  // namespace

void add_family(const Family& family) { registry()[family.name()] = &family; }

const Family* find_family(std::string_view name) {
    const auto it = registry().find(name);
    return it == registry().end() ? nullptr : it->second;
}

std::vector<const Family*> families() {
    std::vector<const Family*> v;
    v.reserve(registry().size());
    for (const auto& [name, f] : registry()) v.push_back(f);
    return v;
}

std::string family_names() {
    std::string s;
    for (const auto& [name, f] : registry()) {
        if (!s.empty()) s += ", ";
        s += name;
    }
    return s;
}

bool Family::speaks(std::string_view protocol) const {
    const auto p = protocols();
    return std::find(p.begin(), p.end(), protocol) != p.end();
}

}  // namespace plcemu::config
