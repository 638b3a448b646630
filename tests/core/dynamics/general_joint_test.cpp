// The general joint of KHR_physics_rigid_bodies (core/dynamics/dynamics_joints.cpp), each against
// a closed form: a ball-joint pendulum's period, a slider's position and velocity drives, a soft
// limit's static deflection, a drive's maxForce, a one-sided limit, a cone, enableCollision, the
// acceleration mode, a kinematic body's declared velocity. Every length is scaled by S (a scene in
// millimetres, metres and kilometres): the relative answers are the same.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;
constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;

using scene::JointDrive;
using scene::JointKind;
using scene::JointLimit;

JointLimit limit(std::uint8_t linear_axes,
                 std::uint8_t angular_axes,
                 std::optional<double> min,
                 std::optional<double> max,
                 std::optional<double> stiffness = std::nullopt,
                 double damping = 0.0) {
  JointLimit l;
  l.linear_axes = linear_axes;
  l.angular_axes = angular_axes;
  l.min = min;
  l.max = max;
  l.stiffness = stiffness;
  l.damping = damping;
  return l;
}

// a joint of the general kind between a and b (-1: the scene), frames at the anchors, unturned
scene::Joint generalJoint(std::int32_t a,
                          std::int32_t b,
                          const Vec3& anchor_A,
                          const Vec3& anchor_B,
                          std::vector<JointLimit> limits) {
  scene::Joint j = joint(JointKind::kGeneric, a, b, anchor_A, anchor_B);
  j.limits = std::move(limits);
  return j;
}

class Scaled : public ::testing::TestWithParam<double> {};

// a small cube on a massless rod of length L from a ball joint at the origin swings at the
// physical pendulum's period 2 pi sqrt(I_pivot / (m g L)) (2 pi sqrt(L / g) for a point mass; the
// cube's own inertia adds 7e-5 relative here), times 1 + theta0^2 / 16 for the amplitude.
// Tolerance 2e-3 relative: semi-implicit Euler's period error is (omega h)^2 / 24 ~ 4e-7 and the
// drift correction of the joint a fraction of the slop; 2e-3 is a broken joint's margin, not the
// integrator's.
TEST_P(Scaled, BallJointPendulumSwingsAtItsSmallAnglePeriod) {
  const double S = GetParam();
  const double L = 1.0 * S, half = 0.01 * S, theta0 = 0.05, g = kG * S;
  SceneModel s;
  s.gravity_W = Vec3{0, -g, 0};
  const Vec3 x0{L * std::sin(theta0), -L * std::cos(theta0), 0.0};
  s.bodies.push_back(dynamicBody("bob", boxShape(Vec3{half}), at(x0), 1000.0));
  s.joints.push_back(generalJoint(0, -1, -x0, Vec3{0.0}, {limit(7, 0, 0.0, 0.0)}));
  Rig rig(std::move(s));
  const double m = rig.scene->bodies[0].mass;
  const double I = m * L * L + m * (2 * half) * (2 * half) / 6.0;
  const double T = 2.0 * kPi * std::sqrt(I / (m * g * L)) * (1.0 + theta0 * theta0 / 16.0);
  std::vector<double> crossings;  // times x goes from - to +
  double prev = rig.dyn->centerOfMass(0).x, worst_anchor = 0.0;
  const int ticks = static_cast<int>(5.2 * T / kDt);
  for (int k = 1; k <= ticks; ++k) {
    rig.tick(kDt);
    const double x = rig.dyn->centerOfMass(0).x;
    if (prev < 0.0 && x >= 0.0)
      crossings.push_back(kDt * (k - 1 + prev / (prev - x)));
    prev = x;
    const Pose X = rig.dyn->pose(0);
    worst_anchor = std::max(worst_anchor, glm::length(X.translation + X.rotation * -x0));
  }
  ASSERT_GE(crossings.size(), 4u);
  const double period =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(period / T, 1.0, 2e-3) << "period " << period << " s, expected " << T << " s";
  EXPECT_LT(worst_anchor, 1e-3 * L);
}

// a slider (one free linear axis) between a static rail and a block: the block's offset along
// the free axis, its velocity along it
struct Slider {
  Rig rig;
  double mass = 0.0;
  double offset() const { return rig.dyn->centerOfMass(1)[axis]; }
  double velocity() const { return rig.dyn->linearVelocity(1)[axis]; }
  int axis = 0;
};

std::unique_ptr<Slider> slider(double S,
                               int axis,
                               std::vector<JointDrive> drives,
                               const std::vector<JointLimit>& extra = {},
                               double density = 1000.0,
                               bool gravity = false) {
  SceneModel s;
  if (gravity)
    s.gravity_W = Vec3{0, -kG * S, 0};
  s.bodies.push_back(
      staticBody("rail", boxShape(Vec3{0.5 * S, 0.01 * S, 0.01 * S}), at(Vec3{0, -0.5 * S, 0})));
  s.bodies.push_back(dynamicBody("block", boxShape(Vec3{0.05 * S}), at(Vec3{0.0}), density));
  const auto others = static_cast<std::uint8_t>(7u & ~(1u << axis));
  std::vector<JointLimit> limits = {limit(others, 0, std::nullopt, 0.0), limit(0, 7, 0.0, 0.0)};
  for (const JointLimit& l : extra)
    limits.push_back(l);
  // a's frame on the rail at the block's start: the offset is the block's position
  scene::Joint j = generalJoint(0, 1, Vec3{0, 0.5 * S, 0}, Vec3{0.0}, limits);
  j.drives = std::move(drives);
  s.joints.push_back(j);
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  auto out = std::unique_ptr<Slider>(new Slider{Rig(std::move(s), o)});
  out->mass = out->rig.scene->bodies[1].mass;
  out->axis = axis;
  return out;
}

JointDrive linearDrive(int axis) {
  JointDrive d;
  d.axis = static_cast<std::uint8_t>(axis);
  return d;
}

// critically damped position drive: x(t) = xt (1 - (1 + w t) e^(-w t)), w = sqrt(k / m)
TEST_P(Scaled, SliderPositionDriveReachesItsTarget) {
  const double S = GetParam();
  const double target = 0.1 * S, w = 20.0;
  auto probe = slider(S, 0, {});
  const double m = probe->mass;
  JointDrive d = linearDrive(0);
  d.position_target = target;
  d.stiffness = m * w * w;
  d.damping = 2.0 * m * w;
  auto sl = slider(S, 0, {d});
  sl->rig.run(100);  // t = 0.1 s: w t = 2
  const double wt = w * 0.1;
  EXPECT_NEAR(sl->offset() / target, 1.0 - (1.0 + wt) * std::exp(-wt), 0.02);
  sl->rig.run(1400);  // t = 1.5 s: the closed form is within 1e-11 of the target
  EXPECT_NEAR(sl->offset() / target, 1.0, 1e-4);
  EXPECT_NEAR(sl->velocity() / target, 0.0, 1e-4);
  // the locked axes held
  const Vec3 c = sl->rig.dyn->centerOfMass(1);
  EXPECT_LT(std::hypot(c.y, c.z), 1e-6 * S);
}

// a velocity drive (damping c, no stiffness): v(t) = vt (1 - e^(-c t / m))
TEST_P(Scaled, SliderVelocityDriveReachesItsVelocity) {
  const double S = GetParam();
  const double vt = 0.2 * S, tau = 0.05;
  auto probe = slider(S, 2, {});
  JointDrive d = linearDrive(2);
  d.velocity_target = vt;
  d.damping = probe->mass / tau;
  auto sl = slider(S, 2, {d});
  sl->rig.run(50);  // one time constant
  EXPECT_NEAR(sl->velocity() / vt, 1.0 - std::exp(-1.0), 0.02);
  sl->rig.run(450);  // ten
  EXPECT_NEAR(sl->velocity() / vt, 1.0, 1e-3);
}

// a block hanging on a soft limit (min = max = 0, stiffness k) sinks by m g / k exactly; at a
// stiffness a million times larger (a period of 0.6 ticks) the implicit spring stays stable and
// its deflection is still m g / k
TEST_P(Scaled, SoftLimitDeflectsByWeightOverStiffness) {
  const double S = GetParam();
  for (const double factor : {1.0, 1e6}) {
    SceneModel s;
    s.gravity_W = Vec3{0, -kG * S, 0};
    s.bodies.push_back(dynamicBody("weight", boxShape(Vec3{0.05 * S}), at(Vec3{0.0}), 1000.0));
    const double m = s.bodies[0].mass;
    const double k = factor * m * kG * S / (0.02 * S);  // 2 cm (scaled) at factor 1
    const double c = 2.0 * std::sqrt(k * m);
    s.joints.push_back(
        generalJoint(0, -1, Vec3{0.0}, Vec3{0.0},
                     {limit(5, 0, 0.0, 0.0), limit(0, 7, 0.0, 0.0), limit(2, 0, 0.0, 0.0, k, c)}));
    DynamicsOptions o;
    o.sleep_time_s = 0.0;
    Rig rig(std::move(s), o);
    double fastest = 0.0;
    for (int t = 0; t < 2000; ++t) {
      rig.tick(kDt);
      fastest = std::max(fastest, glm::length(rig.dyn->linearVelocity(0)));
    }
    const double expected = m * kG * S / k;
    EXPECT_NEAR(-rig.dyn->centerOfMass(0).y / expected, 1.0, 1e-3) << "factor " << factor;
    EXPECT_LT(glm::length(rig.dyn->linearVelocity(0)), 1e-6 * S);
    EXPECT_LT(fastest, 1.0 * S) << "factor " << factor;  // no blow-up
  }
}

// a drive that would lift the block (target above, stiff) but may pull with at most half its
// weight: the block falls at g / 2
TEST_P(Scaled, DriveMaxForceIsRespected) {
  const double S = GetParam();
  auto probe = slider(S, 1, {}, {}, 1000.0, true);
  const double m = probe->mass;
  JointDrive d = linearDrive(1);
  d.position_target = 0.5 * S;
  d.stiffness = 1e6 * m;
  d.damping = 1e3 * m;
  d.max_force = 0.5 * m * kG * S;
  auto sl = slider(S, 1, {d}, {}, 1000.0, true);
  const int n = 200;
  sl->rig.run(n);
  // semi-implicit Euler at a constant acceleration a: v_n = a n h, x_n = a h^2 n (n + 1) / 2
  const double a = -0.5 * kG * S;
  EXPECT_NEAR(sl->offset() / (a * kDt * kDt * n * (n + 1) / 2.0), 1.0, 1e-6);
  EXPECT_NEAR(sl->velocity() / (a * kDt * n), 1.0, 1e-6);
}

// a one-sided linear limit (min only): the block falls onto it and rests there; thrown upwards
// nothing stops it: it rises v^2 / 2g
TEST_P(Scaled, OneSidedLinearLimit) {
  const double S = GetParam();
  const double floor = -0.1 * S;
  auto sl = slider(S, 1, {}, {limit(2, 0, floor, std::nullopt)}, 1000.0, true);
  double lowest = 0.0;
  for (int t = 0; t < 1000; ++t) {
    sl->rig.tick(kDt);
    lowest = std::min(lowest, sl->offset());
  }
  EXPECT_NEAR(sl->offset() / floor, 1.0, 1e-2);
  EXPECT_GT(lowest, floor - 0.02 * std::abs(floor));

  SceneModel s = *sl->rig.scene;
  const double v0 = 1.0 * S;
  s.bodies[1].linear_velocity_W = Vec3{0, v0, 0};
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  Rig up(std::move(s), o);
  double highest = 0.0;
  for (int t = 0; t < 200; ++t) {
    up.tick(kDt);
    highest = std::max(highest, up.dyn->centerOfMass(1).y);
  }
  EXPECT_NEAR(highest / (v0 * v0 / (2.0 * kG * S)), 1.0, 1e-2);
}

// a bar on a ball joint whose x axis must stay within a cone of 0.3 rad about the scene's x
// axis: gravity pulls it down, a spin about y throws it sideways; it never leaves the cone and
// ends on its edge
TEST_P(Scaled, ConeLimitKeepsABarWithinItsAngle) {
  const double S = GetParam();
  const double cone = 0.3;
  SceneModel s;
  s.gravity_W = Vec3{0, -kG * S, 0};
  Body bar = dynamicBody("bar", boxShape(Vec3{0.2 * S, 0.02 * S, 0.02 * S}),
                         at(Vec3{0.2 * S, 0, 0}), 1000.0);
  bar.angular_velocity_W = Vec3{0, 2.0, 0};
  s.bodies.push_back(bar);
  s.joints.push_back(generalJoint(0, -1, Vec3{-0.2 * S, 0, 0}, Vec3{0.0},
                                  {limit(7, 0, 0.0, 0.0), limit(0, 6, std::nullopt, cone)}));
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  Rig rig(std::move(s), o);
  double widest = 0.0;
  for (int t = 0; t < 3000; ++t) {
    rig.tick(kDt);
    const Vec3 x = rig.dyn->pose(0).rotation * Vec3{1, 0, 0};
    widest = std::max(widest, std::acos(std::clamp(x.x, -1.0, 1.0)));
  }
  const Vec3 x = rig.dyn->pose(0).rotation * Vec3{1, 0, 0};
  EXPECT_LT(widest, cone + 0.01);
  EXPECT_NEAR(std::acos(std::clamp(x.x, -1.0, 1.0)), cone, 0.01);
  EXPECT_LT(x.y, -0.2);  // it hangs down on the cone's edge
}

// a box jointed to the floor below it (a loose distance limit that never binds) falls through
// the floor when the joint keeps them apart (enableCollision false, the KHR default), rests on it
// otherwise
TEST_P(Scaled, EnableCollisionSaysWhetherJointedBodiesCollide) {
  const double S = GetParam();
  for (const bool collide : {false, true}) {
    SceneModel s;
    s.gravity_W = Vec3{0, -kG * S, 0};
    s.bodies.push_back(staticBody("floor", boxShape(Vec3{1 * S, 0.05 * S, 1 * S}), at(Vec3{0.0})));
    s.bodies.push_back(
        dynamicBody("box", boxShape(Vec3{0.05 * S}), at(Vec3{0, 0.15 * S, 0}), 1000.0));
    scene::Joint j =
        generalJoint(1, 0, Vec3{0.0}, Vec3{0, 0.15 * S, 0}, {limit(7, 0, std::nullopt, 10.0 * S)});
    j.enable_collision = collide;
    s.joints.push_back(j);
    Rig rig(std::move(s));
    rig.run(500);
    const double y = rig.dyn->centerOfMass(1).y;
    if (collide)
      EXPECT_NEAR(y / S, 0.1, 0.002);
    else
      EXPECT_LT(y / S, -0.5);  // fell 1.2 (scaled) in 0.5 s, through the floor
  }
}

// "acceleration" mode scales the gains by the effective mass: a block ten times heavier moves the
// same; in "force" mode (the same gains times the light block's mass) it does not
TEST_P(Scaled, AccelerationModeMovesEveryMassTheSame) {
  const double S = GetParam();
  const double m_light = slider(S, 0, {}, {}, 1000.0)->mass;
  for (const bool acceleration : {true, false}) {
    JointDrive d = linearDrive(0);
    d.acceleration = acceleration;
    d.position_target = 0.1 * S;
    const double scale = acceleration ? 1.0 : m_light;
    d.stiffness = 400.0 * scale;  // 1/s^2 in acceleration mode
    d.damping = 20.0 * scale;     // 1/s
    auto light = slider(S, 0, {d}, {}, 1000.0);
    auto heavy = slider(S, 0, {d}, {}, 10000.0);
    double worst = 0.0;
    for (int t = 0; t < 500; ++t) {
      light->rig.tick(kDt);
      heavy->rig.tick(kDt);
      worst = std::max(worst, std::abs(light->offset() - heavy->offset()));
    }
    if (acceleration)
      EXPECT_LT(worst, 1e-9 * S);
    else
      EXPECT_GT(worst, 1e-3 * S);
  }
}

// a hinge about y (Y up: a door) built from limits, with a velocity drive: it turns through full
// turns at the target rate (no singularity at 90 degrees), about its axis only, its anchor held.
// The drive sets b's (the scene's) rate in a's (the door's) frame: the door turns at -rate
TEST_P(Scaled, DrivenHingeAboutYTurnsFullCircles) {
  const double S = GetParam();
  const double rate = 3.0;  // rad/s: three full turns in the run
  SceneModel s;
  s.bodies.push_back(dynamicBody("door", boxShape(Vec3{0.2 * S, 0.3 * S, 0.02 * S}),
                                 at(Vec3{0.2 * S, 0, 0}), 1000.0));
  scene::Joint j = generalJoint(0, -1, Vec3{-0.2 * S, 0, 0}, Vec3{0.0},
                                {limit(7, 0, 0.0, 0.0), limit(0, 5, std::nullopt, 0.0)});
  JointDrive d;
  d.angular = true;
  d.acceleration = true;
  d.axis = 1;
  d.velocity_target = rate;
  d.damping = 50.0;  // 1/s
  j.drives.push_back(d);
  s.joints.push_back(j);
  DynamicsOptions o;
  o.sleep_time_s = 0.0;
  Rig rig(std::move(s), o);
  double worst_anchor = 0.0, worst_tilt = 0.0, turned = 0.0;
  for (int t = 0; t < 6500; ++t) {
    rig.tick(kDt);
    const Pose X = rig.dyn->pose(0);
    worst_anchor =
        std::max(worst_anchor, glm::length(X.translation + X.rotation * Vec3{-0.2 * S, 0, 0}));
    worst_tilt = std::max(worst_tilt, 1.0 - (X.rotation * Vec3{0, 1, 0}).y);
    turned += rig.dyn->angularVelocity(0).y * kDt;
  }
  const Vec3 w = rig.dyn->angularVelocity(0);
  EXPECT_NEAR(-w.y / rate, 1.0, 1e-3);
  EXPECT_LT(std::hypot(w.x, w.z), 1e-6);
  EXPECT_LT(turned, -2.0 * (2.0 * kPi));
  EXPECT_LT(worst_anchor, 1e-3 * S);
  EXPECT_LT(worst_tilt, 1e-6);
}

// a kinematic box with a declared linearVelocity moves at it (exactly) and pushes a dynamic box
// in its way along at the same speed
TEST_P(Scaled, KinematicVelocityMovesTheBodyAndPushes) {
  const double S = GetParam();
  const double v = 0.5 * S;
  SceneModel s;
  Body pusher = staticBody("pusher", boxShape(Vec3{0.05 * S}), at(Vec3{0.0}));
  pusher.motion = Motion::kKinematic;
  pusher.linear_velocity_W = Vec3{v, 0, 0};
  s.bodies.push_back(pusher);
  s.bodies.push_back(dynamicBody("box", boxShape(Vec3{0.05 * S}), at(Vec3{0.2 * S, 0, 0}), 1000.0));
  Rig rig(std::move(s));
  rig.run(1000);
  EXPECT_NEAR(rig.dyn->pose(0).translation.x / S, 0.5, 1e-9);
  EXPECT_NEAR(rig.dyn->linearVelocity(1).x / v, 1.0, 0.01);
  EXPECT_NEAR((rig.dyn->pose(1).translation.x - rig.dyn->pose(0).translation.x) / S, 0.1, 0.002);
}

INSTANTIATE_TEST_SUITE_P(MillimetresMetresKilometres, Scaled, ::testing::Values(1e-3, 1.0, 1e3));

}  // namespace
}  // namespace hapticd::dynamics::testing
