// Contact: restitution at the time of impact (elastic, inelastic, in metres and millimetres),
// material combine modes, no energy gain in a closed frictionless box, a stack that stays up,
// a box on a slope that sticks below the friction angle and slides above it at g(sin - mu cos).
#include <gtest/gtest.h>

#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;
#ifdef HAPTICD_DYNAMICS_SHORT_RUNS
constexpr double kLongRunS = 15.0;  // sanitizer builds: a quarter of the run, the same bounds
#else
constexpr double kLongRunS = 60.0;
#endif

// A scene under gravity with one material (friction mu, restitution e) and a static floor of
// that material whose top face is y = 0.
SceneModel floorScene(double mu, double e) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.materials.push_back(material(mu, e));
  s.bodies.push_back(staticBody("floor", boxShape(Vec3{1, 0.1, 1}), at(Vec3{0, -0.1, 0}), 0));
  return s;
}

// a cube dropped from rest onto a floor; `unit` scales every length (1: metres, 1000: mm)
struct Bounce {
  double v_before = 0.0;  // velocity at the end of the tick before the impact
  double v_after = 0.0;   // at the end of the impact tick
  double g = 0.0;
  int impact_tick = -1;
};

Bounce dropCube(double e, double unit, const Quat& tilt = Quat{1, 0, 0, 0}) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81 * unit, 0};
  s.materials.push_back(material(0.0, e));
  s.bodies.push_back(
      staticBody("floor", boxShape(Vec3{1, 0.1, 1} * unit), at(Vec3{0, -0.1, 0} * unit), 0));
  s.bodies.push_back(dynamicBody("cube", boxShape(Vec3{0.05} * unit),
                                 at(Vec3{0, 0.3, 0} * unit, tilt), 1000.0 / (unit * unit * unit),
                                 0));
  Rig rig(std::move(s));
  Bounce out;
  out.g = 9.81 * unit;
  double prev = 0.0;
  for (int k = 0; k < 1000; ++k) {
    rig.tick(kDt);
    const double v = rig.dyn->linearVelocity(1).y;
    if (v > -1e-9 * unit && prev < 0.0) {
      out.v_before = prev;
      out.v_after = v;
      out.impact_tick = k;
      break;
    }
    prev = v;
  }
  return out;
}

TEST(Restitution, ElasticAndInelasticBounceAtTheTimeOfImpact) {
  for (const double e : {1.0, 0.5, 0.0}) {
    const Bounce b = dropCube(e, 1.0);
    ASSERT_GE(b.impact_tick, 0) << e;
    // the tick: gravity first (v - g dt), then the impulse at the time of impact, no gravity
    // after it within the tick: v_after = -e (v_before - g dt) exactly
    const double v_in = b.v_before - b.g * kDt;
    EXPECT_NEAR(b.v_after, -e * v_in, 1e-6 * std::abs(v_in)) << "e=" << e;
  }
}

TEST(Restitution, SameRelativeResultInMillimetres) {
  for (const double e : {1.0, 0.5}) {
    const Bounce m = dropCube(e, 1.0);
    const Bounce mm = dropCube(e, 1000.0);
    EXPECT_EQ(m.impact_tick, mm.impact_tick);
    EXPECT_NEAR(mm.v_after / 1000.0, m.v_after, 1e-6 * std::abs(m.v_after));
  }
}

TEST(Restitution, CombineModes) {
  using scene::Combine;
  const auto rebound = [](double ea, double eb, Combine ca, Combine cb) {
    SceneModel s;
    s.gravity_W = Vec3{0, -9.81, 0};
    Material a = material(0.0, ea, ca), b = material(0.0, eb, cb);
    s.materials = {a, b};
    s.bodies.push_back(staticBody("floor", boxShape(Vec3{1, 0.1, 1}), at(Vec3{0, -0.1, 0}), 0));
    s.bodies.push_back(dynamicBody("cube", boxShape(Vec3{0.05}), at(Vec3{0, 0.2, 0}), 1000.0, 1));
    Rig rig(std::move(s));
    double prev = 0.0;
    for (int k = 0; k < 1000; ++k) {
      rig.tick(kDt);
      const double v = rig.dyn->linearVelocity(1).y;
      if (v > 0.0 && prev < 0.0)
        return -v / (prev - 9.81 * kDt);
      prev = v;
    }
    return -1.0;
  };
  EXPECT_NEAR(rebound(0.2, 0.8, Combine::kAverage, Combine::kMaximum), 0.5, 1e-6);
  EXPECT_NEAR(rebound(0.2, 0.8, Combine::kMinimum, Combine::kMaximum), 0.2, 1e-6);
  EXPECT_NEAR(rebound(0.2, 0.8, Combine::kMaximum, Combine::kMultiply), 0.8, 1e-6);
  EXPECT_NEAR(rebound(0.5, 0.8, Combine::kMultiply, Combine::kMultiply), 0.4, 1e-6);
}

// cubes (or bricks) and spheres bouncing in a closed box, no gravity, no friction, fully
// elastic; returns the worst total energy, the final one and the net change over impact ticks
struct BoxRun {
  double e0 = 0.0, worst = 0.0, final = 0.0, impact_change = 0.0;
  std::uint32_t impacts = 0;
};

BoxRun closedBox(bool isotropic) {
  SceneModel s;
  s.materials.push_back(material(0.0, 1.0));
  const double L = 0.5, w = 0.05;
  const auto wall = [&](const Vec3& c, const Vec3& h) {
    s.bodies.push_back(staticBody("wall", boxShape(h), at(c), 0));
  };
  wall(Vec3{0, -L - w, 0}, Vec3{L + 2 * w, w, L + 2 * w});
  wall(Vec3{0, L + w, 0}, Vec3{L + 2 * w, w, L + 2 * w});
  wall(Vec3{-L - w, 0, 0}, Vec3{w, L + 2 * w, L + 2 * w});
  wall(Vec3{L + w, 0, 0}, Vec3{w, L + 2 * w, L + 2 * w});
  wall(Vec3{0, 0, -L - w}, Vec3{L + 2 * w, L + 2 * w, w});
  wall(Vec3{0, 0, L + w}, Vec3{L + 2 * w, L + 2 * w, w});
  // a cube and an icosphere have isotropic inertia; the brick does not
  const auto cube = boxShape(isotropic ? Vec3{0.05} : Vec3{0.06, 0.04, 0.05});
  const auto ball = ellipsoidShape(Vec3{0.05}, 1);
  for (int i = 0; i < 6; ++i) {
    const Vec3 c{-0.3 + 0.3 * (i % 3), -0.2 + 0.4 * (i / 3), 0.1 * (i % 2)};
    Body b = dynamicBody("b", i % 2 ? ball : cube,
                         at(c, glm::angleAxis(0.3 * i, glm::normalize(Vec3{1, 2, 3}))), 1000.0, 0);
    b.linear_velocity_W = Vec3{std::sin(1.0 + i), std::cos(2.0 * i), std::sin(3.0 * i)} * 1.5;
    b.angular_velocity_W = Vec3{std::cos(i), 2.0 * std::sin(i), 1.0} * 3.0;
    s.bodies.push_back(b);
  }
  Rig rig(std::move(s));
  BoxRun out;
  out.e0 = rig.energy();
  double prev = out.e0;
  const int n = static_cast<int>(kLongRunS / kDt);
  for (int k = 0; k < n; ++k) {
    const StepReport r = rig.tick(kDt);
    out.impacts += r.toi_substeps;
    const double e = rig.energy();
    out.worst = std::max(out.worst, e);
    if (r.impulse_points > 0)
      out.impact_change += e - prev;
    prev = e;
    for (std::uint32_t b = 6; b < 12; ++b) {
      const Vec3 x = rig.dyn->centerOfMass(b);
      EXPECT_LT(std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)}), L) << "escaped at " << k;
    }
  }
  out.final = rig.energy();
  std::printf(
      "closed box (%s): %d s, %u impacts, final/initial energy %.9f, worst %.9f, net "
      "change over impact ticks %.3g\n",
      isotropic ? "cubes and spheres" : "bricks and spheres", static_cast<int>(kLongRunS),
      out.impacts, out.final / out.e0, out.worst / out.e0, out.impact_change / out.e0);
  return out;
}

// isotropic bodies: the rotation is exact, so the energy may move only through the impulses
TEST(Energy, NoGainInAClosedFrictionlessBox) {
  const BoxRun r = closedBox(true);
  EXPECT_LE(r.worst, r.e0 * (1.0 + 1e-9)) << "energy gained";
  EXPECT_LE(r.impact_change, 1e-9 * r.e0);
  EXPECT_GT(r.final, 0.2 * r.e0);  // and the test means something: they kept moving
  EXPECT_GT(r.impacts, 100u);
}

// bricks: on top, the free-rotation integrator's bounded O((w dt)^2) error (w up to 7 rad/s:
// (w dt)^2 = 5e-5; FreeMotion shows it bounded and not drifting)
TEST(Energy, NoGainInAClosedFrictionlessBoxOfBricks) {
  const BoxRun r = closedBox(false);
  EXPECT_LE(r.worst, r.e0 * (1.0 + 5e-5)) << "energy gained";
  EXPECT_LE(r.final, r.e0 * (1.0 + 5e-5));
  // the impact ticks carry the same rotation error (the impulses alone: the isotropic test)
  EXPECT_LE(r.impact_change, 5e-5 * r.e0);
  EXPECT_GT(r.final, 0.2 * r.e0);
  EXPECT_GT(r.impacts, 100u);
}

TEST(Stack, FourBoxesStayStandingFor60s) {
  SceneModel s = floorScene(0.6, 0.0);
  const double h = 0.05;
  for (int i = 0; i < 4; ++i) {
    s.bodies.push_back(
        dynamicBody("box", boxShape(Vec3{h}), at(Vec3{0, h + 2 * h * i, 0}), 500.0, 0));
  }
  // sleep off: the resting contact is solved on every tick
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  Rig rig(std::move(s), o);
  const int n = static_cast<int>(kLongRunS / kDt);
  double worst = 0.0, jitter = 0.0;
  for (int k = 0; k < n; ++k) {
    rig.tick(kDt);
    for (std::uint32_t b = 1; b <= 4; ++b) {
      if (k >= n / 2) {
        jitter = std::max(jitter, glm::length(rig.dyn->linearVelocity(b)) +
                                      glm::length(rig.dyn->angularVelocity(b)) * h);
      }
      // every corner of every box, from where it was placed
      const geom::Transform X = rig.dyn->pose(b).toTransform();
      const Vec3 start{0, h + 2 * h * (b - 1), 0};
      for (int c = 0; c < 8; ++c) {
        const Vec3 corner{c & 1 ? h : -h, c & 2 ? h : -h, c & 4 ? h : -h};
        worst = std::max(worst, glm::length(X.apply(corner) - (start + corner)));
      }
    }
  }
  EXPECT_LT(worst, 1e-3) << "worst drift of any box corner from where it was placed (m)";
  for (std::uint32_t b = 1; b <= 4; ++b) {
    EXPECT_LT(glm::length(rig.dyn->linearVelocity(b)), 1e-4);
  }
  // no jitter: in the second half no point of any box moves faster than 10 um/s
  EXPECT_LT(jitter, 1e-5);
  std::printf(
      "stack of 4: worst drift %.3f mm over %d s, largest speed in the second half %.3g m/s\n",
      worst * 1e3, static_cast<int>(kLongRunS), jitter);
}

// a box resting on a static slope of angle theta, friction mu (static == dynamic)
double slopeAcceleration(double theta, double mu, double* normal_drift) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.materials.push_back(material(mu, 0.0));
  const Quat tilt = glm::angleAxis(theta, Vec3{0, 0, 1});
  const Vec3 up = tilt * Vec3{0, 1, 0};
  const Vec3 down_slope = tilt * Vec3{-1, 0, 0};
  s.bodies.push_back(staticBody("slope", boxShape(Vec3{3, 0.1, 1}), at(-0.1 * up, tilt), 0));
  const double h = 0.05;
  s.bodies.push_back(dynamicBody("box", boxShape(Vec3{h}), at(h * up, tilt), 500.0, 0));
  DynamicsOptions o;
  o.sleep_time_s = 0.0;  // a sticking box is solved on every tick
  Rig rig(std::move(s), o);
  double v0 = 0.0;
  const int t0 = 200, t1 = 1200;
  double drift = 0.0;
  for (int k = 0; k < t1; ++k) {
    rig.tick(kDt);
    const Vec3 x = rig.dyn->pose(1).translation;
    drift = std::max(drift, std::abs(glm::dot(x, up) - h));
    if (k + 1 == t0)
      v0 = glm::dot(rig.dyn->linearVelocity(1), down_slope);
  }
  *normal_drift = drift;
  const double v1 = glm::dot(rig.dyn->linearVelocity(1), down_slope);
  return (v1 - v0) / ((t1 - t0) * kDt);
}

TEST(Friction, BoxOnSlopeSticksBelowTheFrictionAngleAndSlidesAbove) {
  const double mu = 0.5;  // friction angle atan(0.5) = 26.6 degrees
  const double g = 9.81;
  for (const double deg : {10.0, 20.0, 25.0}) {
    double drift = 0.0;
    const double a = slopeAcceleration(deg * std::numbers::pi / 180, mu, &drift);
    EXPECT_NEAR(a, 0.0, 1e-4) << deg << " degrees: sticks";
    EXPECT_LT(drift, 1e-3) << deg;
  }
  for (const double deg : {30.0, 40.0}) {
    const double th = deg * std::numbers::pi / 180;
    const double expected = g * (std::sin(th) - mu * std::cos(th));
    double drift = 0.0;
    const double a = slopeAcceleration(th, mu, &drift);
    EXPECT_NEAR(a, expected, 0.01 * expected) << deg << " degrees: slides";
    EXPECT_LT(drift, 1e-3) << deg;
  }
  // frictionless: g sin
  double drift = 0.0;
  const double th = 0.3;
  EXPECT_NEAR(slopeAcceleration(th, 0.0, &drift), g * std::sin(th), 0.01 * g * std::sin(th));
}

// two cubes whose impacts fall at different times of one tick, with room for one time of
// impact: the cap is flagged and counted, and the second is held apart speculatively
TEST(TimeOfImpact, CapIsFlaggedAndTheRestHeldApart) {
  SceneModel s = floorScene(0.0, 0.5);
  // both reach the floor in the same tick: one 0.1 ms after the other
  const double h = 0.05, v = 2.0;
  for (int i = 0; i < 2; ++i) {
    Body b = dynamicBody("cube", boxShape(Vec3{h}),
                         at(Vec3{-0.3 + 0.6 * i, h + 0.0008 * v + 0.0001 * v * i, 0}), 1000.0, 0);
    b.linear_velocity_W = Vec3{0, -v, 0};
    s.bodies.push_back(b);
  }
  s.gravity_W = Vec3{0};  // a constant closing speed: the times of impact are exact
  DynamicsOptions o;
  o.max_toi_substeps = 1;
  Rig rig(std::move(s), o);
  std::uint32_t flags = 0;
  double deepest = 0.0;
  for (int k = 0; k < 5; ++k) {
    flags |= rig.tick(kDt).flags;
    for (std::uint32_t b = 1; b <= 2; ++b) {
      deepest = std::max(deepest, h - rig.dyn->pose(b).translation.y);
    }
  }
  EXPECT_NE(flags & kStepToiCapped, 0u);
  EXPECT_EQ(rig.dyn->counters().toi_capped, 1u);
  EXPECT_LT(deepest, 1e-3 * h) << "the second cube did not go into the floor";
  EXPECT_NEAR(rig.dyn->linearVelocity(1).y, 0.5 * v, 1e-9) << "the first bounced at its TOI";
  EXPECT_GE(rig.dyn->linearVelocity(2).y, 0.0) << "the second was stopped";
  // with room for both, both bounce
  SceneModel s2 = *rig.scene;
  Rig rig2(std::move(s2));
  for (int k = 0; k < 5; ++k)
    EXPECT_EQ(rig2.tick(kDt).flags & kStepToiCapped, 0u);
  EXPECT_NEAR(rig2.dyn->linearVelocity(1).y, 0.5 * v, 1e-9);
  EXPECT_NEAR(rig2.dyn->linearVelocity(2).y, 0.5 * v, 1e-9);
}

// StepReport::velocity_iterations counts the sequential-impulse iterations every solve of the
// tick ran: none without a contact, all of them when the solve may not stop early, and fewer
// (never below the minimum of two) once a resting contact has converged
TEST(Iterations, TheReportCountsTheIterationsOfEverySolve) {
  const double h = 0.05;
  const auto resting = [&](double tolerance) {
    SceneModel s = floorScene(0.5, 0.0);
    s.bodies.push_back(dynamicBody("cube", boxShape(Vec3{h}), at(Vec3{0, h, 0}), 1000.0, 0));
    DynamicsOptions o;
    o.velocity_tolerance_fraction = tolerance;
    return Rig(std::move(s), o);
  };
  Rig strict = resting(0.0);  // never early
  Rig early = resting(DynamicsOptions{}.velocity_tolerance_fraction);
  for (int k = 0; k < 300; ++k) {
    const StepReport a = strict.tick(kDt);
    const StepReport b = early.tick(kDt);
    ASSERT_GT(a.contact_points, 0u);
    EXPECT_EQ(a.velocity_iterations, 12u * (a.toi_substeps + 1)) << "tick " << k;
    EXPECT_GE(b.velocity_iterations, 2u) << "tick " << k;
    EXPECT_LE(b.velocity_iterations, 12u * (b.toi_substeps + 1)) << "tick " << k;
  }
  // resting, the default tolerance stops the solve at its minimum
  EXPECT_EQ(early.tick(kDt).velocity_iterations, 2u);
  // in free fall, far from the floor: no contact, no solve
  SceneModel s = floorScene(0.5, 0.0);
  s.bodies.push_back(dynamicBody("cube", boxShape(Vec3{h}), at(Vec3{0, 1.0, 0}), 1000.0, 0));
  Rig falling(std::move(s));
  const StepReport r = falling.tick(kDt);
  EXPECT_EQ(r.velocity_iterations, 0u);
}

// a kinematic platform moved by a client (setKinematicPose) lifts a box resting on it
TEST(Kinematic, PlatformLiftsABox) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.materials.push_back(material(0.5, 0.0));
  Body platform = staticBody("platform", boxShape(Vec3{0.3, 0.02, 0.3}), at(Vec3{0, -0.02, 0}), 0);
  platform.motion = Motion::kKinematic;
  s.bodies.push_back(platform);
  s.bodies.push_back(dynamicBody("box", boxShape(Vec3{0.05}), at(Vec3{0, 0.05, 0}), 500.0, 0));
  Rig rig(std::move(s));
  for (int k = 0; k < 200; ++k)
    rig.tick(kDt);  // settle
  const double y0 = rig.dyn->pose(1).translation.y;
  for (int k = 0; k < 1000; ++k) {
    const double y = 0.2 * (k + 1) * kDt;  // up at 0.2 m/s
    rig.dyn->setKinematicPose(0, at(Vec3{0, -0.02 + y, 0}));
    rig.tick(kDt);
    EXPECT_EQ(rig.dyn->pose(0).translation.y, -0.02 + y);
  }
  EXPECT_NEAR(rig.dyn->pose(1).translation.y - y0, 0.2, 1e-3);
  EXPECT_NEAR(rig.dyn->linearVelocity(1).y, 0.2, 1e-3);
  EXPECT_NEAR(rig.dyn->pose(1).translation.x, 0.0, 1e-6);
  // and setKinematicPose ignores a dynamic body
  const Pose before = rig.dyn->pose(1);
  rig.dyn->setKinematicPose(1, at(Vec3{5, 5, 5}));
  rig.tick(kDt);
  EXPECT_LT(glm::length(rig.dyn->pose(1).translation - before.translation), 1e-3);
}

// inputs that are not numbers change nothing; two boxes created half inside each other come
// apart without being thrown (split impulses put no energy into the velocities)
TEST(Robustness, BadInputsChangeNothingAndOverlapsSeparateGently) {
  SceneModel s = floorScene(0.5, 0.5);
  s.bodies.push_back(dynamicBody("a", boxShape(Vec3{0.05}), at(Vec3{0, 0.04, 0}), 500.0, 0));
  s.bodies.push_back(dynamicBody("b", boxShape(Vec3{0.05}), at(Vec3{0.05, 0.09, 0.01}), 500.0, 0));
  Body k = staticBody("pusher", boxShape(Vec3{0.02}), at(Vec3{0.5, 0.02, 0.5}), 0);
  k.motion = Motion::kKinematic;
  k.probe = true;
  s.bodies.push_back(k);
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  Rig rig(std::move(s), o);
  const double nan = std::nan("");
  rig.dyn->setKinematicPose(3, at(Vec3{nan, 0, 0}));
  rig.dyn->setKinematicPose(3, Pose{Vec3{0.5, 0.02, 0.5}, Quat{0, 0, 0, 0}});
  rig.dyn->setExternalWrench(1, Vec3{nan, 0, 0}, Vec3{0});
  HeldInput bad;
  bad.mode = HeldMode::kKinematic;
  bad.X_WB_target = at(Vec3{0, nan, 0});
  double fastest = 0.0;
  for (int k2 = 0; k2 < 2000; ++k2) {
    rig.tick(kDt, &bad);
    for (std::uint32_t b = 1; b <= 2; ++b) {
      const Vec3 v = rig.dyn->linearVelocity(b);
      ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
      fastest = std::max(fastest, glm::length(v));
    }
    EXPECT_EQ(rig.dyn->pose(3).translation, Vec3(0.5, 0.02, 0.5));
  }
  std::printf("overlap: fastest body %.4f m/s\n", fastest);
  // the overlap (5 cm of 10 cm boxes, and a 1 cm into the floor) was pushed out at 20% per
  // tick: nothing moved faster than falling the 4 cm b's bottom starts above the floor
  EXPECT_LT(fastest, 1.05 * std::sqrt(2 * 9.81 * 0.04));
  EXPECT_GT(rig.dyn->pose(1).translation.y, 0.05 - 1e-3);
  const geom::Transform X = geom::relativeTransform(rig.dyn->pose(1), rig.dyn->pose(2));
  EXPECT_GT(std::max({std::abs(X.t.x), std::abs(X.t.y), std::abs(X.t.z)}), 0.1 - 1e-3)
      << "the boxes came apart";
}

// a scene in units of `unit` m: gravity, and one material of friction 0.5
SceneModel scaledScene(double unit) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81 * unit, 0};
  s.materials.push_back(material(0.5, 0.0));
  return s;
}

// a slab of 6 x 6 cube pieces (half edge h, scene units) at X, dynamic at `density` or static
// (density 0)
Body slabBody(const char* name, double h, const Pose& X, double density) {
  const Primitive piece{boxShape(Vec3{h}), Pose{}, scene::ShapeSource::kCode, -1, 0};
  std::vector<Primitive> pieces;
  for (int i = 0; i < 6; ++i) {
    for (int k = 0; k < 6; ++k) {
      pieces.push_back(piece);
      pieces.back().X_BP.translation = Vec3{2 * h * i, 0, 2 * h * k};
    }
  }
  Body b = compoundBody(name, std::move(pieces), X, density > 0.0 ? density : 1.0);
  if (density <= 0.0)
    b.motion = Motion::kStatic;
  return b;
}

// more contact points offered than the solver holds: the nearest are kept. Two slabs of 36
// pieces each (6 mm across) lie side by side on a floor 40 m wide, listed after them and after a
// static rack of 36 pieces 2.5 mm above them; the rack's boxes grow by the world's margin,
// relative to the scene's size (0.28 m), so every piece of a slab is within it of every piece
// of the rack: 2 592 piece pairs, more points than the solver's 1 216. The floor's contacts
// came last and were the ones dropped: the slabs fell through it (a 5 mm part of 64 pieces
// imported twice onto a floor did so, when the parts' boxes grew by the world's margin too:
// Margins.SmallBodiesInALargeSceneAreNearOnlyWhatTheyMayReach). In mm, m and km
TEST(Capacity, SmallBodiesInALargeSceneKeepTheirFloor) {
  for (const double unit : {1e-3, 1.0, 1e3}) {
    SceneModel s = scaledScene(unit);
    const double h = 0.0005;  // the pieces' half edge
    const double density = 500.0 / (unit * unit * unit);
    for (int slab = 0; slab < 2; ++slab) {
      // dropped 1% of a piece's edge
      s.bodies.push_back(
          slabBody("slab", h * unit, at(Vec3{0.01 * slab, h * 1.01, 0} * unit), density));
    }
    s.bodies.push_back(slabBody("rack", h * unit, at(Vec3{0.002, 8 * h, 0} * unit), 0.0));
    s.bodies.push_back(
        staticBody("floor", boxShape(Vec3{20, 0.05, 20} * unit), at(Vec3{0, -0.05, 0} * unit), 0));
    DynamicsOptions o;
    o.sleep_time_s = 0.0;
    Rig rig(std::move(s), o);
    std::uint32_t full = 0;
    for (int k = 0; k < 1000; ++k)
      full |= rig.tick().flags & kStepCapacityFull;
    EXPECT_NE(full, 0u) << "more points offered than held: " << unit;
    for (std::uint32_t b = 0; b < 2; ++b) {
      const double y = rig.dyn->pose(b).translation.y / unit;
      std::printf("unit %g slab %u: origin %.6g m up (rests at %.6g)\n", unit, b, y, h);
      EXPECT_NEAR(y, h, 0.01 * h) << "slab " << b << " at unit " << unit;
    }
  }
}

// a free dynamic body's boxes grow by a margin of its own size and speed, not the world's
// (relative to the scene's size): two slabs of 36 pieces, 6 mm across and 4 mm apart on a floor
// 40 m wide, are not near each other (the world's margin, 0.28 m, made 1 296 piece pairs of
// them), and a 1 mm cube dropped 1 m, 2 cm beside them, 4.4 m/s at the floor (4.4 of its sizes a
// tick), finds the floor before it touches, never clamped, and rests on it. In mm, m and km
TEST(Margins, SmallBodiesInALargeSceneAreNearOnlyWhatTheyMayReach) {
  for (const double unit : {1e-3, 1.0, 1e3}) {
    SceneModel s = scaledScene(unit);
    const double h = 0.0005;
    const double density = 500.0 / (unit * unit * unit);
    for (int slab = 0; slab < 2; ++slab)
      s.bodies.push_back(slabBody("slab", h * unit, at(Vec3{0.01 * slab, h, 0} * unit), density));
    s.bodies.push_back(dynamicBody("cube", boxShape(Vec3{h * unit}),
                                   at(Vec3{-0.02, 1.0 + h, 0} * unit), density, 0));
    s.bodies.push_back(
        staticBody("floor", boxShape(Vec3{20, 0.05, 20} * unit), at(Vec3{0, -0.05, 0} * unit), 0));
    DynamicsOptions o;
    o.sleep_time_s = 0.0;
    Rig rig(std::move(s), o);
    std::size_t most = 0, slab_pairs = 0;
    std::uint32_t flags = 0;
    double lowest = 1e300;
    for (int k = 0; k < 1500; ++k) {
      flags |= rig.tick().flags;
      most = std::max(most, rig.world->contacts().size());
      for (const collision::Contact& c : rig.world->contacts())
        slab_pairs += c.body_a == 0 && c.body_b == 1 ? 1u : 0u;
      lowest = std::min(lowest, rig.dyn->pose(2).translation.y / unit);
    }
    std::printf("unit %g: at most %zu pairs, slab-slab %zu, cube lowest %.6g m, rests at %.6g\n",
                unit, most, slab_pairs, lowest, rig.dyn->pose(2).translation.y / unit);
    EXPECT_EQ(slab_pairs, 0u) << unit;
    // each slab's pieces with the floor, the cube with the floor: no more
    EXPECT_LE(most, 2u * 36u + 1u) << unit;
    EXPECT_EQ(flags & kStepSpeedClamped, 0u) << unit;
    // it did not pass through the floor (its top at 1 mm: it went below by less than its slop)
    EXPECT_GT(lowest, h - 0.01 * h) << unit;
    EXPECT_NEAR(rig.dyn->pose(2).translation.y / unit, h, 0.01 * h) << unit;
  }
}

// a scene of 5 mm slabs for the held body's margins: `s` with a kinematic probe slab at
// `probe_at` (unscaled) and a 40 m static floor under it, the probe's base margin 0.4 mm
// (scaled), sleep off
struct MarginRig {
  std::unique_ptr<collision::CollisionWorld> world;
  std::unique_ptr<Dynamics> dyn;
};
MarginRig marginRig(SceneModel& s, double unit, const Vec3& probe_at) {
  Body probe = slabBody("probe", 0.0005 * unit, at(probe_at * unit), 0.0);
  probe.motion = Motion::kKinematic;
  s.probe_body = static_cast<std::int32_t>(s.bodies.size());
  s.bodies.push_back(probe);
  s.bodies.push_back(
      staticBody("floor", boxShape(Vec3{20, 0.05, 20} * unit), at(Vec3{0, -0.05, 0} * unit), 0));
  s.length_scale = lengthScale(s);
  collision::WorldOptions wo;
  wo.probe_margin = 0.0004 * unit;
  MarginRig r;
  r.world = buildCollisionWorld(s, wo).value();
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  r.dyn = Dynamics::create(s, *r.world, o).value();
  return r;
}

// pairs listed between bodies a < b
std::size_t pairsBetween(const collision::CollisionWorld& world, std::uint32_t a, std::uint32_t b) {
  std::size_t n = 0;
  for (const collision::Contact& c : world.contacts())
    n += c.body_a == a && c.body_b == b ? 1u : 0u;
  return n;
}

// the held probe's boxes grow by its base margin (WorldOptions::probe_margin: what the proxy
// reads) or twice its travel in a tick, not the world's margin (0.28 m on a 40 m floor): a 5 mm
// probe of 36 pieces 2 cm from a slab of 36 is near none of its pieces at rest (the world's
// margin made 1 296 pairs of them); moving 1 cm a tick its margin is 2 cm, then at rest again
// its base. In mm, m and km
TEST(Margins, TheHeldProbeIsNearWhatTheProxyReadsOrItsTravelReaches) {
  for (const double unit : {1e-3, 1.0, 1e3}) {
    SceneModel s = scaledScene(unit);
    const double h = 0.0005;
    s.bodies.push_back(
        slabBody("slab", h * unit, at(Vec3{0, h, 0} * unit), 500.0 / (unit * unit * unit)));
    MarginRig rig = marginRig(s, unit, Vec3{0.025, 2 * h, 0});
    auto& world = rig.world;
    auto& dyn = rig.dyn;
    ASSERT_GT(world->options().box_margin, 0.2 * unit);
    const auto probePairs = [&] { return pairsBetween(*world, 0, 1); };
    HeldInput in;
    in.mode = HeldMode::kKinematic;
    std::size_t near_at_rest = 0;
    for (int k = 0; k < 100; ++k) {
      in.X_WB_target = at(Vec3{0.025, 2 * h, 0} * unit);
      world->step();
      dyn->step(*world, 0.001, &in);
      near_at_rest += probePairs();
    }
    EXPECT_EQ(near_at_rest, 0u) << unit;
    EXPECT_EQ(world->margin(1), 0.0004 * unit) << unit;
    // 1 cm a tick away from the slab, along x
    for (int k = 1; k <= 5; ++k) {
      in.X_WB_target = at(Vec3{0.025 + 0.01 * k, 2 * h, 0} * unit);
      world->step();
      dyn->step(*world, 0.001, &in);
    }
    EXPECT_NEAR(world->margin(1), 0.02 * unit, 1e-9 * unit) << unit;
    world->step();
    dyn->step(*world, 0.001, &in);
    EXPECT_EQ(world->margin(1), 0.0004 * unit) << unit;
  }
}

// a body the hand holds (driven: attached to the held body, whose contacts the proxy reads)
// has the held body's margin, its base (what the proxy reads) or twice its travel, not the
// world's: a grabbed 5 mm slab of 36 pieces 2 cm from another is near none of its pieces while
// held still (the world's margin, 0.28 m on a 40 m floor, made 1 296 pairs of them); moved 1 cm a
// tick its margin is 2 cm; let go, a free body's own. In mm, m and km
TEST(Margins, ABodyTheHandHoldsIsNearWhatTheProxyReadsOrItsTravelReaches) {
  for (const double unit : {1e-3, 1.0, 1e3}) {
    SceneModel s = scaledScene(unit);
    const double h = 0.0005;
    const double density = 500.0 / (unit * unit * unit);
    s.bodies.push_back(slabBody("slab", h * unit, at(Vec3{0, h, 0} * unit), density));
    s.bodies.push_back(slabBody("held", h * unit, at(Vec3{0.025, h, 0} * unit), density));
    MarginRig rig = marginRig(s, unit, Vec3{0.025, 4 * h, 0});
    auto& world = rig.world;
    auto& dyn = rig.dyn;
    ASSERT_GT(world->options().box_margin, 0.2 * unit);
    const auto slabPairs = [&] { return pairsBetween(*world, 0, 1); };
    HeldInput in;
    in.mode = HeldMode::kKinematic;
    in.X_WB_target = at(Vec3{0.025, 4 * h, 0} * unit);
    dyn->setDriven(1, true);
    std::size_t near_held_still = 0;
    for (int k = 0; k < 100; ++k) {
      dyn->setKinematicPose(1, at(Vec3{0.025, h, 0} * unit));
      world->step();
      dyn->step(*world, 0.001, &in);
      near_held_still += slabPairs();
    }
    EXPECT_EQ(near_held_still, 0u) << unit;
    EXPECT_EQ(world->margin(1), 0.0004 * unit) << unit;
    // 1 cm a tick away from the other slab, along x, the probe with it
    for (int k = 1; k <= 5; ++k) {
      in.X_WB_target = at(Vec3{0.025 + 0.01 * k, 4 * h, 0} * unit);
      dyn->setKinematicPose(1, at(Vec3{0.025 + 0.01 * k, h, 0} * unit));
      world->step();
      dyn->step(*world, 0.001, &in);
    }
    // (twice its travel and a tick of its gravity, which a driven body does not feel)
    EXPECT_NEAR(world->margin(1), 2.0 * (0.01 + 9.81e-6) * unit, 1e-9 * unit) << unit;
    // let go, the hand moving on with it: it moves on at 10 m/s (scaled), a free body's margin
    // of its own reach
    dyn->setDriven(1, false);
    in.X_WB_target = at(Vec3{0.085, 4 * h, 0} * unit);
    world->step();
    dyn->step(*world, 0.001, &in);
    EXPECT_NEAR(dyn->linearVelocity(1).x, 10.0 * unit, 0.01 * unit) << unit;
    EXPECT_LE(world->margin(1), world->options().box_margin) << unit;
    EXPECT_GT(world->margin(1), 0.019 * unit) << unit;
  }
}

// a box sliding over a floor of flush tiles (separate static boxes, their tops in one plane)
// slides as over one floor: frictionless it keeps its speed, level and unturned; with friction
// it stops where it stops on one floor. Before the levelling of contacts at flush seams
// (CollisionWorld, WorldOptions::level_flush_seams) the next tile's edge, level with the box's
// bottom, struck it as a wall: a 2 cm box at 0.5 m/s stopped at the first seam turning at 18
// rad/s, at 8 m/s it flew up 0.46 m turning at 300 rad/s. A tile 10 % of the box's edge higher is
// a step it strikes still. In mm, m and km
TEST(Seams, ABoxSlidesOverFlushTilesAsOverOneFloor) {
  struct Run {
    double x = 0.0, vx = 0.0, vy_max = 0.0, rise = 0.0, spin = 0.0;
  };
  // n tiles of 10 cm (one of 4 m for n = 1), the tile after the first `step` higher
  const auto slide = [](double unit, int n, double speed, double mu, double step) {
    SceneModel s = scaledScene(unit);
    s.materials[0] = material(mu, 0.0);
    const double h = 0.01;
    for (int i = 0; i < n; ++i) {
      const double half = n == 1 ? 2.0 : 0.05;
      const double x = n == 1 ? 1.95 : 0.1 * i;
      const double up = i >= 1 ? step : 0.0;
      s.bodies.push_back(staticBody("tile", boxShape(Vec3{half, 0.05, 0.5} * unit),
                                    at(Vec3{x, -0.05 + up, 0} * unit), 0));
    }
    Body box = dynamicBody("box", boxShape(Vec3{h * unit}), at(Vec3{0.0, h, 0} * unit),
                           500.0 / (unit * unit * unit), 0);
    box.linear_velocity_W = Vec3{speed, 0, 0} * unit;
    s.bodies.push_back(box);
    DynamicsOptions o;
    o.sleep_time_s = 0.0;
    Rig rig(std::move(s), o);
    const auto b = static_cast<std::uint32_t>(n);
    Run r;
    for (int k = 0; k < 400; ++k) {
      rig.tick();
      r.vy_max = std::max(r.vy_max, std::abs(rig.dyn->linearVelocity(b).y) / unit);
      r.rise = std::max(r.rise, rig.dyn->pose(b).translation.y / unit - h);
      r.spin = std::max(r.spin, glm::length(rig.dyn->angularVelocity(b)));
    }
    r.x = rig.dyn->pose(b).translation.x / unit;
    r.vx = rig.dyn->linearVelocity(b).x / unit;
    return r;
  };
  for (const double unit : {1e-3, 1.0, 1e3}) {
    // At each speed the box's front lands on a seam exactly at a tick. At 2 m/s in mm and km
    // it lay there a rounding's tilt above the tile it was leaving: that pair, touching, was
    // answered by one point (the corner that touched), and the next tile's by its side's normal
    // (a tie at zero depth), from a support the seams' levelling did not see (its closest
    // features an edge and a corner): the box tipped over (36 and 104 rad/s)
    for (const double speed : {0.5, 2.0, 8.0}) {
      const Run one = slide(unit, 1, speed, 0.0, 0.0);
      const Run tiles = slide(unit, 40, speed, 0.0, 0.0);
      std::printf(
          "unit %g speed %g: one floor x %.9g vx %.9g; tiles x %.9g vx %.9g, |vy| %.3g, "
          "rise %.3g, spin %.3g\n",
          unit, speed, one.x, one.vx, tiles.x, tiles.vx, tiles.vy_max, tiles.rise, tiles.spin);
      EXPECT_NEAR(tiles.vx, speed, 1e-9 * speed) << unit << " " << speed;
      EXPECT_NEAR(tiles.x, one.x, 1e-9) << unit << " " << speed;
      EXPECT_LT(tiles.vy_max, 1e-9 * speed) << unit << " " << speed;
      EXPECT_LT(tiles.rise, 1e-9) << unit << " " << speed;
      // (at 2 m/s in mm and km the tick the box's weight passes onto the next tile ends its
      // solve within the solver's convergence tolerance but not exactly: 3.3e-8 rad/s, taken
      // back the next tick; the tolerance, DynamicsOptions::velocity_tolerance_fraction, allows
      // 3.9e-7 rad/s at the box's corner here. At 0.5 and 8 m/s the solve ends exactly)
      EXPECT_LT(tiles.spin, speed == 2.0 ? 1e-7 : 1e-9) << unit << " " << speed;
    }
    // with friction it stops where it stops on one floor
    const Run one = slide(unit, 1, 2.0, 0.5, 0.0);
    const Run tiles = slide(unit, 40, 2.0, 0.5, 0.0);
    EXPECT_NEAR(tiles.x, one.x, 1e-6) << unit;
    EXPECT_LT(tiles.spin, 1e-3) << unit;
    // a step of 1 mm (5 % of the box's edge) is struck
    const Run step = slide(unit, 40, 0.5, 0.0, 0.001);
    EXPECT_LT(step.x, 0.06) << "stopped at the step (0.04 at its face): " << unit;
  }
}

// a resting scene sleeps (steps do no work) and wakes when pushed
TEST(Sleep, RestingSceneSleepsAndWakesWhenPushed) {
  SceneModel s = floorScene(0.5, 0.0);
  s.bodies.push_back(dynamicBody("box", boxShape(Vec3{0.05}), at(Vec3{0, 0.05, 0}), 500.0, 0));
  Rig rig(std::move(s));
  std::uint32_t first_asleep = 0;
  for (std::uint32_t k = 0; k < 2000; ++k) {
    if ((rig.tick(kDt).flags & kStepAsleep) != 0 && first_asleep == 0)
      first_asleep = k;
  }
  EXPECT_GE(first_asleep, 500u) << "still for sleep_time_s first";
  EXPECT_LT(first_asleep, 1000u);
  const std::uint64_t worked = rig.dyn->counters().ticks;
  EXPECT_EQ(worked + rig.dyn->counters().ticks_asleep, 2000u);
  const Pose rest = rig.dyn->pose(1);
  // a push wakes it: twice the friction force, so the box slides
  const double m = rig.scene->bodies[1].mass;
  rig.dyn->setExternalWrench(1, Vec3{2.0 * 0.5 * m * 9.81, 0, 0}, Vec3{0});
  for (int k = 0; k < 100; ++k)
    EXPECT_EQ(rig.tick(kDt).flags & kStepAsleep, 0u);
  EXPECT_GT(rig.dyn->pose(1).translation.x - rest.translation.x, 0.01);
  // released, it stops, and sleeps again
  rig.dyn->setExternalWrench(1, Vec3{0}, Vec3{0});
  std::uint32_t flags = 0;
  for (int k = 0; k < 2000; ++k)
    flags = rig.tick(kDt).flags;
  EXPECT_NE(flags & kStepAsleep, 0u);
  // and never with sleep_time_s = 0
  SceneModel s2 = *rig.scene;
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  Rig awake(std::move(s2), o);
  for (int k = 0; k < 2000; ++k)
    EXPECT_EQ(awake.tick(kDt).flags & kStepAsleep, 0u);
}

// a scene without a probe body: the Simulation adds a probe sphere of its own after the scene's
// bodies; held kinematically, it pushes a box along the floor and feels it
TEST(HeldBody, ExtraProbeSpherePushesABox) {
  SceneModel s = floorScene(0.3, 0.0);
  s.bodies.push_back(dynamicBody("box", boxShape(Vec3{0.05}), at(Vec3{0, 0.05, 0}), 500.0, 0));
  s.length_scale = lengthScale(s);
  auto world = buildCollisionWorld(s, {}).value();
  collision::BodyDesc probe;
  probe.kind = collision::BodyKind::kProbe;
  probe.primitives.push_back({ellipsoidShape(Vec3{0.01}), geom::Transform{}});
  const Pose start = at(Vec3{-0.07, 0.05, 0});
  ASSERT_EQ(world->addBody(probe, start), 2u);
  DynamicsOptions o;
  o.extra_probe_body = 2;
  auto dyn = Dynamics::create(s, *world, o).value();
  HeldInput in;
  in.mode = HeldMode::kKinematic;
  double felt = 0.0;
  for (int k = 0; k < 1000; ++k) {
    in.X_WB_target = at(start.translation + Vec3{0.1 * (k + 1) * kDt, 0, 0});  // 0.1 m/s
    world->step();
    dyn->step(*world, kDt, &in);
    felt += dyn->heldFeedback().impulse_W_ns.x;
  }
  // the sphere moved 0.1 m, the first 0.01 m of it to reach the box: the box followed it
  EXPECT_NEAR(dyn->pose(1).translation.x, 0.1 - 0.01, 1e-3);
  EXPECT_NEAR(dyn->linearVelocity(1).x, 0.1, 1e-2);
  EXPECT_LT(felt, 0.0) << "the hand is pushed back";
  // kinetic friction on the box over the pushing time: mu m g t (the sphere's push balances it)
  const double m = s.bodies[1].mass;
  EXPECT_NEAR(-felt, 0.3 * m * 9.81 * 0.9 + m * 0.1, 0.1 * (0.3 * m * 9.81 * 0.9));
  EXPECT_EQ(dyn->pose(2).translation, in.X_WB_target.translation);
  o.extra_probe_body = 5;
  EXPECT_FALSE(Dynamics::create(s, *world, o).ok());
}

}  // namespace
}  // namespace hapticd::dynamics::testing
