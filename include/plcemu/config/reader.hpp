#pragma once
// Checked reading of config nodes: every accessor checks the node's kind and value and throws
// ConfigError at the node's line and column with a message naming the key. The loader and the
// profiles' own sections read through it, so every section words its errors alike. With an
// Errors list, a reader records an error in one key or entry and reads on (attempt).

#include <cstddef>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "plcemu/config/node.hpp"
#include "plcemu/image/area.hpp"
#include "plcemu/image/naming.hpp"

namespace plcemu::config {

/// One error of a config file: where, and what is wrong there.
struct Diagnostic {
    Position pos;         ///< where
    std::string message;  ///< what, without the position
};

/// A configuration error: "file:line:col: message". The daemon exits with status 2 on it. A
/// loader that reads on past an error (Errors) throws all it found in one: what(), position()
/// and message() are then the first's, errors() has every one (docs/configuration.md,
/// "Configuration").
class ConfigError : public std::runtime_error {
public:
    ConfigError(const Position& pos, const std::string& message);
    /// Several errors (at least one), in the order of their positions; `stopped`: the loader
    /// gave up at Errors::kMax with more still unread.
    ConfigError(std::vector<Diagnostic> errors, bool stopped);
    /// Where the (first) error is.
    const Position& position() const { return errors_.front().pos; }
    /// The (first) message without its position.
    const std::string& message() const { return errors_.front().message; }
    /// Every error, the first included.
    const std::vector<Diagnostic>& errors() const { return errors_; }
    /// True when the loader stopped at Errors::kMax errors.
    bool stopped() const { return stopped_; }
    /// What to print: one "file:line:col: message" line per error, and when the loader stopped,
    /// a last line saying so.
    std::vector<std::string> lines() const;
    /// The same errors, each message after `prefix` ("plcs[1] (kiln): ").
    ConfigError prefixed(const std::string& prefix) const;

private:
    std::vector<Diagnostic> errors_;
    bool stopped_ = false;
};

/// The errors of one config file as the loader finds them, as a compiler collects its own: a
/// key, a list entry or a `plcs:` entry in error is recorded and the others are still read, up
/// to kMax errors; the next one stops the loader.
class Errors {
public:
    /// Errors reported before the loader stops (a compiler's -fmax-errors).
    static constexpr std::size_t kMax = 20;

    /// Records the error(s) of `e` with the prefix in force; past kMax, throws every error
    /// recorded as one ConfigError (stopped).
    void add(const ConfigError& e);
    /// Put before each message recorded from now on (a `plcs:` entry's label and ": ").
    void set_prefix(std::string prefix) { prefix_ = std::move(prefix); }
    /// Errors recorded so far.
    std::size_t size() const { return list_.size(); }
    /// Throws every error recorded, in the order of their positions, as one ConfigError; returns
    /// when there is none.
    void raise() const;
    /// Runs `body`; a ConfigError out of it is recorded (false is returned) and the caller goes
    /// on with the next key. The error that stops the loader goes through.
    template <class Body>
    bool attempt(Body&& body) {
        try {
            body();
            return true;
        } catch (const ConfigError& e) {
            if (stopped_) throw;
            add(e);
            return false;
        }
    }

private:
    std::vector<Diagnostic> list_;
    std::string prefix_;
    bool stopped_ = false;
};

/// Reads nodes of one file, spelling devices and constants the profile's way.
class Reader {
public:
    /// Before a naming is set, integers are plain (decimal, 0x…).
    Reader() = default;
    /// Devices and constants spelt as `naming` says.
    explicit Reader(const image::Naming& naming)
        : naming_(&naming) {}
    /// A reader that records errors in `errors` where it can read on (attempt, report).
    explicit Reader(Errors& errors)
        : errors_(&errors) {}

    /// From the `profile:` key on, devices and constants are spelt the profile's way.
    void set_naming(const image::Naming& naming) { naming_ = &naming; }
    /// The naming in force.
    const image::Naming& naming() const { return *naming_; }

    /// Where `n` stands.
    Position pos(const Node& n) const { return n.pos; }
    /// Throws ConfigError at `n`.
    [[noreturn]] void fail(const Node& n, const std::string& msg) const;
    /// An error at `n` after which reading goes on: recorded in the reader's Errors, or thrown
    /// by a reader without.
    void report(const Node& n, const std::string& msg) const;
    /// Runs `body`, which reads one key or entry: with Errors, an error in it is recorded and
    /// false returned, so the caller reads on; without, it is thrown.
    template <class Body>
    bool attempt(Body&& body) const {
        if (errors_ == nullptr) {
            body();
            return true;
        }
        return errors_->attempt(std::forward<Body>(body));
    }
    /// Errors recorded so far (0 without Errors: the first was thrown).
    std::size_t errors_found() const { return errors_ == nullptr ? 0 : errors_->size(); }
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
    Errors* errors_ = nullptr;  // where errors are recorded; null: each is thrown
};

}  // namespace plcemu::config
