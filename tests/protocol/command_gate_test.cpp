// The command gate on simulated time: newest command wins; a stopped stream is held 20 ms,
// ramps to zero force by 200 ms, then faults until re-armed; no allocation.
#include "protocol/command_gate.h"

#include <gtest/gtest.h>

#include "protocol/spsc_ring.h"
#include "tests/core/alloc_counter.h"

namespace hapticd::proto {
namespace {

constexpr std::uint64_t kMs = 1'000'000;
constexpr std::uint64_t kS1 = 11, kS2 = 22;

PoseCommand at(double x) {
  PoseCommand c;
  c.X_WT.p = {x, 0.0, 0.0};
  c.v_W = {1.0, 0.0, 0.0};
  return c;
}

// the gate's output at `now`: disarmed, no force, no target
void expectDisarmedAt(CommandGate& g, std::uint64_t now) {
  const auto o = g.update(now);
  EXPECT_EQ(o.mode, GateMode::kDisarmed);
  EXPECT_EQ(o.force_scale, 0.0);
  EXPECT_FALSE(o.has_target);
}

TEST(CommandGate, DisarmedRefusesAndGivesNoForce) {
  CommandGate g;
  EXPECT_FALSE(g.submit(kS1, 1, at(1), 0));
  EXPECT_EQ(g.dropped(DropReason::kNotArmed), 1u);
  expectDisarmedAt(g, 1 * kMs);
}

TEST(CommandGate, NewestWinsOlderAndDuplicatesDroppedAndCounted) {
  CommandGate g;
  g.arm(kS1, 0);
  EXPECT_TRUE(g.submit(kS1, 5, at(5), 1 * kMs));
  EXPECT_FALSE(g.submit(kS1, 5, at(55), 1 * kMs));  // duplicate
  EXPECT_FALSE(g.submit(kS1, 3, at(3), 1 * kMs));   // older
  EXPECT_TRUE(g.submit(kS1, 9, at(9), 2 * kMs));
  EXPECT_FALSE(g.submit(kS1, 6, at(6), 2 * kMs));
  const auto o = g.update(2 * kMs);
  EXPECT_EQ(o.mode, GateMode::kStreaming);
  EXPECT_EQ(o.target.X_WT.p[0], 9.0);
  EXPECT_EQ(o.last_sequence, 9u);
  EXPECT_EQ(g.accepted(), 2u);
  EXPECT_EQ(g.dropped(DropReason::kDuplicate), 1u);
  EXPECT_EQ(g.dropped(DropReason::kOlder), 2u);
}

TEST(CommandGate, OnlyTheArmingSessionControls) {
  CommandGate g;
  g.arm(kS1, 0);
  EXPECT_FALSE(g.submit(kS2, 100, at(2), 1 * kMs));
  EXPECT_EQ(g.dropped(DropReason::kNotController), 1u);
  EXPECT_TRUE(g.submit(kS1, 1, at(1), 1 * kMs));
  g.arm(kS2, 2 * kMs);
  EXPECT_FALSE(g.submit(kS2, 100, at(2), 2 * kMs));  // seen before: still a duplicate
  EXPECT_TRUE(g.submit(kS2, 101, at(3), 2 * kMs));
  EXPECT_FALSE(g.submit(kS1, 2, at(4), 2 * kMs));
  EXPECT_EQ(g.update(2 * kMs).target.X_WT.p[0], 3.0);
}

TEST(CommandGate, StreamStopHoldsRampsThenFaultsUntilRearmed) {
  CommandGate g;  // defaults: hold 20 ms, zero at 200 ms
  g.arm(kS1, 0);
  EXPECT_EQ(g.update(0).mode, GateMode::kArmedIdle);
  EXPECT_EQ(g.update(0).force_scale, 1.0);
  // a 1 kHz stream for 100 ms, then silence; walk the simulated clock in 1 ms ticks
  std::uint64_t seq = 0;
  for (std::uint64_t t = 0; t <= 100 * kMs; t += kMs) {
    ASSERT_TRUE(g.submit(kS1, ++seq, at(static_cast<double>(t)), t));
    const auto o = g.update(t);
    ASSERT_EQ(o.mode, GateMode::kStreaming);
    ASSERT_EQ(o.force_scale, 1.0);
  }
  const std::uint64_t t_last = 100 * kMs;
  double prev = 1.0;
  for (std::uint64_t t = t_last; t <= t_last + 250 * kMs; t += kMs) {
    const auto o = g.update(t);
    const std::uint64_t age = t - t_last;
    if (age <= 20 * kMs) {
      EXPECT_EQ(o.mode, GateMode::kStreaming) << age;
      EXPECT_EQ(o.force_scale, 1.0) << age;
      EXPECT_EQ(o.target.X_WT.p[0], static_cast<double>(t_last));  // held
      EXPECT_EQ(o.target.v_W[0], 1.0);
    } else if (age < 200 * kMs) {
      EXPECT_EQ(o.mode, GateMode::kRamping) << age;
      const double expect = static_cast<double>(200 * kMs - age) / static_cast<double>(180 * kMs);
      EXPECT_NEAR(o.force_scale, expect, 1e-12) << age;
      EXPECT_LT(o.force_scale, prev);  // strictly falling
      EXPECT_EQ(o.target.X_WT.p[0], static_cast<double>(t_last));
      EXPECT_EQ(o.target.v_W[0], 0.0);  // no extrapolation while ramping
      EXPECT_EQ(o.fault_bits, 0u);
    } else {
      EXPECT_EQ(o.mode, GateMode::kFaulted) << age;
      EXPECT_EQ(o.force_scale, 0.0);
      EXPECT_EQ(o.fault_bits, kFaultStreamLost);
    }
    prev = o.force_scale;
  }
  // the fault is latched: a fresh command does not clear it
  EXPECT_FALSE(g.submit(kS1, ++seq, at(1), 400 * kMs));
  EXPECT_EQ(g.dropped(DropReason::kFaulted), 1u);
  EXPECT_EQ(g.update(401 * kMs).mode, GateMode::kFaulted);
  // a straggler older than the dropped one stays dropped after re-arm
  g.arm(kS1, 402 * kMs);
  auto o = g.update(402 * kMs);
  EXPECT_EQ(o.mode, GateMode::kArmedIdle);
  EXPECT_EQ(o.fault_bits, 0u);
  EXPECT_FALSE(o.has_target);
  EXPECT_FALSE(g.submit(kS1, seq - 1, at(2), 403 * kMs));
  EXPECT_TRUE(g.submit(kS1, seq + 1, at(3), 403 * kMs));
  o = g.update(403 * kMs);
  EXPECT_EQ(o.mode, GateMode::kStreaming);
  EXPECT_EQ(o.force_scale, 1.0);
}

TEST(CommandGate, ARampRecoversWhenTheStreamResumes) {
  CommandGate g;
  g.arm(kS1, 0);
  ASSERT_TRUE(g.submit(kS1, 1, at(1), 0));
  EXPECT_EQ(g.update(100 * kMs).mode, GateMode::kRamping);
  ASSERT_TRUE(g.submit(kS1, 2, at(2), 100 * kMs));
  const auto o = g.update(100 * kMs);
  EXPECT_EQ(o.mode, GateMode::kStreaming);
  EXPECT_EQ(o.force_scale, 1.0);
}

TEST(CommandGate, DisarmDropsForceAtOnce) {
  CommandGate g;
  g.arm(kS1, 0);
  ASSERT_TRUE(g.submit(kS1, 1, at(1), 0));
  g.disarm(1 * kMs);
  expectDisarmedAt(g, 1 * kMs);
}

TEST(CommandGate, TimeNeverRunsBackwards) {
  CommandGate g;
  g.arm(kS1, 0);
  ASSERT_TRUE(g.submit(kS1, 1, at(1), 300 * kMs));
  // an earlier time is taken as now: the command is fresh, not 300 ms in the future
  EXPECT_EQ(g.update(10 * kMs).mode, GateMode::kStreaming);
}

TEST(CommandGate, ConfigurableTimes) {
  CommandGate g(CommandGateConfig{.hold_ns = 5 * kMs, .zero_ns = 10 * kMs});
  g.arm(kS1, 0);
  ASSERT_TRUE(g.submit(kS1, 1, at(1), 0));
  EXPECT_EQ(g.update(5 * kMs).mode, GateMode::kStreaming);
  EXPECT_NEAR(g.update(7 * kMs).force_scale, 0.6, 1e-12);
  EXPECT_EQ(g.update(10 * kMs).mode, GateMode::kFaulted);
}

TEST(CommandGate, ManySessionsForgetTheLeastRecentlyUsed) {
  CommandGate g;
  g.arm(kS1, 0);
  ASSERT_TRUE(g.submit(kS1, 50, at(1), 0));
  // 2 × kSessions other sessions push kS1 out of the table... unless kS1 keeps being used
  for (std::uint64_t s = 100; s < 100 + 2 * CommandGate::kSessions; ++s) {
    g.submit(s, 1, at(0), 0);
    ASSERT_TRUE(g.submit(kS1, 51 + s, at(1), 0));
  }
  EXPECT_FALSE(g.submit(kS1, 50, at(1), 0));  // still remembered: older
}

TEST(CommandGate, ServoCallsDoNotAllocate) {
  CommandGate g;
  SpscRing<std::uint64_t> ring(64);
  g.arm(kS1, 0);
  const auto before = testing_alloc::count();
  std::uint64_t seq = 0;
  for (std::uint64_t t = 0; t < 1000 * kMs; t += kMs) {
    ring.push(t);
    std::uint64_t v = 0;
    while (ring.pop(v))
      g.submit(kS1, ++seq, at(1), v);
    if (t % (300 * kMs) == 0)
      g.arm(kS1, t);
    (void)g.update(t);
  }
  g.disarm(0);
  EXPECT_EQ(testing_alloc::count(), before);
}

}  // namespace
}  // namespace hapticd::proto
