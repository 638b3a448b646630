// The attach modes of §6.2, tick by tick: a body grabbed rigidly and carried; a wheel on a hinge
// attached at its rim (the probe keeps its radius and turns with the wheel) and at its centre
// (the probe becomes the wheel: fixed position, turning about the axis, felt through torque),
// each driven until a tooth of the wheel meets a stop.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/core/alloc_counter.h"
#include "tests/core/geometry_helpers.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

using scene::Motion;
constexpr double kPi = std::numbers::pi;

using testing::prism;

TEST(Attach, GrabARigidBodyCarryItSetItDownAndLetGo) {
  scene::SceneModel s;
  s.bodies.push_back(
      makeBody("floor", Motion::kStatic, at(0, -0.05, 0), {boxShape(Vec3{0.2, 0.05, 0.2})}));
  s.bodies.push_back(makeBody("box", Motion::kDynamic, at(0, 0.01, 0), {boxShape(Vec3{0.01})}));
  // under gravity: the dynamics move the box once it is let go (it leaves the hand with the
  // hand's last velocity; without gravity it would drift on from there), so it comes to rest on
  // the floor where it was set down
  s.gravity_W = Vec3{0.0, -9.81, 0.0};
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(make(finish(s), o), o);
  const double r = o.probe_sphere_radius_m;
  const double touch = 0.02 + r + 0.0003;  // 0.3 mm above the box's top
  Path path({{0.0, at(0, 0.06, 0)},
             {0.5, at(0, touch, 0)},
             {0.7, at(0, touch, 0), 1},             // press: grab
             {1.5, at(0.05, touch + 0.03, 0), 1},   // carry up and across
             {2.5, at(0.05, touch - 0.002, 0), 1},  // set it down, pressing 2 mm
             {3.0, at(0.05, touch - 0.002, 0), 1},
             {3.2, at(0.05, touch, 0), 0},  // let go
             {4.0, at(0.05, 0.06, 0), 0},
             {4.2, at(0.05, 0.06, 0), 0}});
  std::uint8_t mode_carrying = 0;
  run.sim().prepareThread();  // as the daemon does on its servo thread before the first tick
  const std::uint64_t allocations_before = testing_alloc::count();
  Vec3 box_carried{0.0}, box_end{0.0};
  double set_down_force = 0.0;
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    if (std::abs(in.t_s - 1.5) < 1e-9) {
      mode_carrying = out.attach_mode;
      box_carried = run.sim().bodyPoses()[0].X_WB.translation;
    }
    if (std::abs(in.t_s - 2.9) < 1e-9)
      set_down_force = out.force_W_n.y;
    box_end = run.sim().bodyPoses()[0].X_WB.translation;
  });
  const std::uint64_t allocations = testing_alloc::count() - allocations_before;
  f.print("grab, carry, set down, let go");
  EXPECT_EQ(allocations, 0u);  // grabbing and letting go allocate nothing
  std::printf(
      "  carried to (%.2f, %.2f, %.2f) mm; set down pressing 2 mm: %.3f N; left at (%.2f, %.2f, "
      "%.2f) mm\n",
      1e3 * box_carried.x, 1e3 * box_carried.y, 1e3 * box_carried.z, set_down_force,
      1e3 * box_end.x, 1e3 * box_end.y, 1e3 * box_end.z);
  expectInvariants(f, o, 1e-3);
  EXPECT_EQ(mode_carrying, 1);
  EXPECT_NEAR(box_carried.x, 0.05, 1e-4);
  // carried 0.03 m up, less the coupling's sag under the box's weight (grab_weight, the 1 kg box
  // felt at the hand): m g / k_c, k_c = k_s r / (r - 1) with r the proxy stiffness ratio
  const double k_c = o.response.stiffness_n_per_m * o.response.proxy_stiffness_ratio /
                     (o.response.proxy_stiffness_ratio - 1.0);
  EXPECT_NEAR(box_carried.y, 0.04 - 1.0 * 9.81 / k_c, 1e-3);
  EXPECT_GT(set_down_force, 0.9);      // the floor pushes the carried box back: k_s * ~2 mm
  EXPECT_NEAR(box_end.x, 0.05, 1e-4);  // it stays where it was let go
  EXPECT_NEAR(box_end.y, 0.01, 1e-4);  // on the floor
}

// A wheel (16-gon hub of radius 40 mm, 10 mm thick, one tooth out to 50 mm at angle 0) on a
// hinge about z through the origin, and a static stop at 30 degrees that the tooth meets.
std::shared_ptr<const scene::SceneModel> wheelScene() {
  scene::SceneModel s;
  Pose tooth_pose = at(0.045, 0, 0);
  s.bodies.push_back(
      makeBody("wheel", Motion::kDynamic, at(0, 0, 0),
               {hullShape(prism(16, 0.04, 0.005)), boxShape(Vec3{0.005, 0.003, 0.005})},
               {Pose{}, tooth_pose}));
  const Quat q30 = axisAngle(Vec3{0, 0, 1}, kPi / 6);
  s.bodies.push_back(makeBody("stop", Motion::kStatic,
                              Pose{0.046 * Vec3{std::cos(kPi / 6), std::sin(kPi / 6), 0}, q30},
                              {boxShape(Vec3{0.004, 0.003, 0.005})}));
  scene::Joint j;
  j.kind = scene::JointKind::kHinge;
  j.body_a = 0;
  j.body_b = -1;
  j.hinge_axis = 2;
  s.joints.push_back(j);
  return finish(s);
}

double wheelAngle(const sim::Simulation& sim) {
  const Quat q = sim.bodyPoses()[0].X_WB.rotation;
  return 2.0 * std::atan2(q.z, q.w);
}

TEST(Attach, AtTheRimTheProbeKeepsItsRadiusAndTurnsTheWheelUntilTheToothMeetsTheStop) {
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(make(wheelScene(), o), o);
  const double r = o.probe_sphere_radius_m;
  const double R = 0.04 + r + 0.0003;  // the probe 0.3 mm off the hub's vertex at 90 degrees
  auto onCircle = [&](double deg, double radius, std::uint32_t b) {
    const double a = deg * kPi / 180.0;
    return Key{0.0, at(radius * std::cos(a), radius * std::sin(a), 0), b};
  };
  std::vector<Key> keys;
  auto add = [&](double t, Key k) {
    k.t_s = t;
    keys.push_back(k);
  };
  add(0.0, onCircle(90, R + 0.02, 0));
  add(0.5, onCircle(90, R, 0));
  add(0.7, onCircle(90, R, 1));  // click at the rim
  for (int i = 1; i <= 20; ++i)
    add(0.7 + 0.1 * i, onCircle(90 + 1.5 * i, R, 1));  // sweep 30 degrees
  add(3.2, onCircle(120, R, 1));
  add(3.7, onCircle(120, R + 0.003, 1));  // pull outwards 3 mm: the probe keeps its radius
  add(4.0, onCircle(120, R + 0.003, 1));
  add(4.5, onCircle(120, R, 1));
  for (int i = 1; i <= 20; ++i)
    add(4.5 + 0.1 * i, onCircle(120 - 1.5 * i, R, 1));  // back
  add(6.7, onCircle(90, R, 0));
  add(7.2, onCircle(90, R + 0.02, 0));
  add(7.4, onCircle(90, R + 0.02, 0));
  double angle_mid = 0.0, angle_blocked = 0.0, radial_pull = 0.0, tangential_blocked = 0.0;
  std::uint8_t mode = 0;
  double angle_end = 1.0;
  const Path path(keys);
  run.sim().prepareThread();  // as the daemon does on its servo thread before the first tick
  const std::uint64_t allocations_before = testing_alloc::count();
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    const double a = in.t_s;
    if (std::abs(a - 1.3) < 1e-9)
      angle_mid = wheelAngle(run.sim()), mode = out.attach_mode;
    if (std::abs(a - 3.2) < 1e-9) {
      angle_blocked = wheelAngle(run.sim());
      const Vec3 t{-std::sin(120 * kPi / 180), std::cos(120 * kPi / 180), 0};
      tangential_blocked = glm::dot(out.force_W_n, t);
    }
    if (std::abs(a - 3.95) < 1e-9) {
      const Vec3 radial{std::cos(120 * kPi / 180), std::sin(120 * kPi / 180), 0};
      radial_pull = glm::dot(out.force_W_n, radial);
    }
    angle_end = wheelAngle(run.sim());
  });
  const std::uint64_t allocations = testing_alloc::count() - allocations_before;
  f.print("attach at the rim");
  EXPECT_EQ(allocations, 0u);
  std::printf(
      "  mode %u; wheel at %.2f deg when the hand is at 99 deg; blocked at %.2f deg (hand at "
      "120), tangential force %.3f N; pulled 3 mm out: radial force %.3f N; back at %.3f deg\n",
      mode, angle_mid * 180 / kPi, angle_blocked * 180 / kPi, tangential_blocked, radial_pull,
      angle_end * 180 / kPi);
  expectInvariants(f, o, 1e-3);
  EXPECT_EQ(mode, 2);
  EXPECT_NEAR(angle_mid * 180 / kPi, 9.0, 0.5);  // the wheel follows the hand round
  EXPECT_GT(angle_blocked * 180 / kPi, 15.0);    // it turned until the tooth met the stop
  EXPECT_LT(angle_blocked * 180 / kPi, 25.0);
  EXPECT_LT(tangential_blocked, -1.0);           // the stop holds the hand back
  EXPECT_LT(radial_pull, -1.5);                  // the rim pulls the hand back in
  EXPECT_NEAR(angle_end, 0.0, 0.5 * kPi / 180);  // and round back to the start
}

TEST(Attach, AtTheCentreTheProbeBecomesTheWheelAndFeelsTheStopAsTorque) {
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  Runner run(make(wheelScene(), o), o);
  const double r = o.probe_sphere_radius_m;
  const Vec3 p0{0.003, 0.0, 0.005 + r + 0.0003};  // over the hub's face, 3 mm from the axis
  auto turned = [&](double deg, std::uint32_t b, Vec3 off = Vec3{0.0}) {
    return Key{0.0, Pose{p0 + off, axisAngle(Vec3{0, 0, 1}, deg * kPi / 180.0)}, b};
  };
  std::vector<Key> keys;
  auto add = [&](double t, Key k) {
    k.t_s = t;
    keys.push_back(k);
  };
  add(0.0, turned(0, 0, Vec3{0, 0, 0.02}));
  add(0.5, turned(0, 0));
  add(0.7, turned(0, 1));   // click near the centre
  add(2.7, turned(30, 1));  // twist the handle 30 degrees
  add(3.2, turned(30, 1));
  add(3.7, turned(30, 1, Vec3{0.002, 0, 0}));  // and push it 2 mm sideways: it stays put
  add(4.0, turned(30, 1, Vec3{0.002, 0, 0}));
  add(4.5, turned(30, 1));
  add(6.5, turned(0, 1));
  add(6.7, turned(0, 0));
  add(7.2, turned(0, 0, Vec3{0, 0, 0.02}));
  add(7.4, turned(0, 0, Vec3{0, 0, 0.02}));
  double angle_mid = 0.0, angle_blocked = 0.0, torque_blocked = 0.0, side_force = 0.0,
         torque_free = 1.0;
  std::uint8_t mode = 0;
  const Figures f = run.run(Path(keys), [&](const sim::TickInput& in, const sim::TickOutput& out) {
    if (std::abs(in.t_s - 1.2) < 1e-9) {
      angle_mid = wheelAngle(run.sim());
      mode = out.attach_mode;
      torque_free = std::abs(out.torque_W_nm.z);
    }
    if (std::abs(in.t_s - 3.2) < 1e-9)
      angle_blocked = wheelAngle(run.sim()), torque_blocked = out.torque_W_nm.z;
    if (std::abs(in.t_s - 3.95) < 1e-9)
      side_force = out.force_W_n.x;
  });
  f.print("attach at the centre");
  std::printf(
      "  mode %u; wheel at %.2f deg when the hand has turned 7.5 deg (torque %.2g N m); "
      "blocked at %.2f deg with the hand at 30: torque %.4f N m; pushed 2 mm sideways: %.3f N\n",
      mode, angle_mid * 180 / kPi, torque_free, angle_blocked * 180 / kPi, torque_blocked,
      side_force);
  expectInvariants(f, o, 1e-3);
  EXPECT_EQ(mode, 3);
  EXPECT_NEAR(angle_mid * 180 / kPi, 7.5, 0.5);
  EXPECT_LT(torque_free, 1e-3);  // a free wheel turns without resistance
  EXPECT_GT(angle_blocked * 180 / kPi, 15.0);
  EXPECT_LT(angle_blocked * 180 / kPi, 25.0);
  EXPECT_LT(torque_blocked, -1e-3);  // the stop is felt through the handle's torque
  EXPECT_LT(side_force, -1.0);       // the handle's position is fixed
}

}  // namespace
}  // namespace hapticd::simtest
