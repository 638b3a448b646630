// TickOrder (client/tick_order.h): states back in tick order, duplicates and late ones dropped
// and counted, gaps counted as missing ticks.
#include "client/tick_order.h"

#include <gtest/gtest.h>

#include <vector>

namespace hapticd::client {
namespace {

proto::State at(std::uint64_t tick) {
  proto::State s;
  s.tick = tick;
  s.pairs_tested = static_cast<std::uint32_t>(tick * 10);
  return s;
}

TEST(TickOrder, ReordersWithinTheWindowAndCountsGaps) {
  std::vector<std::uint64_t> out;
  std::vector<std::uint32_t> pairs;
  TickOrder order(
      [&](const proto::State& s) {
        out.push_back(s.tick);
        pairs.push_back(s.pairs_tested);
      },
      4);
  for (std::uint64_t t : {10u, 11u, 13u, 12u, 12u, 16u, 14u, 11u, 17u})
    order.push(at(t));
  order.flush();
  EXPECT_EQ(out, (std::vector<std::uint64_t>{10, 11, 12, 13, 14, 16, 17}));
  EXPECT_EQ(pairs, (std::vector<std::uint32_t>{100, 110, 120, 130, 140, 160, 170}));
  EXPECT_EQ(order.written(), 7u);
  EXPECT_EQ(order.missing(), 1u);     // 15
  EXPECT_EQ(order.duplicates(), 2u);  // the second 12, and 11 again after it was written
  EXPECT_EQ(order.late(), 0u);
  EXPECT_EQ(order.firstTick(), 10u);
  EXPECT_EQ(order.lastTick(), 17u);
}

TEST(TickOrder, AStateOlderThanTheWindowIsLateAndItsTickStaysMissing) {
  std::vector<std::uint64_t> out;
  TickOrder order([&](const proto::State& s) { out.push_back(s.tick); }, 2);
  for (std::uint64_t t : {1u, 3u, 4u, 5u, 2u, 6u})  // 2 arrives after 3 was written
    order.push(at(t));
  order.flush();
  EXPECT_EQ(out, (std::vector<std::uint64_t>{1, 3, 4, 5, 6}));
  EXPECT_EQ(order.late(), 1u);
  EXPECT_EQ(order.missing(), 1u);
}

TEST(TickOrder, NothingWrittenNothingMissing) {
  TickOrder order([](const proto::State&) {});
  order.flush();
  EXPECT_EQ(order.written(), 0u);
  EXPECT_EQ(order.missing(), 0u);
}

}  // namespace
}  // namespace hapticd::client
