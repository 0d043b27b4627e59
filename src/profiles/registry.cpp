#include "plcemu/config/family.hpp"
#include "plcemu/profiles/profile.hpp"

namespace plcemu::profiles {

// One registry, the config loader's (config::add_family): the profiles are the families there.

std::unique_ptr<instructions::Services> Profile::services(const config::Config& /*config*/) const {
    return std::make_unique<instructions::Services>();
}

Registration::Registration(const Profile& profile) { config::add_family(profile); }

const Profile* find(std::string_view name) {
    return dynamic_cast<const Profile*>(config::find_family(name));
}

const Profile& of(const config::Config& config) {
    const Profile* p = find(config.profile);
    // The loader accepts registered names only; a Config built by hand must name one too.
    if (p == nullptr) throw config::ConfigError({config.path, 1, 1}, "unknown profile");
    return *p;
}

std::vector<instructions::Statement> listing_statements(const config::Config& config) {
    const Profile& profile = of(config);
    const instructions::Dialect* dialect = profile.listing();
    if (dialect == nullptr) {
        throw config::ConfigError(config.listing.front().pos,
                                  "program: profile " + config.profile +
                                      " has no instruction list; write the program as entries");
    }
    std::vector<instructions::ListingLine> lines;
    lines.reserve(config.listing.size());
    for (const auto& l : config.listing) {
        lines.push_back({l.text, {l.pos.file.str(), l.pos.line, l.pos.column}});
    }
    try {
        return instructions::read_listing(lines, *dialect);
    } catch (const instructions::BindError& e) {
        const auto& w = e.where();
        throw config::ConfigError({w.file, w.line, w.column}, e.what());
    }
}

std::vector<ProgramInstruction> program_instructions(const config::Config& config) {
    std::vector<ProgramInstruction> out;
    for (const auto& e : config.program) out.push_back({e.mnemonic, e.pos});
    if (config.listing.empty() || find(config.profile) == nullptr) return out;
    try {
        for (const auto& s : listing_statements(config)) {
            if (s.function == nullptr) continue;
            out.push_back(
                {std::string(s.function->name), {s.where.file, s.where.line, s.where.column}});
        }
    } catch (const config::ConfigError&) {
        // Reported with its position when the program is built.
    }
    return out;
}

std::vector<const Profile*> all() {
    std::vector<const Profile*> v;
    for (const config::Family* f : config::families()) {
        if (const auto* p = dynamic_cast<const Profile*>(f)) v.push_back(p);
    }
    return v;
}

std::string_view family_name(std::uint32_t family) {
    for (const Profile* p : all()) {
        if (p->family() == family) return p->name();
    }
    return {};
}

}  // namespace plcemu::profiles
