// Modbus TCP framing (docs/profile-fbs.md, "Modbus map"): the MBAP splitter that the TCP server
// and the fuzz harness share. A protocol identifier other than 0 or a length field outside
// 2..254 is a bad header (the server closes the connection); anything shorter than a whole
// frame waits for more bytes.

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "modbus/mbap.hpp"

namespace plcemu::modbus {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes frame(std::uint16_t tid, std::uint16_t protocol, std::uint16_t length, std::size_t body) {
    Bytes b{static_cast<std::uint8_t>(tid >> 8),      static_cast<std::uint8_t>(tid & 0xFF),
            static_cast<std::uint8_t>(protocol >> 8), static_cast<std::uint8_t>(protocol & 0xFF),
            static_cast<std::uint8_t>(length >> 8),   static_cast<std::uint8_t>(length & 0xFF)};
    b.resize(b.size() + body, 0x01);
    return b;
}

TEST(Mbap, AWholeFrameIsUnitIdAndLengthBytesAfterTheHeader) {
    const Bytes f = frame(7, 0, 6, 6);  // unit + FC03 request
    const MbapFrame r = next_mbap_frame(f);
    EXPECT_EQ(r.status, MbapStatus::Frame);
    EXPECT_EQ(r.size, 12u);
    EXPECT_EQ(r.length, 6);
}

TEST(Mbap, FewerBytesThanTheHeaderOrTheFrameWait) {
    const Bytes f = frame(7, 0, 6, 6);
    for (std::size_t n = 0; n < f.size(); ++n) {
        EXPECT_EQ(next_mbap_frame({f.data(), n}).status, MbapStatus::Incomplete) << n << " bytes";
    }
}

TEST(Mbap, PipelinedFramesAreSplitOneAtATime) {
    Bytes two = frame(1, 0, 6, 6);
    const Bytes second = frame(2, 0, 2, 2);
    two.insert(two.end(), second.begin(), second.end());
    const MbapFrame a = next_mbap_frame(two);
    ASSERT_EQ(a.status, MbapStatus::Frame);
    const MbapFrame b = next_mbap_frame(std::span(two).subspan(a.size));
    ASSERT_EQ(b.status, MbapStatus::Frame);
    EXPECT_EQ(a.size + b.size, two.size());
}

// docs/profile-fbs.md, Modbus map: protocol identifier ≠ 0 closes the connection.
TEST(Mbap, ANonZeroProtocolIdentifierIsBad) {
    EXPECT_EQ(next_mbap_frame(frame(1, 1, 6, 6)).status, MbapStatus::Bad);
    EXPECT_EQ(next_mbap_frame(frame(1, 0xFFFF, 6, 6)).status, MbapStatus::Bad);
}

// docs/profile-fbs.md, Modbus map: a length field out of 2..254 closes the connection, judged as
// soon as the unit ID is in (without waiting for a body that a length of 0 or 1 cannot describe).
TEST(Mbap, LengthOutsideTwoTo254IsBad) {
    for (int len : {0, 1, 255, 256, 0xFFFF}) {
        EXPECT_EQ(next_mbap_frame(frame(1, 0, static_cast<std::uint16_t>(len), 1)).status,
                  MbapStatus::Bad)
            << len;
    }
    EXPECT_EQ(next_mbap_frame(frame(1, 0, 2, 2)).status, MbapStatus::Frame);
    const MbapFrame max = next_mbap_frame(frame(1, 0, 254, 254));
    EXPECT_EQ(max.status, MbapStatus::Frame);
    EXPECT_EQ(max.size, kMaxTcpAdu);
}

}  // namespace
}  // namespace plcemu::modbus
