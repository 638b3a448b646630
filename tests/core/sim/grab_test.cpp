// A dynamic body grabbed by the probe is felt with its weight and its inertia (issue 6 point 3):
// a 1 kg box lifted under g = 9.81 m/s^2 weighs 9.81 N on the hand; resting on the floor while
// held, the floor carries it; accelerated sideways at 1 m/s^2 it pulls back with 1 N.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/geometry/rotation.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

using scene::Motion;

struct GrabRun {
  Vec3 resting_force{0.0};     // held, the box still on the floor
  Vec3 lifted_force{0.0};      // mean over the last 0.5 s of holding it still in the air
  Vec3 weight{0.0};            // TickOutput::grab_weight_W_n then
  double accel_force_x = 0.0;  // mean F_x while accelerating at +1 m/s^2 along x
  double box_y = 0.0;          // box centre after the lift
  bool attached = false;
  bool finite = true;
};

// A floor (top face y = 0) and a dynamic cube of 0.1 m at rest on it (1 kg), under gravity.
std::shared_ptr<const scene::SceneModel> boxOnFloor() {
  scene::SceneModel sc;
  sc.bodies.push_back(
      makeBody("floor", Motion::kStatic, at(0, -0.05, 0), {boxShape(Vec3{1.0, 0.05, 1.0})}));
  sc.bodies.push_back(makeBody("box", Motion::kDynamic, at(0, 0.05, 0), {boxShape(Vec3{0.05})}));
  sc.gravity_W = Vec3{0, -9.81, 0};
  sc.length_scale = 2.9;
  return finish(sc);
}

// Scene: floor, a 1 kg cube of 0.1 m at rest on it, the probe sphere (r 0.01) resting on its top.
// The device presses, grabs (button 1), lifts by 0.3 m in 1 s, holds, then accelerates along +x.
GrabRun runGrab(const sim::SimOptions& o) {
  GrabRun r;
  auto created = sim::Simulation::create(boxOnFloor(), o);
  EXPECT_TRUE(created.ok());
  if (!created.ok())
    return r;
  auto sim = sim::withOutputStage(std::move(created).value(), o.response);
  const double dt = o.response.tick_s;
  const double y0 = 0.1095;  // the sphere 0.5 mm into the box's top: resting on it
  Vec3 lifted_sum{0.0}, weight_sum{0.0};
  int lifted_n = 0, accel_n = 0;
  double accel_sum = 0.0;
  for (int k = 0; k <= 3000; ++k) {
    const double t = k * dt;
    sim::TickInput in;
    in.t_s = t;
    double x = 0.0, y = y0;
    if (t > 0.4)
      y = y0 + 0.3 * std::min(1.0, (t - 0.4) / 1.0);
    if (t > 2.5)
      x = 0.5 * 1.0 * (t - 2.5) * (t - 2.5);  // 1 m/s^2 from rest: 0.3 m/s by 2.8 s
    if (t > 2.8)
      x = 0.045 + 0.3 * (t - 2.8) - 0.5 * 1.0 * (t - 2.8) * (t - 2.8);  // and back to rest
    in.X_W_device = at(x, y, 0.0);
    in.buttons = t >= 0.2 ? 1u : 0u;
    const sim::TickOutput out = sim->step(in);
    r.finite = r.finite && std::isfinite(out.force_W_n.x) && std::isfinite(out.force_W_n.y) &&
               std::isfinite(out.force_W_n.z);
    if (k == 300) {
      r.resting_force = out.force_W_n;
      r.attached = out.attached_body == 1;
    }
    if (t >= 2.0 && t < 2.5) {
      lifted_sum += out.force_W_n;
      weight_sum += out.grab_weight_W_n;
      ++lifted_n;
    }
    if (t >= 2.5 && std::abs(t - 2.5) < 1e-9)
      r.box_y = sim->bodyPoses()[0].X_WB.translation.y;
    if (t >= 2.6 && t < 2.8) {
      accel_sum += out.force_W_n.x;
      ++accel_n;
    }
  }
  r.lifted_force = lifted_sum / static_cast<double>(lifted_n);
  r.weight = weight_sum / static_cast<double>(lifted_n);
  r.accel_force_x = accel_sum / accel_n;
  return r;
}

TEST(SimGrab, AGrabbedBoxIsFeltWithItsWeightAndTheFloorCarriesItWhileItRests) {
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  const GrabRun r = runGrab(o);
  std::printf(
      "  1 kg box: held on the floor F (%.4f, %.4f, %.4f) N; lifted F (%.4f, %.4f, %.4f) N "
      "(m g = 9.81 N), box at y %.4f; accelerating at 1 m/s^2: F_x %.4f N\n",
      r.resting_force.x, r.resting_force.y, r.resting_force.z, r.lifted_force.x, r.lifted_force.y,
      r.lifted_force.z, r.box_y, r.accel_force_x);
  EXPECT_TRUE(r.finite);
  EXPECT_TRUE(r.attached);
  // on the floor the floor carries it (the hand feels less than a tenth of the weight)
  EXPECT_LT(glm::length(r.resting_force), 0.981);
  // lifted and held still: m g downward, within 1%
  EXPECT_NEAR(r.lifted_force.y, -9.81, 0.0981);
  EXPECT_NEAR(r.lifted_force.x, 0.0, 0.01);
  EXPECT_NEAR(r.lifted_force.z, 0.0, 0.01);
  EXPECT_NEAR(r.weight.y, -9.81, 1e-12);
  // carried up by 0.3 m (less the coupling's sag m g / k_c = 16 mm)
  EXPECT_GT(r.box_y, 0.05 + 0.3 - 0.02);
  // accelerated at +1 m/s^2: its inertia pulls back with m a = 1 N, within 2%
  EXPECT_NEAR(r.accel_force_x, -1.0, 0.02);
}

TEST(SimGrab, WithoutTheKnobsNoWeightAndNoInertia) {
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  o.response.grab_weight = false;
  o.response.grab_inertia = false;
  const GrabRun r = runGrab(o);
  std::printf("  knobs off: lifted F (%.4f, %.4f, %.4f) N; accelerating: F_x %.4f N\n",
              r.lifted_force.x, r.lifted_force.y, r.lifted_force.z, r.accel_force_x);
  EXPECT_TRUE(r.attached);
  EXPECT_LT(glm::length(r.lifted_force), 0.01);
  EXPECT_LT(std::abs(r.accel_force_x), 0.02);
}

// The same grab in a closed loop with a hand model (the daemon's sim hand: 0.5 kg on 200 N/m and
// 20 N s/m toward its target; rotation 0.001 kg m^2 on 1 N m/rad and 0.06 N m s/rad), driven by
// the force and torque the Simulation gives it. Lifted, then its target jumped 5 cm sideways:
// the inertia fed back (a 1 kg box is twice the hand's mass) must not make the loop ring or
// diverge: the hand settles, the force settles at m g.
struct LoopRun {
  double settle_speed = 0.0;  // largest hand speed over the last 0.5 s, 2.5 s after the jump
  double settle_spin = 0.0;   // largest hand angular speed then (rad/s)
  Vec3 settle_force{0.0};     // mean force then
  double max_force = 0.0;
  bool finite = true;
  bool attached = false;
};

LoopRun runLoop(bool inertia) {
  LoopRun r;
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  o.response.grab_inertia = inertia;
  auto created = sim::Simulation::create(boxOnFloor(), o);
  EXPECT_TRUE(created.ok());
  if (!created.ok())
    return r;
  auto sim = sim::withOutputStage(std::move(created).value(), o.response);
  const double dt = 0.001, mass = 0.5, k = 200.0, c = 20.0;
  const double inertia_h = 0.001, k_r = 1.0, c_r = 0.06;
  Vec3 x{0.0, 0.1095, 0.0}, v{0.0}, w{0.0};
  Quat q{1.0, 0.0, 0.0, 0.0};
  Vec3 settle_sum{0.0};
  int settle_n = 0;
  for (int i = 0; i <= 6000; ++i) {
    const double t = i * dt;
    Vec3 target{0.0, 0.1095, 0.0};
    if (t > 0.4)
      target.y += 0.3 * std::min(1.0, (t - 0.4) / 1.0) + 0.049;  // lift, and carry the sag
    if (t > 3.0)
      target.x = 0.05;
    sim::TickInput in;
    in.t_s = t;
    in.X_W_device = Pose{x, q};
    in.buttons = t >= 0.2 ? 1u : 0u;
    const sim::TickOutput out = sim->step(in);
    const Vec3 F = out.force_W_n, T = out.torque_W_nm;
    r.finite = r.finite && geom::finite(F) && geom::finite(T);
    if (!r.finite)
      break;
    r.max_force = std::max(r.max_force, glm::length(F));
    r.attached = r.attached || out.attached_body == 1;
    // the hand: semi-implicit Euler
    v += dt * (k * (target - x) - c * v + F) / mass;
    x += dt * v;
    w += dt * (-k_r * geom::rotationVector(q) - c_r * w + T) / inertia_h;
    q = glm::normalize(geom::quatFromRotationVector(w * dt) * q);
    if (t >= 5.5) {
      r.settle_speed = std::max(r.settle_speed, glm::length(v));
      r.settle_spin = std::max(r.settle_spin, glm::length(w));
      settle_sum += F;
      ++settle_n;
    }
  }
  r.settle_force = settle_sum / static_cast<double>(std::max(settle_n, 1));
  return r;
}

TEST(SimGrab, InAClosedLoopWithAHandModelTheGrabSettles) {
  for (const bool inertia : {false, true}) {
    const LoopRun r = runLoop(inertia);
    std::printf(
        "  hand loop, inertia %s: settled speed %.2e m/s, spin %.2e rad/s, force (%.4f, %.4f, "
        "%.4f) N, largest |F| %.3f N\n",
        inertia ? "on" : "off", r.settle_speed, r.settle_spin, r.settle_force.x, r.settle_force.y,
        r.settle_force.z, r.max_force);
    EXPECT_TRUE(r.finite);
    EXPECT_TRUE(r.attached);
    // measured: inertia on, 2.6e-6 m/s and 2.8e-5 rad/s (decaying ten-fold per 0.5 s)
    EXPECT_LT(r.settle_speed, 1e-4);
    EXPECT_LT(r.settle_spin, 1e-3);
    EXPECT_NEAR(r.settle_force.y, -9.81, 0.1);
  }
}

}  // namespace
}  // namespace hapticd::simtest
