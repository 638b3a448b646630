// Shared memory: a seqlock reader never sees a torn state while a writer thread publishes; the
// command ring delivers in order across threads and refuses bad slots; dead peers are seen by
// their heartbeat (simulated times); attach refuses what it must.
#include "protocol/shm.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <thread>

#include "protocol/seqlock.h"
#include "tests/core/alloc_counter.h"

namespace hapticd::proto {
namespace {

std::string uniqueName(const char* what) {
  return "/hapticd-test-" + std::to_string(::getpid()) + "-" + what;
}

// a state whose every field is a function of k, so a mix of two writes is detectable
ShmState stateFor(std::uint64_t k) {
  ShmState s{};
  const double d = static_cast<double>(k);
  s.tick = k;
  s.sim_time_ns = k * 1000;
  s.publish_ns = k * 7;
  for (int i = 0; i < 7; ++i) {
    s.X_WD[i] = d + i;
    s.X_WP[i] = -d - i;
  }
  for (int i = 0; i < 3; ++i) {
    s.force_n[i] = d * 0.5 + i;
    s.torque_nm[i] = d * 0.25 - i;
  }
  s.force_scale = 1.0 / (1.0 + d);
  s.last_command_sequence = k + 1;
  s.tick_misses = k + 2;
  s.tick_p50_ns = k + 3;
  s.tick_p99_ns = k + 4;
  s.tick_max_ns = k + 5;
  s.fault_bits = k & 0xff;
  s.state_flags = k & 0x1f;
  s.contact_count = k % 100;
  s.body_count = kShmBodies;
  for (std::size_t b = 0; b < kShmBodies; ++b) {
    s.bodies[b].index = k + b;
    for (int i = 0; i < 7; ++i)
      s.bodies[b].X_WB[i] = d * static_cast<double>(b) + i;
  }
  return s;
}

bool consistent(const ShmState& s) {
  const ShmState e = stateFor(s.tick);
  return std::memcmp(&s, &e, sizeof s) == 0;
}

TEST(Shm, SeqlockReaderNeverSeesATornState) {
  auto server = ShmServer::create(uniqueName("seqlock"));
  ASSERT_TRUE(server) << server.error().message;
  auto client = ShmClient::attach(server.value().name());
  ASSERT_TRUE(client) << client.error().message;
  ShmState s{};
  EXPECT_FALSE(client.value().readState(s));  // nothing published yet
  std::atomic<bool> stop{false};
  constexpr std::uint64_t kWrites = 300000;
  std::thread writer([&] {
    for (std::uint64_t k = 1; k <= kWrites; ++k)
      server.value().publish(stateFor(k));
    stop = true;
  });
  std::uint64_t reads = 0, torn = 0, last = 0, backwards = 0;
  while (!stop || reads == 0) {
    if (!client.value().readState(s))
      continue;
    ++reads;
    if (!consistent(s))
      ++torn;
    if (s.tick < last)
      ++backwards;
    last = s.tick;
  }
  writer.join();
  EXPECT_GT(reads, 0u);
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  ASSERT_TRUE(client.value().readState(s));
  EXPECT_EQ(s.tick, kWrites);
  EXPECT_TRUE(consistent(s));
}

// the seqlock of the state block (protocol/seqlock.h) on its own, outside a segment
TEST(ShmSeqlock, InProcessReaderNeverSeesATornValue) {
  SeqlockBlock<ShmState> lock;
  ShmState s{};
  EXPECT_FALSE(lock.tryRead(s));
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    for (std::uint64_t k = 1; k <= 200000; ++k)
      lock.write(stateFor(k));
    stop = true;
  });
  std::uint64_t reads = 0, torn = 0;
  while (!stop || reads == 0) {
    if (!lock.tryRead(s))
      continue;
    ++reads;
    torn += !consistent(s);
  }
  writer.join();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(lock.writes(), 200000u);
  ASSERT_TRUE(lock.tryRead(s));
  EXPECT_EQ(s.tick, 200000u);
}

TEST(Shm, ToStateCarriesEveryField) {
  ShmState in = stateFor(3);
  in.X_WD[3] = 0.0;
  in.X_WD[4] = 0.0;
  in.X_WD[5] = 0.0;
  in.X_WD[6] = 1.0;
  in.body_count = 2;
  State out;
  out.contacts.resize(3);
  toState(in, out);
  EXPECT_EQ(out.tick, 3u);
  EXPECT_EQ(out.sim_time_ns, 3000u);
  EXPECT_EQ(out.X_WD.p[0], 3.0);
  EXPECT_EQ(out.X_WD.q[3], 1.0);
  EXPECT_EQ(out.X_WP.q[0], -6.0);
  EXPECT_EQ(out.force_n[2], 3.5);
  EXPECT_EQ(out.torque_nm[1], -0.25);
  EXPECT_EQ(out.last_command_sequence, 4u);
  EXPECT_EQ(out.tick_misses, 5u);
  EXPECT_EQ(out.tick_p50_ns, 6u);
  EXPECT_EQ(out.tick_p99_ns, 7u);
  EXPECT_EQ(out.tick_max_ns, 8u);
  EXPECT_EQ(out.contact_count, 3u);
  EXPECT_TRUE(out.contacts.empty());
  ASSERT_EQ(out.bodies.size(), 2u);
  EXPECT_EQ(out.bodies[1].body_index, 4u);
  EXPECT_EQ(out.bodies[1].X_WB.p[0], 3.0);
}

TEST(Shm, ToStateCarriesTheMinorOneFieldsSaturatedAndChecked) {
  ShmState in = stateFor(3);
  in.pairs_tested = 41;
  in.pairs_skipped = (1ull << 40);  // saturates
  in.max_penetration_m = 2.5e-4;
  in.tick_ns = 17000;
  State out;
  toState(in, out);
  EXPECT_EQ(out.pairs_tested, 41u);
  EXPECT_EQ(out.pairs_skipped, 0xffffffffu);
  EXPECT_EQ(out.max_penetration_m, 2.5e-4);
  EXPECT_EQ(out.tick_ns, 17000u);
  in.max_penetration_m = -1.0;  // never negative in a State (its decoder would refuse it)
  toState(in, out);
  EXPECT_EQ(out.max_penetration_m, 0.0);
  in.max_penetration_m = std::nan("");
  toState(in, out);
  EXPECT_EQ(out.max_penetration_m, 0.0);
}

TEST(Shm, CommandRingAcrossThreadsInOrderAndBadSlotsRefused) {
  auto server = ShmServer::create(uniqueName("ring"));
  ASSERT_TRUE(server) << server.error().message;
  auto client = ShmClient::attach(server.value().name());
  ASSERT_TRUE(client) << client.error().message;
  constexpr std::uint64_t kCommands = 50000;
  std::thread producer([&] {
    ASSERT_TRUE(client.value().pushArm(1));
    for (std::uint64_t k = 1; k <= kCommands; ++k) {
      PoseCommand p;
      p.X_WT.p = {static_cast<double>(k), 0.0, 0.0};
      if (k % 1000 == 0)
        p.v_W[0] = std::nan("");  // a bad slot: refused by the consumer
      while (!client.value().pushPose(p, k))
        std::this_thread::yield();
    }
  });
  std::uint64_t got = 0, last_seq = 0, last_x = 0, arms = 0;
  const auto before = testing_alloc::count();
  ShmCommandEvent e;
  while (got + arms < kCommands - kCommands / 1000 + 1) {
    if (!server.value().popCommand(e)) {
      std::this_thread::yield();
      continue;
    }
    if (e.kind == ShmCommandEvent::Kind::kArm) {
      ++arms;
      continue;
    }
    ASSERT_EQ(e.kind, ShmCommandEvent::Kind::kPose);
    ASSERT_GT(e.sequence, last_seq);
    ASSERT_GT(e.pose.X_WT.p[0], static_cast<double>(last_x));
    EXPECT_EQ(e.session_id, client.value().sessionId());
    last_seq = e.sequence;
    last_x = static_cast<std::uint64_t>(e.pose.X_WT.p[0]);
    ++got;
  }
  EXPECT_EQ(testing_alloc::count(), before);  // the consumer side allocates nothing
  producer.join();
  EXPECT_FALSE(server.value().popCommand(e));
  EXPECT_EQ(arms, 1u);
  EXPECT_EQ(got, kCommands - kCommands / 1000);
  EXPECT_EQ(last_x, kCommands - 1);
  EXPECT_EQ(server.value().commandsRefused(), kCommands / 1000);
}

TEST(Shm, DeadPeerDetectedByHeartbeat) {
  auto server = ShmServer::create(uniqueName("beat"));
  ASSERT_TRUE(server) << server.error().message;
  auto client = ShmClient::attach(server.value().name());
  ASSERT_TRUE(client);
  constexpr std::uint64_t kTimeout = 100'000'000;                     // 100 ms
  EXPECT_FALSE(client.value().serverAlive(1'000'000'000, kTimeout));  // never beat
  EXPECT_FALSE(server.value().clientAlive(1'000'000'000, kTimeout));
  server.value().beat(1'000'000'000);
  client.value().beat(1'000'000'000);
  EXPECT_TRUE(client.value().serverAlive(1'050'000'000, kTimeout));
  EXPECT_TRUE(server.value().clientAlive(1'100'000'000, kTimeout));
  // the server stops beating; the client keeps on
  client.value().beat(1'150'000'000);
  EXPECT_FALSE(client.value().serverAlive(1'150'000'001, kTimeout));
  EXPECT_TRUE(server.value().clientAlive(1'200'000'000, kTimeout));
  EXPECT_FALSE(server.value().clientAlive(1'250'000'001, kTimeout));
}

TEST(Shm, AttachRefusesMissingSegmentAndALiveSecondClient) {
  auto none = ShmClient::attach(uniqueName("missing"));
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("is hapticd running"), std::string::npos);
  auto server = ShmServer::create(uniqueName("two"));
  ASSERT_TRUE(server);
  auto first = ShmClient::attach(server.value().name());
  ASSERT_TRUE(first);
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  const std::uint64_t now = static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000ull +
                            static_cast<std::uint64_t>(ts.tv_nsec);
  first.value().beat(now);
  auto second = ShmClient::attach(server.value().name(), 60'000'000'000ull);
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message.find("another client"), std::string::npos);
  // a client whose heartbeat is stale may be replaced; its generation differs
  auto third = ShmClient::attach(server.value().name(), 0);
  ASSERT_TRUE(third) << third.error().message;
  EXPECT_NE(third.value().sessionId(), first.value().sessionId());
  EXPECT_FALSE(ShmServer::create("no-slash"));
}

TEST(Shm, SegmentRemovedWithTheServer) {
  const std::string name = uniqueName("gone");
  {
    auto server = ShmServer::create(name);
    ASSERT_TRUE(server);
  }
  EXPECT_FALSE(ShmClient::attach(name));
}

}  // namespace
}  // namespace hapticd::proto
