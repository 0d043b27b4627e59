// A program from its entries, through a profile's instruction table.

#include <string>

#include "plcemu/image/excerpt.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

std::string Where::text() const {
    return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

std::string Entry::ordinal() const {
    return (step ? "step " : "program entry ") + std::to_string(index);
}

void OperationError::raise(image::Image& img, std::uint16_t error, int index) const noexcept {
    img.write_word(code, error);
    img.write_word(entry, static_cast<std::uint16_t>(index));
    img.write_bit(flag, true);
}

BindError::BindError(Where where, const std::string& message)
    : std::runtime_error(message),
      where_(std::move(where)) {}

engine::Program make_program(const std::vector<Entry>& program,
                             const Table& table,
                             const image::Layout& layout,
                             const image::Naming& naming,
                             const Services& services,
                             engine::Tags* operands) {
    engine::Program p;
    p.reserve(program.size());
    // What the entries bound so far declared, kept as the program grows: each entry checks its
    // operands against it without re-reading the earlier instructions.
    engine::Declarations earlier;
    for (const auto& e : program) {
        const auto it = table.find(e.mnemonic);
        if (it == table.end()) {
            std::string names;
            for (const auto& [k, v] : table) names += std::string(names.empty() ? "" : ", ") + k;
            throw BindError(e.where, "unknown instruction '" + image::excerpt(e.mnemonic) +
                                         "' (this profile knows: " + names + ")");
        }
        const BindContext ctx{layout, naming, services, earlier, operands};
        p.push_back(it->second(e, ctx));
        p.back()->declare(earlier);
    }
    return p;
}

}  // namespace plcemu::instructions
