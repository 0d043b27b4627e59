#include <algorithm>
#include <map>

#include "plcemu/profiles/profile.hpp"

namespace plcemu::profiles {

namespace {

// Built on first use: registrations run during static initialisation, in any order.
std::map<std::string_view, const Profile*>& registry() {
    static std::map<std::string_view, const Profile*> r;
    return r;
}

}  // namespace

std::unique_ptr<instructions::Services> Profile::services(const config::Config& /*config*/) const {
    return std::make_unique<instructions::Services>();
}

Registration::Registration(const Profile& profile) { registry()[profile.name()] = &profile; }

const Profile* find(std::string_view name) {
    const auto it = registry().find(name);
    return it == registry().end() ? nullptr : it->second;
}

const Profile& of(const config::Config& config) {
    const Profile* p = find(config.profile);
    // The loader accepts registered names only; a Config built by hand must name one too.
    if (p == nullptr) throw config::ConfigError({config.path, 1, 1}, "unknown profile");
    return *p;
}

std::vector<const Profile*> all() {
    std::vector<const Profile*> v;
    for (const auto& [name, p] : registry()) v.push_back(p);
    return v;
}

std::string names() {
    std::string s;
    for (const auto& [name, p] : registry()) {
        if (!s.empty()) s += ", ";
        s += name;
    }
    return s;
}

}  // namespace plcemu::profiles
