#pragma once
// Rising-edge detection for the pulse forms (MOVP, PLS) and the counters, with the FX family's
// start: the remembered input is OFF at every start and reload, so an input already ON in the
// first scan is an edge (docs/profile-vb.md, "Program entries").

namespace plcemu::instructions {

/// Remembers an input from one scan to the next.
class RisingEdge {
public:
    /// True when `in` is ON now and was OFF at the previous call (or there was none).
    bool operator()(bool in) noexcept {
        const bool edge = in && !prev_;
        prev_ = in;
        return edge;
    }

private:
    bool prev_ = false;
};

/// Remembers an input from one scan to the next, for its falling edges.
class FallingEdge {
public:
    /// True when `in` is OFF now and was ON at the previous call (never at the first).
    bool operator()(bool in) noexcept {
        const bool edge = !in && prev_;
        prev_ = in;
        return edge;
    }

private:
    bool prev_ = false;
};

}  // namespace plcemu::instructions
