// Sweep and prune against an O(N^2) brute force on random moving boxes: teleports, boxes added and
// removed mid-run, equal endpoints, zero extents, both update paths, filters, events.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <set>

#include "core/collision/broad_phase.h"
#include "tests/core/alloc_counter.h"

namespace hapticd::collision {
namespace {

using geom::Vec3;
using PairSet = std::set<std::pair<std::uint32_t, std::uint32_t>>;

struct Sim {
  struct Item {
    Aabb box;
    BoxFilter filter;
    Vec3 v{0.0};
    std::uint32_t handle = 0;
    bool live = false;
  };
  std::vector<Item> items;
  SweepAndPrune sap;
  PairSet replayed;  // the pair set rebuilt from events alone

  PairSet brute() const {
    PairSet s;
    for (std::size_t i = 0; i < items.size(); ++i) {
      for (std::size_t j = i + 1; j < items.size(); ++j) {
        const Item& a = items[i];
        const Item& b = items[j];
        if (!a.live || !b.live)
          continue;
        if (a.filter.body == b.filter.body || (a.filter.is_static && b.filter.is_static))
          continue;
        if ((a.filter.group & b.filter.mask) == 0 || (b.filter.group & a.filter.mask) == 0)
          continue;
        bool overlap = true;
        for (int k = 0; k < 3; ++k) {
          overlap = overlap && a.box.lo[k] <= b.box.hi[k] && b.box.lo[k] <= a.box.hi[k];
        }
        if (overlap)
          s.insert({std::min(a.handle, b.handle), std::max(a.handle, b.handle)});
      }
    }
    return s;
  }
  PairSet ours() const {
    PairSet s;
    for (const BoxPair& p : sap.pairs())
      s.insert({p.lo, p.hi});
    return s;
  }
  void replay() {
    for (const PairEvent& e : sap.takeEvents()) {
      const auto key = std::make_pair(e.pair.lo, e.pair.hi);
      if (e.kind == PairEvent::Kind::kAdded) {
        ASSERT_TRUE(replayed.insert(key).second) << "added twice";
      } else {
        ASSERT_EQ(replayed.erase(key), 1u) << "removed but absent";
      }
    }
  }
};

// `moving_share`: fraction of boxes moved each frame (small: the per-endpoint path; large: re-sort)
void run(double moving_share,
         std::uint64_t seed,
         std::size_t& frames_checked,
         std::size_t& max_pairs) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t n = 300;
  const double side = std::cbrt(70.0 * n);
  Sim sim;
  auto randomBox = [&](Sim::Item& it) {
    const Vec3 c{u(rng) * side, u(rng) * side, u(rng) * side};
    Vec3 h{0.5 + u(rng), 0.5 + u(rng), 0.5 + u(rng)};
    if (u(rng) < 0.1)
      h[static_cast<int>(u(rng) * 3)] = 0.0;  // zero extent on an axis
    it.box = {c - h, c + h};
    if (u(rng) < 0.1) {  // snap to a grid: many exactly equal endpoints
      it.box.lo = glm::floor(it.box.lo);
      it.box.hi = glm::max(it.box.lo, glm::floor(it.box.hi));
    }
  };
  for (std::size_t i = 0; i < n; ++i) {
    Sim::Item it;
    randomBox(it);
    it.filter.body = static_cast<std::uint32_t>(i % 250);  // some boxes share a body
    it.filter.is_static = u(rng) < 0.3;
    it.filter.group = u(rng) < 0.1 ? 2u : 1u;
    it.filter.mask = u(rng) < 0.1 ? ~2u : ~0u;
    it.v = glm::normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5}) * (0.01 + 0.3 * u(rng));
    it.handle = sim.sap.add(it.box, it.filter);
    it.live = true;
    sim.items.push_back(it);
  }
  sim.sap.commit();
  sim.replay();
  for (int frame = 0; frame < 300; ++frame) {
    for (auto& it : sim.items) {
      if (!it.live || it.filter.is_static || u(rng) > moving_share)
        continue;
      if (u(rng) < 0.01) {
        randomBox(it);  // teleport
      } else {
        it.box.lo += it.v;
        it.box.hi += it.v;
        for (int k = 0; k < 3; ++k) {
          if (it.box.lo[k] < 0.0 || it.box.hi[k] > side)
            it.v[k] = -it.v[k];
        }
      }
      sim.sap.update(it.handle, it.box);
    }
    if (frame % 17 == 5) {  // remove one box, add one (handles are reused)
      auto& it = sim.items[static_cast<std::size_t>(u(rng) * n)];
      if (it.live) {
        sim.sap.remove(it.handle);
        it.live = false;
      } else {
        randomBox(it);
        it.handle = sim.sap.add(it.box, it.filter);
        it.live = true;
      }
    }
    sim.sap.commit();
    sim.replay();
    if (::testing::Test::HasFatalFailure())
      return;
    const PairSet ref = sim.brute();
    ASSERT_EQ(sim.ours(), ref) << "frame " << frame;
    ASSERT_EQ(sim.replayed, ref) << "events, frame " << frame;
    ++frames_checked;
    max_pairs = std::max(max_pairs, ref.size());
  }
}

// run() over three seeds from first_seed with `moving` of the boxes moving, and its figures
void runSeeds(double moving, std::uint64_t first_seed, const char* what) {
  std::size_t frames = 0, pairs = 0;
  for (std::uint64_t seed = first_seed; seed < first_seed + 3; ++seed) {
    run(moving, seed, frames, pairs);
    if (::testing::Test::HasFatalFailure())
      return;
  }
  std::printf("[figures] %s: %zu frames equal to brute force, up to %zu pairs\n", what, frames,
              pairs);
}

TEST(SweepAndPrune, EqualsBruteForceFewMoving) {
  runSeeds(0.05, 1, "few moving");
}

TEST(SweepAndPrune, EqualsBruteForceAllMoving) {
  runSeeds(1.0, 4, "all moving");
}

TEST(SweepAndPrune, TouchingBoxesOverlap) {
  SweepAndPrune sap;
  BoxFilter a, b;
  a.body = 1;
  b.body = 2;
  const auto ha = sap.add({{0, 0, 0}, {1, 1, 1}}, a);
  const auto hb = sap.add({{1, 0, 0}, {2, 1, 1}}, b);  // touching at x = 1
  sap.commit();
  EXPECT_TRUE(sap.overlapping(ha, hb));
  sap.update(hb, {{1.5, 0, 0}, {2.5, 1, 1}});
  sap.commit();
  EXPECT_FALSE(sap.overlapping(ha, hb));
  sap.update(hb, {{-5, 0.5, 0.5}, {-5, 0.5, 0.5}});  // a point box, jumping over
  sap.commit();
  EXPECT_FALSE(sap.overlapping(ha, hb));
  sap.update(hb, {{0.5, 0.5, 0.5}, {0.5, 0.5, 0.5}});  // a point box inside
  sap.commit();
  EXPECT_TRUE(sap.overlapping(ha, hb));
}

TEST(SweepAndPrune, UpdateAllocatesNothingAfterWarmUp) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  SweepAndPrune sap;
  sap.reserve(2000, 20000);
  std::vector<std::uint32_t> handles;
  std::vector<Aabb> boxes;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 c{u(rng) * 40, u(rng) * 40, u(rng) * 40};
    boxes.push_back({c - 1.0, c + 1.0});
    BoxFilter f;
    f.body = static_cast<std::uint32_t>(i);
    handles.push_back(sap.add(boxes.back(), f));
  }
  sap.commit();
  sap.takeEvents();
  auto frame = [&](double share) {
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      if (u(rng) > share)
        continue;
      const Vec3 d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
      boxes[i].lo += d * 0.2;
      boxes[i].hi += d * 0.2;
      sap.update(handles[i], boxes[i]);
    }
    sap.commit();
    sap.takeEvents();
  };
  for (int f = 0; f < 20; ++f)
    frame(f % 2 ? 1.0 : 0.01);  // warm-up, both paths
  const std::uint64_t before = testing_alloc::count();
  for (int f = 0; f < 200; ++f)
    frame(f % 2 ? 1.0 : 0.01);
  EXPECT_EQ(testing_alloc::count() - before, 0u);
}

}  // namespace
}  // namespace hapticd::collision
