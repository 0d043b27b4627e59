#pragma once
// Each FB temperature point has at most one controlling instruction: two TSTCs or TPCTLs
// running PID on one point would fight over its heater (FB manual FUN73/FUN86: WR "其它地方不可
// 重复使用", can't be repeated in using). Checked at load, at the later entry
// (docs/profile-fb.md, "FUN86 TPCTL").

#include <array>
#include <string>
#include <string_view>

#include "instructions/operands.hpp"
#include "profiles/fb/points.hpp"

namespace plcemu::profiles::fb {

/// Which entry controls each point, as the program binds.
class ControlledPoints {
public:
    /// `mnemonic` at `where` controls points first…first+count−1: refused at `key` if an earlier
    /// entry controls one of them.
    void claim(instructions::Operands& ops,
               const char* key,
               std::string_view mnemonic,
               long long first,
               long long count,
               const std::string& where);

private:
    std::array<std::string, Points::kCount> by_{};  // "the TSTC at file:line:col", or empty
};

}  // namespace plcemu::profiles::fb
