// The FATEK protocol's framing and rules beyond the scenarios (docs/profile-fbs.md, "FATEK
// protocol"; FBs manual, Appendix 2 FATEK Communication Protocol): frames cut from a TCP stream
// (pipelined, split across reads, bytes before STX, the 508-byte limit), a serial line's 1 s
// gap, UDP datagrams checked whole, stations, a read-only listener, disabled inputs through
// scans, RUN/STOP, the order of the error checks and the all-or-nothing mixed write.

#include <gtest/gtest.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <string>

#include "fatek/checksum.hpp"
#include "fatek/serial.hpp"
#include "fatek/split.hpp"
#include "support/fatek_rig.hpp"

namespace plcemu::fatek {
namespace {

using image::Area;
using testing::FatekRig;
using testing::stx_etx;
using namespace std::chrono_literals;

std::span<const std::uint8_t> bytes_of(const std::string& s) {
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// `text` (station, command, data) with its checksum appended.
std::string summed(const std::string& text) {
    const std::string head = "\x02" + text;
    char hex[3];
    std::snprintf(hex, sizeof hex, "%02X", checksum(bytes_of(head)));
    return text + hex;
}

// A request to station 1 with its checksum, between STX and ETX.
std::string frame(const std::string& command_and_data) {
    return stx_etx(summed("01" + command_and_data));
}

// A reply from station 1 with its checksum, between STX and ETX.
std::string reply(const std::string& command_and_data) { return frame(command_and_data); }

// What a TCP connection does with the bytes received so far: cut frames, answer each; the
// rest waits for more bytes.
std::string feed(FatekStream& p, std::string& buffered) {
    std::string replies;
    std::array<std::uint8_t, kMaxFrame> out{};
    for (;;) {
        const listener::Split s = p.split(bytes_of(buffered));
        EXPECT_NE(s.cut, listener::Cut::Bad);  // a FATEK connection is never closed for bytes
        if (s.cut == listener::Cut::Incomplete) break;
        if (s.cut == listener::Cut::Skip) {  // noise: dropped, never answered
            buffered.erase(0, s.size);
            continue;
        }
        const std::size_t n = p.answer(bytes_of(buffered).first(s.size), out);
        replies.append(reinterpret_cast<const char*>(out.data()), n);
        buffered.erase(0, s.size);
    }
    return replies;
}

TEST(FatekFraming, ChecksumIsThePlainSumFromStx) {
    EXPECT_EQ(checksum(bytes_of(std::string("\x02") + "0140")), 0xC7);
    EXPECT_EQ(checksum(bytes_of(std::string("\x02") + "01490")), 0x00);  // wraps exactly
    EXPECT_EQ(summed("014603R00012"), "014603R0001275");  // the manual's read of R12-R14
}

TEST(FatekFraming, PipelinedFramesAreAnsweredInOrder) {
    FatekRig rig;
    rig.plc.image().set_word(Area::R, 7, 0x1234);
    std::string buffered = frame("40") + frame("4601R00007") + frame("4EHI");
    EXPECT_EQ(feed(rig.protocol, buffered), reply("400010000") + reply("4601234") + reply("4EHI"));
    EXPECT_TRUE(buffered.empty());
}

TEST(FatekFraming, AFrameSplitAcrossReadsWaitsForItsEtx) {
    FatekRig rig;
    const std::string whole = frame("4601R00000");
    std::string buffered;
    for (std::size_t i = 0; i + 1 < whole.size(); ++i) {
        buffered += whole[i];
        EXPECT_EQ(feed(rig.protocol, buffered), "");
    }
    buffered += whole.back();
    EXPECT_EQ(feed(rig.protocol, buffered), reply("4600000"));
}

TEST(FatekFraming, BytesBeforeStxAreSkippedAndAnStxRestarts) {
    FatekRig rig;
    std::string buffered = "garbage\r\n" + std::string("\x02") + "0146" + frame("40");
    EXPECT_EQ(feed(rig.protocol, buffered), reply("400010000"));
    EXPECT_TRUE(buffered.empty());
    // Bytes with no STX at all are skipped as they come.
    buffered = "\x03zz";
    EXPECT_EQ(rig.protocol.split(bytes_of(buffered)).cut, listener::Cut::Skip);
    EXPECT_EQ(rig.protocol.split(bytes_of(buffered)).size, 3u);
    EXPECT_EQ(feed(rig.protocol, buffered), "");
}

TEST(FatekFraming, FrameOf508BytesIsTheLongest) {
    FatekRig rig;
    // 500 data characters: the longest frame, echoed whole.
    const std::string longest = frame("4E" + std::string(500, 'Q'));
    ASSERT_EQ(longest.size(), 508u);
    std::string buffered = longest;
    EXPECT_EQ(feed(rig.protocol, buffered), longest);
    // 508 bytes and no ETX: skipped, and so is what follows up to the next STX.
    buffered = frame("4E" + std::string(501, 'Q')) + frame("40");
    EXPECT_EQ(rig.protocol.split(bytes_of(buffered)).cut, listener::Cut::Skip);
    EXPECT_EQ(rig.protocol.split(bytes_of(buffered)).size, 508u);
    EXPECT_EQ(feed(rig.protocol, buffered), reply("400010000"));
    // Fewer than 508 bytes without ETX: a frame still arriving.
    buffered = "\x02" + std::string(506, 'Q');
    EXPECT_EQ(rig.protocol.split(bytes_of(buffered)).cut, listener::Cut::Incomplete);
}

TEST(FatekFraming, DatagramIsCheckedWhole) {
    FatekRig rig;
    EXPECT_EQ(rig.send(frame("40")), reply("400010000"));
    EXPECT_EQ(rig.send("x" + frame("40")), "");          // bytes before STX
    EXPECT_EQ(rig.send(frame("40") + frame("40")), "");  // two frames in one datagram
    EXPECT_EQ(rig.send(frame("40") + "x"), "");          // bytes after ETX
    EXPECT_EQ(rig.send(stx_etx("0140C")), "");           // shorter than 8 bytes
    EXPECT_EQ(rig.send(stx_etx("0140G7")),
              "");  // checksum not hex
    EXPECT_EQ(rig.send(stx_etx(summed("0G40"))),
              "");  // station not hex
}

TEST(FatekFraming, LowerCaseHexIsAcceptedAndAnsweredInUpperCase) {
    FatekRig rig;
    rig.plc.image().set_word(Area::R, 0, 0xABCD);
    // "4e" and a lower-case checksum; the values written in lower case.
    std::string echo = summed("014eab");
    echo[echo.size() - 1] = static_cast<char>(std::tolower(echo.back()));
    echo[echo.size() - 2] = static_cast<char>(std::tolower(echo[echo.size() - 2]));
    EXPECT_EQ(rig.ask(echo), reply("4Eab"));
    EXPECT_EQ(rig.send(frame("4701R00001beef")), reply("470"));
    EXPECT_EQ(rig.plc.image().word(Area::R, 1), 0xBEEF);
    EXPECT_EQ(rig.send(frame("4601R00000")), reply("460ABCD"));
}

TEST(FatekStations, OnlyTheOwnStationAnswersAndBroadcastsAreSilent) {
    FatekRig rig;
    EXPECT_EQ(rig.send(stx_etx(summed("0240"))), "");
    EXPECT_EQ(rig.send(stx_etx(summed("FF40"))), "");
    EXPECT_EQ(rig.send(stx_etx(summed("0040"))),
              "");  // a read to all: nothing visible
    EXPECT_EQ(rig.send(stx_etx(summed("00410"))), "");
    EXPECT_FALSE(rig.plc.engine().running());  // executed, never answered
}

TEST(FatekSerialLine, FrameAcrossReadsIsAnsweredAndASecondOfSilenceAbandonsIt) {
    FatekRig rig;
    FatekSerial line(testing::setup_of(rig.plc));
    const auto t0 = listener::SerialProtocol::Clock::time_point{} + 100s;
    const std::string f = frame("40");
    EXPECT_FALSE(line.deadline().has_value());
    EXPECT_TRUE(line.receive(bytes_of(f.substr(0, 3)), t0).empty());
    ASSERT_TRUE(line.deadline().has_value());
    EXPECT_EQ(*line.deadline(), t0 + 1s);
    const auto r = line.receive(bytes_of(f.substr(3)), t0 + 900ms);
    EXPECT_EQ(std::string(r.begin(), r.end()), reply("400010000"));
    EXPECT_FALSE(line.deadline().has_value());

    // 1 s without a byte: the frame begun is abandoned, the rest is skipped.
    EXPECT_TRUE(line.receive(bytes_of(f.substr(0, 4)), t0 + 2s).empty());
    EXPECT_TRUE(line.expire(t0 + 3s).empty());
    EXPECT_FALSE(line.deadline().has_value());
    EXPECT_TRUE(line.receive(bytes_of(f.substr(4)), t0 + 3100ms).empty());
    // The same when the rest comes late without the timer having fired.
    EXPECT_TRUE(line.receive(bytes_of(f.substr(0, 4)), t0 + 4s).empty());
    EXPECT_TRUE(line.receive(bytes_of(f.substr(4)), t0 + 5s).empty());
    EXPECT_EQ(line.stats().gaps, 2u);
    // Then a whole frame is answered again.
    const auto again = line.receive(bytes_of(f), t0 + 6s);
    EXPECT_EQ(std::string(again.begin(), again.end()), reply("400010000"));
}

TEST(FatekSerialLine, FramesInOneReadAreAllAnswered) {
    FatekRig rig;
    FatekSerial line(testing::setup_of(rig.plc));
    const auto r = line.receive(bytes_of("zz" + frame("40") + frame("4EA")), {});
    EXPECT_EQ(std::string(r.begin(), r.end()), reply("400010000") + reply("4EA"));
}

TEST(FatekAccess, ReadOnlyListenerRefusesEveryChangeWithError3) {
    FatekRig rig("profile: fbs\n", true);
    EXPECT_EQ(rig.send(frame("410")), reply("413"));
    EXPECT_EQ(rig.send(frame("423M0001")), reply("423"));
    EXPECT_EQ(rig.send(frame("421Y0001")), reply("423"));
    EXPECT_EQ(rig.send(frame("4501M00011")), reply("453"));
    EXPECT_EQ(rig.send(frame("4701R000010001")), reply("473"));
    EXPECT_EQ(rig.send(frame("4901R000010001")), reply("493"));
    EXPECT_TRUE(rig.plc.engine().running());
    EXPECT_FALSE(rig.plc.image().bit(Area::M, 1));
    EXPECT_EQ(rig.plc.image().word(Area::R, 1), 0);
    EXPECT_FALSE(rig.plc.engine().holds().held(Area::Y, 1));
    // Reads are served.
    EXPECT_EQ(rig.send(frame("4401M0001")), reply("4400"));
}

// A reload that makes a kept listener read-only (or not) takes effect at the next request.
TEST(FatekAccess, ReadOnlyFollowsTheListenerAtOnce) {
    FatekRig rig;
    EXPECT_EQ(rig.send(frame("4701R000010001")), reply("470"));
    rig.protocol.units().set_read_only(true);
    EXPECT_EQ(rig.send(frame("4701R000010002")), reply("473"));
    EXPECT_EQ(rig.plc.image().word(Area::R, 1), 1);
    rig.protocol.units().set_read_only(false);
    EXPECT_EQ(rig.send(frame("4701R000010002")), reply("470"));
    EXPECT_EQ(rig.plc.image().word(Area::R, 1), 2);
}

TEST(FatekAccess, DisabledInputIsWrittenAndKeptThroughScans) {
    FatekRig rig;
    EXPECT_EQ(rig.send(frame("4501X00071")),
              reply("453"));  // enabled: read-only
    EXPECT_EQ(rig.send(frame("421X0007")),
              reply("420"));  // disable
    EXPECT_EQ(rig.send(frame("4303X0006")), reply("430010"));
    EXPECT_EQ(rig.send(frame("4501X00071")), reply("450"));
    rig.plc.engine().run_scans(5);
    EXPECT_EQ(rig.send(frame("4401X0007")), reply("4401"));
    EXPECT_EQ(rig.send(frame("424X0007")),
              reply("420"));  // reset while disabled
    EXPECT_EQ(rig.send(frame("4401X0007")), reply("4400"));
    EXPECT_EQ(rig.send(frame("422X0007")),
              reply("420"));  // enable again
    EXPECT_EQ(rig.send(frame("423X0007")), reply("423"));
    EXPECT_EQ(rig.send(frame("4701WX0000FFFF")),
              reply("473"));  // W forms too
    EXPECT_FALSE(rig.plc.image().bit(Area::X, 7));
}

TEST(FatekAccess, ProtectedRegistersAreRefusedWithError3) {
    FatekRig rig("profile: fbs\nmodbus:\n  write_protect: [R100-R109]\n");
    EXPECT_EQ(rig.send(frame("4701R038400001")),
              reply("473"));  // IR
    EXPECT_EQ(rig.send(frame("4702R0009900010002")), reply("473"));
    EXPECT_EQ(rig.send(frame("4701DR0010900010002")), reply("473"));
    EXPECT_EQ(rig.plc.image().word(Area::R, 99), 0);
    EXPECT_EQ(rig.send(frame("4701R001100001")), reply("470"));
}

TEST(FatekRunStop, StopTurnsOutputsOffAndRunResumes) {
    FatekRig rig;
    rig.plc.engine().run_scans(1);
    EXPECT_EQ(rig.send(frame("4502Y000011")), reply("450"));
    EXPECT_TRUE(rig.plc.image().bit(Area::M, 1926));
    EXPECT_EQ(rig.send(frame("410")), reply("410"));
    EXPECT_FALSE(rig.plc.image().bit(Area::Y, 0));
    EXPECT_FALSE(rig.plc.image().bit(Area::M, 1926));
    EXPECT_EQ(rig.send(frame("40")), reply("400000000"));
    EXPECT_EQ(rig.send(frame("410")),
              reply("410"));  // STOP while stopped
    rig.plc.engine().run_scans(2);
    EXPECT_EQ(rig.send(frame("4402Y0000")), reply("44000"));
    EXPECT_EQ(rig.send(frame("411")), reply("410"));
    rig.plc.engine().run_scans(1);
    EXPECT_TRUE(rig.plc.image().bit(Area::M, 1926));
    EXPECT_EQ(rig.send(frame("40")), reply("400010000"));
    EXPECT_EQ(rig.send(frame("412")), reply("412"));
    EXPECT_EQ(rig.send(frame("4111")), reply("414"));
}

// Format (4), then value (2), then address (A), then protection (3): the first failing decides.
TEST(FatekErrors, ChecksRunFormatValueAddressProtection) {
    FatekRig rig;
    // Count 65 (2), an absent area (A) and a wrong value count (4): 4.
    EXPECT_EQ(rig.send(frame("4741F000000001")), reply("474"));
    // Count 65 and an absent area: 2.
    EXPECT_EQ(rig.send(frame("4741F00000" + std::string(65 * 4, '0'))), reply("472"));
    // An absent area on a protected... X write: A before 3.
    EXPECT_EQ(rig.send(frame("4502X025511")), reply("45A"));
    // A value that is not 0/1 on an enabled input: 2 before 3.
    EXPECT_EQ(rig.send(frame("4501X00007")), reply("452"));
    // 42: syntax before the code, the code before the address.
    EXPECT_EQ(rig.send(frame("429M001")), reply("424"));
    EXPECT_EQ(rig.send(frame("429R00001")), reply("422"));
    EXPECT_EQ(rig.send(frame("423R00001")), reply("42A"));
    // 46: a non-hex count, a name with a letter in its digits, trailing characters.
    EXPECT_EQ(rig.send(frame("460GR00000")), reply("464"));
    EXPECT_EQ(rig.send(frame("4601R0000A")), reply("464"));
    EXPECT_EQ(rig.send(frame("4601R000001")), reply("464"));
    EXPECT_EQ(rig.send(frame("4601QQ0000")),
              reply("46A"));  // no such prefix
    // 32-bit names: 32 at most.
    EXPECT_EQ(rig.send(frame("4621DR00000")), reply("462"));
    EXPECT_EQ(rig.send(frame("4601DR08071")),
              reply("46A"));  // R8072 does not exist
    // The counters: RC on a 32-bit one, DRC on a 16-bit one, DRT: A.
    EXPECT_EQ(rig.send(frame("4601RC0200")), reply("46A"));
    EXPECT_EQ(rig.send(frame("4601DRC0199")), reply("46A"));
    EXPECT_EQ(rig.send(frame("4601DRT0000")), reply("46A"));
    // A discrete where registers are read, a register where discretes are.
    EXPECT_EQ(rig.send(frame("4601Y0000")), reply("46A"));
    EXPECT_EQ(rig.send(frame("4401R00000")), reply("44A"));
    // Data where a command takes none.
    EXPECT_EQ(rig.send(frame("400")), reply("404"));
    EXPECT_EQ(rig.send(frame("530")), reply("534"));
    // Mixed: more than 64 weight, 0 items.
    std::string heavy = "33";  // 51 names of 32 bits: weight 102
    for (int i = 0; i < 51; ++i) heavy += "DR00000";
    EXPECT_EQ(rig.send(frame("48" + heavy)), reply("482"));
    EXPECT_EQ(rig.send(frame("4800")), reply("482"));
    EXPECT_EQ(rig.send(frame("4802R00000")),
              reply("484"));  // fewer names than NN
}

TEST(FatekErrors, MixedWriteIsAllOrNothing) {
    FatekRig rig;
    // R300 first, then an enabled input: 3, and R300 is not written.
    EXPECT_EQ(rig.send(frame("4902R003000001X00001")), reply("493"));
    // R300 first, then a register in the hole: A.
    EXPECT_EQ(rig.send(frame("4902R003000001R042000001")), reply("49A"));
    // A discrete value that is not 0/1: 2.
    EXPECT_EQ(rig.send(frame("4902R003000001M00005")), reply("492"));
    EXPECT_EQ(rig.plc.image().word(Area::R, 300), 0);
    EXPECT_FALSE(rig.plc.image().bit(Area::M, 0));
    // All well: all written, W and DW forms and 32-bit pairs included.
    EXPECT_EQ(rig.send(frame("4904Y00001WM00168001DD0001012345678M00011")), reply("490"));
    const image::Image& img = rig.plc.image();
    EXPECT_TRUE(img.bit(Area::Y, 0));
    EXPECT_TRUE(img.bit(Area::M, 16));
    EXPECT_TRUE(img.bit(Area::M, 31));
    EXPECT_FALSE(img.bit(Area::M, 17));
    EXPECT_EQ(img.word(Area::D, 10), 0x5678);
    EXPECT_EQ(img.word(Area::D, 11), 0x1234);
    EXPECT_EQ(rig.send(frame("4601DWM0000")), reply("46080010002"));
}

TEST(FatekRegisters, ConsecutiveItemsOfEveryForm) {
    FatekRig rig;
    image::Image& img = rig.plc.image();
    // DD: register pairs; DRC: one counter after another; WY: 16 outputs after 16.
    EXPECT_EQ(rig.send(frame("4702DD001000000000100020003")), reply("470"));
    EXPECT_EQ(img.word(Area::D, 100), 1);
    EXPECT_EQ(img.word(Area::D, 102), 3);
    EXPECT_EQ(img.word(Area::D, 103), 2);
    EXPECT_EQ(rig.send(frame("4702DRC02540000000A0001000B")), reply("470"));
    EXPECT_EQ(img.word(Area::CV, 308), 0x000A);
    EXPECT_EQ(img.word(Area::CV, 310), 0x000B);
    EXPECT_EQ(img.word(Area::CV, 311), 0x0001);
    EXPECT_EQ(rig.send(frame("4602DRC0255")),
              reply("46A"));  // C256 does not exist
    EXPECT_EQ(rig.send(frame("4702WY000000010080")), reply("470"));
    EXPECT_TRUE(img.bit(Area::Y, 0));
    EXPECT_TRUE(img.bit(Area::Y, 23));
    EXPECT_EQ(rig.send(frame("4602WY0008")), reply("46080000000"));
    // 64 registers, the most a request reads.
    EXPECT_EQ(rig.send(frame("4640R00000")).size(), 9u + 64 * 4);
    EXPECT_EQ(rig.send(frame("4601R04167")).substr(5, 1),
              "0");  // the last before the hole
    EXPECT_EQ(rig.send(frame("4601R04168")), reply("46A"));
    EXPECT_EQ(rig.send(frame("4601R05000")), reply("4600000"));
}

// docs/profile-fb.md, "FATEK protocol": the FB answers as the FBs over its own areas.
TEST(FatekFb, NamesAndStatusFollowTheFbLayout) {
    FatekRig rig("profile: fb\n");
    rig.plc.image().set_word(Area::D, 3071, 0x0102);
    EXPECT_EQ(rig.send(frame("4601D03071")), reply("4600102"));
    EXPECT_EQ(rig.send(frame("4601D03072")), reply("46A"));
    EXPECT_EQ(rig.send(frame("4601R04200")), reply("46A"));
    // 53: D registers 0C00h (3072), the rest as on the FBs.
    EXPECT_EQ(rig.send(frame("53")),
              reply("530010102408000010001000040004007D203E800001F880C0001000100"));
}

}  // namespace
}  // namespace plcemu::fatek
