// Tags, the replay window and the token bucket, on their own.
#include "protocol/auth.h"

#include <gtest/gtest.h>

namespace hapticd::proto {
namespace {

TEST(Auth, KeyHexRoundTripAndErrors) {
  const Key k = randomKey();
  std::string err;
  auto back = parseKeyHex("  " + keyToHex(k) + "\n", &err);
  ASSERT_TRUE(back.has_value()) << err;
  EXPECT_EQ(*back, k);
  EXPECT_FALSE(parseKeyHex("abc", &err));
  EXPECT_NE(err.find("64 hex digits"), std::string::npos);
  EXPECT_FALSE(parseKeyHex(std::string(63, 'a') + "g", &err));
  EXPECT_NE(err.find("character 64"), std::string::npos) << err;
}

TEST(Auth, TagVerifiesAndAnyFlippedBitFails) {
  const Key k = randomKey();
  std::vector<std::uint8_t> buf(512);
  Header h;
  h.session_id = 5;
  h.sequence = 9;
  PoseCommand p;
  const std::size_t n = encodeDatagram(h, p, &k, buf);
  ASSERT_EQ(n, kHeaderSize + PoseCommand::kFixedSize + kMacSize);
  buf.resize(n);
  Header got;
  ASSERT_EQ(decodeHeader(buf, got).code, Errc::kOk);
  EXPECT_TRUE(got.flags & kFlagMac);
  EXPECT_TRUE(verifyTag(buf, k));
  Key other = k;
  other[0] ^= 1;
  EXPECT_FALSE(verifyTag(buf, other));
  for (std::size_t i = 0; i < n; i += 7) {
    auto b = buf;
    b[i] ^= 0x10;
    EXPECT_FALSE(verifyTag(b, k)) << i;
  }
}

TEST(Auth, ReplayWindowAcceptsEachNumberOnce) {
  ReplayWindow w;
  EXPECT_FALSE(w.check(0));
  for (std::uint64_t s : {5u, 3u, 4u, 1u, 2000u, 1500u}) {
    ASSERT_TRUE(w.check(s)) << s;
    w.accept(s);
    EXPECT_FALSE(w.check(s)) << s;
  }
  EXPECT_FALSE(w.check(5));                             // replay inside the window
  EXPECT_FALSE(w.check(2000 - ReplayWindow::kWindow));  // too old
  EXPECT_TRUE(w.check(2000 - ReplayWindow::kWindow + 1));
  EXPECT_TRUE(w.check(1999));
  // a long jump forgets the old bits without accepting stale numbers
  w.accept(100000);
  EXPECT_FALSE(w.check(2000));
  EXPECT_TRUE(w.check(99999));
  EXPECT_FALSE(w.check(100000));
}

TEST(Auth, ReplayWindowBitmapAgreesWithASet) {
  // every number in a reordered stream is accepted exactly once
  ReplayWindow w;
  std::uint64_t accepted = 0;
  for (std::uint64_t base = 1; base < 20000; base += 100)
    for (std::uint64_t k = 100; k-- > 0;) {
      const std::uint64_t s = base + k;  // descending inside each block of 100
      if (w.check(s)) {
        w.accept(s);
        ++accepted;
      }
      EXPECT_FALSE(w.check(s));
    }
  EXPECT_EQ(accepted, 20000u);
}

TEST(Auth, TokenBucketOnSimulatedTime) {
  TokenBucket b(RateLimitConfig{.packets_per_s = 1000.0, .burst = 10.0}, 0);
  int taken = 0;
  for (int i = 0; i < 100; ++i)
    taken += b.take(0);
  EXPECT_EQ(taken, 10);            // the burst
  EXPECT_FALSE(b.take(500'000));   // 0.5 ms: half a token
  EXPECT_TRUE(b.take(1'000'000));  // 1 ms: one token
  EXPECT_FALSE(b.take(1'000'000));
  taken = 0;
  for (int i = 0; i < 100; ++i)
    taken += b.take(1'000'000'000);  // refilled to the burst only
  EXPECT_EQ(taken, 10);
  TokenBucket unlimited(RateLimitConfig{.packets_per_s = 0.0, .burst = 0.0});
  for (int i = 0; i < 1000; ++i)
    ASSERT_TRUE(unlimited.take(0));
}

}  // namespace
}  // namespace hapticd::proto
