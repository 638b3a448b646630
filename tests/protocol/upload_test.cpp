// Chunk reassembly: out of order, duplicated, overlapping and missing chunks; bounds; a stale
// upload; the bytes handed over only when complete and hashed.
#include "protocol/upload.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "tests/protocol/samples.h"

namespace hapticd::proto {
namespace {

using testing::randomBytes;

SceneBegin announce(const std::vector<std::uint8_t>& data, std::uint32_t id = 1) {
  SceneBegin b;
  b.upload_id = id;
  b.total_bytes = data.size();
  b.sha256 = sha256(data);
  b.name = "t.glb";
  return b;
}

// the whole upload is there: commit says complete and hands over exactly `data`
void expectHandedOver(Reassembly& r, const std::vector<std::uint8_t>& data) {
  EXPECT_EQ(r.commit(0), CommitOutcome::kComplete);
  EXPECT_EQ(r.take(), data);
}

TEST(Upload, Sha256MatchesKnownVector) {
  const std::string abc = "abc";
  const auto h = sha256({reinterpret_cast<const std::uint8_t*>(abc.data()), abc.size()});
  const std::uint8_t expect[4] = {0xba, 0x78, 0x16, 0xbf};  // SHA-256("abc") begins ba7816bf
  EXPECT_TRUE(std::equal(expect, expect + 4, h.begin()));
}

TEST(Upload, InOrderCompletesAndHandsOverExactBytes) {
  const auto data = randomBytes(10000, 1);
  Reassembly r;
  ASSERT_TRUE(r.begin(announce(data), 0, nullptr));
  for (std::size_t off = 0; off < data.size(); off += 1000) {
    EXPECT_EQ(r.commit(0), CommitOutcome::kIncomplete);
    EXPECT_TRUE(r.take().empty());  // nothing before commit says complete
    EXPECT_EQ(r.add(off, std::span(data).subspan(off, 1000), 0), ChunkOutcome::kStored);
  }
  EXPECT_EQ(r.receivedBytes(), data.size());
  EXPECT_EQ(r.rangeCount(), 1u);
  EXPECT_EQ(r.commit(1), CommitOutcome::kComplete);
  EXPECT_EQ(r.take(), data);
  EXPECT_FALSE(r.active());
}

TEST(Upload, ShuffledDuplicatedOverlappingChunksStillExact) {
  const auto data = randomBytes(123457, 2);
  std::mt19937 rng(3);
  // random chunks of 1..3000 bytes covering everything, many overlapping, each sent 1-3 times
  struct C {
    std::size_t off, len;
  };
  std::vector<C> chunks;
  for (std::size_t off = 0; off < data.size();) {
    const std::size_t len = std::min<std::size_t>(1 + rng() % 3000, data.size() - off);
    chunks.push_back({off, len});
    // an overlapping extra piece starting inside this chunk
    const std::size_t o2 = off + rng() % len;
    chunks.push_back({o2, std::min<std::size_t>(1 + rng() % 2000, data.size() - o2)});
    const int copies = static_cast<int>(rng() % 3);
    for (int k = 0; k < copies; ++k)
      chunks.push_back({off, len});
    off += len;
  }
  std::shuffle(chunks.begin(), chunks.end(), rng);
  Reassembly r(UploadLimits{.max_scene_bytes = 1 << 20, .max_chunk_bytes = 4096});
  ASSERT_TRUE(r.begin(announce(data), 0, nullptr));
  std::size_t dups = 0;
  for (const auto& c : chunks) {
    const auto o = r.add(c.off, std::span(data).subspan(c.off, c.len), 0);
    ASSERT_TRUE(o == ChunkOutcome::kStored || o == ChunkOutcome::kDuplicate);
    dups += o == ChunkOutcome::kDuplicate;
    EXPECT_LE(r.receivedBytes(), data.size());
  }
  EXPECT_GT(dups, 0u);
  expectHandedOver(r, data);
}

TEST(Upload, MissingRangesListedInOrder) {
  const auto data = randomBytes(10000, 4);
  Reassembly r;
  ASSERT_TRUE(r.begin(announce(data), 0, nullptr));
  ASSERT_EQ(r.add(1000, std::span(data).subspan(1000, 1000), 0), ChunkOutcome::kStored);
  ASSERT_EQ(r.add(5000, std::span(data).subspan(5000, 500), 0), ChunkOutcome::kStored);
  auto m = r.missing(64);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0], (SceneStatus::Range{0, 1000}));
  EXPECT_EQ(m[1], (SceneStatus::Range{2000, 3000}));
  EXPECT_EQ(m[2], (SceneStatus::Range{5500, 4500}));
  EXPECT_EQ(r.missing(2).size(), 2u);
  EXPECT_EQ(r.commit(0), CommitOutcome::kIncomplete);
  for (const auto& g : m)
    ASSERT_EQ(r.add(g.offset, std::span(data).subspan(g.offset, g.length), 0),
              ChunkOutcome::kStored);
  EXPECT_TRUE(r.missing(64).empty());
  expectHandedOver(r, data);
}

TEST(Upload, FirstBytesWinAndALyingOverlapFailsTheHash) {
  const auto data = randomBytes(4000, 5);
  Reassembly r;
  ASSERT_TRUE(r.begin(announce(data), 0, nullptr));
  auto bad = data;
  for (std::size_t i = 1000; i < 2000; ++i)
    bad[i] ^= 0xff;
  // the corrupt copy arrives first for [1000, 2000): it wins, the good copy is a duplicate
  ASSERT_EQ(r.add(1000, std::span(bad).subspan(1000, 1000), 0), ChunkOutcome::kStored);
  ASSERT_EQ(r.add(0, std::span(data).subspan(0, 4000).first(4000), 0), ChunkOutcome::kStored);
  EXPECT_EQ(r.receivedBytes(), 4000u);
  EXPECT_EQ(r.commit(0), CommitOutcome::kHashMismatch);
  EXPECT_FALSE(r.active());  // reset: the client must begin again
  EXPECT_TRUE(r.take().empty());
}

TEST(Upload, BoundsRefused) {
  UploadLimits lim;
  lim.max_scene_bytes = 1000;
  lim.max_chunk_bytes = 100;
  Reassembly r(lim);
  const auto big = randomBytes(1001, 6);
  std::string err;
  EXPECT_FALSE(r.begin(announce(big), 0, &err));
  EXPECT_NE(err.find("1001 bytes refused"), std::string::npos) << err;
  EXPECT_EQ(r.add(0, std::span(big).first(10), 0), ChunkOutcome::kNotBegun);
  const auto data = randomBytes(1000, 7);
  ASSERT_TRUE(r.begin(announce(data), 0, nullptr));
  EXPECT_EQ(r.add(0, std::span(data).first(101), 0), ChunkOutcome::kTooLarge);
  EXPECT_EQ(r.add(950, std::span(data).first(51), 0), ChunkOutcome::kOutOfRange);
  EXPECT_EQ(r.add(1000, std::span(data).first(1), 0), ChunkOutcome::kOutOfRange);
  EXPECT_EQ(r.add(UINT64_MAX, std::span(data).first(2), 0), ChunkOutcome::kOutOfRange);
  EXPECT_EQ(r.add(0, std::span(data).first(0), 0), ChunkOutcome::kOutOfRange);
  EXPECT_EQ(r.receivedBytes(), 0u);
}

TEST(Upload, FragmentationBounded) {
  UploadLimits lim;
  lim.max_ranges = 4;
  Reassembly r(lim);
  const auto data = randomBytes(100, 8);
  ASSERT_TRUE(r.begin(announce(data), 0, nullptr));
  for (std::uint64_t off : {0u, 10u, 20u, 30u})
    ASSERT_EQ(r.add(off, std::span(data).subspan(off, 1), 0), ChunkOutcome::kStored);
  EXPECT_EQ(r.add(40, std::span(data).subspan(40, 1), 0), ChunkOutcome::kTooFragmented);
  // a chunk that merges into existing ranges is still taken
  EXPECT_EQ(r.add(1, std::span(data).subspan(1, 9), 0), ChunkOutcome::kStored);
  EXPECT_EQ(r.rangeCount(), 3u);
}

TEST(Upload, StaleUploadTimesOut) {
  UploadLimits lim;
  lim.stale_timeout_ns = 1'000'000'000;
  Reassembly r(lim);
  const auto data = randomBytes(100, 9);
  ASSERT_TRUE(r.begin(announce(data), 5'000'000'000, nullptr));
  EXPECT_FALSE(r.stale(5'900'000'000));
  ASSERT_EQ(r.add(0, std::span(data).first(10), 5'900'000'000), ChunkOutcome::kStored);
  EXPECT_FALSE(r.stale(6'800'000'000));  // activity restarts the clock
  EXPECT_TRUE(r.stale(6'900'000'001));
}

TEST(Upload, ResentBeginKeepsProgressNewBeginRestarts) {
  const auto data = randomBytes(1000, 10);
  Reassembly r;
  ASSERT_TRUE(r.begin(announce(data, 3), 0, nullptr));
  ASSERT_EQ(r.add(0, std::span(data).first(500), 0), ChunkOutcome::kStored);
  ASSERT_TRUE(r.begin(announce(data, 3), 1, nullptr));
  EXPECT_EQ(r.receivedBytes(), 500u);
  ASSERT_TRUE(r.begin(announce(data, 4), 2, nullptr));
  EXPECT_EQ(r.receivedBytes(), 0u);
  EXPECT_EQ(r.uploadId(), 4u);
}

}  // namespace
}  // namespace hapticd::proto
