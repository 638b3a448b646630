// Sweep and prune against an O(N^2) brute force on random moving boxes: teleports, boxes added and
// removed mid-run, equal endpoints, zero extents, all three update paths (per endpoint, the
// insertion-sort pass, the grid) and switches between them, mm and km, filters, events.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "core/collision/broad_phase.h"
#include "core/common/sanitizers.h"
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

// How a run moves its boxes and which paths the broad phase may take.
struct Motion {
  double moving = 0.05;                  // fraction of the boxes moved each frame...
  double (*share)(int frame) = nullptr;  // ...or this fraction in this frame
  double scale = 1.0;                    // every length times this (mm: 1e-3, km: 1e3)
  std::size_t grid_min = static_cast<std::size_t>(-1);  // SweepAndPrune::setGridMinBoxes
  bool points = false;                                  // every box of zero size
  bool large = false;                                   // some boxes far wider than the rest
};

struct Figures {
  std::size_t frames = 0, max_pairs = 0;
  std::uint64_t grid_commits = 0, swaps = 0;
};

// `moving_share`: fraction of boxes moved each frame (small: the per-endpoint path; large: re-sort
// or, from motion.grid_min boxes, the grid)
void run(const Motion& motion, std::uint64_t seed, Figures& fig) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t n = 300;
  const double s = motion.scale;
  const double side = std::cbrt(70.0 * n) * s;
  Sim sim;
  sim.sap.setGridMinBoxes(motion.grid_min);
  auto randomBox = [&](Sim::Item& it) {
    const Vec3 c{u(rng) * side, u(rng) * side, u(rng) * side};
    Vec3 h = Vec3{0.5 + u(rng), 0.5 + u(rng), 0.5 + u(rng)} * s;
    if (u(rng) < 0.1)
      h[static_cast<int>(u(rng) * 3)] = 0.0;  // zero extent on an axis
    if (motion.points)
      h = Vec3{0.0};
    it.box = {c - h, c + h};
    if (u(rng) < 0.1) {  // snap to a grid: many exactly equal endpoints, faces touching
      it.box.lo = glm::floor(it.box.lo / s) * s;
      it.box.hi = glm::max(it.box.lo, glm::floor(it.box.hi / s) * s);
    }
  };
  for (std::size_t i = 0; i < n; ++i) {
    Sim::Item it;
    randomBox(it);
    it.filter.body = static_cast<std::uint32_t>(i % 250);  // some boxes share a body
    it.filter.is_static = u(rng) < 0.3;
    it.filter.group = u(rng) < 0.1 ? 2u : 1u;
    it.filter.mask = u(rng) < 0.1 ? ~2u : ~0u;
    if (motion.large && i % 50 == 7) {  // a slab across the scene, 20-60 times a box
      const int k = static_cast<int>(i / 50) % 3;
      it.box.lo[k] = -0.1 * side;
      it.box.hi[k] = (0.2 + u(rng)) * side;
    }
    it.v =
        glm::normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5}) * (0.01 + 0.3 * u(rng)) * s;
    it.handle = sim.sap.add(it.box, it.filter);
    it.live = true;
    sim.items.push_back(it);
  }
  if (motion.large) {  // a floor of infinite extent, static
    Sim::Item it;
    it.box = {Vec3{-INFINITY, -INFINITY, 0.0}, Vec3{INFINITY, INFINITY, 0.3 * side}};
    it.filter.body = 1000;
    it.filter.is_static = true;
    it.handle = sim.sap.add(it.box, it.filter);
    it.live = true;
    sim.items.push_back(it);
  }
  sim.sap.commit();
  sim.replay();
  for (int frame = 0; frame < 300; ++frame) {
    const double share = motion.share != nullptr ? motion.share(frame) : motion.moving;
    for (auto& it : sim.items) {
      if (!it.live || it.filter.is_static || u(rng) > share)
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
    ++fig.frames;
    fig.max_pairs = std::max(fig.max_pairs, ref.size());
  }
  fig.grid_commits += sim.sap.gridCommits();
  fig.swaps += sim.sap.swaps();
}

// run() over three seeds from first_seed, and its figures
Figures runSeeds(const Motion& motion, std::uint64_t first_seed, const char* what) {
  Figures fig;
  for (std::uint64_t seed = first_seed; seed < first_seed + 3; ++seed) {
    run(motion, seed, fig);
    if (::testing::Test::HasFatalFailure())
      return fig;
  }
  std::printf("[figures] %s: %zu frames equal to brute force, up to %zu pairs, %llu on the grid\n",
              what, fig.frames, fig.max_pairs, static_cast<unsigned long long>(fig.grid_commits));
  return fig;
}

Figures runSeeds(double moving, std::uint64_t first_seed, const char* what) {
  Motion motion;
  motion.moving = moving;
  return runSeeds(motion, first_seed, what);
}

TEST(SweepAndPrune, EqualsBruteForceFewMoving) {
  runSeeds(0.05, 1, "few moving");
}

TEST(SweepAndPrune, EqualsBruteForceAllMoving) {
  const Figures fig = runSeeds(1.0, 4, "all moving");
  EXPECT_EQ(fig.grid_commits, 0u);  // the insertion-sort pass, with transitions
}

// the grid path (every commit that moves a third of the boxes or more)
TEST(SweepAndPrune, GridEqualsBruteForceAllMoving) {
  Motion motion;
  motion.moving = 1.0;
  motion.grid_min = 0;
  const Figures fig = runSeeds(motion, 7, "all moving, grid");
  EXPECT_GE(fig.grid_commits, 3u * 250);
}

TEST(SweepAndPrune, GridEqualsBruteForceHalfMoving) {
  Motion motion;
  motion.moving = 0.5;
  motion.grid_min = 0;
  const Figures fig = runSeeds(motion, 10, "half moving, grid");
  EXPECT_GE(fig.grid_commits, 3u * 250);
}

// all, some, one and no box moving in turn: the grid, then the forced recomputation that
// re-sorts the lists, then the per-endpoint path, and back
double switching(int frame) {
  constexpr double kShares[] = {1.0, 1.0, 0.01, 0.0, 0.05, 1.0, 0.5, 0.2, 1.0, 0.003, 0.003, 0.7};
  return kShares[frame % 12];
}

TEST(SweepAndPrune, SwitchingBetweenGridAndSweepKeepsThePairs) {
  Motion motion;
  motion.share = switching;
  motion.grid_min = 0;
  const Figures fig = runSeeds(motion, 13, "switching");
  EXPECT_GE(fig.grid_commits, 3u * 100);
  EXPECT_GT(fig.swaps, 0u);
}

TEST(SweepAndPrune, GridInMillimetresAndKilometres) {
  Motion motion;
  motion.share = switching;
  motion.grid_min = 0;
  for (const double scale : {1e-3, 1e3}) {
    motion.scale = scale;
    const Figures fig = runSeeds(motion, 16, scale < 1.0 ? "switching, mm" : "switching, km");
    EXPECT_GE(fig.grid_commits, 3u * 100);
  }
}

// zero-size boxes everywhere: the width histogram gives no cell size, the grid's extent does
TEST(SweepAndPrune, GridOfPointBoxes) {
  Motion motion;
  motion.share = switching;
  motion.grid_min = 0;
  motion.points = true;
  const Figures fig = runSeeds(motion, 19, "switching, points");
  EXPECT_GE(fig.grid_commits, 3u * 100);
}

// slabs across the scene and a floor of infinite extent among the boxes: the boxes wider than a
// cell, tested against the cells they cover (or all boxes)
TEST(SweepAndPrune, GridWithLargeBoxes) {
  Motion motion;
  motion.share = switching;
  motion.grid_min = 0;
  motion.large = true;
  const Figures fig = runSeeds(motion, 22, "switching, large boxes");
  EXPECT_GE(fig.grid_commits, 3u * 50);
}

// exactly touching faces: unit cubes on an integer lattice, moved by whole units, so that every
// neighbour touches at a face, an edge or a corner or is a unit apart
TEST(SweepAndPrune, GridAndSweepOnALatticeOfTouchingCubes) {
  for (const double scale : {1e-3, 1.0, 1e3}) {
    std::mt19937_64 rng(25);
    std::uniform_int_distribution<int> cell(0, 11), step(-1, 1);
    Sim sim;
    sim.sap.setGridMinBoxes(0);
    for (std::uint32_t i = 0; i < 400; ++i) {
      Sim::Item it;
      const Vec3 lo{static_cast<double>(cell(rng)), static_cast<double>(cell(rng)),
                    static_cast<double>(cell(rng))};
      it.box = {lo * scale, (lo + 1.0) * scale};
      it.filter.body = i;
      it.handle = sim.sap.add(it.box, it.filter);
      it.live = true;
      sim.items.push_back(it);
    }
    sim.sap.commit();
    sim.replay();
    for (int frame = 0; frame < 60; ++frame) {
      const double share = switching(frame);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      for (auto& it : sim.items) {
        if (u(rng) > share)
          continue;
        const Vec3 lo = glm::round(it.box.lo / scale) + Vec3{static_cast<double>(step(rng)),
                                                             static_cast<double>(step(rng)),
                                                             static_cast<double>(step(rng))};
        it.box = {lo * scale, (lo + 1.0) * scale};
        sim.sap.update(it.handle, it.box);
      }
      sim.sap.commit();
      sim.replay();
      if (::testing::Test::HasFatalFailure())
        return;
      const PairSet ref = sim.brute();
      ASSERT_EQ(sim.ours(), ref) << "scale " << scale << ", frame " << frame;
      ASSERT_EQ(sim.replayed, ref) << "events, scale " << scale << ", frame " << frame;
      ASSERT_GT(ref.size(), 100u);  // touching neighbours are pairs
    }
    EXPECT_GE(sim.sap.gridCommits(), 20u);
  }
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
  ASSERT_GE(2000u, sap.gridMinBoxes());  // both paths: the grid and the per-endpoint moves
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
  EXPECT_GE(sap.gridCommits(), 100u);
}

constexpr bool kAsan = hapticd::kAddressSanitizer;

long minorFaults() {
  rusage r{};
  getrusage(RUSAGE_THREAD, &r);
  return r.ru_minflt;
}

// reserve() writes the grid's scratch once (off the servo thread), so that the first commit that
// moves most boxes writes no fresh pages: before, the first grid commit among 20 000 boxes wrote
// about 2 MB of scratch for the first time (some 500 page faults; at 100 000 boxes 30 ms of page
// faults on the benchmark machine). Counted by this thread's minor page faults, not by time.
TEST(SweepAndPrune, FirstGridCommitAfterReserveFaultsFewPages) {
  if (kAsan)
    GTEST_SKIP() << "AddressSanitizer faults its own shadow pages";
  constexpr std::size_t kBoxes = 20000;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double side = std::cbrt(70.0 * static_cast<double>(kBoxes));
  SweepAndPrune sap;
  sap.reserve(kBoxes, 8 * kBoxes);
  std::vector<std::uint32_t> handles;
  std::vector<Aabb> boxes;
  for (std::size_t i = 0; i < kBoxes; ++i) {
    const Vec3 c{u(rng) * side, u(rng) * side, u(rng) * side};
    boxes.push_back({c - 1.0, c + 1.0});
    BoxFilter f;
    f.body = static_cast<std::uint32_t>(i);
    handles.push_back(sap.add(boxes.back(), f));
  }
  sap.commit();
  sap.takeEvents();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Vec3 d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
    boxes[i].lo += d * 0.1;
    boxes[i].hi += d * 0.1;
    sap.update(handles[i], boxes[i]);
  }
  const long before = minorFaults();
  sap.commit();
  const long faults = minorFaults() - before;
  ASSERT_EQ(sap.gridCommits(), 1u);
  // a few pages of events (written for the first time in the half of the event lists that
  // takeEvents() swapped in) are allowed
  EXPECT_LE(faults, 16) << "page faults in the first grid commit";
}

}  // namespace
}  // namespace hapticd::collision
