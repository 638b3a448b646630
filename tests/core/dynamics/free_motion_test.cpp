// Motion without contact against closed form: free fall, a spin about a principal axis,
// torque-free precession of an asymmetric body (energy and angular momentum conserved); mass
// properties; gravity only where declared; a scene without dynamic bodies costs nothing.
#include <gtest/gtest.h>

#include <limits>

#include "tests/core/alloc_counter.h"
#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;

TEST(MassProperties, BoxMatchesClosedForm) {
  const Vec3 h{0.1, 0.2, 0.3};
  std::vector<Primitive> prims{Primitive{boxShape(h), Pose{Vec3{1, 2, 3}, Quat{1, 0, 0, 0}}}};
  const MassProperties mp = computeMassProperties(prims, 500.0);
  const double m = 500.0 * 8 * h.x * h.y * h.z;
  EXPECT_NEAR(mp.mass, m, 1e-12 * m);
  EXPECT_NEAR(glm::length(mp.com_B - Vec3{1, 2, 3}), 0.0, 1e-12);
  const Vec3 d = 2.0 * h;
  EXPECT_NEAR(mp.inertia_B[0][0], m / 12 * (d.y * d.y + d.z * d.z), 1e-12 * m);
  EXPECT_NEAR(mp.inertia_B[1][1], m / 12 * (d.x * d.x + d.z * d.z), 1e-12 * m);
  EXPECT_NEAR(mp.inertia_B[2][2], m / 12 * (d.x * d.x + d.y * d.y), 1e-12 * m);
  EXPECT_NEAR(mp.inertia_B[0][1], 0.0, 1e-12 * m);
  EXPECT_NEAR(mp.inertia_B[1][2], 0.0, 1e-12 * m);
}

TEST(FreeMotion, FreeFallMatchesClosedForm) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  Body b = dynamicBody("box", boxShape(Vec3{0.05}), at(Vec3{0, 10, 0}), 1000.0);
  b.linear_velocity_W = Vec3{1.0, 2.0, 0.0};
  s.bodies.push_back(b);
  Rig rig(std::move(s));
  const int n = 1000;
  rig.run(n, kDt);
  const double t = n * kDt;
  const Vec3 v = rig.dyn->linearVelocity(0);
  // velocity exact; position: semi-implicit Euler adds exactly g t dt / 2 (first order)
  EXPECT_NEAR(v.x, 1.0, 1e-12);
  EXPECT_NEAR(v.y, 2.0 - 9.81 * t, 1e-11);
  const Vec3 x = rig.dyn->pose(0).translation;
  const double closed = 10.0 + 2.0 * t - 0.5 * 9.81 * t * t;
  const double euler = closed - 0.5 * 9.81 * t * kDt;
  EXPECT_NEAR(x.y, euler, 1e-10);
  EXPECT_LE(std::abs(x.y - closed), 0.5 * 9.81 * t * kDt * (1 + 1e-9));
  EXPECT_NEAR(x.x, t, 1e-12);
  EXPECT_EQ(rig.dyn->counters().ticks, static_cast<std::uint64_t>(n));
}

TEST(FreeMotion, NoGravityWhereNotDeclaredAndGravityFactor) {
  SceneModel s;  // no gravity declared
  s.bodies.push_back(dynamicBody("a", boxShape(Vec3{0.05}), at(Vec3{0, 1, 0}), 1000.0));
  Rig rig(s);
  rig.run(200, kDt);
  EXPECT_EQ(rig.dyn->pose(0).translation, Vec3(0, 1, 0));

  SceneModel g = s;
  g.gravity_W = Vec3{0, -10, 0};
  g.bodies[0].gravity_factor = 0.5;
  Rig rig2(g);
  for (int k = 0; k < 1000; ++k)
    rig2.tick(kDt);
  EXPECT_NEAR(rig2.dyn->linearVelocity(0).y, -5.0, 1e-11);
}

TEST(FreeMotion, BallisticSpinAboutPrincipalAxis) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  Body b = dynamicBody("bar", boxShape(Vec3{0.2, 0.05, 0.1}), at(Vec3{0, 0, 0}), 1000.0);
  b.angular_velocity_W = Vec3{0, 7.0, 0};
  b.linear_velocity_W = Vec3{0, 5.0, 0};
  s.bodies.push_back(b);
  Rig rig(std::move(s));
  const int n = 2000;
  rig.run(n, kDt);
  const double t = n * kDt;
  const Quat expected = glm::angleAxis(7.0 * t, Vec3{0, 1, 0});
  const Quat q = rig.dyn->pose(0).rotation;
  EXPECT_GT(std::abs(glm::dot(q, expected)), 1.0 - 1e-12);
  EXPECT_NEAR(glm::length(rig.dyn->angularVelocity(0) - Vec3{0, 7, 0}), 0.0, 1e-10);
  EXPECT_NEAR(rig.dyn->linearVelocity(0).y, 5.0 - 9.81 * t, 1e-10);
}

// an asymmetric body spinning near its intermediate axis tumbles (Dzhanibekov): the hardest
// torque-free case; energy and world angular momentum must hold
TEST(FreeMotion, TorqueFreePrecessionConservesEnergyAndMomentum) {
  SceneModel s;
  Body b = dynamicBody("brick", boxShape(Vec3{0.3, 0.1, 0.05}), at(Vec3{0}), 1000.0);
  b.angular_velocity_W = Vec3{0.05, 6.0, 0.05};
  s.bodies.push_back(b);
  Rig rig(s);
  const Mat3 I_B = rig.scene->bodies[0].inertia_B;
  const auto momentum = [&] {
    const Mat3 R = glm::mat3_cast(rig.dyn->pose(0).rotation);
    return R * I_B * glm::transpose(R) * rig.dyn->angularVelocity(0);
  };
  const double e0 = rig.dyn->kineticEnergy();
  const Vec3 L0 = momentum();
  double worst_e = 0.0, worst_l = 0.0, worst_first_half = 0.0;
  double min_wz = 1e9, max_wz = -1e9;
  for (int k = 0; k < 20000; ++k) {
    rig.tick(kDt);
    worst_e = std::max(worst_e, std::abs(rig.dyn->kineticEnergy() - e0) / e0);
    if (k == 9999)
      worst_first_half = worst_e;
    worst_l = std::max(worst_l, glm::length(momentum() - L0) / glm::length(L0));
    const Vec3 w_B =
        glm::transpose(glm::mat3_cast(rig.dyn->pose(0).rotation)) * rig.dyn->angularVelocity(0);
    min_wz = std::min(min_wz, w_B.y);
    max_wz = std::max(max_wz, w_B.y);
  }
  EXPECT_LT(worst_l, 1e-10);                    // L is carried exactly (up to rounding)
  EXPECT_LT(worst_e, 2e-6);                     // second order in w dt (here 0.006): 5e-7 measured
  EXPECT_LE(worst_e, 1.01 * worst_first_half);  // bounded: no drift in the second 10 s
  std::printf("precession: worst relative energy error %.3g, momentum %.3g\n", worst_e, worst_l);
  EXPECT_LT(min_wz, 0.0);  // it did tumble: the body-frame spin reversed
  EXPECT_GT(max_wz, 0.0);
}

// a fast tumble (|w| from 150 to 180 rad/s: w dt up to 0.18 rad per tick) of an asymmetric
// body: carrying L keeps |w| bounded where explicit gyroscopic integration blows up, and the
// splitting keeps the energy within 1e-3
TEST(FreeMotion, FastTumbleStaysBounded) {
  SceneModel s;
  Body b = dynamicBody("brick", boxShape(Vec3{0.3, 0.1, 0.05}), at(Vec3{0}), 1000.0);
  b.angular_velocity_W = Vec3{2.0, 150.0, 2.0};  // tumbles: |w| up to 180 rad/s
  s.bodies.push_back(b);
  Rig rig(s);
  const Mat3 I_B = rig.scene->bodies[0].inertia_B;
  const double e0 = rig.dyn->kineticEnergy();
  const Vec3 L0 = I_B * b.angular_velocity_W;
  double worst_e = 0.0, worst_l = 0.0;
  for (int k = 0; k < 20000; ++k) {
    rig.tick(kDt);
    const Mat3 R = glm::mat3_cast(rig.dyn->pose(0).rotation);
    const Vec3 L = R * I_B * glm::transpose(R) * rig.dyn->angularVelocity(0);
    worst_l = std::max(worst_l, glm::length(L - L0) / glm::length(L0));
    worst_e = std::max(worst_e, std::abs(rig.dyn->kineticEnergy() - e0) / e0);
  }
  EXPECT_LT(worst_l, 1e-9);
  EXPECT_LT(worst_e, 1e-3);  // |w| <= |L| / I_min always; the energy error is O((w dt)^2)
  EXPECT_EQ(rig.dyn->counters().speed_clamped, 0u);
  std::printf("fast tumble (w dt up to 0.18): worst relative energy error %.3g, momentum %.3g\n",
              worst_e, worst_l);
}

// KHR: a declared mass of 0 is infinite (the body coasts, nothing pushes it); a declared
// inertia component of 0 is infinite about that axis (the body never turns about it)
TEST(MassProperties, ZeroMeansInfinite) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  Body heavy = dynamicBody("heavy", boxShape(Vec3{0.1}), at(Vec3{0, 0, 0}), 1000.0);
  heavy.mass = 0.0;
  heavy.linear_velocity_W = Vec3{0.5, 0, 0};
  Body ball = dynamicBody("ball", ellipsoidShape(Vec3{0.02}), at(Vec3{0, 0.3, 0}), 1000.0);
  Body wheel = dynamicBody("wheel", boxShape(Vec3{0.1, 0.02, 0.1}), at(Vec3{1, 0, 0}), 1000.0);
  wheel.inertia_B[0][0] = 0.0;  // infinite about x and z: it may only turn about y
  wheel.inertia_B[2][2] = 0.0;
  wheel.angular_velocity_W = Vec3{1, 2, 3};
  s.bodies = {heavy, ball, wheel};
  s.gravity_W = Vec3{0, -9.81, 0};
  Rig rig(s);
  double ball_min_vy = 0.0;
  bool bounced = false;
  for (int k = 0; k < 400; ++k) {
    rig.tick(kDt);
    const double vy = rig.dyn->linearVelocity(1).y;
    ball_min_vy = std::min(ball_min_vy, vy);
    bounced = bounced || (ball_min_vy < -1.0 && vy >= 0.0);
    EXPECT_EQ(rig.dyn->linearVelocity(0), Vec3(0.5, 0, 0)) << "the infinite mass coasts";
  }
  EXPECT_NEAR(rig.dyn->pose(0).translation.x, 0.5 * 0.4, 1e-9);
  EXPECT_EQ(rig.dyn->pose(0).translation.y, 0.0) << "no gravity on an infinite mass";
  EXPECT_TRUE(bounced) << "the ball landed on it and was stopped";
  const Vec3 w = rig.dyn->angularVelocity(2);
  const Vec3 w_B = glm::transpose(glm::mat3_cast(rig.dyn->pose(2).rotation)) * w;
  EXPECT_NEAR(w_B.x, 0.0, 1e-12);
  EXPECT_NEAR(w_B.z, 0.0, 1e-12);
  EXPECT_NEAR(w_B.y, 2.0, 1e-12);
}

TEST(NoOp, SceneWithoutDynamicBodiesDoesNoWork) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.bodies.push_back(staticBody("floor", boxShape(Vec3{1, 0.1, 1}), at(Vec3{0, -0.1, 0})));
  Body k = staticBody("door", boxShape(Vec3{0.1}), at(Vec3{0, 0.5, 0}));
  k.motion = Motion::kKinematic;
  s.bodies.push_back(k);
  Rig rig(s);
  EXPECT_FALSE(rig.dyn->active());
  const std::uint64_t before = testing_alloc::count();
  for (int i = 0; i < 1000; ++i) {
    const StepReport r = rig.dyn->step(*rig.world, kDt);
    EXPECT_EQ(r.contact_points, 0u);
  }
  EXPECT_EQ(testing_alloc::count(), before);
  EXPECT_EQ(rig.dyn->counters().ticks, 0u);
  EXPECT_EQ(rig.dyn->pose(1).translation, Vec3(0, 0.5, 0));
}

TEST(Create, RefusesBadBodiesAndOptions) {
  SceneModel s;
  Body b = dynamicBody("a", boxShape(Vec3{0.1}), at(Vec3{0}), 1000.0);
  b.mass = -1.0;
  s.bodies.push_back(b);
  auto world = buildCollisionWorld(s, {}).value();
  auto r = Dynamics::create(s, *world);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("'a'"), std::string::npos);
  s.bodies[0].mass = std::nan("");
  EXPECT_FALSE(Dynamics::create(s, *world).ok());
  s.bodies[0].mass = 1.0;
  s.bodies[0].inertia_B[1][1] = -1.0;
  EXPECT_FALSE(Dynamics::create(s, *world).ok());
  s.bodies[0].inertia_B[1][1] = s.bodies[0].inertia_B[0][0];
  ASSERT_TRUE(Dynamics::create(s, *world).ok());
  DynamicsOptions o;
  o.velocity_iterations = 0;
  EXPECT_FALSE(Dynamics::create(s, *world, o).ok());
  for (const double t : {-0.001, std::nan(""), std::numeric_limits<double>::infinity()}) {
    DynamicsOptions bad;
    bad.slop_settle_time_s = t;
    EXPECT_FALSE(Dynamics::create(s, *world, bad).ok()) << t;
  }
  DynamicsOptions off;
  off.slop_settle_time_s = 0.0;  // no gravity bound on the slop
  EXPECT_TRUE(Dynamics::create(s, *world, off).ok());
  scene::Joint j;
  j.body_a = 0;
  j.body_b = 5;
  s.joints.push_back(j);
  EXPECT_FALSE(Dynamics::create(s, *world).ok());
}

}  // namespace
}  // namespace hapticd::dynamics::testing
