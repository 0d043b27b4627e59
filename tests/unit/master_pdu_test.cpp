// The master's PDUs (docs/profile-vb.md, "FNC149 MBUS", reply checks): requests as the Modbus
// application protocol lays them out, and replies that answer them, or do not (status 6).

#include "modbus/master_pdu.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

namespace plcemu::modbus {
namespace {

using B = std::vector<std::uint8_t>;
using W = std::vector<std::uint16_t>;

B encode(std::uint8_t fc, std::uint16_t addr, std::uint16_t qty, const W& values = {}) {
    std::array<std::uint8_t, kMaxRequestPdu> out{};
    const std::size_t n = encode_request(fc, addr, qty, values, out);
    return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

TEST(MasterPdu, RequestsAsTheProtocolLaysThemOut) {
    EXPECT_EQ(encode(3, 0x1000, 10), (B{3, 0x10, 0x00, 0, 10}));
    EXPECT_EQ(encode(1, 7, 2), (B{1, 0, 7, 0, 2}));
    EXPECT_EQ(encode(5, 2, 1, {1}), (B{5, 0, 2, 0xFF, 0x00}));
    EXPECT_EQ(encode(5, 2, 1, {0}), (B{5, 0, 2, 0x00, 0x00}));
    EXPECT_EQ(encode(6, 2000, 1, {0x1234}), (B{6, 0x07, 0xD0, 0x12, 0x34}));
    EXPECT_EQ(encode(15, 0, 10, {1, 0, 1, 0, 0, 0, 0, 1, 1, 1}),
              (B{15, 0, 0, 0, 10, 2, 0x85, 0x03}));
    EXPECT_EQ(encode(16, 1000, 2, {11, 0xABCD}), (B{16, 0x03, 0xE8, 0, 2, 4, 0, 11, 0xAB, 0xCD}));
}

TEST(MasterPdu, NoRequestForAnotherFunctionOrABadQuantity) {
    EXPECT_TRUE(encode(7, 0, 1).empty());
    EXPECT_TRUE(encode(3, 0, 0).empty());
    EXPECT_TRUE(encode(3, 0, 126).empty());
    EXPECT_TRUE(encode(16, 0, 3, {1, 2}).empty()) << "fewer values than the quantity";
}

struct Checked {
    ReplyVerdict verdict;
    std::uint8_t exception;
    W values;
};

Checked check(const B& request, const B& reply, std::size_t n = 0) {
    std::array<std::uint16_t, 64> values{};
    const ReplyCheck c = check_reply(request, reply, values);
    return {c.verdict, c.exception,
            W(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n))};
}

TEST(MasterPdu, ReadRepliesGiveTheirValues) {
    const auto regs = check(encode(3, 0, 2), {3, 4, 0x12, 0x34, 0, 5}, 2);
    EXPECT_EQ(regs.verdict, ReplyVerdict::Ok);
    EXPECT_EQ(regs.values, (W{0x1234, 5}));
    const auto bits = check(encode(2, 0, 10), {2, 2, 0x85, 0x02}, 10);
    EXPECT_EQ(bits.verdict, ReplyVerdict::Ok);
    EXPECT_EQ(bits.values, (W{1, 0, 1, 0, 0, 0, 0, 1, 0, 1}));
}

TEST(MasterPdu, WriteRepliesEchoTheRequest) {
    EXPECT_EQ(check(encode(16, 1000, 2, {1, 2}), {16, 0x03, 0xE8, 0, 2}).verdict, ReplyVerdict::Ok);
    EXPECT_EQ(check(encode(6, 1, 1, {9}), {6, 0, 1, 0, 9}).verdict, ReplyVerdict::Ok);
    EXPECT_EQ(check(encode(16, 1000, 2, {1, 2}), {16, 0x03, 0xE9, 0, 2}).verdict,
              ReplyVerdict::Malformed)
        << "another address";
    EXPECT_EQ(check(encode(16, 1000, 2, {1, 2}), {16, 0x03, 0xE8, 0, 3}).verdict,
              ReplyVerdict::Malformed)
        << "another quantity";
    EXPECT_EQ(check(encode(6, 1, 1, {9}), {6, 0, 1, 0, 8}).verdict, ReplyVerdict::Malformed)
        << "another value";
}

TEST(MasterPdu, ExceptionRepliesGiveTheirCode) {
    const auto c = check(encode(16, 0, 1, {1}), {0x90, 0x0B});
    EXPECT_EQ(c.verdict, ReplyVerdict::Exception);
    EXPECT_EQ(c.exception, 0x0B);
    EXPECT_EQ(check(encode(16, 0, 1, {1}), {0x83, 0x02}).verdict, ReplyVerdict::Malformed)
        << "an exception to another function code";
    EXPECT_EQ(check(encode(16, 0, 1, {1}), {0x90, 0x02, 0}).verdict, ReplyVerdict::Malformed);
}

TEST(MasterPdu, MalformedReplies) {
    const B read = encode(3, 0, 2);
    for (const B& reply : {B{}, B{4, 4, 0, 1, 0, 2}, B{3, 2, 0, 1}, B{3, 4, 0, 1, 0},
                           B{3, 4, 0, 1, 0, 2, 0}, B{3, 3, 0, 1, 0, 2}}) {
        EXPECT_EQ(check(read, reply).verdict, ReplyVerdict::Malformed) << reply.size();
    }
    EXPECT_EQ(check(encode(1, 0, 9), {1, 1, 0xFF}).verdict, ReplyVerdict::Malformed)
        << "9 bits need 2 bytes";
}

}  // namespace
}  // namespace plcemu::modbus
