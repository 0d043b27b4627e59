// Reading a listing into statements, and writing them back (plcemu/instructions/listing.hpp).

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/image/excerpt.hpp"
#include "plcemu/instructions/listing.hpp"

namespace plcemu::instructions {

namespace {

// A word of a line and where it stands. It points into its line: a listing's words are read
// without copying their text or the file's name, which took most of a line's time.
struct Word {
    std::string_view text;
    int column = 0;                     ///< from the line's first character
    const ListingLine* line = nullptr;  ///< the line it stands in

    Where where() const {
        Where w = line->where;
        w.column += column;
        return w;
    }
};

// ASCII case only, as the vendors' tools: mnemonics and device names are ASCII, and the C
// library's locale-aware toupper was a tenth of a line's time.
std::string upper(std::string_view s) {
    std::string u(s);
    for (char& c : u) {
        if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
    }
    return u;
}

std::string lower(std::string_view s) {
    std::string u(s);
    for (char& c : u) {
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    }
    return u;
}

bool digits(std::string_view s) {
    if (s.empty()) return false;
    for (const char c : s) {
        if (c < '0' || c > '9') return false;
    }
    return true;
}

// The words of a line: separated by blanks or commas, up to a `;` or `//` comment. A `:`
// ends a word and stays with it ("S:" "R0", "S:R0" → "S:" "R0").
void words_of(const ListingLine& line, std::vector<Word>& out) {
    out.clear();
    const std::string_view t = line.text;
    std::size_t i = 0;
    while (i < t.size()) {
        const char c = t[i];
        if (c == ';' || (c == '/' && i + 1 < t.size() && t[i + 1] == '/')) break;
        if (c == ' ' || c == '\t' || c == ',' || c == '\r') {
            ++i;
            continue;
        }
        const std::size_t start = i;
        // A comment ends the word it touches too ("OUT Y1;x", "OUT Y1//x").
        while (i < t.size() && t[i] != ' ' && t[i] != '\t' && t[i] != ',' && t[i] != ';' &&
               t[i] != '\r' && t[i] != ':' && !t.substr(i).starts_with("//")) {
            ++i;
        }
        if (i < t.size() && t[i] == ':') ++i;
        out.push_back({t.substr(start, i - start), static_cast<int>(start), &line});
    }
}

bool is_key(const Word& w) { return w.text.size() > 1 && w.text.back() == ':'; }

// `key:` words and the value after each; bare words stay in order.
void read_operands(std::vector<Word>::const_iterator it,
                   std::vector<Word>::const_iterator end,
                   Statement& s) {
    while (it != end) {
        // Each named operand is checked against those before it: without a bound, 100,000 on a
        // line took minutes to refuse.
        if (s.operands.size() + s.named.size() >= kMaxOperands) {
            throw BindError(it->where(), s.mnemonic + ": more than " +
                                             std::to_string(kMaxOperands) +
                                             " operands; no instruction takes so many");
        }
        if (is_key(*it)) {
            const std::string key = lower(it->text.substr(0, it->text.size() - 1));
            const Where kw = it->where();
            ++it;
            if (it == end || is_key(*it)) {
                // Quoted as written: "OUT Y0:" is more likely a stray colon than a name.
                throw BindError(kw, s.mnemonic + ": operand '" + image::excerpt((it - 1)->text) +
                                        "' has no value after it (a word ending in ':' names "
                                        "the operand that follows)");
            }
            for (const auto& [k, v] : s.named) {
                if (k == key)
                    throw BindError(
                        kw, s.mnemonic + ": duplicate operand '" + image::excerpt(key) + "'");
            }
            s.named.emplace_back(key, Operand{std::string(it->text), it->where()});
        } else {
            if (!s.named.empty()) {
                throw BindError(it->where(), s.mnemonic + ": operand '" + image::excerpt(it->text) +
                                                 "' after named operands needs its name");
            }
            s.operands.push_back({std::string(it->text), it->where()});
        }
        ++it;
    }
}

// A function instruction written by name (MOV, MOVP), if the dialect knows it.
const FunctionSpelling* by_name(const Dialect& d, std::string_view word, bool& pulse) {
    for (const auto& f : d.functions) {
        if (word == f.name) {
            pulse = false;
            return &f;
        }
        if (f.pulse && word.size() == f.name.size() + 1 &&
            word.substr(0, f.name.size()) == f.name && word.back() == 'P') {
            pulse = true;
            return &f;
        }
    }
    return nullptr;
}

const FunctionSpelling* by_number(const Dialect& d, int n) {
    for (const auto& f : d.functions) {
        if (f.number == n) return &f;
    }
    return nullptr;
}

// Reads the function a statement names from `it` on ("FUN 86 TPCTL", "FUN86", "FNC12 MOVP",
// "MOV"); returns false when the words do not start a function.
bool read_function(const Dialect& d,
                   std::vector<Word>::const_iterator& it,
                   std::vector<Word>::const_iterator end,
                   Statement& s) {
    const std::string first = upper(it->text);
    const std::string prefix = upper(d.function_prefix);
    bool pulse = false;
    // As the ladder box shows it: "86.TPCTL", "8P.MOV".
    if (const auto dot = first.find('.'); d.box_labels && dot != std::string::npos && dot > 0) {
        std::string number = first.substr(0, dot);
        if (number.back() == 'P') {
            pulse = true;
            number.pop_back();
        }
        bool named_pulse = false;
        const FunctionSpelling* f = by_name(d, first.substr(dot + 1), named_pulse);
        if (digits(number) && number.size() <= 4 && f != nullptr &&
            f->number == std::stoi(number) && (!pulse || f->pulse)) {
            s.where = it->where();
            s.function = f;
            s.pulse = pulse || named_pulse;
            s.mnemonic = std::string(f->name) + (s.pulse ? "P" : "");
            ++it;
            return true;
        }
        throw BindError(it->where(), "'" + image::excerpt(it->text) + "': not a function of " +
                                         std::string(d.tool) + " here");
    }
    if (!prefix.empty() && first.compare(0, prefix.size(), prefix) == 0) {
        std::string rest = first.substr(prefix.size());
        auto next = it + 1;
        if (rest.empty() && next != end &&
            digits(next->text.substr(0, next->text.find_first_not_of("0123456789")))) {
            rest = upper(next->text);
            ++next;
        } else if (rest.empty()) {
            throw BindError(it->where(), prefix + ": expected the function's number after it");
        }
        std::string number = rest;
        if (!number.empty() && number.back() == 'P') {
            pulse = true;
            number.pop_back();
        }
        if (!digits(number) || number.size() > 4) {
            throw BindError(it->where(), "'" + image::excerpt(it->text) + "': expected " + prefix +
                                             " and a function number");
        }
        const FunctionSpelling* f = by_number(d, std::stoi(number));
        if (f == nullptr) {
            std::string known;
            for (const auto& g : d.functions) {
                if (g.number < 0) continue;
                known += (known.empty() ? "" : ", ") + prefix + std::to_string(g.number) + " " +
                         std::string(g.name);
            }
            throw BindError(it->where(), prefix + " " + number + ": no such function in " +
                                             std::string(d.tool) + " here (known: " + known + ")");
        }
        if (pulse && !f->pulse) {
            throw BindError(it->where(), std::string(f->name) + " has no pulse form");
        }
        s.where = it->where();
        // The name may follow the number, and must then be this function's.
        if (next != end && !is_key(*next)) {
            bool named_pulse = false;
            const std::string n = upper(next->text);
            if (by_name(d, n, named_pulse) == f) {
                pulse = pulse || named_pulse;
                ++next;
            } else if (!n.empty() && std::isalpha(static_cast<unsigned char>(n[0])) &&
                       n.find_first_of("0123456789") == std::string::npos) {
                throw BindError(next->where(), prefix + std::to_string(f->number) + " is " +
                                                   std::string(f->name) + ", not '" +
                                                   image::excerpt(next->text) + "'");
            }
        }
        s.function = f;
        s.pulse = pulse;
        s.mnemonic = std::string(f->name) + (pulse ? "P" : "");
        it = next;
        return true;
    }
    const FunctionSpelling* f = by_name(d, first, pulse);
    if (f == nullptr) return false;
    s.where = it->where();
    s.function = f;
    s.pulse = pulse;
    s.mnemonic = first;
    ++it;
    return true;
}

}  // namespace

std::vector<Statement> read_listing(const std::vector<ListingLine>& lines, const Dialect& dialect) {
    std::vector<Statement> out;
    // A statement a line at most (comments and operand lines make fewer): one allocation.
    out.reserve(std::min(lines.size(), kMaxStatements));
    std::vector<Word> words;
    for (const auto& line : lines) {
        words_of(line, words);
        if (words.empty()) continue;
        auto it = words.cbegin();
        // A line of operands only continues the function above it (the mnemonic view lists a
        // function's operands below it).
        if (is_key(*it)) {
            if (out.empty() || out.back().function == nullptr) {
                throw BindError(it->where(), "operand '" + image::excerpt(it->text) +
                                                 "' without a function instruction above it");
            }
            read_operands(it, words.cend(), out.back());
            continue;
        }
        if (digits(it->text)) ++it;  // a step number, as --print-program writes it
        if (it == words.cend()) continue;
        Statement s;
        if (out.size() >= kMaxStatements) {
            throw BindError(it->where(), "the program has more than " +
                                             std::to_string(kMaxStatements) +
                                             " statements; refused");
        }
        s.step = static_cast<int>(out.size()) + 1;
        if (!read_function(dialect, it, words.cend(), s)) {
            // The longest spelling first: "LD NOT" before "LD", "OUT NOT" before "OUT".
            const std::string one = upper(it->text);
            const std::string two = it + 1 != words.cend() ? one + " " + upper((it + 1)->text) : "";
            auto found = dialect.words.cend();
            if (!two.empty()) found = dialect.words.find(two);
            const bool pair = found != dialect.words.cend();
            if (!pair) found = dialect.words.find(one);
            if (found == dialect.words.cend()) {
                throw BindError(it->where(), "unknown instruction '" + image::excerpt(it->text) +
                                                 "' (not in " + std::string(dialect.tool) + ")");
            }
            s.where = it->where();
            s.mnemonic = found->first;
            s.spelling = found->second;
            it += pair ? 2 : 1;
        }
        read_operands(it, words.cend(), s);
        out.push_back(std::move(s));
    }
    return out;
}

std::string format_listing(const std::vector<Statement>& statements) {
    std::string out;
    for (const auto& s : statements) {
        std::string step = std::to_string(s.step);
        if (step.size() < 4) step.insert(0, 4 - step.size(), '0');
        // Appended piece by piece: GCC 12 at -O2 warns (-Wrestrict, a false positive) on
        // `"literal" + std::string&&` here.
        out += step;
        out += "  ";
        out += s.mnemonic;
        for (const auto& o : s.operands) {
            out += ' ';
            out += o.text;
        }
        for (const auto& [k, v] : s.named) {
            out += ' ';
            out += upper(k);
            out += ':';
            out += v.text;
        }
        out += '\n';
    }
    return out;
}

}  // namespace plcemu::instructions
