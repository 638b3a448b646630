// The daemon's lock-free hand-offs: an SPSC ring between two threads keeps order and loses
// nothing; a seqlock reader never sees a torn value (the project's one ring and seqlock,
// protocol/, as the servo loop uses them); the scene exchange frees every pointer exactly once.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "daemon/handoff/scene_exchange.h"
#include "protocol/seqlock.h"
#include "protocol/spsc_ring.h"

namespace hapticd::daemon {
namespace {

using proto::Seqlock;
using proto::SpscRing;

TEST(SpscRing, RefusesWhenFullAndKeepsOrder) {
  SpscRing<int> ring(4);
  EXPECT_EQ(ring.capacity(), 4u);
  for (int i = 0; i < 4; ++i)
    EXPECT_TRUE(ring.push(i));
  EXPECT_FALSE(ring.push(99));
  int v = -1;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(ring.pop(v));
}

TEST(SpscRing, TwoThreadsPassAMillionValuesInOrder) {
  SpscRing<std::uint64_t> ring(64);
  constexpr std::uint64_t kN = 1'000'000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kN;)
      if (ring.push(i))
        ++i;
  });
  std::uint64_t expected = 0;
  std::uint64_t v = 0;
  while (expected < kN) {
    if (ring.pop(v)) {
      ASSERT_EQ(v, expected);
      ++expected;
    }
  }
  producer.join();
  EXPECT_TRUE(ring.empty());
}

struct Block {
  std::uint64_t a, b, c, d, e;
};

TEST(Seqlock, ReaderNeverSeesATornValue) {
  Seqlock<Block> lock;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> last_written{0};
  std::thread writer([&] {
    for (std::uint64_t i = 1; !stop.load(std::memory_order_relaxed); ++i) {
      lock.write(Block{i, i, i, i, i});
      last_written.store(i, std::memory_order_relaxed);
    }
  });
  std::uint64_t last = 0, changes = 0;
  for (int n = 0; n < 300'000; ++n) {
    const Block b = lock.read();
    ASSERT_EQ(b.a, b.b);
    ASSERT_EQ(b.a, b.c);
    ASSERT_EQ(b.a, b.d);
    ASSERT_EQ(b.a, b.e);
    ASSERT_GE(b.a, last);  // never goes back in time
    if (b.a != last)
      ++changes;
    last = b.a;
  }
  stop = true;
  writer.join();
  EXPECT_EQ(lock.read().e, last_written.load());
  EXPECT_EQ(lock.writes(), last_written.load() + 1);  // + the constructor's write
  (void)changes;  // how often the reader saw the writer move depends on the scheduler
}

struct Counted {
  explicit Counted(int* deaths) : deaths_(deaths) {}
  ~Counted() { ++*deaths_; }
  int* deaths_;
};

TEST(PointerExchange, EveryPointerFreedOnceOnTheOwnerSide) {
  int deaths = 0;
  auto* current = new Counted(&deaths);
  {
    PointerExchange<Counted> ex;
    Counted* seen = current;
    EXPECT_FALSE(ex.take(current));
    ex.offer(std::make_unique<Counted>(&deaths));
    ex.offer(std::make_unique<Counted>(&deaths));  // replaces the untaken one
    EXPECT_EQ(deaths, 1);
    EXPECT_TRUE(ex.take(current));
    EXPECT_NE(current, seen);
    // the retiree waits for reclaim(): a second offer is not taken until then
    ex.offer(std::make_unique<Counted>(&deaths));
    Counted* before = current;
    EXPECT_FALSE(ex.take(current));
    EXPECT_EQ(current, before);
    ex.reclaim();
    EXPECT_EQ(deaths, 2);
    EXPECT_TRUE(ex.take(current));
    ex.reclaim();
    EXPECT_EQ(deaths, 3);
  }
  delete current;
  EXPECT_EQ(deaths, 4);
}

std::atomic<int> g_made{0}, g_freed{0};
struct Node {
  Node() { ++g_made; }
  Node(const Node&) = delete;
  ~Node() { ++g_freed; }
};

TEST(PointerExchange, SwapsUnderContentionWithoutLeakOrDoubleFree) {
  std::uint64_t swaps = 0;
  {
    PointerExchange<Node> ex;
    Node* current = new Node;
    std::atomic<bool> stop{false};
    std::thread servo([&] {
      while (!stop.load())
        if (ex.take(current))
          ++swaps;
    });
    for (int i = 0; i < 20000; ++i) {
      ex.offer(std::make_unique<Node>());
      // every other offer waits to be taken; the rest may be replaced before the servo sees them
      while (i % 2 == 0 && ex.pending()) {
        ex.reclaim();
        std::this_thread::yield();
      }
      ex.reclaim();
    }
    stop = true;
    servo.join();
    ex.reclaim();
    delete current;
  }
  EXPECT_GE(swaps, 10000u);
  EXPECT_EQ(g_made.load(), 20001);
  EXPECT_EQ(g_freed.load(), g_made.load());
}

}  // namespace
}  // namespace hapticd::daemon
