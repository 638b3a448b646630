// The collision step: contacts equal direct pair queries on every close pair; the scheduler's
// guarantees; determinism; no allocation per step.
#include "core/collision/collision_world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <thread>

#include "tests/core/alloc_counter.h"
#include "tests/reference/reference.h"

namespace hapticd::collision {
namespace {

using geom::Pose;
using geom::Quat;

std::shared_ptr<const Polytope> shape(std::vector<Vec3> pts) {
  return std::make_shared<const Polytope>(Polytope::fromPoints(pts).value());
}

std::vector<Vec3> box(double h) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i)
    p.push_back(Vec3{i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
  return p;
}

// A scene: a grid of static cubes and ellipsoid hulls, and a probe body of several primitives.
struct Scene {
  CollisionWorld world;
  std::vector<BodyDesc> descs;
  std::vector<Pose> poses;
  std::uint32_t probe = 0;

  explicit Scene(const WorldOptions& o) : world(o) {
    const auto cube = shape(box(0.01));
    const auto ell = shape(reference::ellipsoidPoints(40, 0.012, 0.008, 0.006, 3));
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        BodyDesc d;
        d.kind = BodyKind::kStatic;
        d.primitives.push_back({(i + j) % 2 ? cube : ell, Transform{}});
        add(d, Pose{Vec3{i * 0.025, 0.0, j * 0.025}, Quat{1, 0, 0, 0}});
      }
    }
    BodyDesc p;
    p.kind = BodyKind::kProbe;
    for (int k = 0; k < 5; ++k) {
      Transform X;
      X.t = Vec3{0.012 * k, 0.0, 0.0};
      p.primitives.push_back({k % 2 ? ell : cube, X});
    }
    probe = add(p, Pose{Vec3{0.05, 0.03, 0.05}, Quat{1, 0, 0, 0}});
  }
  std::uint32_t add(const BodyDesc& d, const Pose& X) {
    const std::uint32_t id = world.addBody(d, X);
    if (descs.size() <= id)
      descs.resize(id + 1), poses.resize(id + 1);
    descs[id] = d;
    poses[id] = X;
    return id;
  }
  void move(const Pose& X) {
    world.setPose(probe, X);
    poses[probe] = X;
  }
};

Transform primitiveWorld(const Scene& s, std::uint32_t body, std::uint32_t prim) {
  return s.poses[body].toTransform() * s.descs[body].primitives[prim].X_BP;
}

// Every primitive pair of different bodies (not both static) whose margin-grown boxes overlap,
// by brute force over vertices.
std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>, double>
expected(const Scene& s, const std::vector<std::uint32_t>& live, double margin) {
  std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>, double> out;
  auto boxOf = [&](std::uint32_t b, std::uint32_t p) {
    const Transform X = primitiveWorld(s, b, p);
    Aabb a{Vec3{1e300}, Vec3{-1e300}};
    for (const auto& v : s.descs[b].primitives[p].shape->vertices()) {
      a.lo = glm::min(a.lo, X.apply(v.p));
      a.hi = glm::max(a.hi, X.apply(v.p));
    }
    a.lo -= margin;
    a.hi += margin;
    return a;
  };
  for (std::size_t i = 0; i < live.size(); ++i) {
    for (std::size_t j = i + 1; j < live.size(); ++j) {
      std::uint32_t ba = live[i], bb = live[j];
      if (ba > bb)
        std::swap(ba, bb);
      if (s.descs[ba].kind == BodyKind::kStatic && s.descs[bb].kind == BodyKind::kStatic)
        continue;
      for (std::uint32_t pa = 0; pa < s.descs[ba].primitives.size(); ++pa) {
        for (std::uint32_t pb = 0; pb < s.descs[bb].primitives.size(); ++pb) {
          const Aabb x = boxOf(ba, pa), y = boxOf(bb, pb);
          bool overlap = true;
          for (int k = 0; k < 3; ++k)
            overlap = overlap && x.lo[k] <= y.hi[k] && y.lo[k] <= x.hi[k];
          if (!overlap)
            continue;
          const Transform XA = primitiveWorld(s, ba, pa), XB = primitiveWorld(s, bb, pb);
          const geom::Mat3 Rt = glm::transpose(XA.R);
          PairCache c;
          out[{ba, bb, pa, pb}] =
              queryPair(*s.descs[ba].primitives[pa].shape, *s.descs[bb].primitives[pb].shape,
                        Transform{Rt * XB.R, Rt * (XB.t - XA.t)}, c)
                  .distance;
        }
      }
    }
  }
  return out;
}

TEST(CollisionWorld, ContactsEqualDirectPairQueries) {
  WorldOptions o;
  o.box_margin = 0.002;
  Scene s(o);
  std::vector<std::uint32_t> live;
  for (std::uint32_t b = 0; b < s.descs.size(); ++b)
    live.push_back(b);
  std::size_t checked = 0, max_pairs = 0;
  std::uint32_t extra = 0;
  bool extra_live = false;
  for (int k = 0; k < 400; ++k) {
    const double t = k * 0.01;
    s.move(Pose{Vec3{0.06 + 0.05 * std::sin(t), 0.012 + 0.01 * std::cos(1.3 * t),
                     0.06 + 0.05 * std::cos(t)},
                glm::angleAxis(0.5 * t, glm::normalize(Vec3{1, 2, 3}))});
    if (k == 100) {  // a kinematic body added mid-run
      BodyDesc d;
      d.kind = BodyKind::kKinematic;
      d.primitives.push_back({shape(box(0.015)), Transform{}});
      extra = s.add(d, Pose{Vec3{0.05, 0.02, 0.05}, Quat{1, 0, 0, 0}});
      live.push_back(extra);
      extra_live = true;
    }
    if (k == 300 && extra_live) {  // and removed again
      s.world.removeBody(extra);
      live.erase(std::find(live.begin(), live.end(), extra));
      extra_live = false;
    }
    const StepStats st = s.world.step();
    EXPECT_EQ(st.pairs_skipped, 0u);
    const auto want = expected(s, live, o.box_margin);
    ASSERT_EQ(s.world.contacts().size(), want.size()) << "step " << k;
    for (const Contact& c : s.world.contacts()) {
      const auto it = want.find({c.body_a, c.body_b, c.prim_a, c.prim_b});
      ASSERT_NE(it, want.end()) << "step " << k;
      ASSERT_EQ(c.age, 0u);
      ASSERT_NEAR(c.distance, it->second, 1e-12) << "step " << k;
      ++checked;
    }
    max_pairs = std::max(max_pairs, want.size());
    // grouped by body pair
    for (std::size_t i = 1; i < s.world.contacts().size(); ++i) {
      const auto& p = s.world.contacts()[i - 1];
      const auto& q = s.world.contacts()[i];
      ASSERT_TRUE(p.body_a < q.body_a || (p.body_a == q.body_a && p.body_b <= q.body_b));
    }
  }
  std::printf("[figures] world: %zu contacts checked over 400 steps, up to %zu close pairs\n",
              checked, max_pairs);
  EXPECT_GT(max_pairs, 3u);
}

TEST(CollisionWorld, SchedulerTestsEveryPairWithinCeilPOverB) {
  for (const std::uint32_t budget : {1u, 2u, 3u, 5u}) {
    WorldOptions o;
    o.box_margin = 0.004;
    o.budget.max_pairs = budget;
    Scene s(o);
    // park the probe among the static bodies: a fixed set of close pairs, some in contact
    s.move(Pose{Vec3{0.05, 0.012, 0.05}, Quat{1, 0, 0, 0}});
    s.world.step();
    std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>, std::uint64_t>
        last;
    std::uint64_t worst = 0, worst_contact = 0;
    std::size_t pairs = 0;
    for (int k = 0; k < 200; ++k) {
      // tiny motion: the same pairs stay close
      s.move(Pose{Vec3{0.05 + 1e-6 * (k % 2), 0.012, 0.05}, Quat{1, 0, 0, 0}});
      const StepStats st = s.world.step();
      pairs = st.pairs_overlapping;
      ASSERT_EQ(st.pairs_tested + st.pairs_skipped, st.pairs_overlapping);
      ASSERT_EQ(st.pairs_tested, std::min(budget, st.pairs_overlapping));
      const std::uint64_t bound = (st.pairs_overlapping + budget - 1) / budget;
      std::uint32_t stalest_skipped = 0;
      for (const Contact& c : s.world.contacts()) {
        const auto key = std::make_tuple(c.body_a, c.body_b, c.prim_a, c.prim_b);
        if (c.age == 0) {
          if (last.count(key) != 0 && k > 20) {
            const std::uint64_t gap = static_cast<std::uint64_t>(k) - last[key];
            worst = std::max(worst, gap);
            if (c.distance <= o.box_margin)
              worst_contact = std::max(worst_contact, gap);
            ASSERT_LE(gap, bound) << "budget " << budget << " step " << k;
          }
          last[key] = static_cast<std::uint64_t>(k);
        } else {
          stalest_skipped = std::max(stalest_skipped, c.age);
          ASSERT_LE(c.age, bound);
        }
      }
      ASSERT_EQ(st.worst_staleness, stalest_skipped) << "step " << k;
    }
    std::printf(
        "[figures] budget %u pairs/tick, %zu close pairs: worst gap between tests %llu ticks "
        "(bound %zu), in contact %llu\n",
        budget, pairs, static_cast<unsigned long long>(worst), (pairs + budget - 1) / budget,
        static_cast<unsigned long long>(worst_contact));
    EXPECT_GT(pairs, budget) << "the scene must need scheduling";
  }
}

TEST(CollisionWorld, ContactPairsFirstWhenTheBudgetAllows) {
  WorldOptions o;
  o.box_margin = 0.004;
  o.budget.max_pairs = 4;
  Scene s(o);
  s.move(Pose{Vec3{0.05, 0.012, 0.05}, Quat{1, 0, 0, 0}});
  for (int k = 0; k < 50; ++k)
    s.world.step();
  // pairs in contact (within the margin) are tested more often than the others
  std::map<bool, std::pair<std::uint64_t, std::uint64_t>> tests;  // in contact -> (tests, samples)
  for (int k = 0; k < 200; ++k) {
    s.world.step();
    for (const Contact& c : s.world.contacts()) {
      auto& t = tests[c.distance <= o.box_margin];
      t.first += c.age == 0;
      ++t.second;
    }
  }
  ASSERT_GT(tests[true].second, 0u);
  ASSERT_GT(tests[false].second, 0u);
  const double rate_contact = double(tests[true].first) / double(tests[true].second);
  const double rate_other = double(tests[false].first) / double(tests[false].second);
  std::printf("[figures] tested per tick: in contact %.3f, others %.3f\n", rate_contact,
              rate_other);
  EXPECT_GT(rate_contact, rate_other);
}

TEST(CollisionWorld, UnlimitedBudgetSkipsNothingAndRunsAreIdentical) {
  WorldOptions o;
  o.box_margin = 0.003;
  Scene a(o), b(o);
  for (int k = 0; k < 300; ++k) {
    const Pose X{Vec3{0.05 + 0.03 * std::sin(k * 0.02), 0.011, 0.05 + 0.03 * std::cos(k * 0.017)},
                 glm::angleAxis(k * 0.01, Vec3{0, 1, 0})};
    a.move(X);
    b.move(X);
    const StepStats sa = a.world.step();
    b.world.step();
    ASSERT_EQ(sa.pairs_skipped, 0u);
    ASSERT_EQ(sa.worst_staleness, 0u);
    ASSERT_EQ(a.world.contacts().size(), b.world.contacts().size());
    for (std::size_t i = 0; i < a.world.contacts().size(); ++i) {
      const Contact& x = a.world.contacts()[i];
      const Contact& y = b.world.contacts()[i];
      ASSERT_EQ(std::memcmp(&x.distance, &y.distance, sizeof(double)), 0);
      ASSERT_EQ(std::memcmp(&x.normal, &y.normal, sizeof(Vec3)), 0);
      ASSERT_EQ(x.manifold.count, y.manifold.count);
      ASSERT_EQ(x.age, 0u);
    }
  }
}

TEST(CollisionWorld, StepAllocatesNothingAfterReserve) {
  WorldOptions o;
  o.box_margin = 0.002;
  o.budget.max_pairs = 6;
  Scene s(o);
  s.world.reserve(256, 1024);
  auto step = [&](int k) {
    s.move(Pose{Vec3{0.06 + 0.04 * std::sin(k * 0.01), 0.012, 0.06 + 0.04 * std::cos(k * 0.01)},
                glm::angleAxis(k * 0.003, glm::normalize(Vec3{1, 2, 3}))});
    s.world.step();
  };
  for (int k = 0; k < 50; ++k)
    step(k);  // warm-up: the depth scratch grows to its size here
  const std::uint64_t before = testing_alloc::count();
  for (int k = 50; k < 2050; ++k)
    step(k);
  EXPECT_EQ(testing_alloc::count() - before, 0u);
}

// The narrow phase's depth scratch belongs to the world, sized as the bodies are added: a thread
// that never queried anything steps a world of penetrating pairs from its first step on without
// allocating (a per-thread scratch would grow on that thread's first penetration).
TEST(CollisionWorld, StepAllocatesNothingFromTheFirstStepOnANewThread) {
  WorldOptions o;
  o.box_margin = 0.002;
  Scene s(o);
  s.world.reserve(256, 1024);
  std::uint64_t allocations = 0;
  std::uint32_t penetrating = 0;
  std::thread servo([&] {
    const std::uint64_t before = testing_alloc::count();
    for (int k = 0; k < 2000; ++k) {
      s.move(Pose{Vec3{0.06 + 0.04 * std::sin(k * 0.01), 0.012, 0.06 + 0.04 * std::cos(k * 0.01)},
                  glm::angleAxis(k * 0.003, glm::normalize(Vec3{1, 2, 3}))});
      s.world.step();
      for (const Contact& c : s.world.contacts())
        penetrating += c.answered && c.status == ContactStatus::kPenetrating ? 1u : 0u;
    }
    allocations = testing_alloc::count() - before;
  });
  servo.join();
  EXPECT_GT(penetrating, 1000u);  // the depth was asked for, many times
  EXPECT_EQ(allocations, 0u);
}

// A disabled body's pairs are neither tested nor listed; enabled again (even unmoved, with
// skip_unmoved_pairs) they are tested at the next step; toggling allocates nothing.
TEST(CollisionWorld, ADisabledBodyHasNoPairsAndIsTestedAgainWhenEnabled) {
  WorldOptions o;
  o.box_margin = 1e-3;
  o.skip_unmoved_pairs = true;
  CollisionWorld world(o);
  world.reserve(8, 64);
  const auto cube = shape(box(0.01));
  BodyDesc floor_desc;
  floor_desc.kind = BodyKind::kStatic;
  floor_desc.primitives.push_back({cube, Transform{}});
  BodyDesc kin_desc = floor_desc;
  kin_desc.kind = BodyKind::kKinematic;
  BodyDesc probe_desc = floor_desc;
  probe_desc.kind = BodyKind::kProbe;
  const std::uint32_t floor = world.addBody(floor_desc, Pose{Vec3{0.0}, Quat{1, 0, 0, 0}});
  const std::uint32_t kin = world.addBody(kin_desc, Pose{Vec3{0.0, 0.0195, 0.0}, Quat{1, 0, 0, 0}});
  const std::uint32_t probe =
      world.addBody(probe_desc, Pose{Vec3{0.0, 0.039, 0.0}, Quat{1, 0, 0, 0}});
  const auto pairsWith = [&](std::uint32_t body) {
    std::uint32_t n = 0;
    for (const Contact& c : world.contacts())
      n += c.body_a == body || c.body_b == body;
    return n;
  };
  StepStats st = world.step();
  EXPECT_EQ(pairsWith(kin), 2u);  // with the floor and the probe
  EXPECT_EQ(st.pairs_tested, 2u);
  // unmoved: nothing is tested again
  st = world.step();
  EXPECT_EQ(st.pairs_tested, 0u);
  const std::uint64_t before = testing_alloc::count();
  world.setEnabled(kin, false);
  EXPECT_FALSE(world.enabled(kin));
  st = world.step();
  EXPECT_EQ(pairsWith(kin), 0u);
  EXPECT_EQ(st.pairs_tested, 0u);
  // moved while disabled: still no pairs
  world.setPose(kin, Pose{Vec3{0.0, 0.02, 0.0}, Quat{1, 0, 0, 0}});
  st = world.step();
  EXPECT_EQ(pairsWith(kin), 0u);
  EXPECT_EQ(st.pairs_tested, 0u);
  world.setEnabled(kin, true);
  st = world.step();
  EXPECT_EQ(pairsWith(kin), 2u);
  EXPECT_EQ(st.pairs_tested, 2u);
  for (const Contact& c : world.contacts()) {
    EXPECT_TRUE(c.answered);
    EXPECT_EQ(c.age, 0u);
  }
  // a disabled body moved far away and enabled there: its old pairs leave, no new ones
  world.setEnabled(kin, false);
  world.setPose(kin, Pose{Vec3{1.0, 0.0, 0.0}, Quat{1, 0, 0, 0}});
  world.step();
  world.setEnabled(kin, true);
  world.step();
  EXPECT_EQ(pairsWith(kin), 0u);
  EXPECT_EQ(pairsWith(probe), 0u);  // the probe and the floor are 19 mm apart
  EXPECT_EQ(pairsWith(floor), 0u);
  EXPECT_EQ(testing_alloc::count() - before, 0u);
}

}  // namespace
}  // namespace hapticd::collision
