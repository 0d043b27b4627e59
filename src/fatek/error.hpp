#pragma once
// The error code that starts every FATEK reply but 4E's (FBs manual, Appendix 2 FATEK
// Communication Protocol, error codes; docs/profile-fbs.md, "FATEK protocol").

#include <cstdint>

namespace plcemu::fatek {

/// An error code, as the character the reply carries.
enum class Error : std::uint8_t {
    None = '0',           ///< no error: the data follow
    Value = '2',          ///< illegal value: a count or a value out of range
    WriteDisabled = '3',  ///< a device no master may write, or a read-only listener
    Format = '4',         ///< illegal format, or a command the PLC does not have
    Address = 'A',        ///< illegal address: no such device, or the wrong kind
};

}  // namespace plcemu::fatek
