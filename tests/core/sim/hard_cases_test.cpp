// The hard cases of issue 5, tick by tick on simulated time: peg in hole with 0.1 mm clearance
// (insert with a wobble, jam, push, pull out), an edge sliding along an edge, a vertex driven
// into a three-wall corner, the same case in millimetres and metres, and a bitwise identical
// replay. Every tick keeps the invariants of harness.h; each test prints its figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <vector>

#include "core/sim/model.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

using scene::Motion;

scene::Body staticBox(const std::string& name,
                      const Vec3& centre,
                      const Vec3& half,
                      Quat q = Quat{1, 0, 0, 0}) {
  return makeBody(name, Motion::kStatic, Pose{centre, q}, {boxShape(half)});
}

// Peg 20 mm square, 60 mm long; hole 20.1 mm square (0.1 mm clearance), 40 mm deep.
constexpr double kPegHalf = 0.01, kPegHalfLength = 0.03, kHoleHalf = 0.01005, kWall = 0.01,
                 kDepth = 0.04;

std::shared_ptr<const scene::SceneModel> pegInHole() {
  scene::SceneModel s;
  s.name = "peg in hole";
  s.bodies.push_back(staticBox("floor", Vec3{0, -0.01, 0}, Vec3{0.1, 0.01, 0.1}));
  const double c = kHoleHalf + kWall / 2;
  s.bodies.push_back(
      staticBox("wall+x", Vec3{c, kDepth / 2, 0}, Vec3{kWall / 2, kDepth / 2, kHoleHalf + kWall}));
  s.bodies.push_back(
      staticBox("wall-x", Vec3{-c, kDepth / 2, 0}, Vec3{kWall / 2, kDepth / 2, kHoleHalf + kWall}));
  s.bodies.push_back(
      staticBox("wall+z", Vec3{0, kDepth / 2, c}, Vec3{kHoleHalf, kDepth / 2, kWall / 2}));
  s.bodies.push_back(
      staticBox("wall-z", Vec3{0, kDepth / 2, -c}, Vec3{kHoleHalf, kDepth / 2, kWall / 2}));
  auto peg = makeBody("peg", Motion::kKinematic, at(0, 0.08, 0),
                      {boxShape(Vec3{kPegHalf, kPegHalfLength, kPegHalf})});
  peg.probe = true;
  s.bodies.push_back(peg);
  return finish(s);
}

Path pegPath() {
  const Vec3 x{1, 0, 0}, z{0, 0, 1};
  const double top = kDepth + kPegHalfLength;  // peg origin when its end is at the mouth
  std::vector<Key> k;
  k.push_back({0.0, at(0, 0.08, 0)});
  k.push_back({1.0, at(0, top + 0.001, 0)});
  // in, aligned (a tilt of more than ~0.1 degree cannot enter a 0.05 mm clearance per side)
  const double inside = top - 0.006;
  k.push_back({1.5, at(0, inside, 0)});
  // on down with a wobble of the hand: +-0.5 degrees about x and z, alternating
  const double wob = 0.5 * std::numbers::pi / 180.0;
  const double bottom = kPegHalfLength + 0.005;
  for (int i = 1; i <= 6; ++i) {
    const double y = inside + (bottom - inside) * i / 6.0;
    const Quat q = axisAngle(i % 2 ? x : z, i % 4 < 2 ? wob : -wob);
    k.push_back({1.5 + 0.25 * i, at(0, y, 0, q)});
  }
  k.push_back({3.1, at(0, bottom, 0)});
  // jam: the hand tilts 2 degrees while the peg is deep in the hole
  k.push_back({3.5, at(0, bottom, 0, axisAngle(z, 2.0 * std::numbers::pi / 180.0))});
  k.push_back({3.7, at(0, bottom, 0, axisAngle(z, 2.0 * std::numbers::pi / 180.0))});
  k.push_back({4.0, at(0, bottom, 0)});
  // push: the hand 3 mm below the floor
  k.push_back({5.0, at(0, kPegHalfLength - 0.003, 0)});
  k.push_back({5.5, at(0, kPegHalfLength - 0.003, 0)});
  // pull out, back to the start
  k.push_back({8.0, at(0, 0.08, 0)});
  k.push_back({8.5, at(0, 0.08, 0)});
  return Path(k);
}

TEST(HardCases, PegInHoleWithATenthOfAMillimetreClearance) {
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(make(pegInHole(), o), o);
  double push_force = 0.0, max_lateral = 0.0, jam_torque = 0.0, lowest = 1.0, delta = 0.0;
  Vec3 end_gap{1.0};
  const Figures f = run.run(pegPath(), [&](const sim::TickInput& in, const sim::TickOutput& out) {
    const Vec3 p = out.X_W_proxy.translation;
    // the peg's lower end (the centre of its end face) must stay within the clearance
    const Vec3 end = p + out.X_W_proxy.rotation * Vec3{0, -kPegHalfLength, 0};
    if (end.y < kDepth)
      max_lateral = std::max({max_lateral, std::abs(end.x), std::abs(end.z)});
    lowest = std::min(lowest, p.y - kPegHalfLength);
    if (std::abs(in.t_s - 5.4) < 1e-9)
      push_force = out.force_W_n.y, delta = out.delta_m;
    if (std::abs(in.t_s - 3.6) < 1e-9)
      jam_torque = out.torque_W_nm.z;
    end_gap = p - in.X_W_device.translation;
    if (std::getenv("TRACE"))
      std::printf(
          "T %.3f dev %.5f %.5f %.5f prx %.5f %.5f %.5f F %.4f %.4f %.4f c %u pen %.3g d %.3g\n",
          in.t_s, 1e3 * in.X_W_device.translation.x, 1e3 * in.X_W_device.translation.y,
          1e3 * in.X_W_device.translation.z, 1e3 * p.x, 1e3 * p.y, 1e3 * p.z, out.force_W_n.x,
          out.force_W_n.y, out.force_W_n.z, out.contacts, out.max_penetration_m, 1e3 * out.delta_m);
  });
  f.print("peg in hole, 0.1 mm clearance");
  const double expect = o.response.stiffness_n_per_m * (delta + 0.003);
  std::printf(
      "  push force %.4f N (k_s (delta + D) = %.4f N) | jam torque %.5f N m | largest "
      "lateral offset of the end in the hole %.4g mm | lowest end %.4g mm | end offset %.3g m\n",
      push_force, expect, jam_torque, 1e3 * max_lateral, 1e3 * lowest, glm::length(end_gap));
  expectInvariants(f, o, 1e-3);
  EXPECT_NEAR(push_force, expect, 0.02 * expect);
  EXPECT_LT(jam_torque, 0.0);  // the walls resist the tilt
  EXPECT_LT(lowest, 1e-6);     // the peg reached the floor: the walls did not block it
  // its end stayed in the hole: the 0.05 mm clearance per side, plus the penetration bound
  EXPECT_LT(max_lateral, kHoleHalf - kPegHalf + 1e-3 * 0.01);
  EXPECT_LT(glm::length(end_gap), 1e-9);  // back out in free space the proxy is on the device
}

// A bar's lower edge (along x) on a ridge's upper edge (along z): crossed edges, one contact point
// with the vertical normal; the bar slides along its own edge, then along the ridge's.
TEST(HardCases, EdgeSlidingAlongAnEdge) {
  scene::SceneModel s;
  s.name = "edge on edge";
  const double ridge = 0.01 * std::sqrt(2.0);
  s.bodies.push_back(staticBox("ridge", Vec3{0, -ridge, 0}, Vec3{0.01, 0.01, 0.1},
                               axisAngle(Vec3{0, 0, 1}, std::numbers::pi / 4)));
  const Quat r45 = axisAngle(Vec3{1, 0, 0}, std::numbers::pi / 4);
  auto bar = makeBody("bar", Motion::kKinematic, at(0, ridge + 0.003, 0, r45),
                      {boxShape(Vec3{0.05, 0.01, 0.01})});
  bar.probe = true;
  s.bodies.push_back(bar);
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(make(finish(s), o), o);
  const double D = 0.002;
  const double y = ridge - D;
  Path path({{0.0, at(0, ridge + 0.003, 0, r45)},
             {0.5, at(-0.03, y, 0, r45)},
             {1.0, at(-0.03, y, 0, r45)},
             {3.0, at(0.03, y, 0, r45)},  // along the bar's edge
             {3.5, at(0.0, y, 0, r45)},
             {5.5, at(0.0, y, 0.05, r45)},  // along the ridge's edge
             {6.0, at(0.0, y, 0.05, r45)},
             {6.5, at(0.0, ridge + 0.003, 0.05, r45)},
             {7.5, at(0, ridge + 0.003, 0, r45)},
             {7.7, at(0, ridge + 0.003, 0, r45)}});
  double worst_ratio = 0.0, worst_err = 0.0, worst_balance = 0.0, fy = 0.0, ty = 0.0, fy_arm = 0.0;
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    const bool along_bar = in.t_s > 1.2 && in.t_s<3.0, along_ridge = in.t_s> 3.7 && in.t_s < 5.5;
    if (!along_bar && !along_ridge)
      return;
    worst_ratio =
        std::max(worst_ratio, std::hypot(out.force_W_n.x, out.force_W_n.z) / out.force_W_n.y);
    // the coupling balances the contact's penalty force (a quasi-static proxy)
    worst_balance = std::max(worst_balance, glm::length(out.force_W_n - out.contact_force_W_n) /
                                                glm::length(out.force_W_n));
    // with the contact under the bar's centre there is no lever arm: the felt force is the
    // paper's k_s (delta + D); elsewhere the proxy also turns, so the force is less
    if (std::abs(in.X_W_device.translation.x) < 1e-4 || along_ridge) {
      const double expect = o.response.stiffness_n_per_m * (out.delta_m + D);
      worst_err = std::max(worst_err, std::abs(out.force_W_n.y - expect) / expect);
      fy = out.force_W_n.y;
    }
    if (along_bar && std::abs(in.X_W_device.translation.x - 0.02) < 2e-5) {
      ty = out.torque_W_nm.z;
      fy_arm = out.force_W_n.y;
    }
  });
  f.print("edge sliding along an edge");
  std::printf(
      "  under the centre F_y %.4f N, worst |F_y - k_s (delta + D)| / k_s (delta + D) = %.3g; "
      "largest |F_xz|/F_y %.3g; worst |F - F_contact|/|F| %.3g; torque with the contact "
      "20 mm off centre %.4f N m\n",
      fy, worst_err, worst_ratio, worst_balance, ty);
  expectInvariants(f, o, 1e-3);
  EXPECT_LT(worst_err, 0.02);
  EXPECT_LT(worst_ratio, 0.02);  // frictionless: the ridge pushes up, not along or across
  EXPECT_LT(worst_balance, 0.02);
  // the contact 20 mm on the bar's -x side: T = R x F = (-0.02, 0, 0) x (0, F_y, 0) about -z
  EXPECT_NEAR(ty, -0.02 * fy_arm, 0.05 * 0.02 * fy_arm);
}

// A scene of three static walls meeting at the origin: the planes x = 0, y = 0 (the floor) and
// z = 0, free space x, y, z > 0.
scene::SceneModel threeWallCorner(const std::string& name) {
  scene::SceneModel s;
  s.name = name;
  s.bodies.push_back(staticBox("floor", Vec3{0.05, -0.05, 0.05}, Vec3{0.15, 0.05, 0.15}));
  s.bodies.push_back(staticBox("wall x", Vec3{-0.05, 0.1, 0.05}, Vec3{0.05, 0.1, 0.15}));
  s.bodies.push_back(staticBox("wall z", Vec3{0.1, 0.1, -0.05}, Vec3{0.1, 0.1, 0.05}));
  return s;
}

// A narrow pyramid whose apex points into the corner of three walls (x = 0, y = 0, z = 0 planes,
// free space x, y, z > 0): three vertex-face contacts at one point with three normals.
TEST(HardCases, VertexDrivenIntoAThreeWallCorner) {
  scene::SceneModel s = threeWallCorner("corner");
  const Vec3 d = glm::normalize(Vec3{1, 1, 1});
  const Vec3 u = glm::normalize(glm::cross(d, Vec3{0, 1, 0}));
  const Vec3 v = glm::cross(d, u);
  std::vector<Vec3> pts{Vec3{0.0}};
  for (int i = 0; i < 3; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 3.0;
    pts.push_back(0.04 * d + 0.008 * (std::cos(a) * u + std::sin(a) * v));
  }
  auto tip = makeBody("tip", Motion::kKinematic, at(0.02, 0.02, 0.02), {hullShape(pts)});
  tip.probe = true;
  s.bodies.push_back(tip);
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(make(finish(s), o), o);
  run.setNormal(d);
  const double D = 0.003;  // the hand 3 mm past the corner along the diagonal
  Path path({{0.0, at(0.02, 0.02, 0.02)},
             {1.0, Pose{-D * d, Quat{1, 0, 0, 0}}},
             {2.0, Pose{-D * d, Quat{1, 0, 0, 0}}},
             {3.0, at(0.02, 0.02, 0.02)},
             {3.2, at(0.02, 0.02, 0.02)}});
  Vec3 f_hold{0.0}, p_hold{0.0};
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    if (std::abs(in.t_s - 1.9) < 1e-9)
      f_hold = out.force_W_n, p_hold = out.X_W_proxy.translation;
  });
  f.print("vertex into a three-wall corner");
  // the proxy's apex rests where the three grown walls meet, (delta', delta', delta'): the force
  // is k_s times the device's distance from there, along the diagonal
  const double angle = std::acos(glm::dot(glm::normalize(f_hold), d));
  const double expect = o.response.stiffness_n_per_m * glm::length(p_hold + D * d) * 0.98;
  std::printf(
      "  held force %.4f N at %.3g rad from the diagonal; proxy apex at (%.4g, %.4g, %.4g) mm\n",
      glm::length(f_hold), angle, 1e3 * p_hold.x, 1e3 * p_hold.y, 1e3 * p_hold.z);
  expectInvariants(f, o, 1e-3);
  EXPECT_LT(angle, 1e-3);
  EXPECT_GT(glm::length(f_hold), expect);
  EXPECT_GT(p_hold.x, 0.0);  // the apex stays out of all three walls
  EXPECT_GT(p_hold.y, 0.0);
  EXPECT_GT(p_hold.z, 0.0);
}

// The degenerate twin: an axis-aligned cube's corner into the same corner, so that its three
// faces meet the three walls at once (three face-face contacts, the vertex and its edges in the
// walls' planes).
TEST(HardCases, CubeCornerDrivenIntoAThreeWallCorner) {
  scene::SceneModel s = threeWallCorner("cube corner");
  const double h = 0.01;
  auto cube = makeBody("cube", Motion::kKinematic, at(0.03, 0.03, 0.03), {boxShape(Vec3{h})});
  cube.probe = true;
  s.bodies.push_back(cube);
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(make(finish(s), o), o);
  const Vec3 d = glm::normalize(Vec3{1, 1, 1});
  run.setNormal(d);
  const double D = 0.002;  // each face 2 mm into its wall
  Path path({{0.0, at(0.03, 0.03, 0.03)},
             {1.0, at(h - D, h - D, h - D)},
             {2.0, at(h - D, h - D, h - D)},
             {3.0, at(0.03, 0.03, 0.03)},
             {3.2, at(0.03, 0.03, 0.03)}});
  Vec3 f_hold{0.0}, t_hold{0.0}, p_hold{0.0};
  double delta = 0.0;
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    if (std::abs(in.t_s - 1.9) < 1e-9) {
      f_hold = out.force_W_n, t_hold = out.torque_W_nm, p_hold = out.X_W_proxy.translation;
      delta = out.delta_m;
    }
  });
  f.print("cube corner into a three-wall corner");
  const double expect = o.response.stiffness_n_per_m * (delta + D);
  std::printf(
      "  held force (%.4f, %.4f, %.4f) N (k_s (delta + D) = %.4f N on each axis), torque "
      "%.2g N m\n",
      f_hold.x, f_hold.y, f_hold.z, expect, glm::length(t_hold));
  expectInvariants(f, o, 1e-3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(f_hold[k], expect, 0.02 * expect);  // each wall pushes along its own normal
    EXPECT_GT(p_hold[k], h - 1e-3);                 // and the cube stays out of it
  }
  EXPECT_LT(glm::length(t_hold), 1e-4);
}

// The face-on-face case built in metres and in millimetres gives the same forces (relative).
TEST(HardCases, MillimetresAndMetresGiveTheSameAnswer) {
  std::vector<Vec3> forces[2];
  for (int unit = 0; unit < 2; ++unit) {
    const double s = unit == 0 ? 1.0 : 1000.0;
    scene::SceneModel sc;
    sc.bodies.push_back(staticBox("floor", Vec3{0, -0.05, 0} * s, Vec3{0.2, 0.05, 0.2} * s));
    auto cube =
        makeBody("cube", Motion::kKinematic, at(0, 0.05 * s, 0), {boxShape(Vec3{0.01 * s})});
    cube.probe = true;
    sc.bodies.push_back(cube);
    // torques are in N per scene unit: N mm in the millimetre scene
    const sim::SimOptions o = scaledResponseOptions(s);
    Runner run(make(finish(sc), o), o);
    const Quat tilt = axisAngle(Vec3{1, 0, 1}, 0.01);
    Path path({{0.0, at(0, 0.05 * s, 0)},
               {1.0, at(0, 0.008 * s, 0)},
               {1.5, at(0.003 * s, 0.008 * s, 0, tilt)},
               {2.0, at(0, 0.05 * s, 0)}});
    run.run(path, [&](const sim::TickInput&, const sim::TickOutput& out) {
      forces[unit].push_back(out.force_W_n);
      forces[unit].push_back(out.torque_W_nm / s);
    });
  }
  ASSERT_EQ(forces[0].size(), forces[1].size());
  double worst = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < forces[0].size(); ++i) {
    worst = std::max(worst, glm::length(forces[0][i] - forces[1][i]));
    largest = std::max(largest, glm::length(forces[0][i]));
  }
  std::printf("[unit scale] largest force %.4f N, largest difference m vs mm %.3g N\n", largest,
              worst);
  EXPECT_GT(largest, 1.0);
  EXPECT_LT(worst, 1e-6 * largest);
}

// The same scene and pose sequence give a bitwise identical output sequence.
TEST(HardCases, ReplayIsBitwiseIdentical) {
  std::uint64_t h[2];
  for (int i = 0; i < 2; ++i) {
    sim::SimOptions o;
    Runner run(make(pegInHole(), o), o);
    h[i] = run.run(pegPath()).hash;
  }
  std::printf("[determinism] hash %016llx and %016llx\n", static_cast<unsigned long long>(h[0]),
              static_cast<unsigned long long>(h[1]));
  EXPECT_EQ(h[0], h[1]);
}

// A coarse convex piece, as `hapticctl import` makes of a curved model (a UV sphere of 8 segments
// and 4 rings, rings turned by half a segment: faces 30 to 45 degrees apart, some smoothed by the
// force shading, some creases), pressed by the config's 10 mm probe sphere with the device driven
// to the piece's centre, 10 cm inside, held there and lifted (the replayed touch of issue 16).
// The proxy must stay within the penetration allowance on every tick (docs/response.md "A
// sub-step too deep"): before 2026-12-04 a sub-step was too deep only when it went deeper by a
// twentieth of the allowance, and its third halving was kept whatever its depth, so the proxy
// crept in by just less than that each tick, up to 2.1 mm here (0.69 mm with shading off).
std::shared_ptr<const scene::SceneModel> coarseBall(double radius, int segments, int rings) {
  std::vector<Vec3> points;
  for (int i = 0; i <= rings; ++i) {
    const double theta = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * std::numbers::pi * (j + 0.5 * (i % 2)) / segments;
      points.push_back(radius * Vec3{std::sin(theta) * std::cos(phi), std::cos(theta),
                                     std::sin(theta) * std::sin(phi)});
    }
  }
  scene::SceneModel s;
  s.name = "coarse ball";
  s.bodies.push_back(makeBody("ball", Motion::kStatic, at(0, 0, 0), {hullShape(points)}));
  return finish(s);  // no probe body: the config's probe sphere
}

class ProxyAllowance : public ::testing::TestWithParam<double> {};

TEST_P(ProxyAllowance, ACoarsePiecePressedFromFarInsideIsNeverPenetratedPastIt) {
  sim::SimOptions o;
  o.response.crease_angle_deg = GetParam();
  const auto ball = coarseBall(0.1, 8, 4);
  // 1.5 max_force_n / (proxy_stiffness_ratio k_s): 0.5 mm at the defaults
  const double allowance = sim::SimModel::compile(ball, o).value()->penetration_allowance_m;
  ASSERT_NEAR(allowance, 5e-4, 1e-12);
  for (const Vec3 entry : {Vec3{-0.0225, 0, 0}, Vec3{0.0225, 0, 0.02}, Vec3{-0.0075, 0, 0.04}}) {
    SCOPED_TRACE(testing::Message() << "entry x " << entry.x << " z " << entry.z);
    const Pose above = at(entry.x, 0.15, entry.z), inside = at(entry.x, 0.0, entry.z);
    const Path path({{0.0, above}, {0.5, above}, {1.5, inside}, {2.0, inside}, {3.0, above}});
    Runner run(make(ball, o), o);
    double deepest = 0.0;
    std::uint32_t over = 0, pressed = 0;
    sim::TickOutput last;
    const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
      deepest = std::max(deepest, out.max_penetration_m);
      over += out.max_penetration_m > allowance ? 1u : 0u;
      // held 10 cm inside: pressed at the force limit
      pressed += in.t_s >= 1.5 && in.t_s <= 2.0 && out.contacts > 0 &&
                         glm::length(out.force_W_n) > 0.99 * o.response.max_force_n
                     ? 1u
                     : 0u;
      last = out;
    });
    EXPECT_TRUE(f.all_finite);
    EXPECT_LE(f.max_force_n, o.response.max_force_n * (1.0 + 1e-12));
    EXPECT_EQ(over, 0u) << "deepest " << deepest * 1e3 << " mm";
    EXPECT_LE(deepest, allowance);
    EXPECT_EQ(pressed, 501u);
    // lifted clear: the proxy is back at the device
    EXPECT_LT(glm::length(last.X_W_proxy.translation - above.translation), 1e-9);
  }
}

// force shading on (the default 40 degrees: the piece's 30-degree bends smoothed) and off
INSTANTIATE_TEST_SUITE_P(ShadingOnAndOff, ProxyAllowance, ::testing::Values(40.0, 0.0));

}  // namespace
}  // namespace hapticd::simtest
