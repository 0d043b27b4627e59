// The FATEK protocol's acceptance scenarios (docs/profile-fbs.md, "FATEK protocol", scenarios;
// FBs manual, Appendix 2 FATEK Communication Protocol), byte for byte, on one listener in order:
// each step's state carries into the next.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support/fatek_rig.hpp"

namespace plcemu::fatek {
namespace {

using image::Area;
using testing::FatekRig;
using testing::stx_etx;

// The scenarios' start state: station 1, RUN, every device 0 but these.
void start_state(daemon::Plc& plc) {
    image::Image& img = plc.image();
    img.set_word(Area::R, 0, 1234);
    img.set_word(Area::R, 2, 0xFFFF);
    img.set_word(Area::R, 10, 0x5678);
    img.set_word(Area::R, 11, 0x1234);
    img.set_word(Area::D, 0, 100);
    img.set_bit(Area::M, 0, true);
    img.set_bit(Area::M, 2, true);
    img.set_bit(Area::X, 0, true);
    img.set_bit(Area::X, 3, true);
    img.set_word(Area::TV, 0, 5);
    img.set_word(Area::CV, 0, 7);
    img.set_word(Area::CV, 200, 0x86A0);  // C200 = 100000, low word first
    img.set_word(Area::CV, 201, 0x0001);
}

struct Step {
    const char* what;
    const char* request;  // between STX and ETX
    const char* reply;    // between STX and ETX; "" for no reply
};

const std::vector<Step> kSteps{
    {"1 gist status", "0140C7", "0140001000018"},
    {"2 read R0-R2", "014603R0000072", "0146004D20000FFFFAF"},
    {"3 read M0-M2", "014403M00003B", "014401018D"},
    {"4 read DR10", "014601DR00010B5", "0146012345678A1"},
    {"5 read D0", "014601D0000062", "014600064C7"},
    {"6 write R100,R101", "014702R0010000010002F6", "01470FE"},
    {"6 read back R100-R101", "014602R0010072", "014600001000280"},
    {"7 write Y0-Y2", "014503Y0000101DA", "01450FC"},
    {"7 read back Y0-Y2", "014403Y000047", "014401018D"},
    {"8 set M1", "01423M00010A", "01420F9"},
    {"8 read WM0", "014601WM000092", "014600007C4"},
    {"9 disable Y5", "01421Y000518", "01420F9"},
    {"9 read flags Y4-Y6", "014303Y00044A", "014300108B"},
    {"10 mixed read", "014805R00000M0000DR00010X0003RT00008B", "0148004D211234567810005A4"},
    {"11 read DRC200", "014601DRC0200C9", "01460000186A09D"},
    {"12 mixed write", "014902R00200ABCDM00101BF", "0149000"},
    {"12 mixed read back", "014802R00200M001083", "01480ABCD13A"},
    {"13 loop-back", "014EABCDEFGB8", "014EABCDEFGB8"},
    {"14 STOP", "01410F8", "01410F8"},
    {"14 gist status after STOP", "0140C7", "0140000000017"},
    {"14 RUN", "01411F9", "01410F8"},
    {"15 detailed status", "0153CB",
     "01530010102408000010001000040004007D203E800001F880FA00100010022"},
    {"16 error 2: 46 count 65", "014641R0000074", "01462FF"},
    {"17 error 2: 46 count 00", "014600R000006F", "01462FF"},
    {"18 error A: R4200", "014601R0420076", "0146A0E"},
    {"19 error A: WX0003", "014601WX0003A0", "0146A0E"},
    {"20 error A: F", "014601F0000064", "0146A0E"},
    {"21 error 4: command 4F", "014FDD", "014F411"},
    {"22 error 4: 47 value count", "014702R001000001064", "0147402"},
    {"23 error 3: X0 enabled", "014501X0000176", "01453FF"},
    {"24 error 2: 42 code 5", "01425M00010C", "01422FB"},
    {"25 bad checksum", "014603R0000000", ""},
    {"25 other station", "024603R0000073", ""},
    {"25 broadcast write R5=7", "004701R0000500073C", ""},
    {"25 R5 after broadcast", "014601R0000575", "014600007C4"},
};

TEST(FatekScenarios, EveryStepByteForByte) {
    FatekRig rig;
    start_state(rig.plc);
    for (const Step& s : kSteps) {
        SCOPED_TRACE(s.what);
        const std::string want = *s.reply ? stx_etx(s.reply) : "";
        EXPECT_EQ(rig.ask(s.request), want);
    }
    // What the steps changed, seen in the image.
    const image::Image& img = rig.plc.image();
    EXPECT_EQ(img.word(Area::R, 100), 1);
    EXPECT_EQ(img.word(Area::R, 101), 2);
    EXPECT_EQ(img.word(Area::R, 200), 0xABCD);
    EXPECT_EQ(img.word(Area::R, 5), 7);
    EXPECT_TRUE(img.bit(Area::M, 10));
    EXPECT_TRUE(rig.plc.engine().holds().held(Area::Y, 5));
}

}  // namespace
}  // namespace plcemu::fatek
