#pragma once
// Edge detection for the edge contacts, the pulse forms (MOVP, PLS) and the counters, with the
// FX family's start: the remembered input is OFF at every start, reload and STOP->RUN (the scan's
// first_scan), so an input already ON in the first scan is a rising edge
// (docs/program-language.md, "How a program runs").

namespace plcemu::instructions {

/// Remembers an input from one scan to the next.
class RisingEdge {
public:
    /// True when `in` is ON now and was OFF at the previous call (or this is a first scan).
    bool operator()(bool in, bool first_scan) noexcept {
        const bool edge = in && (first_scan || !prev_);
        prev_ = in;
        return edge;
    }

private:
    bool prev_ = false;
};

/// Remembers an input from one scan to the next, for its falling edges.
class FallingEdge {
public:
    /// True when `in` is OFF now and was ON at the previous call (never in a first scan).
    bool operator()(bool in, bool first_scan) noexcept {
        const bool edge = !in && prev_ && !first_scan;
        prev_ = in;
        return edge;
    }

private:
    bool prev_ = false;
};

}  // namespace plcemu::instructions
