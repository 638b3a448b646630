// The hand-offs between threads and processes (protocol/seqlock.h, protocol/spsc_ring.h): the
// in-process seqlock always has a value and writeRanges publishes only what it is asked to; the
// ring's front/dropFront peek and drop in order, and a consumer resynchronises past a producer
// that ran more than a capacity ahead (a broken process writing a shared segment).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>

#include "protocol/seqlock.h"
#include "protocol/spsc_ring.h"

namespace hapticd::proto {
namespace {

struct Lists {
  std::uint64_t count;
  std::uint64_t items[6];
};

TEST(Seqlock, HoldsTheDefaultValueFromConstruction) {
  Seqlock<Lists> lock;
  EXPECT_EQ(lock.writes(), 1u);
  const Lists l = lock.read();
  EXPECT_EQ(l.count, 0u);
  EXPECT_EQ(l.items[5], 0u);
}

TEST(Seqlock, WriteRangesPublishesOnlyTheRanges) {
  Seqlock<Lists> lock;
  Lists a{3, {1, 2, 3, 4, 5, 6}};
  lock.write(a);
  Lists b{2, {10, 20, 30, 40, 50, 60}};
  using Range = Seqlock<Lists>::Range;
  const Range ranges[] = {{offsetof(Lists, count), sizeof b.count},
                          {offsetof(Lists, items), 2 * sizeof b.items[0]}};
  lock.writeRanges(b, ranges, 2);
  EXPECT_EQ(lock.writes(), 3u);
  const Lists got = lock.read();
  EXPECT_EQ(got.count, 2u);
  EXPECT_EQ(got.items[0], 10u);
  EXPECT_EQ(got.items[1], 20u);
  EXPECT_EQ(got.items[2], 3u);  // left from the earlier write
  EXPECT_EQ(got.items[5], 6u);
}

TEST(SpscRing, FifoAndFullAndEmpty) {
  SpscRing<int> r(4);
  int v = 0;
  EXPECT_FALSE(r.pop(v));
  for (int i = 0; i < 4; ++i)
    EXPECT_TRUE(r.push(i));
  EXPECT_FALSE(r.push(99));
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(r.pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(r.pop(v));
}

TEST(SpscRing, FrontPeeksAndDropFrontTakesInOrder) {
  SpscRing<int> ring(3);  // rounded up to 4
  EXPECT_EQ(ring.capacity(), 4u);
  EXPECT_EQ(ring.front(), nullptr);
  EXPECT_FALSE(ring.dropFront());
  ASSERT_TRUE(ring.push(7));
  ASSERT_TRUE(ring.push(8));
  ASSERT_NE(ring.front(), nullptr);
  EXPECT_EQ(*ring.front(), 7);
  EXPECT_EQ(ring.size(), 2u);  // peeking takes nothing
  EXPECT_TRUE(ring.dropFront());
  int v = 0;
  ASSERT_TRUE(ring.pop(v));
  EXPECT_EQ(v, 8);
  EXPECT_TRUE(ring.empty());
}

TEST(SpscRingRef, ConsumerResynchronisesPastABrokenProducer) {
  SpscIndices ix;
  int slots[4] = {};
  SpscRingRef<int> ring(ix, slots, 4);
  ASSERT_TRUE(ring.push(1));
  EXPECT_EQ(ring.resync(), 0u);       // a sane ring is left alone
  ix.head.store(ix.head.load() + 9);  // a producer that wrote past the tail
  EXPECT_EQ(ring.resync(), 10u);
  int v = 0;
  EXPECT_FALSE(ring.pop(v));
  ASSERT_TRUE(ring.push(5));  // and the ring works on from there
  ASSERT_TRUE(ring.pop(v));
  EXPECT_EQ(v, 5);
}

}  // namespace
}  // namespace hapticd::proto
