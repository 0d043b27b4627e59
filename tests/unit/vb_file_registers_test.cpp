// VB file registers (docs/profile-vb.md, "File registers"): program data in D that the program
// may read but no operand may write, with presets applied at every start and reload.

#include <gtest/gtest.h>

#include <string>

#include "support/vb_plc.hpp"

namespace plcemu::profiles::vb {
namespace {

using image::Area;
using testing::VbPlc;

constexpr const char* kHead = "file_registers: D1000-D1009\ninit: {D1000: [5, 6]}\n";

TEST(VbFileRegisters, TheProgramReadsThem) {
    VbPlc p("  - MOV: {en: M9000, s: D1001, d: D0}\n", kHead);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 1000), 5);
    EXPECT_EQ(p.word(Area::D, 0), 6);
}

// Presets win over a retained value: a state file whose D1000 holds 99 starts with 5 again.
TEST(VbFileRegisters, PresetsWinOverRetainedValues) {
    std::vector<std::byte> storage;
    {
        VbPlc first("  - MOV: {en: M9000, s: K1, d: D0}\n", kHead);
        storage.assign(first.plc.image().storage().begin(), first.plc.image().storage().end());
    }
    VbPlc warm("  - MOV: {en: M9000, s: K1, d: D0}\n", kHead, storage);
    warm.set_word(Area::D, 1000, 99);
    warm.set_word(Area::D, 300, 99);
    std::vector<std::byte> kept(warm.plc.image().storage().begin(),
                                warm.plc.image().storage().end());
    VbPlc again("  - MOV: {en: M9000, s: K1, d: D0}\n",
                std::string(kHead) + "# D300 is latched and has no preset\n", kept);
    EXPECT_EQ(again.word(Area::D, 1000), 5);
    EXPECT_EQ(again.word(Area::D, 300), 99);
}

TEST(VbFileRegisters, NoOperandWritesThem) {
    // What loading `program` says, with `more` config after the file registers.
    auto refused = [](const std::string& program, const std::string& more = "") {
        try {
            VbPlc p(program, std::string(kHead) + more);
        } catch (const config::ConfigError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(refused("  - MOV: {en: M0, s: K1, d: D1009}\n").find("file registers"),
              std::string::npos);
    EXPECT_NE(refused("  - WOR: {en: M0, s1: K1, s2: K2, d: D1000}\n").find("file registers"),
              std::string::npos);
    EXPECT_NE(refused("  - TPID: {en: M0, s1: D0, s2: D10, s3: D900, s4: D2000, n: 16}\n")
                  .find("file registers"),
              std::string::npos);
    EXPECT_NE(refused("  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D1009, n: 1}\n")
                  .find("file registers"),
              std::string::npos);
    EXPECT_EQ(refused("  - TPID: {en: M0, s1: D1000, s2: D1001, s3: D100, s4: D2000, n: 1}\n"),
              "accepted");
    // MBUS writes its working area S2; its table S1 is only read.
    const std::string mbus = "mbus: {tcp: {host: 127.0.0.1, port: 5021}}\n";
    EXPECT_NE(refused("  - MBUS: {en: M0, s1: D0, s2: D998}\n", mbus).find("file registers"),
              std::string::npos);
    EXPECT_EQ(refused("  - MBUS: {en: M0, s1: D1000, s2: D100}\n", mbus), "accepted");
}

}  // namespace
}  // namespace plcemu::profiles::vb
