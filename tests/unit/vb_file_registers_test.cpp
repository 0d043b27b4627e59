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
    // Checks that loading `program`, with `more` config after the file registers, is refused at
    // vb.yaml:line:col by the operand `what` naming the registers it would write.
    auto refused = [](const std::string& program, int line, int col, const std::string& what,
                      const std::string& more = "") {
        SCOPED_TRACE(program);
        testing::expect_config_error(
            testing::config_failure([&] { VbPlc p(program, std::string(kHead) + more); }),
            "vb.yaml", line, col,
            what +
                " overlaps D1000-D1009, the file registers (file_registers:), program data "
                "the program only reads");
    };
    auto accepted = [](const std::string& program, const std::string& more = "") {
        return !testing::config_failure([&] {
                    VbPlc p(program, std::string(kHead) + more);
                }).thrown;
    };
    refused("  - MOV: {en: M0, s: K1, d: D1009}\n", 5, 29, "MOV.d: D1009");
    refused("  - WOR: {en: M0, s1: K1, s2: K2, d: D1000}\n", 5, 38, "WOR.d: D1000");
    refused("  - TPID: {en: M0, s1: D0, s2: D10, s3: D900, s4: D2000, n: 16}\n", 5, 41,
            "TPID.s3: D900-D1069");
    refused("  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D1009, n: 1}\n", 5, 51,
            "TPID.s4: D1009-D1014");
    EXPECT_TRUE(accepted("  - TPID: {en: M0, s1: D1000, s2: D1001, s3: D100, s4: D2000, n: 1}\n"));
    // MBUS writes its working area S2; its table S1 is only read.
    const std::string mbus = "mbus: {tcp: {host: 127.0.0.1, port: 5021}}\n";
    refused("  - MBUS: {en: M0, s1: D0, s2: D998}\n", 6, 32, "MBUS.s2: D998-D1001", mbus);
    EXPECT_TRUE(accepted("  - MBUS: {en: M0, s1: D1000, s2: D100}\n", mbus));
}

}  // namespace
}  // namespace plcemu::profiles::vb
