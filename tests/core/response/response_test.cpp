// The parts of the haptic response one by one: the paper's step limit on vectors (§5.3), the one
// output stage, the virtual coupling's passivity at 1 kHz, the proxy's implicit step, penalty
// wrenches (§5.1-5.2), force shading (§5.3) and face-face contact regions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "core/response/coupling.h"
#include "core/response/face_contact.h"
#include "core/response/output_stage.h"
#include "core/response/proxy.h"
#include "core/response/shading.h"
#include "tests/core/geometry_helpers.h"

namespace hapticd::response {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(LimitStep, FollowsThePapersThreeCasesOnTheDifference) {
  bool lim = false;
  const Vec3 f0{1.0, 0.0, 0.0};
  // small: displayed as is
  const Vec3 small = limitStep(f0, f0 + Vec3{0.3, 0, 0}, 0.5, &lim);
  EXPECT_TRUE(small == f0 + Vec3(0.3, 0, 0));
  EXPECT_FALSE(lim);
  // F_max < |D| <= 2 F_max: the mean of the two
  const Vec3 mid = limitStep(f0, f0 + Vec3{0, 0.8, 0}, 0.5, &lim);
  EXPECT_TRUE(lim);
  EXPECT_NEAR(glm::length(mid - (f0 + Vec3{0, 0.4, 0})), 0.0, 1e-15);
  // |D| > 2 F_max: F_max along D
  lim = false;
  const Vec3 far = limitStep(f0, f0 + Vec3{0, 0, -3.0}, 0.5, &lim);
  EXPECT_TRUE(lim);
  EXPECT_NEAR(glm::length(far - (f0 + Vec3{0, 0, -0.5})), 0.0, 1e-15);
}

TEST(LimitStep, BoundsTheChangeOfMagnitudeAndDirectionForAnyInput) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 5.0);
  double worst = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const Vec3 a{g(rng), g(rng), g(rng)}, b{g(rng), g(rng), g(rng)};
    bool lim = false;
    const Vec3 c = limitStep(a, b, 0.5, &lim);
    worst = std::max(worst, glm::length(c - a));
    EXPECT_LE(std::abs(glm::length(c) - glm::length(a)), 0.5 + 1e-12);
  }
  std::printf("[limit step] largest step over 1e5 random pairs %.15f (F_max 0.5)\n", worst);
  EXPECT_LE(worst, 0.5 + 1e-12);
}

OutputLimits limits() {
  OutputLimits l;
  l.ramp_s = 0.1;
  return l;
}

TEST(OutputStage, NonFiniteInputGivesZeroAndRestartsTheRamp) {
  OutputStage s(limits());
  OutputReport r;
  for (int i = 0; i < 200; ++i)
    s.apply({Vec3{0, 5, 0}, Vec3{0.0}}, true, &r);
  EXPECT_NEAR(s.last().force_n.y, 5.0, 1e-12);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Wrench w = s.apply({Vec3{nan, 0, 0}, Vec3{0.0}}, true, &r);
  EXPECT_TRUE(r.non_finite);
  EXPECT_TRUE(std::isfinite(w.force_n.x) && std::isfinite(w.force_n.y));
  EXPECT_LE(glm::length(w.force_n - Vec3{0, 5, 0}), 0.5 + 1e-12);  // fades at the step limit
  EXPECT_EQ(s.rampScale(), 1.0 * 0.001 / 0.1);
  const Wrench inf =
      s.apply({Vec3{0.0}, Vec3{std::numeric_limits<double>::infinity(), 0, 0}}, true, &r);
  EXPECT_TRUE(r.non_finite);
  EXPECT_TRUE(std::isfinite(inf.torque_nm.x));
}

TEST(OutputStage, ClampsRampsAndCutsAtOnceWhenTheDeviceIsLost) {
  OutputStage s(limits());
  OutputReport r;
  // ramp: 0.1 s from zero to full; the step limit never exceeded
  Vec3 prev{0.0};
  int ticks_to_full = -1;
  for (int i = 0; i < 400; ++i) {
    const Wrench w = s.apply({Vec3{0, 40, 0}, Vec3{0, 0, 3}}, true, &r);
    EXPECT_LE(glm::length(w.force_n - prev), 0.5 + 1e-12);
    EXPECT_LE(glm::length(w.force_n), 10.0 + 1e-12);
    EXPECT_LE(glm::length(w.torque_nm), 1.0 + 1e-12);
    prev = w.force_n;
    if (ticks_to_full < 0 && std::abs(w.force_n.y - 10.0) < 1e-12)
      ticks_to_full = i;
  }
  EXPECT_TRUE(r.clamped);
  EXPECT_FALSE(r.ramping);
  std::printf("[output stage] full 10 N after %d ticks (ramp 100 ticks, F_max 0.5 N)\n",
              ticks_to_full);
  EXPECT_GE(ticks_to_full, 99);
  const Wrench lost = s.apply({Vec3{0, 40, 0}, Vec3{0.0}}, false, &r);
  EXPECT_TRUE(lost.force_n == Vec3(0.0));
  EXPECT_TRUE(lost.torque_nm == Vec3(0.0));
  const Wrench back = s.apply({Vec3{0, 40, 0}, Vec3{0.0}}, true, &r);
  EXPECT_TRUE(r.ramping);
  EXPECT_LE(glm::length(back.force_n), 0.5);
}

// One clamp, in the device frame: a 6 N world force that the frame doubles and turns is 12 N on
// the device, cut to 10 N there (in the world frame it would pass). The gate scales it.
TEST(OutputStage, ClampsOnceInTheDeviceFrameAndScalesByTheGate) {
  OutputLimits l;
  l.ramp_s = 0.0;
  OutputStage s(l);
  OutputFrame frame;
  frame.q_DW = glm::angleAxis(kPi / 2.0, Vec3{0, 0, 1});  // world x is device y
  frame.force_scale = 2.0;
  OutputReport r;
  Wrench w;
  for (int i = 0; i < 100; ++i)
    w = s.apply({Vec3{6, 0, 0}, Vec3{0.0}}, OutputInputs{}, frame, &r);
  EXPECT_TRUE(r.clamped);
  EXPECT_NEAR(w.force_n.y, 10.0, 1e-12);
  EXPECT_NEAR(std::abs(w.force_n.x) + std::abs(w.force_n.z), 0.0, 1e-12);
  OutputInputs gated;
  gated.gate_scale = 0.5;
  for (int i = 0; i < 100; ++i)
    w = s.apply({Vec3{6, 0, 0}, Vec3{0.0}}, gated, frame, &r);
  EXPECT_NEAR(w.force_n.y, 5.0, 1e-12);
}

// The fades: a hold (disarm, stop) over hold_fade_s, a fault over fault_fade_s, both to exactly
// zero within the step limit; rearm() brings the force back through the ramp-in.
TEST(OutputStage, FadesToZeroOnAHoldOrAFaultAndRearmRampsBackIn) {
  OutputLimits l;
  l.ramp_s = 0.05;
  l.hold_fade_s = 0.2;
  l.fault_fade_s = 0.02;
  for (const bool fault : {false, true}) {
    OutputStage s(l);
    OutputReport r;
    for (int i = 0; i < 200; ++i)
      s.apply({Vec3{0, 20, 0}, Vec3{0, 0, 2}}, OutputInputs{}, OutputFrame{}, &r);
    EXPECT_EQ(s.last().force_n, Vec3(0, 10, 0));
    OutputInputs in;
    in.fault = fault;
    in.hold = !fault;
    Vec3 prev = s.last().force_n;
    int ticks = 0;
    while (!s.atZero() && ticks < 1000) {
      const Wrench w = s.apply({Vec3{0, 20, 0}, Vec3{0, 0, 2}}, in, OutputFrame{}, &r);
      EXPECT_LE(glm::length(w.force_n - prev), l.max_force_step_n + 1e-12);
      prev = w.force_n;
      ++ticks;
    }
    ASSERT_TRUE(s.atZero());
    EXPECT_EQ(s.last().torque_nm, Vec3(0.0));
    // the gain reaches zero after fade_s / tick ticks (the step limit may hold it up a little)
    const int fade_ticks = static_cast<int>(std::lround((fault ? 0.02 : 0.2) / l.tick_s));
    std::printf("[fade] %s: zero after %d ticks (fade %d ticks)\n", fault ? "fault" : "hold", ticks,
                fade_ticks);
    EXPECT_GE(ticks, fade_ticks);
    EXPECT_LE(ticks, fade_ticks + 20);
    EXPECT_EQ(s.rampRestarts(), 0u);
    s.rearm();
    EXPECT_EQ(s.fadeGain(), 1.0);
    EXPECT_EQ(s.rampRestarts(), 1u);
    const Wrench back = s.apply({Vec3{0, 20, 0}, Vec3{0.0}}, OutputInputs{}, OutputFrame{}, &r);
    EXPECT_TRUE(r.ramping);
    EXPECT_EQ(back.force_n, Vec3(0.0));  // the ramp starts from zero
  }
}

// A virtual wall through the coupling: the proxy held on the surface x = 0, the device moving in
// and out of it sinusoidally, F held for each tick. Energy the coupling gives the hand over whole
// cycles: a sampled spring alone gives K/2 sum dx^2 > 0; the damper B = K dt takes it back.
double wallEnergy(double damping_factor, double amplitude, double hz, double* abs_out) {
  CouplingParams p;
  p.stiffness_n_per_m = 600.0;
  p.damping_n_s_per_m = damping_factor * p.stiffness_n_per_m * p.tick_s;
  VirtualCoupling c(p);
  const int n = static_cast<int>(std::lround(10.0 / hz / p.tick_s));  // 10 cycles
  double e = 0.0, abs_e = 0.0;
  Vec3 prev_x{0.0}, prev_f{0.0};
  for (int k = 0; k <= n; ++k) {
    const double t = k * p.tick_s;
    const Vec3 x{-amplitude * 0.5 * (1.0 - std::cos(2.0 * kPi * hz * t)), 0.0, 0.0};  // x <= 0
    const Wrench w = c.step(x, Quat{1, 0, 0, 0}, Vec3{0.0}, Quat{1, 0, 0, 0});
    if (k > 0) {
      e += glm::dot(prev_f, x - prev_x);
      abs_e += std::abs(glm::dot(prev_f, x - prev_x));
    }
    prev_x = x;
    prev_f = w.force_n;
  }
  *abs_out = abs_e;
  return e;
}

TEST(VirtualCoupling, IsPassiveAtOneKilohertzWithTheDefaultDamping) {
  for (const double hz : {0.5, 2.0, 10.0, 30.0}) {
    double abs0 = 0.0, abs1 = 0.0;
    const double e0 = wallEnergy(0.0, 0.005, hz, &abs0);
    const double e1 = wallEnergy(1.0, 0.005, hz, &abs1);
    std::printf(
        "[coupling] %5.1f Hz, 5 mm: energy to the hand without damping %+.3e J, with B = K dt "
        "%+.3e J (of %.3e J moved)\n",
        hz, e0, e1, abs1);
    EXPECT_GT(e0, 0.0);  // the sampled spring alone is active
    EXPECT_LE(e1, 0.0);  // the damper makes it passive
  }
}

TEST(VirtualCoupling, RotationalSpringTurnsTheHandTowardTheProxy) {
  CouplingParams p;
  p.rot_stiffness_nm_per_rad = 2.0;
  VirtualCoupling c(p);
  const Quat q = glm::angleAxis(0.1, Vec3{0, 0, 1});
  const Wrench w = c.step(Vec3{0.0}, Quat{1, 0, 0, 0}, Vec3{0.0}, q);
  EXPECT_NEAR(w.torque_nm.z, 0.2, 1e-12);
  EXPECT_NEAR(glm::length(w.force_n), 0.0, 1e-15);
}

TEST(PenaltyWrench, TotalDoesNotDependOnThePointCountAndTorqueIsRxF) {
  const double k = 30000.0, delta = 1e-4;
  ContactRow one{Vec3{0.01, 0, 0}, Vec3{0, 1, 0}, -2e-4, k};
  const Wrench w1 = penaltyWrench(std::span<const ContactRow>(&one, 1), Vec3{0.0}, delta);
  std::vector<ContactRow> four;
  four.reserve(4);
  for (int i = 0; i < 4; ++i)
    four.push_back({Vec3{0.01, 0, 0.001 * (i - 1.5)}, Vec3{0, 1, 0}, -2e-4, k / 4});
  const Wrench w4 = penaltyWrench(four, Vec3{0.0}, delta);
  EXPECT_NEAR(w1.force_n.y, k * (delta + 2e-4), 1e-9);  // k (delta + D_p)
  EXPECT_NEAR(glm::length(w4.force_n - w1.force_n), 0.0, 1e-9);
  EXPECT_NEAR(w1.torque_nm.z, 0.01 * w1.force_n.y, 1e-12);  // R x F
  EXPECT_NEAR(glm::length(w4.torque_nm - w1.torque_nm), 0.0, 1e-12);
  // within delta: k (delta - d); beyond: nothing
  ContactRow near{Vec3{0.0}, Vec3{0, 1, 0}, 0.4e-4, k};
  EXPECT_NEAR(penaltyWrench(std::span<const ContactRow>(&near, 1), Vec3{0.0}, delta).force_n.y,
              k * (delta - 0.4e-4), 1e-9);
  ContactRow far{Vec3{0.0}, Vec3{0, 1, 0}, 2e-4, k};
  EXPECT_TRUE(penaltyWrench(std::span<const ContactRow>(&far, 1), Vec3{0.0}, delta).force_n ==
              Vec3(0.0));
}

ProxyParams params() {
  ProxyParams p;
  p.coupling_stiffness = 612.0;
  p.rot_coupling_stiffness = 0.5;
  p.delta = 1e-4;
  p.max_travel = 5e-4;
  return p;
}

TEST(ProxyStep, FreeSpaceReachesTheTargetAndTheSafeDistanceBoundsEveryPoint) {
  ProxyProblem pb;
  pb.radius = 0.02;
  pb.h_target_W = Vec3{1e-4, -2e-4, 0.5e-4};
  pb.q_target = glm::angleAxis(0.005, glm::normalize(Vec3{1, 2, 3}));
  const ProxyStep s = solveProxyStep(pb, {}, params());
  EXPECT_FALSE(s.travel_limited);
  EXPECT_NEAR(glm::length(s.dc_W - pb.h_target_W), 0.0, 1e-15);
  EXPECT_NEAR(glm::length(s.dtheta_W - geom::rotationVector(pb.q_target)), 0.0, 1e-12);
  // far: scaled so that |dc| + |dtheta| r <= max travel
  pb.h_target_W = Vec3{0.05, 0, 0};
  const ProxyStep f = solveProxyStep(pb, {}, params());
  EXPECT_TRUE(f.travel_limited);
  EXPECT_NEAR(glm::length(f.dc_W) + glm::length(f.dtheta_W) * pb.radius, 5e-4, 1e-15);
}

// Coulomb friction on the proxy's rows: a floor of four rows (mu_s 0.6, mu_d 0.4), the device
// 2 mm into it and pulled sideways: inside the cone the proxy does not move sideways; beyond it
// (or, sliding, beyond mu_d N) it moves so that the pull left is mu_d N; no friction, no hold.
TEST(ProxyStep, FrictionSticksInsideTheConeAndSlidesOnItsEdge) {
  ProxyParams p = params();
  p.max_travel = 1.0;  // the whole step at once
  const double kp = 30600.0;
  std::vector<ContactRow> rows;
  rows.reserve(4);
  for (const Vec3 at :
       {Vec3{-0.01, 0, -0.01}, Vec3{0.01, 0, -0.01}, Vec3{-0.01, 0, 0.01}, Vec3{0.01, 0, 0.01}}) {
    ContactRow r{at, Vec3{0, 1, 0}, 0.5 * p.delta, kp / 4.0};
    r.mu_s = 0.6;
    r.mu_d = 0.4;
    rows.push_back(r);
  }
  ProxyProblem pb;
  pb.radius = 0.02;
  pb.c_W = pb.h_W = Vec3{0.0, 0.01, 0.0};
  auto pullAfter = [&](const ProxyStep& st) {
    const Vec3 e = pb.h_target_W - (pb.h_W + st.dc_W);
    return Vec3{e.x, 0.0, e.z} * p.coupling_stiffness;
  };
  // N about k_c * 2 mm = 1.22 N; a pull of 0.5 N (0.41 N) sticks
  pb.h_target_W = pb.h_W + Vec3{0.5 / p.coupling_stiffness, -0.002, 0.0};
  const ProxyStep stick = solveProxyStep(pb, rows, p);
  EXPECT_TRUE(stick.stuck);
  EXPECT_FALSE(stick.sliding);
  EXPECT_LT(std::abs(stick.dc_W.x), 1e-15);
  EXPECT_NEAR(glm::length(pullAfter(stick)), 0.5, 1e-9);
  // a pull of 1.0 N (0.82 N) is beyond mu_s N: it slides, the pull left mu_d N
  pb.h_target_W = pb.h_W + Vec3{0.6 / p.coupling_stiffness, -0.002, 0.8 / p.coupling_stiffness};
  const ProxyStep slide = solveProxyStep(pb, rows, p);
  EXPECT_TRUE(slide.sliding);
  EXPECT_GT(slide.normal_force_n, 1.0);
  EXPECT_NEAR(glm::length(pullAfter(slide)), 0.4 * slide.normal_force_n,
              1e-9 * slide.normal_force_n);
  EXPECT_NEAR(pullAfter(slide).z / pullAfter(slide).x, 0.8 / 0.6, 1e-9);  // along the pull
  // already sliding, the 0.5 N pull (beyond mu_d N = 0.49 N) goes on sliding
  pb.sliding = true;
  pb.h_target_W = pb.h_W + Vec3{0.55 / p.coupling_stiffness, -0.002, 0.0};
  const ProxyStep still = solveProxyStep(pb, rows, p);
  EXPECT_TRUE(still.sliding);
  EXPECT_NEAR(glm::length(pullAfter(still)), 0.4 * still.normal_force_n,
              1e-9 * still.normal_force_n);
  // frictionless rows: the proxy follows the pull, nothing holds it
  for (ContactRow& r : rows)
    r.mu_s = r.mu_d = 0.0;
  const ProxyStep none = solveProxyStep(pb, rows, p);
  EXPECT_FALSE(none.stuck || none.sliding);
  EXPECT_LT(glm::length(pullAfter(none)), 1e-9);
}

TEST(ProxyStep, AContactRowHoldsTheProxyAndARowThatWouldPullIsDropped) {
  const ProxyParams p = params();
  const double kp = 30600.0;
  // a floor under the proxy: four rows at gap 0.5 delta, the device 2 mm below
  std::vector<ContactRow> rows;
  rows.reserve(4);
  for (int i = 0; i < 4; ++i) {
    rows.push_back(
        {Vec3{i & 1 ? 0.01 : -0.01, -0.01, i & 2 ? 0.01 : -0.01}, Vec3{0, 1, 0}, 0.5e-4, kp / 4});
  }
  ProxyProblem pb;
  pb.radius = 0.0173;
  pb.h_target_W = Vec3{0, -0.002, 0};
  const ProxyStep s = solveProxyStep(pb, rows, p);
  // equilibrium: k_c (target - x) = k_p (delta - gap - x)  =>  x = (k_c t + k_p (delta - gap)) /
  // (k_c + k_p)
  const double x =
      (p.coupling_stiffness * -0.002 + kp * (p.delta - 0.5e-4)) / (p.coupling_stiffness + kp);
  EXPECT_NEAR(s.dc_W.y, x, 1e-12);
  EXPECT_NEAR(glm::length(s.dtheta_W), 0.0, 1e-12);
  EXPECT_EQ(s.active, 4u);
  // the device above: the rows would pull the proxy down, so they are dropped
  pb.h_target_W = Vec3{0, 0.0003, 0};
  const ProxyStep up = solveProxyStep(pb, rows, p);
  EXPECT_EQ(up.active, 0u);
  EXPECT_NEAR(up.dc_W.y, 0.0003, 1e-12);
}

TEST(ProxyStep, AHingeBasisTurnsAboutItsAxisOnly) {
  ProxyProblem pb;
  pb.c_W = Vec3{0.0};
  pb.h_W = Vec3{0.04, 0, 0};                 // a rim handle 40 mm out
  pb.h_target_W = Vec3{0.04, 0.001, 0.002};  // pulled up (tangent) and along the axis z
  pb.radius = 0.01;  // small enough that the safe distance does not cut this step
  pb.basis = ProxyBasis::hinge(Vec3{0.0}, Vec3{0, 0, 1}, pb.c_W);
  const ProxyParams p = params();
  const ProxyStep s = solveProxyStep(pb, {}, p);
  EXPECT_NEAR(s.dtheta_W.x, 0.0, 1e-15);
  EXPECT_NEAR(s.dtheta_W.y, 0.0, 1e-15);
  // the tangential pull against the linear spring at 40 mm and the rotational spring; the axial
  // pull does nothing: phi = k_c r e / (k_c r^2 + k_r)
  const double kc = p.coupling_stiffness, kr = p.rot_coupling_stiffness;
  EXPECT_NEAR(s.dtheta_W.z, kc * 0.04 * 0.001 / (kc * 0.04 * 0.04 + kr), 1e-12);
  EXPECT_NEAR(glm::length(s.dc_W), 0.0, 1e-15);  // the centre is on the axis
}

using testing::prism;

TEST(ForceShading, NormalsAreContinuousAcrossSmoothEdgesAndCreasesStaySharp) {
  const auto cyl = geom::Polytope::fromPoints(prism(32, 0.02, 0.01)).value();
  const ShadingTable table(cyl, 40.0 * kPi / 180.0);
  EXPECT_EQ(table.smoothEdges(), 32u);  // the 32 side edges; the caps' rims are 90 degree creases
  // walk round the cylinder at mid height: the shaded normal against the true cylinder normal,
  // and its jump between neighbouring samples
  double worst_true = 0.0, worst_facet = 0.0, worst_jump = 0.0;
  Vec3 prev{0.0};
  const int n = 3200;
  for (int i = 0; i <= n; ++i) {
    const double a = 2.0 * kPi * i / n;
    const Vec3 radial{std::cos(a), std::sin(a), 0.0};
    // the point on the facet surface along this direction
    const std::uint32_t f = bestFace(cyl, radial, geom::Feature{});
    const auto& face = cyl.faces()[f];
    const Vec3 x = radial * (face.offset / glm::dot(face.normal, radial));
    const Vec3 ns = table.shadedNormalOnFace(cyl, f, x);
    worst_true = std::max(worst_true, std::acos(std::min(1.0, glm::dot(ns, radial))));
    worst_facet = std::max(worst_facet, std::acos(std::min(1.0, glm::dot(face.normal, radial))));
    if (i > 0)
      worst_jump = std::max(worst_jump, std::acos(std::min(1.0, glm::dot(ns, prev))));
    prev = ns;
  }
  std::printf(
      "[shading] 32-gon: facet normal up to %.4f rad from the true normal, shaded %.4f rad; "
      "largest jump between samples 2 mrad apart %.5f rad\n",
      worst_facet, worst_true, worst_jump);
  EXPECT_LT(worst_true, 0.6 * worst_facet);
  EXPECT_LT(worst_jump, 0.01);  // no jump at the edges (the facet normal jumps 0.196 rad there)
  // a box keeps its creases
  const auto box = geom::Polytope::fromPoints(prism(4, 0.02, 0.01)).value();
  const ShadingTable sharp(box, 40.0 * kPi / 180.0);
  EXPECT_EQ(sharp.smoothEdges(), 0u);
}

// A contact on a crease keeps its own normal (issue 16): the rim of a 32-gon prism, a side facet
// (smoothed to its neighbours) against the cap (90 degrees: a crease). Until 2026-12-04 a rim
// edge's normal became the side facet's shaded normal, here 39 degrees off; on an imported
// model's piece that read an edge as the face under it and held the probe under a seam.
TEST(ForceShading, AContactOnACreaseKeepsItsOwnNormal) {
  const auto cyl = geom::Polytope::fromPoints(prism(32, 0.02, 0.01)).value();
  const ShadingTable table(cyl, 40.0 * kPi / 180.0);
  std::uint32_t rim = 0, side = 0;
  bool have_rim = false, have_side = false;
  for (std::uint32_t e = 0; e < cyl.edges().size(); ++e) {
    const auto& edge = cyl.edges()[e];
    const double z0 = cyl.faces()[edge.face[0]].normal.z, z1 = cyl.faces()[edge.face[1]].normal.z;
    const bool cap0 = std::abs(z0) > 0.99, cap1 = std::abs(z1) > 0.99;
    if (cap0 != cap1 && !have_rim && z0 + z1 > 0.5)
      rim = e, have_rim = true;  // a top rim edge: a side facet and the top cap
    if (!cap0 && !cap1 && !have_side)
      side = e, have_side = true;  // a side edge: two side facets, smoothed
  }
  ASSERT_TRUE(have_rim && have_side);
  // the rim edge's middle, and a normal between the side facet's and the cap's, nearer the side
  const auto& er = cyl.edges()[rim];
  const Vec3 mid = 0.5 * (cyl.vertices()[er.tail].p + cyl.vertices()[er.head].p);
  const Vec3 radial = glm::normalize(Vec3{mid.x, mid.y, 0.0});
  const Vec3 n = glm::normalize(radial + Vec3{0.0, 0.0, 0.8});
  const Vec3 on_edge = table.shadedNormal(cyl, mid, n, geom::Feature::edge(rim));
  EXPECT_LT(glm::length(on_edge - n), 1e-12);
  const Vec3 at_vertex =
      table.shadedNormal(cyl, cyl.vertices()[er.tail].p, n, geom::Feature::vertex(er.tail));
  EXPECT_LT(glm::length(at_vertex - n), 1e-12);
  // a smooth edge is still shaded: on a side edge, half way between its two facets' normals
  const auto& es = cyl.edges()[side];
  const Vec3 ms = 0.5 * (cyl.vertices()[es.tail].p + cyl.vertices()[es.head].p);
  const Vec3 n0 = cyl.faces()[es.face[0]].normal, n1 = cyl.faces()[es.face[1]].normal;
  const Vec3 shaded = table.shadedNormal(cyl, ms, n0, geom::Feature::edge(side));
  EXPECT_LT(glm::length(shaded - glm::normalize(n0 + n1)), 1e-9);
}

TEST(FaceContact, ClipsTheHeldFaceToTheEnvironmentsFace) {
  auto square = [](double h, double t) {
    std::vector<Vec3> p;
    p.reserve(8);
    for (int i = 0; i < 8; ++i)
      p.push_back(Vec3{i & 1 ? h : -h, i & 2 ? t : -t, i & 4 ? h : -h});
    return geom::Polytope::fromPoints(p).value();
  };
  const auto floor = square(0.05, 0.01);  // top face y = 0.01
  const auto cube = square(0.01, 0.01);
  geom::Transform X_WE;
  geom::Transform X_WH;
  X_WH.t = Vec3{0.045, 0.0201, 0.0};  // half over the floor's edge at x = 0.05, 0.1 mm above
  FaceContact fc;
  ASSERT_TRUE(faceContact(floor, X_WE, geom::Feature{}, cube, X_WH, geom::Feature{}, Vec3{0, 1, 0},
                          0.95, &fc));
  EXPECT_EQ(fc.count, 4u);
  double xmax = -1.0, xmin = 1.0;
  for (std::uint32_t i = 0; i < fc.count; ++i) {
    EXPECT_NEAR(fc.gap[i], 1e-4, 1e-12);
    xmax = std::max(xmax, fc.p_W[i].x);
    xmin = std::min(xmin, fc.p_W[i].x);
  }
  EXPECT_NEAR(xmax, 0.05, 1e-12);  // clipped at the floor's edge
  EXPECT_NEAR(xmin, 0.035, 1e-12);
  EXPECT_NEAR(fc.n_W.y, 1.0, 1e-15);
  // a normal far from both faces: no face contact (the caller keeps the manifold)
  EXPECT_FALSE(faceContact(floor, X_WE, geom::Feature{}, cube, X_WH, geom::Feature{},
                           glm::normalize(Vec3{1, 1, 0}), 0.95, &fc));
}

}  // namespace
}  // namespace hapticd::response
