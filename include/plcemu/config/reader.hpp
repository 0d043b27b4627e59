#pragma once
// Checked reading of config nodes: every accessor checks the node's kind and value and throws
// ConfigError at the node's line and column with a message naming the key. The loader and the
// profiles' own sections read through it, so every section words its errors alike.

#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "plcemu/config/node.hpp"
#include "plcemu/image/area.hpp"
#include "plcemu/image/naming.hpp"

namespace plcemu::config {

/// A configuration error: "file:line:col: message". The daemon exits with status 2 on it.
class ConfigError : public std::runtime_error {
public:
    ConfigError(const Position& pos, const std::string& message);
    /// Where the error is.
    const Position& position() const { return pos_; }
    /// The message without its position.
    const std::string& message() const { return message_; }

private:
    Position pos_;
    std::string message_;
};

/// Reads nodes of one file, spelling devices and constants the profile's way.
class Reader {
public:
    /// Before a naming is set, integers are plain (decimal, 0x…).
    Reader() = default;
    /// Devices and constants spelt as `naming` says.
    explicit Reader(const image::Naming& naming)
        : naming_(&naming) {}

    /// From the `profile:` key on, devices and constants are spelt the profile's way.
    void set_naming(const image::Naming& naming) { naming_ = &naming; }
    /// The naming in force.
    const image::Naming& naming() const { return *naming_; }

    /// Where `n` stands.
    Position pos(const Node& n) const { return n.pos; }
    /// Throws ConfigError at `n`.
    [[noreturn]] void fail(const Node& n, const std::string& msg) const;
    /// `n` must be a mapping.
    void expect_map(const Node& n, const std::string& what) const;
    /// `n` must be a mapping whose keys are among `known`, each once (catches typos).
    void check_keys(const Node& n,
                    const std::string& what,
                    std::initializer_list<const char*> known) const;
    /// The same with a list made at run time.
    void check_keys(const Node& n,
                    const std::string& what,
                    const std::vector<std::string>& known) const;
    /// A scalar, as written.
    std::string scalar(const Node& n, const std::string& what) const;
    /// An integer in the profile's grammar (K100, H0011, 0x11, 100), within lo..hi.
    long long integer(const Node& n, const std::string& what, long long lo, long long hi) const;
    /// A finite number within lo..hi.
    double number(const Node& n, const std::string& what, double lo, double hi) const;
    /// true/yes/on/1 or false/no/off/0.
    bool boolean(const Node& n, const std::string& what) const;
    /// A device of the profile's naming.
    image::Device device(const Node& n, const std::string& what) const;
    /// A device range such as D100-D199.
    image::Range range(const Node& n, const std::string& what) const;

private:
    // " (X and Y are numbered in octal …)" after an error about `text`, or "".
    std::string octal_hint(const std::string& text) const;

    static inline const image::Naming kPlain{};  // before `profile:`: plain integers only
    const image::Naming* naming_ = &kPlain;
};

}  // namespace plcemu::config
