// Joints: a hinged pendulum stays on its axis, a hinge limit holds, a fixed joint keeps two
// bodies together; two gears on hinges, one driven by the held body's torque (or turned
// kinematically by the probe), turn at their tooth ratio (§6.2, "gear turning").
#include <gtest/gtest.h>

#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {
namespace {

constexpr double kDt = 0.001;
constexpr double kPi = std::numbers::pi;

scene::Joint hingeToWorld(std::int32_t body,
                          const Vec3& anchor_B,
                          const Vec3& anchor_W,
                          std::uint8_t axis) {
  return joint(scene::JointKind::kHinge, body, -1, anchor_B, anchor_W, axis);
}

// hinge angle of body 0 about z (rotation of the body from its start)
double angleZ(const Quat& q) {
  return 2.0 * std::atan2(q.z, q.w);
}

TEST(Hinge, PendulumStaysOnItsAxisAndKeepsItsEnergy) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.bodies.push_back(
      dynamicBody("bar", boxShape(Vec3{0.2, 0.02, 0.02}), at(Vec3{0.2, 1, 0}), 1000.0));
  s.joints.push_back(hingeToWorld(0, Vec3{-0.2, 0, 0}, Vec3{0, 1, 0}, 2));
  Rig rig(std::move(s));
  const double e0 = rig.energy();
  double worst_anchor = 0.0, worst_off_axis = 0.0, worst_gain = 0.0, lowest = 1e9;
  for (int k = 0; k < 10000; ++k) {
    rig.tick(kDt);
    const Pose X = rig.dyn->pose(0);
    const Vec3 anchor = X.translation + X.rotation * Vec3{-0.2, 0, 0};
    worst_anchor = std::max(worst_anchor, glm::length(anchor - Vec3{0, 1, 0}));
    const Vec3 w = rig.dyn->angularVelocity(0);
    worst_off_axis = std::max(worst_off_axis, std::hypot(w.x, w.y));
    worst_gain = std::max(worst_gain, rig.energy() - e0);
    lowest = std::min(lowest, X.translation.y);
  }
  EXPECT_LT(worst_anchor, 1e-3 * 0.2) << "anchor drift, relative to the bar";
  EXPECT_LT(worst_off_axis, 1e-9);
  const double swing = rig.scene->bodies[0].mass * 9.81 * 0.2;  // energy of the swing (J)
  EXPECT_LT(worst_gain, 1e-3 * swing);
  EXPECT_LT(lowest, 1.0 - 0.19);  // it swung through the bottom
  std::printf("pendulum: anchor drift %.3g m, energy gain %.3g J\n", worst_anchor, worst_gain);
}

TEST(Hinge, LimitHolds) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  s.bodies.push_back(
      dynamicBody("bar", boxShape(Vec3{0.2, 0.02, 0.02}), at(Vec3{0.2, 1, 0}), 1000.0));
  scene::Joint j = hingeToWorld(0, Vec3{-0.2, 0, 0}, Vec3{0, 1, 0}, 2);
  j.hinge_min = -0.5;
  j.hinge_max = 0.5;
  s.joints.push_back(j);
  DynamicsOptions o;
  o.sleep_time_s = 0.0;  // resting on the limit is solved on every tick
  Rig rig(std::move(s), o);
  double lowest = 0.0;
  for (int k = 0; k < 3000; ++k) {
    rig.tick(kDt);
    lowest = std::min(lowest, angleZ(rig.dyn->pose(0).rotation));
  }
  EXPECT_GT(lowest, -0.5 - 0.01);
  EXPECT_NEAR(angleZ(rig.dyn->pose(0).rotation), -0.5, 0.005);
  EXPECT_LT(glm::length(rig.dyn->angularVelocity(0)), 1e-3);
}

TEST(Fixed, KeepsTwoBodiesTogether) {
  SceneModel s;
  s.gravity_W = Vec3{0, -9.81, 0};
  Body a = dynamicBody("a", boxShape(Vec3{0.05}), at(Vec3{0, 0, 0}), 1000.0);
  a.angular_velocity_W = Vec3{1, 2, 3};
  Body b = dynamicBody("b", boxShape(Vec3{0.1, 0.02, 0.02}), at(Vec3{0.15, 0, 0}), 1000.0);
  b.angular_velocity_W = Vec3{1, 2, 3};
  b.linear_velocity_W = glm::cross(Vec3{1, 2, 3}, Vec3{0.15, 0, 0});
  s.bodies = {a, b};
  s.joints.push_back(joint(scene::JointKind::kFixed, 0, 1, Vec3{0.075, 0, 0}, Vec3{-0.075, 0, 0}));
  Rig rig(std::move(s));
  double worst = 0.0;
  for (int k = 0; k < 3000; ++k) {
    rig.tick(kDt);
    const geom::Transform X = geom::relativeTransform(rig.dyn->pose(0), rig.dyn->pose(1));
    for (const Vec3 p : {Vec3{0.1, 0.02, 0.02}, Vec3{-0.1, -0.02, 0.02}}) {
      worst = std::max(worst, glm::length(X.apply(p) - (p + Vec3{0.15, 0, 0})));
    }
  }
  EXPECT_LT(worst, 1e-3 * 0.1) << "relative motion of the joined bodies, relative to their size";
}

// a door hinged (about y) to a frame that is itself a free dynamic body: their relative motion
// is a rotation about the hinge axis only
TEST(Hinge, BetweenTwoDynamicBodies) {
  SceneModel s;
  Body frame = dynamicBody("frame", boxShape(Vec3{0.02, 0.2, 0.02}), at(Vec3{0}), 1000.0);
  frame.angular_velocity_W = Vec3{0.5, 0.2, -0.3};
  Body door = dynamicBody("door", boxShape(Vec3{0.15, 0.2, 0.01}), at(Vec3{0.17, 0, 0}), 500.0);
  door.angular_velocity_W = Vec3{0.5, 3.2, -0.3};  // the frame's spin plus 3 rad/s about the hinge
  door.linear_velocity_W = glm::cross(door.angular_velocity_W, Vec3{0.15, 0, 0});
  s.bodies = {frame, door};
  s.joints.push_back(joint(scene::JointKind::kHinge, 0, 1, Vec3{0.02, 0, 0}, Vec3{-0.15, 0, 0}, 1));
  Rig rig(std::move(s));
  const double e0 = rig.dyn->kineticEnergy();
  double worst_e = 0.0;
  double worst_anchor = 0.0, worst_axis = 0.0, turned = 0.0, prev = 0.0;
  for (int k = 0; k < 3000; ++k) {
    rig.tick(kDt);
    const Pose A = rig.dyn->pose(0), B = rig.dyn->pose(1);
    const Vec3 pa = A.translation + A.rotation * Vec3{0.02, 0, 0};
    const Vec3 pb = B.translation + B.rotation * Vec3{-0.15, 0, 0};
    worst_anchor = std::max(worst_anchor, glm::length(pa - pb));
    worst_axis =
        std::max(worst_axis, glm::length(A.rotation * Vec3{0, 1, 0} - B.rotation * Vec3{0, 1, 0}));
    const Quat rel = glm::conjugate(A.rotation) * B.rotation;
    const double angle = 2.0 * std::atan2(rel.y, rel.w);
    turned += std::abs(std::remainder(angle - prev, 2 * kPi));
    prev = angle;
    worst_e = std::max(worst_e, rig.dyn->kineticEnergy());
  }
  EXPECT_LE(worst_e, e0 * (1 + 1e-4)) << "no energy from the joint";
  EXPECT_LT(worst_anchor, 1e-3 * 0.15);
  EXPECT_LT(worst_axis, 1e-3);
  EXPECT_GT(turned, 1.0) << "the door did turn on its hinge";
  std::printf(
      "hinge between bodies: anchor drift %.3g m, axis misalignment %.3g, turned %.2f "
      "rad, energy %.6f -> %.6f J\n",
      worst_anchor, worst_axis, turned, e0, rig.dyn->kineticEnergy());
}

// a spur gear of n straight-flanked teeth, module m, pitch radius m n / 2, in the z = 0 plane
std::vector<Primitive> gear(int n, double m, double half_thickness, double phase) {
  const double r = m * n / 2.0;
  std::vector<Primitive> prims;
  std::vector<glm::dvec2> disc;
  for (int k = 0; k < 48; ++k) {
    const double a = 2 * kPi * k / 48;
    disc.push_back({(r - m) * std::cos(a), (r - m) * std::sin(a)});
  }
  prims.push_back(Primitive{prismShape(disc, half_thickness), Pose{}});
  const double root = r - 1.2 * m, tip = r + 0.8 * m;
  const auto tooth = prismShape({{root, -0.3 * kPi * m},
                                 {tip, -0.15 * kPi * m},
                                 {tip, 0.15 * kPi * m},
                                 {root, 0.3 * kPi * m}},
                                half_thickness);
  for (int k = 0; k < n; ++k) {
    const double a = phase + 2 * kPi * k / n;
    prims.push_back(Primitive{tooth, Pose{Vec3{0}, glm::angleAxis(a, Vec3{0, 0, 1})}});
  }
  return prims;
}

struct Gears {
  SceneModel s;
  static constexpr int kN1 = 12, kN2 = 24;
  static constexpr double kM = 0.01;
  Gears() {
    s.gravity_W = Vec3{0, -9.81, 0};
    // frictionless teeth: the ratio and the load are the teeth's alone (a collider without a
    // material would have scene::kDefaultFriction)
    s.materials.push_back(material(0.0, 0.0));
    const double c = kM * (kN1 + kN2) / 2.0;
    for (int g = 0; g < 2; ++g) {
      Body b;
      b.name = g == 0 ? "driver" : "driven";
      b.motion = Motion::kDynamic;
      b.X_WB = at(Vec3{g == 0 ? 0.0 : c, 0, 0});
      // driver: a tooth toward the driven gear; driven: a gap toward the driver
      b.primitives = g == 0 ? gear(kN1, kM, 0.01, 0.0) : gear(kN2, kM, 0.01, kPi + kPi / kN2);
      for (Primitive& p : b.primitives)
        p.material = 0;
      const MassProperties mp = computeMassProperties(b.primitives, 1000.0);
      b.mass = mp.mass;
      b.com_B = mp.com_B;
      b.inertia_B = mp.inertia_B;
      b.probe = g == 0;
      s.bodies.push_back(b);
      s.joints.push_back(hingeToWorld(g, Vec3{0}, b.X_WB.translation, 2));
    }
  }
};

TEST(Gears, TorqueOnTheDriverTurnsTheDrivenGearAtTheToothRatio) {
  Gears g;
  Rig rig(g.s);
  // the driven gear carries a small load torque against its rotation, so that the teeth stay
  // in mesh on the driving flank
  rig.dyn->setExternalWrench(1, Vec3{0}, Vec3{0, 0, 0.002});
  HeldInput in;
  in.mode = HeldMode::kWrench;
  in.torque_W_nm = Vec3{0, 0, 0.01};
  double worst_axis = 0.0;
  double prev_a = 0.0, prev_b = 0.0, turn_a = 0.0, turn_b = 0.0;
  for (int k = 0; k < 3000; ++k) {
    rig.tick(kDt, &in);
    // unwrap the angles
    const double a = angleZ(rig.dyn->pose(0).rotation), b = angleZ(rig.dyn->pose(1).rotation);
    turn_a += std::remainder(a - prev_a, 2 * kPi);
    turn_b += std::remainder(b - prev_b, 2 * kPi);
    prev_a = a;
    prev_b = b;
    for (std::uint32_t i = 0; i < 2; ++i) {
      const Vec3 w = rig.dyn->angularVelocity(i);
      worst_axis = std::max(worst_axis, std::hypot(w.x, w.y));
      const Vec3 centre = i == 0 ? Vec3{0} : Vec3{0.18, 0, 0};
      worst_axis = std::max(worst_axis, glm::length(rig.dyn->pose(i).translation - centre) / 0.12);
    }
  }
  const double ratio = -turn_b / turn_a;
  EXPECT_GT(turn_a, 2 * kPi) << "the driver turned at least once";
  EXPECT_NEAR(ratio, double(Gears::kN1) / Gears::kN2, 0.02 * Gears::kN1 / Gears::kN2);
  EXPECT_LT(worst_axis, 1e-3) << "the gears turn only about their axes";
  std::printf("gears (torque): driver %.2f rad, driven %.2f rad, ratio %.4f (teeth %.4f)\n", turn_a,
              turn_b, ratio, double(Gears::kN1) / Gears::kN2);
}

TEST(Gears, ProbeTurningTheDriverFeelsTheLoad) {
  Gears g;
  Rig rig(g.s);
  const double load = 0.002;  // N m on the driven gear, against its rotation
  rig.dyn->setExternalWrench(1, Vec3{0}, Vec3{0, 0, load});
  HeldInput in;
  in.mode = HeldMode::kKinematic;
  const double w = 2.0;  // rad/s, the hand turning the driver
  double impulse_sum = 0.0, force_sum = 0.0;
  double prev_b = 0.0, turn_b = 0.0, turn_b0 = 0.0, ke0 = 0.0;
  const int n = 3000, n0 = 1000;
  for (int k = 0; k < n; ++k) {
    in.X_WB_target = at(Vec3{0}, glm::angleAxis(w * (k + 1) * kDt, Vec3{0, 0, 1}));
    rig.tick(kDt, &in);
    const double b = angleZ(rig.dyn->pose(1).rotation);
    turn_b += std::remainder(b - prev_b, 2 * kPi);
    prev_b = b;
    const HeldFeedback& fb = rig.dyn->heldFeedback();
    if (k == n0 - 1)
      turn_b0 = turn_b, ke0 = rig.dyn->kineticEnergy();
    if (k >= n0)
      impulse_sum += fb.angular_impulse_W_nms.z, force_sum += fb.torque_W_nm.z * kDt;
  }
  const double turn_a = w * n * kDt;
  EXPECT_NEAR(-turn_b / turn_a, double(Gears::kN1) / Gears::kN2, 0.02 * Gears::kN1 / Gears::kN2);
  // the hand feels the load through the teeth: the work the hand does on the driver covers the
  // load's work and the driven gear's kinetic energy (straight-flanked teeth are not conjugate:
  // their inelastic impacts take some more), and no energy comes from nowhere
  const double hand_work = -impulse_sum * w;  // the torque on the hand opposes the turning
  const double load_work = load * std::abs(turn_b - turn_b0);
  const double ke_change = rig.dyn->kineticEnergy() - ke0;
  EXPECT_GT(hand_work, 0.0);
  EXPECT_GE(hand_work, load_work + ke_change - 1e-3 * load_work);
  // the spread torque record carries the same angular impulse (less what is still in the window)
  EXPECT_NEAR(force_sum, impulse_sum, 0.05 * std::abs(impulse_sum));
  std::printf("gears (probe): hand work %.5f J, load work %.5f J, driven KE change %.5f J\n",
              hand_work, load_work, ke_change);
}

}  // namespace
}  // namespace hapticd::dynamics::testing
