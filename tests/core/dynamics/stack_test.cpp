// Stacks at every size (issue 17): four boxes of 5 mm, 2 cm, 10 cm and 1 m edges, placed touching
// or dropped from gaps of 1% of the edge, with friction 0.6 and without; towers of ten and a
// pyramid of twenty; the same stack in mm, m and km. Every bound is relative to the edge.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;
#ifdef HAPTICD_DYNAMICS_SHORT_RUNS
constexpr double kRunS = 3.0;  // sanitizer builds: shorter runs, the same bounds
constexpr double kLongRunS = 10.0;
constexpr bool kShortRuns = true;
#else
constexpr double kRunS = 10.0;
constexpr double kLongRunS = 60.0;
constexpr bool kShortRuns = false;
#endif

struct StackCase {
  double edge = 0.1;
  double gap_fraction = 0.0;  // between the boxes and above the floor, of the edge
  double mu = 0.6;
  double seconds = kRunS;
  double settle_s = 1.0;
  double unit = 1.0;  // every length (and gravity) times this: a scene in other units
  DynamicsOptions options;
};

struct StackResult {
  double drift = 0.0;     // worst corner drift after settling, of the edge
  double spin = 0.0;      // fastest turning of any box after settling (rad/s)
  double momentum = 0.0;  // largest |horizontal momentum| after settling / (total mass * edge/s)
  double lowest = 0.0;    // lowest box centre height / its rest height (fallen: < 1)
  std::uint64_t ticks_asleep = 0;
};

// the boxes' rest centres: a column (`tower` high) or a pyramid of rows of boxes side by side
std::vector<Vec3> column(int boxes, double edge, double gap) {
  std::vector<Vec3> c;
  c.reserve(static_cast<std::size_t>(boxes));
  for (int i = 0; i < boxes; ++i)
    c.push_back(Vec3{0, 0.5 * edge + gap + (edge + gap) * i, 0});
  return c;
}

std::vector<Vec3> pyramid(int base, double edge, double gap) {
  std::vector<Vec3> c;
  for (int row = 0; row < base; ++row) {
    const int n = base - row;
    for (int i = 0; i < n; ++i) {
      const double x = (i - 0.5 * (n - 1)) * (edge + gap);
      c.push_back(Vec3{x, 0.5 * edge + gap + (edge + gap) * row, 0});
    }
  }
  return c;
}

// Runs `rig` for `ticks`, the dynamic bodies 1..n cubes of half edge `half[b - 1]` whose centres
// rest at height `rest_y[b - 1]`: their rest poses taken at tick `settle`, then the worst corner
// drift (of `edge`), spin and horizontal momentum after it, and the lowest centre at the end
StackResult watchStack(Rig& rig,
                       const std::vector<double>& half,
                       const std::vector<double>& rest_y,
                       double edge,
                       int settle,
                       int ticks) {
  const std::size_t nb = half.size();
  std::vector<geom::Transform> rest(nb + 1);
  double mass = 0.0;
  for (std::uint32_t b = 1; b <= nb; ++b)
    mass += rig.scene->bodies[b].mass;
  StackResult r;
  r.lowest = 1e300;
  for (int k = 0; k < ticks; ++k) {
    rig.tick(kDt);
    if (k + 1 < settle)
      continue;
    Vec3 p{0.0};
    for (std::uint32_t b = 1; b <= nb; ++b) {
      const geom::Transform X = rig.dyn->pose(b).toTransform();
      if (k + 1 == settle) {
        rest[b] = X;
        continue;
      }
      p += rig.scene->bodies[b].mass * rig.dyn->linearVelocity(b);
      const double h = half[b - 1];
      for (int q = 0; q < 8; ++q) {
        const Vec3 corner{q & 1 ? h : -h, q & 2 ? h : -h, q & 4 ? h : -h};
        r.drift = std::max(r.drift, glm::length(X.apply(corner) - rest[b].apply(corner)) / edge);
      }
      r.spin = std::max(r.spin, glm::length(rig.dyn->angularVelocity(b)));
    }
    r.momentum = std::max(r.momentum, std::hypot(p.x, p.z) / (mass * edge));
  }
  for (std::uint32_t b = 1; b <= nb; ++b)
    r.lowest = std::min(r.lowest, rig.dyn->pose(b).translation.y / rest_y[b - 1]);
  r.ticks_asleep = rig.dyn->counters().ticks_asleep;
  return r;
}

// `centres_m`: where the boxes start; `rest_m`: where they rest (no gaps)
StackResult runStack(const StackCase& c,
                     const std::vector<Vec3>& centres_m,
                     const std::vector<Vec3>& rest_m) {
  const double u = c.unit;
  const double edge = c.edge * u;
  const double h = 0.5 * edge;
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81 * u, 0};
  s.materials.push_back(material(c.mu, 0.0));
  const double fh = 12.0 * edge;
  s.bodies.push_back(staticBody("floor", boxShape(Vec3{fh, h, fh}), at(Vec3{0, -h, 0}), 0));
  for (const Vec3& x : centres_m)
    s.bodies.push_back(dynamicBody("box", boxShape(Vec3{h}), at(x * u), 500.0 / (u * u * u), 0));
  Rig rig(std::move(s), c.options);
  std::vector<double> rest_y;
  for (const Vec3& x : rest_m)
    rest_y.push_back(x.y * u);
  return watchStack(rig, std::vector<double>(centres_m.size(), h), rest_y, edge,
                    static_cast<int>(c.settle_s / kDt),
                    static_cast<int>((c.settle_s + c.seconds) / kDt));
}

// a scene under 9.81 m/s2 (down y) with material 0 of friction `mu` (no restitution) and a
// static floor slab 24 edges wide and one thick, its top face through the origin, turned by R
SceneModel floorScene(double edge, double mu, const Quat& R = Quat{1, 0, 0, 0}) {
  const double h = 0.5 * edge;
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.materials.push_back(material(mu, 0.0));
  s.bodies.push_back(
      staticBody("floor", boxShape(Vec3{12 * edge, h, 12 * edge}), at(R * Vec3{0, -h, 0}, R), 0));
  return s;
}

// how far q turns (rad)
double turnAngle(const Quat& q) {
  return 2.0 * std::asin(std::min(1.0, glm::length(Vec3{q.x, q.y, q.z})));
}

DynamicsOptions awake() {
  DynamicsOptions o;
  o.sleep_time_s = 0.0;  // every tick solved: the resting contact itself is under test
  return o;
}

struct SizeCase {
  double edge;
  double gap;
  double mu;
};

std::string name(const SizeCase& c) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%g mm, gap %g%%, mu %g", c.edge * 1e3, c.gap * 100, c.mu);
  return buf;
}

// `boxes` boxes in a column (4: a stack, 10: a tower), settled for 1 s (a tower 2 s), then
// `seconds` simulated
void expectStands(int boxes, const SizeCase& sc, double seconds) {
  StackCase c;
  c.edge = sc.edge;
  c.gap_fraction = sc.gap;
  c.mu = sc.mu;
  c.seconds = seconds;
  c.settle_s = boxes > 4 ? 2.0 : 1.0;
  c.options = awake();
  const StackResult r =
      runStack(c, column(boxes, sc.edge, sc.gap * sc.edge), column(boxes, sc.edge, 0.0));
  std::printf("%d boxes, %s, %g s: drift %.3g edges, spin %.3g rad/s, momentum %.3g\n", boxes,
              name(sc).c_str(), seconds, r.drift, r.spin, r.momentum);
  EXPECT_LT(r.drift, 1e-3) << boxes << " boxes, " << name(sc) << ": a corner moved";
  // no spin-up: no box turns faster than 1e-3 rad/s
  EXPECT_LT(r.spin, 1e-3) << boxes << " boxes, " << name(sc);
  EXPECT_GT(r.lowest, 0.99) << boxes << " boxes, " << name(sc) << ": a box fell";
  if (sc.mu == 0.0) {
    // without friction every contact force of an aligned stack is vertical
    EXPECT_LT(r.momentum, 1e-12) << boxes << " boxes, " << name(sc)
                                 << ": horizontal momentum from nowhere";
  }
}

// The matrix: stacks of 4 and towers of 10, edges 5 mm, 2 cm, 10 cm and 1 m, placed
// touching and dropped from gaps of 1% of the edge, friction 0 and 0.6, each a minute simulated
// after settling (10 s in sanitizer builds): no corner moves more than 1e-3 of the edge, nothing
// turns, nothing falls, and without friction no horizontal momentum appears. (Before each flat
// contact's normal rows were solved together, frictionless stacks of small boxes drifted 1.0e-3
// to 0.26 of the edge in 10 s, 2 cm towers 1.0e-3 to 1.6e-3 and dropped 10 cm ones 5e-3: with
// their points solved one by one the boxes turned a little and traded sideways speed through the
// tilt, which nothing takes back without friction. Before a resting frictionless flat contact
// was levelled by the split impulses, the frictionless tower of ten 2 cm boxes dropped from 1%
// gaps drifted 2.8e-3 to 8.7e-3 of the edge in a minute: a shear growing from rounding, 1e-19 of
// the edge at 0.1 s, e-folding in 1.6 s; see correctBlock in core/dynamics/dynamics_solver.cpp.)
TEST(Stack, EveryStackAndTowerStandsForAMinute) {
  for (const int boxes : {4, 10}) {
    for (const double edge : {0.005, 0.02, 0.1, 1.0}) {
      for (const double gap : {0.0, 0.01}) {
        for (const double mu : {0.0, 0.6}) {
          const SizeCase sc{edge, gap, mu};
          expectStands(boxes, sc, kLongRunS);
        }
      }
    }
  }
}

// 6 + 5 + 4 + 3 + 2 = 20 boxes, 1% apart side by side, on each other's edges
TEST(Stack, PyramidOfTwentyStands) {
  for (const double edge : {0.02, 0.1}) {
    StackCase c;
    c.edge = edge;
    c.mu = 0.6;
    c.seconds = 0.5 * kRunS;
    c.settle_s = 2.0;
    c.options = awake();
    std::vector<Vec3> centres = pyramid(6, edge, 0.01 * edge), rest = pyramid(6, edge, 0.0);
    centres.pop_back();  // 21 without the top one
    rest.pop_back();
    ASSERT_EQ(centres.size(), 20u);
    const StackResult r = runStack(c, centres, rest);
    std::printf("pyramid of 20, %g mm: drift %.3g edges, spin %.3g rad/s\n", edge * 1e3, r.drift,
                r.spin);
    EXPECT_LT(r.drift, 1e-3) << edge;
    EXPECT_GT(r.lowest, 0.99) << edge;
  }
}

// The pyramid above without friction, dropped from gaps of 1% of the edge (issue 17, "F2"), at
// 5 mm, 2 cm, 10 cm and 1 m, settled 2 s, then a minute (10 s in sanitizer builds): every contact
// force of it is vertical at rest, so no corner may move more than 1e-3 of the edge, nothing may
// turn, and no horizontal momentum may appear.
TEST(Stack, FrictionlessDroppedPyramidStands) {
  for (const double edge : {0.005, 0.02, 0.1, 1.0}) {
    StackCase c;
    c.edge = edge;
    c.mu = 0.0;
    c.seconds = kLongRunS;
    c.settle_s = 2.0;
    c.options = awake();
    std::vector<Vec3> centres = pyramid(6, edge, 0.01 * edge), rest = pyramid(6, edge, 0.0);
    centres.pop_back();  // 21 without the top one
    rest.pop_back();
    const StackResult r = runStack(c, centres, rest);
    std::printf(
        "frictionless dropped pyramid of 20, %g mm: drift %.3g edges, spin %.3g rad/s, "
        "momentum %.3g\n",
        edge * 1e3, r.drift, r.spin, r.momentum);
    EXPECT_LT(r.drift, 1e-3) << edge;
    EXPECT_LT(r.spin, 1e-3) << edge;
    EXPECT_GT(r.lowest, 0.99) << edge;
    EXPECT_LT(r.momentum, 1e-12) << edge << ": horizontal momentum from nowhere";
  }
}

// A frictionless wall of cubes in running bond, six rows (rows of five; every other row four
// with a half-width brick at each end), placed touching and dropped from gaps of 1% of the edge,
// settled 2 s, then 10 s (3 s and not at 0.5 and 1 m in sanitizer builds): every contact force
// of it is vertical at rest.
// With the slop at 0.2% of a 2 m brick's size (3.5 mm) every contact sank toward it at the
// restitution threshold (39 mm/s) for some 80 ticks, the top row at 6 x that; the floor's
// contacts then stopped the whole wall within a few ticks, the bricks bridging two supports
// took the stop unevenly and turned at up to 0.04 rad/s, and without friction the tilted normals
// pushed them apart. Without the bound every case at 0.5-2 m fell (drift 0.5 to 35 edges, spin 0.05
// to 19 rad/s). Within the slop's bound of |g| (8 ms)^2 (DynamicsOptions::slop_settle_time_s) the
// wall settles from the bottom up in some 20 ticks. (Walls of 5 mm and 10 cm bricks, whose slop
// the bound does not change, fell in this rig too, placed touching as well: each contact's slop
// was its smaller body's, so the half bricks rested shallower in their supports than the cubes
// beside them, and a brick bridging the two tilted; with one slop per island they stand.) And the
// dropped wall with a cube of 1% of its edge on the floor beside it, at 5 mm and 10 cm: with the
// smallest size in the whole scene as the slop's length the 10 cm wall fell (3.2e3 edges); with
// the island's slop but the settling tolerance still the scene's, the 5 mm one (4.3e3 edges).
// Both the island's: the same figures as without the cube.
TEST(Stack, FrictionlessRunningBondWallStands) {
  struct WallCase {
    double edge;
    double gap;         // of the edge
    double bead = 0.0;  // a cube this fraction of the edge on the floor beside the wall (0: none)
  };
  for (const WallCase wc :
       {WallCase{0.005, 0.0}, WallCase{0.1, 0.0}, WallCase{0.5, 0.0}, WallCase{1.0, 0.0},
        WallCase{2.0, 0.0}, WallCase{0.005, 0.01}, WallCase{0.1, 0.01}, WallCase{0.5, 0.01},
        WallCase{1.0, 0.01}, WallCase{2.0, 0.01}, WallCase{0.005, 0.01, 0.01},
        WallCase{0.1, 0.01, 0.01}}) {
    if (kShortRuns && (wc.edge == 0.5 || wc.edge == 1.0))
      continue;  // sanitizer builds: the smallest and largest sizes only (the others: 80 s more)
    const double e = wc.edge, h = 0.5 * e, gap = wc.gap * e;
    SceneModel s = floorScene(e, 0.0);
    std::vector<double> half, rest_y;
    for (int row = 0; row < 6; ++row) {
      const double y = h + gap + (e + gap) * row;
      std::vector<std::pair<double, double>> bricks;  // centre x, half width
      if (row % 2 == 0) {
        for (int j = 0; j < 5; ++j)
          bricks.emplace_back((j - 2) * e, h);
      } else {
        bricks.emplace_back(-2.25 * e, 0.25 * e);
        for (int j = 0; j < 4; ++j)
          bricks.emplace_back((j - 1.5) * e, h);
        bricks.emplace_back(2.25 * e, 0.25 * e);
      }
      for (const auto& [x, hx] : bricks) {
        s.bodies.push_back(
            dynamicBody("brick", boxShape(Vec3{hx, h, h}), at(Vec3{x, y, 0}), 500.0, 0));
        half.push_back(h);  // the cube's corners: a half brick's drift measured at its hull's reach
        rest_y.push_back(h + e * row);
      }
    }
    if (wc.bead > 0.0) {  // not watched (after the wall's bodies)
      const double hb = 0.5 * wc.bead * e;
      s.bodies.push_back(
          dynamicBody("bead", boxShape(Vec3{hb}), at(Vec3{6.0 * e, hb, 2.0 * e}), 500.0, 0));
    }
    Rig rig(std::move(s), awake());
    const int settle = 2000;
    const StackResult r =
        watchStack(rig, half, rest_y, e, settle, settle + static_cast<int>(kRunS / kDt));
    std::printf(
        "frictionless running-bond wall, %g mm, gap %g%%, bead %g%%: drift %.3g edges, spin %.3g "
        "rad/s, momentum %.3g\n",
        e * 1e3, wc.gap * 100, wc.bead * 100, r.drift, r.spin, r.momentum);
    EXPECT_LT(r.drift, 1e-3) << e << " m, gap " << wc.gap << ", bead " << wc.bead;
    EXPECT_LT(r.spin, 1e-3) << e << " m, gap " << wc.gap << ", bead " << wc.bead;
    EXPECT_GT(r.lowest, 0.99) << e << " m, gap " << wc.gap << ", bead " << wc.bead;
    EXPECT_LT(r.momentum, 1e-9) << e << " m, gap " << wc.gap << ", bead " << wc.bead
                                << ": horizontal momentum from nowhere";
  }
}

// What the levelling may not hold: a frictionless box whose centre of mass is beyond its
// support's edge tips over it. A cube on a pedestal cube, placed touching and shifted 0.6 of the
// edge along x (its centre 0.1 edge beyond the pedestal's edge), at 5 mm, 2 cm and 1 m: within
// 1 s it has turned more than 0.3 rad and its centre has dropped. (The levelling sweep turns a
// body level on a support pressed at some of its points only when its centre of mass lies over
// its supports: a box bridging two others is pressed at their near edges, one tipping over an
// edge is pressed at that edge too.)
TEST(Stack, FrictionlessOverhangingBoxTipsOver) {
  for (const double edge : {0.005, 0.02, 1.0}) {
    const double h = 0.5 * edge;
    SceneModel s = floorScene(edge, 0.0);
    s.bodies.push_back(dynamicBody("pedestal", boxShape(Vec3{h}), at(Vec3{0, h, 0}), 500.0, 0));
    s.bodies.push_back(
        dynamicBody("box", boxShape(Vec3{h}), at(Vec3{0.6 * edge, 3 * h, 0}), 500.0, 0));
    Rig rig(std::move(s), awake());
    rig.run(1000);
    const Quat q = rig.dyn->pose(2).rotation;
    const double turned = turnAngle(q);
    const double y = rig.dyn->pose(2).translation.y / (3 * h);
    std::printf(
        "overhanging frictionless box, %g mm: turned %.3g rad, centre at %.3g of its "
        "height\n",
        edge * 1e3, turned, y);
    EXPECT_GT(turned, 0.3) << edge;
    EXPECT_LT(y, 0.95) << edge;
  }
}

// issue 17 F1: the held probe (a sphere, kinematic, infinite mass) pushes the top box of a
// frictionless tower of ten sideways, above its centre; the box below it must not move (a level
// frictionless interface passes no horizontal force). Its horizontal slide during the push, of the
// edge, for a push at 0.25 and at 0.1 edge/s (0.25 of the edge in all; the run ends with the
// push: alone the box would slide on, frictionless). Before the fix the pushed box, touching the
// held body, was not levelled (levelSweep), nor was its base once it slid: its tilt within the
// slop stood and its tilted face, the contact's normal, pushed the box below (0.25 / 0.1 edge/s:
// 9.2e-4 / 2.3e-3 of the edge at 5 mm, 6.9e-5 / 1.6e-4 at 2 cm, 3.5e-3 / 1.2e-7 at 1 m).
TEST(Stack, FrictionlessTowerTopPushedByTheProbeLeavesTheBoxBelow) {
  for (const double edge : {0.005, 0.02, 1.0}) {
    for (const double speed : {0.25, 0.1}) {
      const double h = 0.5 * edge;
      const int n = 10;
      SceneModel s = floorScene(edge, 0.0);
      for (const Vec3& x : column(n, edge, 0.0))
        s.bodies.push_back(dynamicBody("box", boxShape(Vec3{h}), at(x), 500.0, 0));
      // the probe: a sphere of radius 0.2 of the edge beside the top box, half way up its upper
      // half, 5% of the edge away from its side face
      const double r = 0.4 * h;
      const Vec3 start{h + r + 0.05 * edge, h + edge * (n - 1) + 0.5 * h, 0};
      Body probe = staticBody("probe", ellipsoidShape(Vec3{r}), at(start), 0);
      probe.motion = Motion::kKinematic;
      probe.probe = true;
      s.bodies.push_back(probe);
      Rig rig(std::move(s), awake());
      HeldInput in;
      in.mode = HeldMode::kKinematic;
      in.X_WB_target = at(start);
      for (int k = 0; k < 1000; ++k)  // settled a second
        rig.tick(kDt, &in);
      const auto second = static_cast<std::uint32_t>(n - 1);
      const auto top = static_cast<std::uint32_t>(n);
      std::vector<Vec3> rest;
      for (std::uint32_t b = 1; b <= top; ++b)
        rest.push_back(rig.dyn->pose(b).translation);
      const auto slid = [&](std::uint32_t b) {
        const Vec3 p = rig.dyn->pose(b).translation - rest[b - 1];
        return std::hypot(p.x, p.z) / edge;
      };
      const double v = speed * edge;
      const int ticks = static_cast<int>(std::lround(0.3 / speed / kDt));
      double below = 0.0, others = 0.0;
      for (int k = 0; k < ticks; ++k) {
        in.X_WB_target = at(start - Vec3{v * (k + 1) * kDt, 0, 0});
        rig.tick(kDt, &in);
        below = std::max(below, slid(second));
        for (std::uint32_t b = 1; b < second; ++b)
          others = std::max(others, slid(b));
      }
      const double moved = (rest[top - 1].x - rig.dyn->pose(top).translation.x) / edge;
      std::printf(
          "frictionless tower, top pushed by the probe at %g edge/s, %g mm: top moved %.3g, the "
          "box below slid %.3g, the others %.3g of the edge\n",
          speed, edge * 1e3, moved, below, others);
      EXPECT_GT(moved, 0.2) << edge << " " << speed;  // the probe did push the top box
      EXPECT_LT(below, 1e-3) << edge << " " << speed;
      EXPECT_LT(others, 1e-3) << edge << " " << speed;
    }
  }
}

// `sidewaysPush` (core/dynamics/dynamics_solver.cpp) lets a contact with an infinite-mass body
// whose normal is within 45 degrees of horizontal pin nothing in the levelling sweep; static walls
// take that path too. Frictionless boxes (one, and a tower of three) on a floor tilted 10 degrees
// down toward a static wall, dropped from 1% of the edge above the floor and above each other and
// 1% of the edge from the wall, at 5 mm, 2 cm and 1 m, against two walls:
// - square to the floor: every box slides into it and rests on it face to face (a flat block);
// - vertical: each box slides until its upper edge meets the wall, a line contact with a
//   horizontal normal (no flat block: the sidewaysPush rule), the tower stepping back 0.18 of the
//   edge per box; it stands (each box's centre of pressure at least 0.16 of the edge inside its
//   support; at 20 degrees a tower of three must topple, the middle box's 0.15 outside, and the
//   solver leaves it standing at 2 cm and 1 m: docs/dynamics.md, Limits).
// After settling 2 s, over 10 s: no corner moves more than 1e-3 of the edge, nothing turns faster
// than 1e-3 rad/s, nothing falls.
TEST(Stack, FrictionlessBoxesAgainstAStaticWallStand) {
  const double tilt = glm::radians(10.0);
  const Quat R = glm::angleAxis(tilt, Vec3{0, 0, 1});
  for (const bool vertical : {false, true}) {
    for (const int n : {1, 3}) {
      for (const double edge : {0.005, 0.02, 1.0}) {
        const double h = 0.5 * edge;
        const double gap = 0.01 * edge;
        // the floor's frame: u along the floor (down toward the wall: -u), v its normal
        const auto W = [&](double u, double v) { return R * Vec3{u, v, 0}; };
        // where box i's centre rests (u) at height v: the square wall's face is at u = 0; the
        // vertical wall's at x = 0, met by the box's upper edge at (u - h, v + h)
        const auto restU = [&](double v) { return vertical ? h + (v + h) * std::tan(tilt) : h; };
        SceneModel s = floorScene(edge, 0.0, R);
        std::vector<double> rest_y;
        for (int i = 0; i < n; ++i) {
          const double v = h + gap + (edge + gap) * i, v_rest = h + edge * i;
          const double u = restU(v) + (vertical ? gap / std::cos(tilt) : gap);
          s.bodies.push_back(dynamicBody("box", boxShape(Vec3{h}), at(W(u, v), R), 500.0, 0));
          rest_y.push_back(W(restU(v_rest), v_rest).y);
        }
        // the wall last: the boxes are bodies 1..n, as watchStack reads them
        if (vertical)
          s.bodies.push_back(staticBody("wall", boxShape(Vec3{h, 6 * edge, 12 * edge}),
                                        at(Vec3{-h, 4 * edge, 0}), 0));
        else
          s.bodies.push_back(staticBody("wall", boxShape(Vec3{h, 6 * edge, 12 * edge}),
                                        at(W(-h, 4 * edge), R), 0));
        Rig rig(std::move(s), awake());
        const StackResult r = watchStack(rig, std::vector<double>(static_cast<std::size_t>(n), h),
                                         rest_y, edge, 2000, 2000 + static_cast<int>(kRunS / kDt));
        std::printf(
            "%d frictionless box(es) on a 10 degree floor against a %s static wall, %g mm: drift "
            "%.3g edges, spin %.3g rad/s, lowest %.6f\n",
            n, vertical ? "vertical" : "square", edge * 1e3, r.drift, r.spin, r.lowest);
        EXPECT_LT(r.drift, 1e-3) << n << " " << vertical << " " << edge;
        EXPECT_LT(r.spin, 1e-3) << n << " " << vertical << " " << edge;
        EXPECT_GT(r.lowest, 0.99) << n << " " << vertical << " " << edge;
      }
    }
  }
}

// What the levelling may not hold, with a load: three boxes, each shifted along x by `step` of the
// edge over the one below, placed touching, with friction 0 and 0.6, at 5 mm, 2 cm and 1 m, for
// 2 s. At 0.4 each box's own centre of mass lies over the box below, but the top two's together
// lies 0.1 of the edge beyond the bottom box's edge: the staircase topples (the top box ends below
// half its height). At 0.3 theirs lies 0.05 inside: it stands (no box turns 1e-3 rad, the
// suite's corner drift of 1e-3 of the edge, or sinks below 0.99 of its height). (Before the
// levelling sweep weighed the load from above, it held the frictionless staircase of 0.4 level at 2
// cm and 1 m: a body pressed at some of its support's points only was levelled when its own centre
// of mass lay over its supports.)
TEST(Stack, FrictionlessStaircaseWhoseLoadOverhangsTopples) {
  for (const double mu : {0.0, 0.6}) {
    for (const double step : {0.3, 0.4}) {
      for (const double edge : {0.005, 0.02, 1.0}) {
        const double h = 0.5 * edge;
        SceneModel s = floorScene(edge, mu);
        for (int i = 0; i < 3; ++i)
          s.bodies.push_back(dynamicBody("box", boxShape(Vec3{h}),
                                         at(Vec3{step * edge * i, h + edge * i, 0}), 500.0, 0));
        Rig rig(std::move(s), awake());
        rig.run(2000);
        double turned = 0.0, lowest = 1e300;
        for (std::uint32_t b = 1; b <= 3; ++b) {
          const Quat q = rig.dyn->pose(b).rotation;
          turned = std::max(turned, turnAngle(q));
          lowest = std::min(lowest, rig.dyn->pose(b).translation.y / (h + edge * (b - 1)));
        }
        const double top = rig.dyn->pose(3).translation.y / (5 * h);
        std::printf(
            "staircase of 3, steps of %g edge, mu %g, %g mm: most turned %.3g rad, lowest %.4g, "
            "top at %.4g of its height\n",
            step, mu, edge * 1e3, turned, lowest, top);
        if (step == 0.4) {
          EXPECT_LT(top, 0.5) << mu << " " << edge << ": the overhanging load stood";
        } else {
          EXPECT_LT(turned, 1e-3) << mu << " " << edge;
          EXPECT_GT(lowest, 0.99) << mu << " " << edge;
        }
      }
    }
  }
}

// The load on a body with two supports: a plank (5 x 0.25 x 1 edges, 100 kg/m3) across two
// cubes whose centres are 2 edges apart (its support spans 3 edges), a heavy cube (2000 kg/m3)
// on it at 1.2 edges from the middle (their centre of mass 1.13 edges out: inside) and at 2.2
// (2.07 edges out: beyond the outer cube's edge at 1.5), friction 0 and 0.6, at 5 mm, 2 cm and
// 1 m, for 2 s. At 1.2 the plank stands (turns less than 1e-3 rad, the heavy cube stays above
// 0.99 of its height); at 2.2 it tips and the heavy cube falls below half its height. (A guard
// of the levelling's load rule: it passed with the body's own centre of mass alone as well.)
TEST(Stack, PlankOnTwoCubesTipsOnlyWhenItsLoadIsBeyondThem) {
  for (const double mu : {0.0, 0.6}) {
    for (const double at_x : {1.2, 2.2}) {
      for (const double edge : {0.005, 0.02, 1.0}) {
        const double h = 0.5 * edge;
        SceneModel s = floorScene(edge, mu);
        for (const double x : {-edge, edge})
          s.bodies.push_back(dynamicBody("cube", boxShape(Vec3{h}), at(Vec3{x, h, 0}), 500.0, 0));
        s.bodies.push_back(dynamicBody("plank", boxShape(Vec3{5 * h, 0.25 * h, h}),
                                       at(Vec3{0, edge + 0.25 * h, 0}), 100.0, 0));
        const double rest_y = edge + 0.5 * h + h;
        s.bodies.push_back(
            dynamicBody("heavy", boxShape(Vec3{h}), at(Vec3{at_x * edge, rest_y, 0}), 2000.0, 0));
        Rig rig(std::move(s), awake());
        rig.run(2000);
        const Quat q = rig.dyn->pose(3).rotation;
        const double turned = turnAngle(q);
        const double y = rig.dyn->pose(4).translation.y / rest_y;
        std::printf(
            "plank on two cubes, heavy cube at %g edges, mu %g, %g mm: plank turned %.3g rad, "
            "heavy cube at %.4g of its height\n",
            at_x, mu, edge * 1e3, turned, y);
        if (at_x > 2.0) {
          EXPECT_LT(y, 0.5) << mu << " " << edge << ": the overhanging load stood";
        } else {
          EXPECT_LT(turned, 1e-3) << mu << " " << edge;
          EXPECT_GT(y, 0.99) << mu << " " << edge;
        }
      }
    }
  }
}

// the same stack in mm, m and km (lengths and gravity scaled alike): the same relative answer
TEST(Stack, SameRelativeAnswerInMillimetresMetresAndKilometres) {
  std::vector<double> height;
  for (const double unit : {1e-3, 1.0, 1e3}) {
    StackCase c;
    c.edge = 0.1;
    c.gap_fraction = 0.01;
    c.unit = unit;
    c.seconds = 0.5;
    c.settle_s = 0.5;
    c.options = awake();
    const StackResult r = runStack(c, column(4, c.edge, 0.01 * c.edge), column(4, c.edge, 0.0));
    height.push_back(r.lowest);
    EXPECT_LT(r.drift, 1e-3) << unit;
  }
  std::printf("lowest box / rest height in mm, m, km: %.15f %.15f %.15f\n", height[0], height[1],
              height[2]);
  EXPECT_NEAR(height[0], height[1], 1e-12);
  // (with the manifold's order of points, km differed by 6e-6 of the height; in the geometry's
  // order, 4e-14 measured)
  EXPECT_NEAR(height[2], height[1], 1e-5);
}

}  // namespace
}  // namespace hapticd::dynamics::testing

namespace hapticd::dynamics::testing {
namespace {

// two stacks apart: each is an island and sleeps; a push wakes only its own stack, a box
// dropped on the other wakes that one
TEST(Islands, EachStackSleepsAndWakesAlone) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.materials.push_back(material(0.6, 0.0));
  const double h = 0.05;
  s.bodies.push_back(staticBody("floor", boxShape(Vec3{2, h, 2}), at(Vec3{0, -h, 0}), 0));
  for (const double x : {-0.5, 0.5}) {
    for (int i = 0; i < 3; ++i)
      s.bodies.push_back(
          dynamicBody("box", boxShape(Vec3{h}), at(Vec3{x, h + 2 * h * i, 0}), 500.0, 0));
  }
  // a box held high above the right stack by a wrench equal to its weight (at rest: it sleeps
  // too), released later
  s.bodies.push_back(dynamicBody("dropped", boxShape(Vec3{h}), at(Vec3{0.5, 1.0, 0}), 500.0, 0));
  Rig rig(std::move(s));
  const std::uint32_t dropped = 7;
  const double m = rig.scene->bodies[dropped].mass;
  rig.dyn->setExternalWrench(dropped, Vec3{0, 9.81 * m, 0}, Vec3{0});
  rig.run(1500);
  for (std::uint32_t b = 1; b <= 7; ++b)
    EXPECT_TRUE(rig.dyn->asleep(b)) << b;
  // the left stack is pushed: it wakes, the right one sleeps on
  const Pose right = rig.dyn->pose(4);
  rig.dyn->setExternalWrench(1, Vec3{0.5 * 0.6 * 3 * m * 9.81, 0, 0}, Vec3{0});
  rig.tick();
  for (std::uint32_t b = 1; b <= 3; ++b)
    EXPECT_FALSE(rig.dyn->asleep(b)) << b;
  for (std::uint32_t b = 4; b <= 6; ++b)
    EXPECT_TRUE(rig.dyn->asleep(b)) << b;
  rig.dyn->setExternalWrench(1, Vec3{0}, Vec3{0});
  // the dropped box falls onto the right stack and wakes it
  rig.dyn->setExternalWrench(dropped, Vec3{0}, Vec3{0});
  bool woke = false;
  for (int k = 0; k < 600 && !woke; ++k) {
    rig.tick();
    woke = !rig.dyn->asleep(6);
    if (!woke) {
      EXPECT_EQ(rig.dyn->pose(4).translation, right.translation) << "asleep: not moved";
    }
  }
  EXPECT_TRUE(woke) << "the falling box woke the stack it hit";
  // everything rests again, and the scene sleeps
  std::uint32_t flags = 0;
  for (int k = 0; k < 3000; ++k)
    flags = rig.tick().flags;
  EXPECT_NE(flags & kStepAsleep, 0u);
  EXPECT_GT(rig.dyn->pose(dropped).translation.y, 6 * h - 1e-3) << "it rests on the stack";
}

}  // namespace
}  // namespace hapticd::dynamics::testing

namespace hapticd::dynamics::testing {
namespace {

// Boxes turned about the vertical against the box below (issue 17, checked outside the suite):
// two equal squares turned by 22.5 or 45 degrees touch in an octagon, eight equally deep
// corners of which the solver keeps four. Which four was rounding's: a corner kept last tick
// could give way to a new one far from it, which had no warm start; the solve, stopped after its
// 12 iterations, then kicked the stack (a tower of six 5 mm boxes turned by 22.5 degrees each,
// friction 0.5, drifted 1.9e-2 of the edge and turned at 0.3 rad/s at 2.13 s; turned 45 degrees
// without friction it was thrown apart). Six boxes each turned `step_deg` more than the one below
// (45: every other one turned), placed touching, settled 2 s, then 20 s (3.3 s in sanitizer
// builds).
TEST(Stack, TwistedBoxesStand) {
  for (const double step_deg : {22.5, 45.0}) {
    for (const double edge : {0.005, 0.02, 0.1}) {
      for (const double mu : {0.0, 0.5}) {
        const double h = 0.5 * edge;
        SceneModel s = floorScene(edge, mu);
        for (int i = 0; i < 6; ++i) {
          const double turn = step_deg == 45.0 ? (i % 2) * 45.0 : i * step_deg;
          const Quat q = glm::angleAxis(turn * std::numbers::pi / 180.0, Vec3{0, 1, 0});
          s.bodies.push_back(
              dynamicBody("box", boxShape(Vec3{h}), at(Vec3{0, h + edge * i, 0}, q), 500.0, 0));
        }
        Rig rig(std::move(s), awake());
        const int settle = 2000;
        const int n = settle + static_cast<int>(kLongRunS / 3.0 / kDt);  // 20 s (3.3 s)
        std::vector<geom::Transform> rest(7);
        double drift = 0.0, spin = 0.0, lowest = 1e300;
        for (int k = 0; k < n; ++k) {
          rig.tick(kDt);
          for (std::uint32_t b = 1; b <= 6; ++b) {
            const geom::Transform X = rig.dyn->pose(b).toTransform();
            if (k + 1 == settle)
              rest[b] = X;
            if (k + 1 <= settle)
              continue;
            for (int c = 0; c < 8; ++c) {
              const Vec3 corner{c & 1 ? h : -h, c & 2 ? h : -h, c & 4 ? h : -h};
              drift = std::max(drift, glm::length(X.apply(corner) - rest[b].apply(corner)) / edge);
            }
            spin = std::max(spin, glm::length(rig.dyn->angularVelocity(b)));
          }
        }
        for (std::uint32_t b = 1; b <= 6; ++b)
          lowest = std::min(lowest, rig.dyn->pose(b).translation.y / (h + edge * (b - 1)));
        std::printf("six boxes turned %g deg, %g mm, mu %g: drift %.3g edges, spin %.3g rad/s\n",
                    step_deg, edge * 1e3, mu, drift, spin);
        EXPECT_LT(drift, 1e-3) << step_deg << " deg, " << edge << " m, mu " << mu;
        EXPECT_LT(spin, 1e-3) << step_deg << " deg, " << edge << " m, mu " << mu;
        EXPECT_GT(lowest, 0.99) << step_deg << " deg, " << edge << " m, mu " << mu;
      }
    }
  }
}

}  // namespace
}  // namespace hapticd::dynamics::testing

namespace hapticd::dynamics::testing {
namespace {

// Towers the fixed iteration counts could not hold at small sizes (issue 17, checked outside
// the suite; the settling iterations of DynamicsOptions::velocity_iterations_max and
// position_iterations_max hold them). Each body: a box of `size` edges, at `x` and `y` edges
// (the centre), turned 45 degrees about the vertical or not, of `density`.
struct TowerBox {
  double size;
  double x;
  double y;
  bool turned;
  double density;
};

struct TowerCase {
  const char* name;
  std::vector<TowerBox> boxes;
  double edge;
  double mu;
};

// placed touching, settled `settle_s` (2 s), then `seconds` (20 s, 3.3 s in sanitizer builds): no
// corner moves more than 1e-3 of the edge, nothing turns faster than 1e-3 rad/s, no box falls below
// 0.99 of its height, and without friction no horizontal momentum appears
void expectTowerStands(const TowerCase& tc,
                       double seconds = kLongRunS / 3.0,
                       double settle_s = 2.0) {
  const double e = tc.edge;
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.materials.push_back(material(tc.mu, 0.0));
  s.bodies.push_back(
      staticBody("floor", boxShape(Vec3{12 * e, 0.5 * e, 12 * e}), at(Vec3{0, -0.5 * e, 0}), 0));
  const Quat q45 = glm::angleAxis(0.25 * std::numbers::pi, Vec3{0, 1, 0});
  for (const TowerBox& b : tc.boxes) {
    s.bodies.push_back(dynamicBody("box", boxShape(Vec3{0.5 * b.size * e}),
                                   at(Vec3{b.x * e, b.y * e, 0}, b.turned ? q45 : Quat{1, 0, 0, 0}),
                                   b.density, 0));
  }
  Rig rig(std::move(s), awake());
  std::vector<double> half, rest_y;
  for (const TowerBox& b : tc.boxes) {
    half.push_back(0.5 * b.size * e);
    rest_y.push_back(b.y * e);
  }
  const int settle = static_cast<int>(settle_s / kDt);
  const StackResult r =
      watchStack(rig, half, rest_y, e, settle, settle + static_cast<int>(seconds / kDt));
  const double drift = r.drift, spin = r.spin, momentum = r.momentum, lowest = r.lowest;
  std::printf("%s, %g mm, mu %g, %g s: drift %.3g edges, spin %.3g rad/s, momentum %.3g\n", tc.name,
              e * 1e3, tc.mu, seconds, drift, spin, momentum);
  EXPECT_LT(drift, 1e-3) << tc.name << ", " << e << " m, mu " << tc.mu;
  EXPECT_LT(spin, 1e-3) << tc.name << ", " << e << " m, mu " << tc.mu;
  EXPECT_GT(lowest, 0.99) << tc.name << ", " << e << " m, mu " << tc.mu;
  if (tc.mu == 0.0) {
    EXPECT_LT(momentum, 1e-9) << tc.name << ", " << e << " m: horizontal momentum from nowhere";
  }
}

// A staircase of ten cubes, each 8% of the edge further along x than the one below (the load of
// the boxes above stays 0.1 edge inside every support), friction 0.6: its first ticks, with no
// warm start and a tick of gravity to stop through ten off-centre contacts, left an error of
// order g dt after 12 iterations, large against a 5 mm box. Without the settling iterations
// (velocity_iterations_max 0) it fell at 5 mm (thrown 8.7e3 edges), leaned and drifted 8.0e-3
// of the edge at 2 cm and 6.8e-4 at 10 cm, turning at 2.3e-3 rad/s. Two light cubes (100
// kg/m3, the upper one turned 45 degrees) under a heavy one (10 000 kg/m3): without friction,
// at 10 cm, the levelling of 6 split-impulse iterations a tick grew a shear from rounding that
// threw the tower apart (position_iterations_max 0: 1.3e3 edges); with friction at 2 cm it
// stands either way.
TEST(Stack, OffsetAndMassGradedTowersStand) {
  std::vector<TowerBox> stair;
  for (int i = 0; i < 10; ++i)
    stair.push_back({1.0, 0.08 * i, 0.5 + i, false, 500.0});
  const std::vector<TowerBox> graded = {
      {1.0, 0, 0.5, false, 100.0}, {1.0, 0, 1.5, true, 100.0}, {1.0, 0, 2.5, false, 10000.0}};
  for (const double edge : {0.005, 0.02, 0.1})
    expectTowerStands({"staircase of ten, 8% steps", stair, edge, 0.6});
  expectTowerStands({"two light boxes under a heavy one", graded, 0.02, 0.6});
  expectTowerStands({"two light boxes under a heavy one", graded, 0.1, 0.0});
}

// The staircase above without friction, at 5 mm, 1 m and 1 km (gravity 9.81 m/s2 at every
// size), placed touching, settled 2 s (the 1 km one 10 s: under the same gravity it sinks into
// its slop, 1.7 m a contact, for about 8 s), then a minute (10 s in sanitizer builds). Every
// contact force of it is vertical at rest, so nothing may move and no horizontal momentum may
// appear. Before the levelling sweep (levelSweep in core/dynamics/dynamics_solver.cpp) it was
// thrown apart at 5 mm (2.6e4 edges) and drifted 0.019 of the edge at 1 m, 0.0030 at 1 km.
TEST(Stack, FrictionlessStaircaseStands) {
  std::vector<TowerBox> stair;
  for (int i = 0; i < 10; ++i)
    stair.push_back({1.0, 0.08 * i, 0.5 + i, false, 500.0});
  for (const double edge : {0.005, 1.0, 1000.0}) {
    expectTowerStands({"frictionless staircase of ten, 8% steps", stair, edge, 0.0}, kLongRunS,
                      edge > 10.0 ? 10.0 : 2.0);
  }
}

// Two light 5 mm cubes under one 100 times denser, friction 0.6 (the 2 cm one is above), placed
// touching, settled 2 s, then a minute. The solve stopped early (2 iterations a tick) on
// corrections that underestimate the error left by the mass ratio, and the top-heavy tower leant
// over from rounding (e-folding 60 ms) and fell at 1.3 s (the heavy box's centre ended at 0.2 of
// its height); the early stop's tolerance is now divided by the mass ratio.
TEST(Stack, HeavyBoxOnTwoLightSmallOnesStands) {
  const std::vector<TowerBox> graded = {
      {1.0, 0, 0.5, false, 100.0}, {1.0, 0, 1.5, true, 100.0}, {1.0, 0, 2.5, false, 10000.0}};
  expectTowerStands({"two light boxes under a heavy one", graded, 0.005, 0.6}, kLongRunS);
}

// Ten cubes alternating 100 and 10 000 kg/m3 (light at the bottom), friction 0.6, placed
// touching (the top one 1e-9 of the edge off centre: the rig is otherwise exactly symmetric and
// nothing seeds a lean), settled 2 s, then a minute, at 5 mm, 2 cm, 10 cm and 1 m (issue 17;
// a case first measured through the daemon). Without the settling rules for unequal masses (the
// velocity solve's settling not stopped by a residual that does not fall, every split-impulse
// iteration run) it measured, 2026-12-05: thrown apart at 5 mm (9.8 edges) and 2 cm (2e4
// edges), at 10 cm a jolt of 1.42e-3 rad/s; the velocity solve stopped unconverged at a
// mass ratio of 100 and the tower leant over from rounding.
TEST(Stack, AlternatingHeavyLightTowerStands) {
  std::vector<TowerBox> alt;
  for (int i = 0; i < 10; ++i)
    alt.push_back({1.0, 0.0, 0.5 + i, false, i % 2 == 0 ? 100.0 : 10000.0});
  alt.back().x = 1e-9;
  for (const double edge : {0.005, 0.02, 0.1, 1.0})
    expectTowerStands({"ten cubes alternating 1:100", alt, edge, 0.6}, kLongRunS);
}

}  // namespace
}  // namespace hapticd::dynamics::testing
