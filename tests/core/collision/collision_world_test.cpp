// The collision step: contacts equal direct pair queries on every close pair; the scheduler's
// guarantees; determinism; no allocation per step.
#include "core/collision/collision_world.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <thread>

#include "core/collision/penetration.h"
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

// WorldOptions::query_method: another method answers every pair query (a study's method inside
// the closed loop), seeing the pair's pose at its previous test (null at its first); its answers
// are the contacts' and no depth is tracked.
TEST(CollisionWorld, AQueryMethodAnswersEveryPairAndSeesThePairsLastPose) {
  // the tick's own answer, its distance marked with what the method was given: 0 at a pair's
  // first test, 1 + how far B moved in A's frame since its last
  struct Marking final : PairQueryMethod {
    std::size_t calls = 0;
    void query(const Polytope& a,
               const Polytope& b,
               const Transform& X_AB,
               const Transform* X_AB_last,
               PairCache& cache,
               PairResult& out) override {
      ++calls;
      out = queryPair(a, b, X_AB, cache);
      if (X_AB_last != nullptr)
        out.distance += 1.0 + glm::length(X_AB.t - X_AB_last->t);
    }
  } marking;
  WorldOptions o;
  o.box_margin = 0.002;
  o.query_method = &marking;
  Scene s(o);
  using Key = std::array<std::uint32_t, 4>;
  std::map<Key, Transform> last;  // each listed pair's pose at its last test
  std::size_t marked = 0, first = 0, tested = 0;
  for (int k = 0; k < 300; ++k) {
    const double t = k * 0.01;
    s.move(Pose{Vec3{0.06 + 0.05 * std::sin(t), 0.012 + 0.01 * std::cos(1.3 * t),
                     0.06 + 0.05 * std::cos(t)},
                glm::angleAxis(0.5 * t, glm::normalize(Vec3{1, 2, 3}))});
    const std::size_t calls = marking.calls;
    const StepStats st = s.world.step();
    ASSERT_EQ(marking.calls - calls, st.pairs_tested) << "step " << k;
    EXPECT_EQ(st.depth_certified + st.depth_fallbacks, 0u);
    tested += st.pairs_tested;
    std::map<Key, Transform> now;
    for (const Contact& c : s.world.contacts()) {
      ASSERT_EQ(c.age, 0u);
      const Key key{c.body_a, c.body_b, c.prim_a, c.prim_b};
      const Transform A = primitiveWorld(s, c.body_a, c.prim_a);
      const Transform B = primitiveWorld(s, c.body_b, c.prim_b);
      const Transform X_AB = A.inverse() * B;
      PairCache cold;
      double want = queryPair(*s.descs[c.body_a].primitives[c.prim_a].shape,
                              *s.descs[c.body_b].primitives[c.prim_b].shape, X_AB, cold)
                        .distance;
      const auto it = last.find(key);
      if (it != last.end()) {
        want += 1.0 + glm::length(X_AB.t - it->second.t);
        ++marked;
      } else {
        ++first;
      }
      ASSERT_NEAR(c.distance, want, 1e-9) << "step " << k;
      now[key] = X_AB;
    }
    last = std::move(now);
  }
  std::printf("[figures] query method: %zu tests, %zu first, %zu with the last pose\n", tested,
              first, marked);
  EXPECT_GT(first, 3u);
  EXPECT_GT(marked, 100u);
}

// WorldOptions::far_distance: a pair is left untested and unlisted only when it is certainly
// farther than the limit (static pairs' and moving pairs' limits apart); every pair within its
// limit is listed with this step's answer, and most of the far pairs are not tested.
TEST(CollisionWorld, FarPairsAreNeitherTestedNorListedAndNoNearPairIsMissed) {
  WorldOptions o;
  o.box_margin = 0.004;  // boxes overlap up to 8 mm apart
  o.far_distance = 0.006;
  o.far_distance_static = 0.005;
  Scene s(o);
  std::vector<std::uint32_t> live;
  for (std::uint32_t b = 0; b < s.descs.size(); ++b)
    live.push_back(b);
  // a kinematic body that moves and turns too (a pair of two moving bodies)
  BodyDesc d;
  d.kind = BodyKind::kKinematic;
  d.primitives.push_back({shape(box(0.008)), Transform{}});
  const std::uint32_t kin = s.add(d, Pose{Vec3{0.05, 0.04, 0.05}, Quat{1, 0, 0, 0}});
  live.push_back(kin);
  std::size_t near = 0, found = 0, tested = 0, far = 0;
  for (int k = 0; k < 400; ++k) {
    const double t = k * 0.01;
    s.move(Pose{Vec3{0.06 + 0.05 * std::sin(t), 0.012 + 0.01 * std::cos(1.3 * t),
                     0.06 + 0.05 * std::cos(t)},
                glm::angleAxis(0.5 * t, glm::normalize(Vec3{1, 2, 3}))});
    if (k % 2 == 0) {
      const Pose X{Vec3{0.06 + 0.04 * std::cos(0.8 * t), 0.035, 0.06 + 0.03 * std::sin(1.1 * t)},
                   glm::angleAxis(0.7 * t, Vec3{0.0, 1.0, 0.0})};
      s.world.setPose(kin, X);
      s.poses[kin] = X;
    }
    const StepStats st = s.world.step();
    EXPECT_EQ(st.pairs_skipped, 0u);
    tested += st.pairs_tested;
    far += st.pairs_far;
    const auto want = expected(s, live, o.box_margin);
    found += want.size();
    std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>, double> got;
    for (const Contact& c : s.world.contacts()) {
      ASSERT_EQ(c.age, 0u) << "step " << k;  // nothing moved without a test of what it nears
      got[{c.body_a, c.body_b, c.prim_a, c.prim_b}] = c.distance;
    }
    for (const auto& [key, distance] : want) {
      const bool with_static = s.descs[std::get<0>(key)].kind == BodyKind::kStatic ||
                               s.descs[std::get<1>(key)].kind == BodyKind::kStatic;
      const double limit = with_static ? o.far_distance_static : o.far_distance;
      const auto it = got.find(key);
      if (distance <= limit) {
        ++near;
        ASSERT_NE(it, got.end()) << "step " << k << ": a pair " << distance << " apart missed";
      }
      if (it != got.end()) {
        ASSERT_NEAR(it->second, distance, 1e-12) << "step " << k;
      }
    }
    for (const auto& [key, distance] : got)
      ASSERT_TRUE(want.count(key)) << "step " << k;
  }
  std::printf(
      "[figures] world: %zu overlapping box pairs over 400 steps, %zu within the far distance, "
      "%zu tested, %zu left as far\n",
      found, near, tested, far);
  EXPECT_GT(near, 100u);
  EXPECT_GT(far, 0u);
  EXPECT_LT(5 * tested, 3 * found);  // 3 508 of 6 723 measured
}

// Two worlds of the same scene under two WorldOptions that must find the same pairs far and
// tested, stepped side by side over 600 steps of one motion: slow and fast stretches, turning, a
// jump (a teleport) at step 300, and from step 450 a turn in place (the bodies' travel is then
// all chord), a kinematic box moved every third step. Asserts each step's pairs tested, far and
// overlapping and the contacts equal (bit for bit); `each` sees both steps' stats (and the
// worlds) after the checks.
template <typename Each>
void stepSideBySide(const WorldOptions& oa, const WorldOptions& ob, Each each) {
  Scene s(oa), r(ob);
  BodyDesc d;
  d.kind = BodyKind::kKinematic;
  d.primitives.push_back({shape(box(0.008)), Transform{}});
  const std::uint32_t kin = s.add(d, Pose{Vec3{0.05, 0.04, 0.05}, Quat{1, 0, 0, 0}});
  ASSERT_EQ(r.add(d, Pose{Vec3{0.05, 0.04, 0.05}, Quat{1, 0, 0, 0}}), kin);
  for (int k = 0; k < 600; ++k) {
    const double t = k * 0.01;
    const double u = std::min(t, 4.5) + (k >= 300 ? 0.7 : 0.0) + 0.3 * std::sin(0.5 * t);
    const double turn = 0.5 * u + (k >= 450 ? 0.03 * (k - 450) : 0.0);
    const Pose X{Vec3{0.06 + 0.05 * std::sin(u), 0.012 + 0.01 * std::cos(1.3 * u),
                      0.06 + 0.05 * std::cos(u)},
                 glm::angleAxis(turn, glm::normalize(Vec3{1, 2, 3}))};
    s.move(X);
    r.move(X);
    if (k % 3 == 0) {
      const Pose K{Vec3{0.06 + 0.04 * std::cos(0.8 * t), 0.035, 0.06 + 0.03 * std::sin(1.1 * t)},
                   glm::angleAxis(0.7 * t, Vec3{0.0, 1.0, 0.0})};
      s.world.setPose(kin, K);
      r.world.setPose(kin, K);
    }
    const StepStats a = s.world.step();
    const StepStats b = r.world.step();
    ASSERT_EQ(a.pairs_tested, b.pairs_tested) << "step " << k;
    ASSERT_EQ(a.pairs_far, b.pairs_far) << "step " << k;
    ASSERT_EQ(a.pairs_overlapping, b.pairs_overlapping) << "step " << k;
    ASSERT_EQ(s.world.contacts().size(), r.world.contacts().size()) << "step " << k;
    for (std::size_t i = 0; i < s.world.contacts().size(); ++i) {
      const Contact& x = s.world.contacts()[i];
      const Contact& y = r.world.contacts()[i];
      ASSERT_EQ(x.body_a, y.body_a);
      ASSERT_EQ(x.body_b, y.body_b);
      ASSERT_EQ(x.prim_a, y.prim_a);
      ASSERT_EQ(x.prim_b, y.prim_b);
      ASSERT_EQ(std::memcmp(&x.distance, &y.distance, sizeof(double)), 0) << "step " << k;
      ASSERT_EQ(std::memcmp(&x.point_a, &y.point_a, sizeof(Vec3)), 0) << "step " << k;
    }
    each(k, a, b, s.world, r.world);
    if (::testing::Test::HasFatalFailure())
      return;
  }
}

// WorldOptions::far_by_travel: a pair kept far by its bodies' travel since it was found far is a
// pair the separating plane would find far too: the same pairs tested and far, the same
// contacts bit for bit, as a world that evaluates every plane every step; and many far pairs are
// kept so (this motion is fast for its margins: 1 370 of 3 981 measured).
TEST(CollisionWorld, FarPairsKeptByTravelAreThoseThePlaneFindsFar) {
  WorldOptions o;
  o.box_margin = 0.004;
  o.far_distance = 0.006;
  o.far_distance_static = 0.005;
  WorldOptions every = o;
  every.far_by_travel = false;
  std::size_t far = 0, kept = 0, kept_every = 0;
  stepSideBySide(o, every,
                 [&](int, const StepStats& a, const StepStats& b, const CollisionWorld&,
                     const CollisionWorld&) {
                   far += a.pairs_far;
                   kept += a.pairs_far_kept;
                   kept_every += b.pairs_far_kept;
                 });
  std::printf("[figures] world: %zu pairs far over 600 steps, %zu of them kept by travel\n", far,
              kept);
  EXPECT_EQ(kept_every, 0u);
  EXPECT_GT(far, 1000u);
  EXPECT_GT(kept, far / 4);
}

// WorldOptions::far_box_bound: a pair not yet tested that the boxes' bound of its centroids'
// plane finds far is a pair the plane's exact gap finds far, and one the bound no longer finds
// far is decided by the exact gap, as if it had been kept: the same pairs tested and far, the
// same contacts bit for bit and the same world state (writeState writes the exact gap), step by
// step, as a world that computes the exact gap at once; and the bound finds pairs far.
TEST(CollisionWorld, FarPairsByTheBoxesBoundAreThoseTheExactPlaneFindsFar) {
  struct Bytes : StateWriter {
    std::string out;
    void bytes(const void* data, std::size_t n) override {
      out.append(static_cast<const char*>(data), n);
    }
  };
  for (const bool travel : {true, false}) {
    WorldOptions o;
    o.box_margin = 0.004;
    o.far_distance = 0.006;
    o.far_distance_static = 0.005;
    o.far_by_travel = travel;
    WorldOptions exact = o;
    exact.far_box_bound = false;
    std::size_t far = 0, bound = 0, bound_exact = 0;
    stepSideBySide(o, exact,
                   [&](int k, const StepStats& a, const StepStats& b, const CollisionWorld& ws,
                       const CollisionWorld& wr) {
                     Bytes bs, br;
                     ws.writeState(bs);
                     wr.writeState(br);
                     ASSERT_EQ(bs.out, br.out) << "step " << k;
                     far += a.pairs_far;
                     bound += a.pairs_far_box_bound;
                     bound_exact += b.pairs_far_box_bound;
                   });
    std::printf(
        "[figures] world (far_by_travel %d): %zu pairs far over 600 steps, %zu of them by the "
        "boxes' bound\n",
        travel ? 1 : 0, far, bound);
    EXPECT_EQ(bound_exact, 0u);
    EXPECT_GT(far, 1000u);
    EXPECT_GT(bound, 50u);
  }
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
  // and the pairs' depth trackers answered most of it (taken from the pool on this thread)
  const CollisionWorld::DepthCounters& d = s.world.depthCounters();
  EXPECT_GT(d.certified, penetrating / 2);
  EXPECT_GT(d.taken, 0u);
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

// N boxes asleep on a floor (each on it and within the margin of its neighbours) and a probe
// moving in free space above them: a step looks at no pair, tests none, lists none and copies
// none, whatever N (200 or 2 000); the probe touching one box looks at its pairs only; the box
// woken is listed again with its pairs' answers kept from before it slept (not tested again: it
// did not move), and tested again once it moves. No allocation on the way.
TEST(CollisionWorld, SleepingBodiesCostAStepNothingWhateverTheirNumber) {
  struct Counts {
    std::uint32_t listed_awake = 0;
    std::uint32_t visited_free = 0, tested_free = 0, listed_free = 0;
    std::uint32_t visited_touch = 0, listed_touch = 0;
    std::uint64_t allocations = 0;
  };
  const auto run = [](int n) -> Counts {
    WorldOptions o;
    o.box_margin = 1e-3;
    o.skip_unmoved_pairs = true;
    CollisionWorld world(o);
    const double h = 0.01, pitch = 0.0205;  // 0.5 mm gaps: neighbours within the margin
    const int side = static_cast<int>(std::ceil(std::sqrt(n)));
    world.reserve(static_cast<std::size_t>(n) + 2, 8 * static_cast<std::size_t>(n) + 64);
    BodyDesc floor_desc;
    floor_desc.kind = BodyKind::kStatic;
    const double half = 0.5 * side * pitch + h;
    floor_desc.primitives.push_back({shape({{-half, -h, -half},
                                            {half, -h, -half},
                                            {-half, 0, -half},
                                            {half, 0, -half},
                                            {-half, -h, half},
                                            {half, -h, half},
                                            {-half, 0, half},
                                            {half, 0, half}}),
                                     Transform{}});
    world.addBody(floor_desc, Pose{Vec3{0.0}, Quat{1, 0, 0, 0}});
    BodyDesc box_desc;
    box_desc.kind = BodyKind::kDynamic;
    box_desc.primitives.push_back({shape(box(h)), Transform{}});
    std::vector<std::uint32_t> boxes;
    for (int i = 0; i < n; ++i) {
      const Vec3 c{(i % side - 0.5 * side) * pitch, h + 2e-4,
                   (static_cast<double>(i / side) - 0.5 * side) * pitch};
      boxes.push_back(world.addBody(box_desc, Pose{c, Quat{1, 0, 0, 0}}));
    }
    BodyDesc probe_desc;
    probe_desc.kind = BodyKind::kProbe;
    probe_desc.primitives.push_back({shape(box(0.005)), Transform{}});
    const std::uint32_t probe = world.addBody(probe_desc, Pose{Vec3{0, 0.2, 0}, Quat{1, 0, 0, 0}});
    Counts c;
    world.step();
    c.listed_awake = static_cast<std::uint32_t>(world.contacts().size());
    const std::uint32_t target = boxes[static_cast<std::size_t>(n / 2)];
    // the answers of the target's pairs before it sleeps
    std::map<std::uint32_t, double> before;
    for (const Contact& k : world.contacts()) {
      if (k.body_a == target || k.body_b == target)
        before[k.body_a + k.body_b - target] = k.distance;
    }
    EXPECT_GE(before.size(), 3u);  // the floor and neighbours
    for (const std::uint32_t b : boxes)
      world.setAsleep(b, true);
    const std::uint64_t alloc0 = testing_alloc::count();
    for (int k = 0; k < 100; ++k) {
      world.setPose(probe, Pose{Vec3{0.05 * std::sin(0.05 * k), 0.2, 0.05 * std::cos(0.05 * k)},
                                Quat{1, 0, 0, 0}});
      const StepStats st = world.step();
      c.visited_free = std::max(c.visited_free, st.pairs_visited);
      c.tested_free = std::max(c.tested_free, st.pairs_tested);
      c.listed_free = std::max(c.listed_free, static_cast<std::uint32_t>(world.contacts().size()));
    }
    // the probe comes down on the target box, 0.5 mm above it: its pairs only are looked at
    const Pose X_target = world.pose(target);
    world.setPose(probe,
                  Pose{X_target.translation + Vec3{0, h + 0.005 + 5e-4, 0}, Quat{1, 0, 0, 0}});
    const StepStats touch = world.step();
    c.allocations = testing_alloc::count() - alloc0;
    c.visited_touch = touch.pairs_visited;
    c.listed_touch = static_cast<std::uint32_t>(world.contacts().size());
    EXPECT_EQ(touch.pairs_tested, c.listed_touch);
    for (const Contact& k : world.contacts()) {
      EXPECT_TRUE(k.body_a == probe || k.body_b == probe);
      EXPECT_TRUE(k.answered);
    }
    // woken (relisted in the same tick): the target's pairs are listed with the answers they
    // had, none tested again (it did not move)
    const std::uint64_t alloc1 = testing_alloc::count();
    world.setAsleep(target, false);
    const StepStats relisted = world.relist();
    c.allocations += testing_alloc::count() - alloc1;
    EXPECT_EQ(relisted.pairs_tested, 0u);
    std::map<std::uint32_t, double> after;
    for (const Contact& k : world.contacts()) {
      if (k.body_a == target || k.body_b == target) {
        EXPECT_TRUE(k.answered);
        after[k.body_a + k.body_b - target] = k.distance;
      }
    }
    for (const auto& [other, d] : before) {
      EXPECT_EQ(after.count(other), 1u) << other;
      if (after.count(other) == 1) {
        EXPECT_EQ(after[other], d) << other;
      }
    }
    EXPECT_EQ(after.size(), before.size() + 1);  // and the probe
    // moved: every pair of it is tested again
    const std::uint64_t alloc2 = testing_alloc::count();
    world.setPose(target, Pose{X_target.translation + Vec3{1e-4, 0, 0}, Quat{1, 0, 0, 0}});
    const StepStats moved = world.step();
    c.allocations += testing_alloc::count() - alloc2;
    EXPECT_EQ(moved.pairs_tested, after.size());
    return c;
  };
  const Counts small = run(200), large = run(2000);
  EXPECT_GT(small.listed_awake, 600u);  // awake: every box's pairs listed
  EXPECT_GT(large.listed_awake, 6000u);
  for (const Counts& c : {small, large}) {
    EXPECT_EQ(c.visited_free, 0u);
    EXPECT_EQ(c.tested_free, 0u);
    EXPECT_EQ(c.listed_free, 0u);
    EXPECT_EQ(c.listed_touch, 1u);  // the probe and the box under it
    EXPECT_EQ(c.allocations, 0u);
  }
  EXPECT_EQ(small.visited_touch, large.visited_touch);
  EXPECT_EQ(large.visited_touch, 1u);
}

// The depth the world's pair gives, against the cold exact method (penetrationDepthExact with a
// fresh cache at the same relative pose): equal within 1e-12 of the pair's size, and its normal
// an MTD direction (the depth along it is the depth). Returns the failure, or "".
std::string checkDepth(const Polytope& a,
                       const Polytope& b,
                       const Pose& X_WA,
                       const Pose& X_WB,
                       const Contact& c) {
  const Transform TA = X_WA.toTransform(), TB = X_WB.toTransform();
  const geom::Mat3 Rt = glm::transpose(TA.R);
  const Transform X_AB{Rt * TB.R, Rt * (TB.t - TA.t)};  // as the world computes it
  DepthCache fresh;
  DepthScratch scratch;
  const DepthResult exact = penetrationDepthExact(a, b, X_AB, fresh, scratch);
  const double size = std::max(a.radius(), b.radius());
  if (!(std::abs(-c.distance - exact.depth) <= 1e-12 * size))
    return "depth " + std::to_string(-c.distance) + " != cold exact " + std::to_string(exact.depth);
  std::uint32_t ha = 0, hb = 0;
  const double along = depthAlong(a, b, X_AB, Rt * c.normal, ha, hb);
  if (!(std::abs(along - exact.depth) <= 1e-10 * size))
    return "the depth along the normal is " + std::to_string(along);
  return "";
}

// A world pair driven along a coherent penetrating path (B turning 0.1 degree and moving 0.1 %
// of the size per step, a 5 degree jump every 97 steps, coming apart and back now and then), in
// metres and millimetres, at 8 to 128 vertices and with boxes: on every tick the world's depth
// equals the cold exact method's, and most ticks are proven from the pair's tracker.
TEST(CollisionWorld, TrackedDepthEqualsTheColdExactMethodOnEveryTick) {
  std::size_t failures = 0;
  for (const double unit : {1.0, 1000.0}) {
    const auto cube = shape(box(0.012 * unit));
    for (const std::size_t n : {0u, 8u, 32u, 128u}) {  // 0: a cube and an 8-point hull
      const auto a = n == 0 ? cube
                            : shape(reference::ellipsoidPoints(n, 0.025 * unit, 0.018 * unit,
                                                               0.012 * unit, 11 + n));
      const auto b = shape(reference::ellipsoidPoints(n == 0 ? 8 : n, 0.025 * unit, 0.018 * unit,
                                                      0.012 * unit, 12 + n));
      WorldOptions o;
      o.box_margin = 0.001 * unit;
      CollisionWorld world(o);
      world.reserve(4, 16);
      BodyDesc da, db;
      da.kind = BodyKind::kStatic;
      da.primitives.push_back({a, Transform{}});
      db.kind = BodyKind::kProbe;
      db.primitives.push_back({b, Transform{}});
      const Pose X_WA{Vec3{0.1, -0.2, 0.3} * unit,
                      glm::angleAxis(0.4, glm::normalize(Vec3{1, 1, 0}))};
      world.addBody(da, X_WA);
      std::mt19937_64 rng(1800 + n);
      std::normal_distribution<double> g(0.0, 1.0);
      Quat q = reference::randomRotation(rng);
      Vec3 dir = glm::normalize(Vec3{g(rng), g(rng), g(rng)});
      // the centres' distance swings from 0.3 of the sum of the inscribed radii to the sum of
      // the radii: overlapping most of the time, apart now and then
      const double r_out = a->radius() + b->radius();
      double r_in = 0.0;
      for (const Polytope* p : {a.get(), b.get()}) {
        double r = 1e300;
        for (const auto& f : p->faces())
          r = std::min(r, f.offset);
        r_in += r;
      }
      Pose X_WB{X_WA.translation + dir * r_in, q};
      const std::uint32_t probe = world.addBody(db, X_WB);
      std::uint64_t penetrating = 0, apart = 0, certified = 0, fallbacks = 0, cold = 0,
                    untracked = 0;
      for (int k = 0; k < 1500; ++k) {
        const bool jump = k % 97 == 96;
        const double turn = (jump ? 5.0 : 0.1) * M_PI / 180.0;
        q = glm::normalize(glm::angleAxis(turn, glm::normalize(Vec3{g(rng), g(rng), g(rng)})) * q);
        dir = glm::normalize(dir + Vec3{g(rng), g(rng), g(rng)} * (jump ? 0.1 : 0.001));
        const double dist = 0.3 * r_in + (r_out - 0.3 * r_in) * (0.5 + 0.5 * std::sin(k * 0.01));
        X_WB = Pose{X_WA.translation + X_WA.rotation * (dir * dist), q};
        world.setPose(probe, X_WB);
        const StepStats st = world.step();
        certified += st.depth_certified;
        fallbacks += st.depth_fallbacks;
        cold += st.depth_cold;
        untracked += st.depth_untracked;
        ASSERT_LE(world.contacts().size(), 1u);
        if (world.contacts().empty() || world.contacts()[0].status != ContactStatus::kPenetrating) {
          ++apart;
          continue;
        }
        const Contact& c = world.contacts()[0];
        ++penetrating;
        const std::string err = checkDepth(*a, *b, X_WA, X_WB, c);
        if (!err.empty() && failures++ < 10) {
          ADD_FAILURE() << "unit " << unit << " N " << n << " tick " << k << ": " << err;
        }
      }
      std::printf(
          "[figures] world pair, N %zu, unit %g: %llu penetrating ticks (%llu not), %llu "
          "certified, %llu fallbacks, %llu cold, %llu untracked\n",
          n, unit, static_cast<unsigned long long>(penetrating),
          static_cast<unsigned long long>(apart), static_cast<unsigned long long>(certified),
          static_cast<unsigned long long>(fallbacks), static_cast<unsigned long long>(cold),
          static_cast<unsigned long long>(untracked));
      EXPECT_GT(penetrating, 300u);
      EXPECT_GT(apart, 50u);  // the pair came apart and back
      EXPECT_GT(certified, penetrating * 3 / 4) << "N " << n << " unit " << unit;
      EXPECT_EQ(untracked, 0u);
      // every depth was the tracker's: certified, or the full method in its place
      EXPECT_GE(certified + fallbacks + cold, penetrating);
    }
  }
  EXPECT_EQ(failures, 0u);
}

// A pair's tracker is given back when the pair ends (a body removed, the pair coming apart) and
// reset when taken: a pair made again, with the same shapes at the same pose (where the old
// tracked state would certify) or with another shape, starts cold; the answers stay exact.
TEST(CollisionWorld, APairMadeAgainTracksAfresh) {
  WorldOptions o;
  o.box_margin = 0.001;
  CollisionWorld world(o);
  world.reserve(8, 32);
  const auto slab = shape(box(0.02));
  const auto ell = shape(reference::ellipsoidPoints(32, 0.025, 0.018, 0.012, 5));
  const auto cube = shape(box(0.01));
  BodyDesc ds, dp;
  ds.kind = BodyKind::kStatic;
  ds.primitives.push_back({slab, Transform{}});
  dp.kind = BodyKind::kKinematic;
  dp.primitives.push_back({ell, Transform{}});
  const Pose X_WS{Vec3{0.0}, Quat{1, 0, 0, 0}};
  world.addBody(ds, X_WS);
  auto poseAt = [](int k) {
    return Pose{Vec3{0.001 * std::sin(0.1 * k), 0.03, 0.0},
                glm::angleAxis(0.3 + 0.002 * k, glm::normalize(Vec3{1, 2, 3}))};
  };
  std::uint32_t p = world.addBody(dp, poseAt(0));
  StepStats st;
  int k = 0;
  for (; k < 20; ++k) {
    world.setPose(p, poseAt(k));
    st = world.step();
  }
  ASSERT_EQ(world.contacts().size(), 1u);
  EXPECT_EQ(world.contacts()[0].status, ContactStatus::kPenetrating);
  EXPECT_EQ(st.depth_certified, 1u);  // tracked
  EXPECT_EQ(world.depthCounters().in_use, 1u);
  EXPECT_EQ(checkDepth(*slab, *ell, X_WS, poseAt(k - 1), world.contacts()[0]), "");

  // removed: its pair ends and gives the tracker back
  world.removeBody(p);
  st = world.step();
  EXPECT_EQ(world.contacts().size(), 0u);
  EXPECT_EQ(world.depthCounters().in_use, 0u);
  // the same body again, where it was: a new pair, which starts cold at its first test (no
  // tracker yet) and at its second (a tracker just taken: one kept with its old state would
  // certify here at once), then is tracked
  p = world.addBody(dp, poseAt(k - 1));
  for (int again = 0; again < 2; ++again) {
    st = world.step();
    ASSERT_EQ(world.contacts().size(), 1u);
    EXPECT_EQ(st.depth_cold, 1u) << again;
    EXPECT_EQ(st.depth_certified + st.depth_fallbacks, 0u) << again;
    EXPECT_EQ(checkDepth(*slab, *ell, X_WS, poseAt(k - 1), world.contacts()[0]), "");
    world.setPose(p, poseAt(k - 1));  // tested again, unmoved
  }
  world.setPose(p, poseAt(k));
  st = world.step();
  EXPECT_EQ(st.depth_certified, 1u);
  EXPECT_EQ(checkDepth(*slab, *ell, X_WS, poseAt(k), world.contacts()[0]), "");

  // another shape in the same body slot: cold again, exact
  world.removeBody(p);
  world.step();
  BodyDesc dc = dp;
  dc.primitives[0].shape = cube;
  const Pose X_WC{Vec3{0.002, 0.025, -0.001}, glm::angleAxis(0.2, glm::normalize(Vec3{3, 1, 2}))};
  const std::uint32_t c = world.addBody(dc, X_WC);
  EXPECT_EQ(c, p);  // the id (and the pair's slot) reused
  for (int again = 0; again < 2; ++again) {
    st = world.step();
    ASSERT_EQ(world.contacts().size(), 1u);
    EXPECT_EQ(st.depth_cold, 1u) << again;
    EXPECT_EQ(st.depth_certified + st.depth_fallbacks, 0u) << again;
    EXPECT_EQ(checkDepth(*slab, *cube, X_WS, X_WC, world.contacts()[0]), "");
    world.setPose(c, X_WC);
  }
  EXPECT_EQ(world.depthCounters().in_use, 1u);

  // apart: the tracker goes back to the pool; in again: cold, not a fallback
  double low = 1.0;
  for (const auto& v : cube->vertices())
    low = std::min(low, (X_WC.rotation * v.p).y);
  world.setPose(c, Pose{Vec3{0.0, 0.0205 - low, 0.0}, X_WC.rotation});  // 0.5 mm above
  world.step();
  ASSERT_EQ(world.contacts().size(), 1u);
  EXPECT_NE(world.contacts()[0].status, ContactStatus::kPenetrating);
  EXPECT_EQ(world.depthCounters().in_use, 0u);
  world.setPose(c, X_WC);
  st = world.step();
  EXPECT_EQ(st.depth_cold, 1u);
  EXPECT_EQ(st.depth_fallbacks, 0u);
  EXPECT_EQ(checkDepth(*slab, *cube, X_WS, X_WC, world.contacts()[0]), "");
}

// A resting stack of 100 boxes on a floor (every pair a tie: A's top face and B's bottom face
// parallel at one depth), each box jiggling as a solver's resting contact does (the overlap
// breathing by 1e-4 of the edge, sideways 1e-3, a turn about the vertical of 1e-4 rad), in metres
// and millimetres. The automatic pool holds two trackers per box, so every pair holds one; almost
// every tracked depth is certified (ties included); every depth equals the cold exact method's.
TEST(CollisionWorld, AStackOfTiedBoxesIsTrackedAndCertified) {
  std::size_t failures = 0;
  for (const double unit : {1.0, 1000.0}) {
    const double h = 0.01 * unit;  // half edge
    WorldOptions o;
    o.box_margin = 0.001 * unit;
    CollisionWorld world(o);
    world.reserve(128, 512);
    const auto cube = shape(box(h));
    std::vector<Vec3> slab = box(1.0);  // a floor 2 x 2 x 0.1 m (scaled), its top at z = 0
    for (Vec3& v : slab)
      v = Vec3{v.x, v.y, v.z > 0.0 ? 0.0 : -0.1} * unit;
    const auto floor_m = shape(slab);
    BodyDesc df, db;
    df.kind = BodyKind::kStatic;
    df.primitives.push_back({floor_m, Transform{}});
    db.kind = BodyKind::kDynamic;
    db.primitives.push_back({cube, Transform{}});
    world.addBody(df, Pose{Vec3{0.0}, Quat{1, 0, 0, 0}});
    constexpr int kBoxes = 100;
    const double overlap = 1e-3 * h;
    auto pose = [&](int i, int k) {
      const double t = static_cast<double>(k) + 7.0 * i;
      const double z = h + i * (2.0 * h - overlap) - overlap * (0.5 + 0.1 * std::sin(t * 0.3));
      return Pose{Vec3{1e-3 * h * std::sin(t * 0.17), 1e-3 * h * std::cos(t * 0.13), z},
                  glm::angleAxis(0.3 * i + 1e-4 * std::sin(t * 0.11), Vec3{0.0, 0.0, 1.0})};
    };
    std::vector<std::uint32_t> ids;
    std::vector<Pose> poses(kBoxes);
    for (int i = 0; i < kBoxes; ++i) {
      poses[static_cast<std::size_t>(i)] = pose(i, 0);
      ids.push_back(world.addBody(db, poses[static_cast<std::size_t>(i)]));
    }
    EXPECT_EQ(world.depthTrackers(), 2u * (kBoxes + 1));
    std::uint64_t certified = 0, fallbacks = 0, cold = 0, untracked = 0, penetrating = 0;
    for (int k = 1; k <= 60; ++k) {
      for (int i = 0; i < kBoxes; ++i) {
        poses[static_cast<std::size_t>(i)] = pose(i, k);
        world.setPose(ids[static_cast<std::size_t>(i)], poses[static_cast<std::size_t>(i)]);
      }
      const StepStats st = world.step();
      if (k > 2) {  // after each pair's first (cold) test and the one that takes its tracker
        certified += st.depth_certified;
        fallbacks += st.depth_fallbacks;
        cold += st.depth_cold;
        untracked += st.depth_untracked;
      }
      for (const Contact& c : world.contacts()) {
        if (c.status != ContactStatus::kPenetrating)
          continue;
        ++penetrating;
        const bool floor_pair = c.body_a == 0;
        const Polytope& a = floor_pair ? *floor_m : *cube;
        const Pose X_WA = floor_pair ? Pose{Vec3{0.0}, Quat{1, 0, 0, 0}} : poses[c.body_a - ids[0]];
        const std::string err = checkDepth(a, *cube, X_WA, poses[c.body_b - ids[0]], c);
        if (!err.empty() && failures++ < 10)
          ADD_FAILURE() << "unit " << unit << " tick " << k << " pair " << c.body_a << ","
                        << c.body_b << ": " << err;
      }
    }
    std::printf(
        "[figures] stack of %d boxes, unit %g: %llu certified, %llu fallbacks, %llu cold, %llu "
        "untracked (ticks 3-60)\n",
        kBoxes, unit, static_cast<unsigned long long>(certified),
        static_cast<unsigned long long>(fallbacks), static_cast<unsigned long long>(cold),
        static_cast<unsigned long long>(untracked));
    EXPECT_EQ(penetrating, 60u * kBoxes);
    // every penetrating pair held a tracker at once (the pool never ran dry: none stolen); the
    // untracked answers are those of pairs backed off after two fallbacks in a row
    EXPECT_EQ(world.depthCounters().peak, static_cast<std::uint32_t>(kBoxes));
    EXPECT_EQ(world.depthCounters().stolen, 0u);
    EXPECT_LE(untracked, 2 * fallbacks);
    // the tie grid's guard band is 4 % of its cells (a fallback there backs the pair off a tick)
    EXPECT_GE(certified, 58u * kBoxes * 85 / 100);
  }
  EXPECT_EQ(failures, 0u);
}

// The automatic pool: at least kMinAutoTrackers, two per tracked primitive, and no more than the
// byte budget holds (unless that is below the minimum); an explicit size is kept exactly.
TEST(CollisionWorld, TheAutomaticTrackerPoolFollowsTheScene) {
  const auto cube = shape(box(0.01));
  BodyDesc d;
  d.kind = BodyKind::kDynamic;
  d.primitives.push_back({cube, Transform{}});
  const std::size_t per = DepthTracker::bytesFor(cube->faces().size(), cube->edges().size());
  for (const std::size_t budget : {std::size_t{4} << 20, 100 * per, 10 * per}) {
    WorldOptions o;
    o.depth_tracker_bytes = budget;
    CollisionWorld world(o);
    world.reserve(256, 1024);
    for (int i = 0; i < 200; ++i) {
      world.addBody(d, Pose{Vec3{0.03 * i, 0.0, 0.0}, Quat{1, 0, 0, 0}});
      const std::size_t want = std::max<std::size_t>(
          WorldOptions::kMinAutoTrackers,
          std::min<std::size_t>(2 * static_cast<std::size_t>(i + 1), budget / per));
      ASSERT_EQ(world.depthTrackers(), want) << "budget " << budget << " bodies " << i + 1;
    }
    EXPECT_LE(world.depthTrackerBytes(), std::max(budget, WorldOptions::kMinAutoTrackers * per));
  }
  WorldOptions fixed;
  fixed.depth_trackers = 5;
  CollisionWorld world(fixed);
  for (int i = 0; i < 20; ++i)
    world.addBody(d, Pose{Vec3{0.03 * i, 0.0, 0.0}, Quat{1, 0, 0, 0}});
  EXPECT_EQ(world.depthTrackers(), 5u);
}

// A pool of one tracker: a penetrating pair tested every step keeps it (two pairs never take
// turns with it: the other is answered untracked); a pair not tested for two steps (unmoved,
// skip_unmoved_pairs) gives it up to a penetrating one. Every answer exact.
TEST(CollisionWorld, AFullTrackerPoolLendsOnlyIdleTrackers) {
  WorldOptions o;
  o.box_margin = 0.001;
  o.skip_unmoved_pairs = true;
  o.depth_trackers = 1;
  CollisionWorld world(o);
  world.reserve(8, 32);
  const auto floor = shape({{-0.1, -0.01, -0.1},
                            {0.1, -0.01, -0.1},
                            {-0.1, 0.0, -0.1},
                            {0.1, 0.0, -0.1},
                            {-0.1, -0.01, 0.1},
                            {0.1, -0.01, 0.1},
                            {-0.1, 0.0, 0.1},
                            {0.1, 0.0, 0.1}});
  const auto ell = shape(reference::ellipsoidPoints(32, 0.025, 0.018, 0.012, 7));
  BodyDesc df, dk;
  df.kind = BodyKind::kStatic;
  df.primitives.push_back({floor, Transform{}});
  dk.kind = BodyKind::kKinematic;
  dk.primitives.push_back({ell, Transform{}});
  const Pose X_WF{Vec3{0.0}, Quat{1, 0, 0, 0}};
  world.addBody(df, X_WF);
  auto poseAt = [](double x, int k) {
    return Pose{Vec3{x + 0.001 * std::sin(0.1 * k), 0.008, 0.0},
                glm::angleAxis(0.3 + 0.002 * k, glm::normalize(Vec3{1, 2, 3}))};
  };
  std::vector<Pose> at(4);
  at[1] = poseAt(-0.05, 0);
  const std::uint32_t k1 = world.addBody(dk, at[1]);
  std::size_t failures = 0;
  auto check = [&]() {
    for (const Contact& c : world.contacts()) {
      ASSERT_EQ(c.status, ContactStatus::kPenetrating);
      const std::string err = checkDepth(*floor, *ell, X_WF, at[c.body_b], c);
      if (!err.empty() && failures++ < 10)
        ADD_FAILURE() << "body " << c.body_b << ": " << err;
    }
  };
  StepStats st;
  for (int k = 0; k < 5; ++k) {
    at[k1] = poseAt(-0.05, k);
    world.setPose(k1, at[k1]);
    st = world.step();
    check();
  }
  EXPECT_EQ(st.depth_certified, 1u);
  // a second body, penetrating: no tracker free, and the first pair was tested this step
  at[2] = poseAt(0.05, 0);
  const std::uint32_t k2 = world.addBody(dk, at[2]);
  for (int k = 5; k < 25; ++k) {
    at[k1] = poseAt(-0.05, k);
    at[k2] = poseAt(0.05, k);
    world.setPose(k1, at[k1]);
    world.setPose(k2, at[k2]);
    st = world.step();
    check();
    EXPECT_EQ(st.depth_certified, 1u) << k;
    // the second pair's first test is cold; at every later one it wants a tracker and has none
    EXPECT_EQ(st.depth_untracked, k == 5 ? 0u : 1u) << k;
  }
  EXPECT_EQ(world.depthCounters().stolen, 0u);
  // the first stops (its pair is no longer tested): two steps later the second takes its tracker
  for (int k = 25; k < 30; ++k) {
    at[k2] = poseAt(0.05, k);
    world.setPose(k2, at[k2]);
    st = world.step();
    check();
  }
  EXPECT_EQ(world.depthCounters().stolen, 1u);
  EXPECT_EQ(world.depthCounters().in_use, 1u);
  EXPECT_EQ(st.depth_certified, 1u);
  EXPECT_EQ(st.depth_untracked, 0u);
  // the first moves again: answered untracked, exact
  at[k1] = poseAt(-0.05, 30);
  world.setPose(k1, at[k1]);
  st = world.step();
  check();
  EXPECT_EQ(st.depth_untracked, 1u);
  EXPECT_EQ(failures, 0u);
}

}  // namespace
}  // namespace hapticd::collision
