// Scene edits through the Simulation (issue 6 "kinematic bodies moved by clients", issue 8 "scene
// updates"): a kinematic paddle moved every tick pushes a dynamic box; a kinematic body moved into
// the resting probe pushes it out; refused edits change nothing; inactive bodies neither fall nor
// collide, are added and removed; contact points; no allocation; mm and km give the same answer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/scene/loader.h"
#include "tests/core/alloc_counter.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

using scene::Motion;
using sim::EditStatus;

scene::Body box(const std::string& name, Motion motion, const Vec3& p, const Vec3& half) {
  return makeBody(name, motion, at(p.x, p.y, p.z), {boxShape(half)});
}

// Options for a scene whose lengths are s times metres: the same relative behaviour.
sim::SimOptions scaledOptions(double s) {
  sim::SimOptions o = scaledResponseOptions(s);
  o.probe_sphere_radius_m *= s;
  return o;
}

Pose poseOf(const sim::Simulation& sim, std::uint32_t body) {
  for (const sim::BodyPose& bp : sim.bodyPoses()) {
    if (bp.body == body)
      return bp.X_WB;
  }
  ADD_FAILURE() << "body " << body << " not in bodyPoses()";
  return Pose{};
}

bool samePose(const Pose& a, const Pose& b) {
  return std::memcmp(&a.translation, &b.translation, sizeof a.translation) == 0 &&
         std::memcmp(&a.rotation, &b.rotation, sizeof a.rotation) == 0;
}

bool sameOutput(const sim::TickOutput& a, const sim::TickOutput& b) {
  return std::memcmp(&a.force_W_n, &b.force_W_n, sizeof a.force_W_n) == 0 &&
         std::memcmp(&a.torque_W_nm, &b.torque_W_nm, sizeof a.torque_W_nm) == 0 &&
         samePose(a.X_W_proxy, b.X_W_proxy) && a.contacts == b.contacts && a.flags == b.flags &&
         a.max_penetration_m == b.max_penetration_m;
}

sim::TickInput tick(std::uint64_t k, const Pose& device, double dt = 0.001) {
  sim::TickInput in;
  in.t_s = static_cast<double>(k) * dt;
  in.X_W_device = device;
  return in;
}

// ---- a kinematic paddle pushing a resting dynamic box

struct PushRun {
  double box_x0 = 0.0, box_x1 = 0.0;  // box centre at the start and the end (units of s)
  double box_speed = 0.0;             // over the last 100 ms, per s
  double worst_overlap = 0.0;         // paddle face past the box's back face, per s
  double box_y_drift = 0.0;           // per s
  double first_contact_s = -1.0;
  bool finite = true;
};

// Scene in units of s metres: floor, a 0.1 s cube at rest on it, a paddle 0.2 s to its left
// moved along +x at 0.2 s per second by setKinematicPose every tick, the probe sphere far above.
PushRun runPaddle(double s) {
  PushRun r;
  scene::SceneModel sc;
  sc.bodies.push_back(
      box("floor", Motion::kStatic, Vec3{0, -0.05, 0} * s, Vec3{1.0, 0.05, 0.5} * s));
  sc.bodies.push_back(box("box", Motion::kDynamic, Vec3{0, 0.05, 0} * s, Vec3{0.05} * s));
  sc.bodies.push_back(
      box("paddle", Motion::kKinematic, Vec3{-0.2, 0.06, 0} * s, Vec3{0.01, 0.05, 0.1} * s));
  sc.gravity_W = Vec3{0, -9.81, 0} * s;
  sc.length_scale = 2.3 * s;
  const auto model = finish(sc);
  const sim::SimOptions o = scaledOptions(s);
  auto sim = makeShaped(model, o);
  if (!sim)
    return r;
  const double v = 0.2;  // per s, per second
  const Pose device = at(0, 1.0 * s, 0);
  r.box_x0 = poseOf(*sim, 1).translation.x / s;
  double x_back = 0.0;
  const int n = 1500;
  for (int k = 0; k < n; ++k) {
    const double t = (k + 1) * 0.001;
    const EditStatus st = sim->setKinematicPose(2, at((-0.2 + v * t) * s, 0.06 * s, 0));
    EXPECT_EQ(st, EditStatus::kOk);
    const sim::TickOutput out = sim->step(tick(static_cast<std::uint64_t>(k), device));
    r.finite = r.finite && std::isfinite(out.force_W_n.x);
    const Pose b = poseOf(*sim, 1);
    const Pose p = poseOf(*sim, 2);
    r.finite = r.finite && std::isfinite(b.translation.x) && std::isfinite(b.translation.y);
    // the paddle's front face against the box's back face
    const double overlap = ((p.translation.x + 0.01 * s) - (b.translation.x - 0.05 * s)) / s;
    r.worst_overlap = std::max(r.worst_overlap, overlap);
    if (r.first_contact_s < 0.0 && b.translation.x / s > r.box_x0 + 1e-4)
      r.first_contact_s = t;
    r.box_y_drift = std::max(r.box_y_drift, std::abs(b.translation.y / s - 0.05));
    if (k == n - 101)
      x_back = b.translation.x / s;
    if (k == n - 1)
      r.box_x1 = b.translation.x / s;
  }
  r.box_speed = (r.box_x1 - x_back) / 0.1;
  return r;
}

TEST(SimEdits, AKinematicPaddleMovedEveryTickPushesARestingBox) {
  const PushRun r = runPaddle(1.0);
  std::printf(
      "  paddle at 0.2 m/s: first contact at %.3f s, box moved %.4f m, box speed %.4f m/s, "
      "worst paddle overlap %.2e m, box height drift %.2e m\n",
      r.first_contact_s, r.box_x1 - r.box_x0, r.box_speed, r.worst_overlap, r.box_y_drift);
  EXPECT_TRUE(r.finite);
  // the paddle meets the box after 0.14 m at 0.2 m/s = 0.7 s (not earlier, not later)
  EXPECT_NEAR(r.first_contact_s, 0.7, 0.02);
  // then it carries it along: 0.8 s at 0.2 m/s
  EXPECT_NEAR(r.box_x1 - r.box_x0, 0.16, 0.01);
  EXPECT_NEAR(r.box_speed, 0.2, 0.02);
  // no tunnelling: the paddle never gets into the box by more than 1% of its size
  EXPECT_LT(r.worst_overlap, 1e-3);
  EXPECT_LT(r.box_y_drift, 1e-3);
}

TEST(SimEdits, ThePaddlePushesTheSameInMillimetresAndKilometres) {
  const PushRun mm = runPaddle(1000.0);
  const PushRun km = runPaddle(1e-3);
  std::printf("  box moved %.6f (mm) vs %.6f (km) scene lengths / s; speed %.6f vs %.6f\n",
              mm.box_x1 - mm.box_x0, km.box_x1 - km.box_x0, mm.box_speed, km.box_speed);
  EXPECT_TRUE(mm.finite && km.finite);
  EXPECT_NEAR(mm.box_x1 - mm.box_x0, 0.16, 0.01);
  EXPECT_NEAR(mm.box_x1 - mm.box_x0, km.box_x1 - km.box_x0, 1e-4);
  EXPECT_NEAR(mm.box_speed, km.box_speed, 1e-3);
  EXPECT_NEAR(mm.first_contact_s, km.first_contact_s, 2e-3);
}

// ---- a kinematic wall moved into the resting probe (no dynamics)

struct WallRun {
  std::vector<Vec3> force;  // per tick
  double max_force = 0.0;
  double max_pen = 0.0;  // largest reported penetration (per s)
  double end_pen = 0.0;  // wall face past the proxy sphere's back at the end (per s)
  double end_force_x = 0.0;
  double first_force_s = -1.0;
  double min_fx_in_contact = 1e9;
  std::size_t end_contact_points = 0;
  std::int32_t end_contact_body = -2;
  Vec3 end_contact_normal{0.0};
  bool finite = true;
};

// the penetration allowance the simulation derives (penetration_allowance_m = 0): 1.5 times the
// proxy's penetration at the force limit
double allowance(const sim::SimOptions& o) {
  const sim::ResponseOptions& r = o.response;
  return r.penetration_allowance_m > 0.0
             ? r.penetration_allowance_m
             : 1.5 * r.max_force_n / (r.proxy_stiffness_ratio * r.stiffness_n_per_m);
}

// The probe, a cube of half side 0.01 s, rests at the origin, the device holding it there; a wall
// (half 0.01 s thick) from x = -0.05 s moves along +x at `v` s per second for 1 s.
WallRun runWall(double s, double v) {
  WallRun r;
  scene::SceneModel sc;
  sc.bodies.push_back(
      box("wall", Motion::kKinematic, Vec3{-0.05, 0, 0} * s, Vec3{0.01, 0.1, 0.1} * s));
  auto probe = box("probe", Motion::kKinematic, Vec3{0.0}, Vec3{0.01} * s);
  probe.probe = true;
  sc.bodies.push_back(probe);
  sc.length_scale = 0.3 * s;
  const sim::SimOptions o = scaledOptions(s);
  auto sim = makeShaped(finish(sc), o);
  if (!sim)
    return r;
  const Pose device = at(0, 0, 0);
  const int n = 1000;
  for (int k = 0; k < n; ++k) {
    const double t = (k + 1) * 0.001;
    EXPECT_EQ(sim->setKinematicPose(0, at((-0.05 + v * t) * s, 0, 0)), EditStatus::kOk);
    const sim::TickOutput out = sim->step(tick(static_cast<std::uint64_t>(k), device));
    r.force.push_back(out.force_W_n);
    r.finite = r.finite && std::isfinite(out.force_W_n.x) && std::isfinite(out.force_W_n.y) &&
               std::isfinite(out.force_W_n.z) && std::isfinite(out.X_W_proxy.translation.x);
    r.max_force = std::max(r.max_force, glm::length(out.force_W_n));
    r.max_pen = std::max(r.max_pen, out.max_penetration_m / s);
    if (r.first_force_s < 0.0 && glm::length(out.force_W_n) > 0.01)
      r.first_force_s = t;
    if (out.contacts > 0)
      r.min_fx_in_contact = std::min(r.min_fx_in_contact, out.force_W_n.x);
    if (k == n - 1) {
      const double wall_face = (-0.05 + v * t + 0.01) * s;
      r.end_pen = (wall_face - (out.X_W_proxy.translation.x - 0.01 * s)) / s;
      r.end_force_x = out.force_W_n.x;
      const auto cps = sim->contactPoints();
      r.end_contact_points = cps.size();
      EXPECT_EQ(cps.size(), out.contacts);
      if (!cps.empty()) {
        r.end_contact_body = cps[0].body;
        r.end_contact_normal = cps[0].n_W;
      }
    }
  }
  return r;
}

TEST(SimEdits, AKinematicWallMovedIntoTheRestingProbePushesItOut) {
  const sim::SimOptions o;
  const WallRun r = runWall(1.0, 0.05);
  std::printf(
      "  wall at 0.05 m/s into the probe: first force at %.3f s, largest |F| %.4f N (limit %.1f), "
      "largest penetration %.3e m, at the end %.3e m (allowance %.1e), F_x %.4f N, %zu contact "
      "points\n",
      r.first_force_s, r.max_force, o.response.max_force_n, r.max_pen, r.end_pen, allowance(o),
      r.end_force_x, r.end_contact_points);
  EXPECT_TRUE(r.finite);
  // the wall's face (from x = -0.04) reaches the probe (at x = -0.01) after 0.03 m at 0.05 m/s
  EXPECT_NEAR(r.first_force_s, 0.6, 0.01);
  // the force on the hand points away from the wall (+x), within the device limit
  EXPECT_GT(r.min_fx_in_contact, 0.0);
  EXPECT_LE(r.max_force, o.response.max_force_n * (1.0 + 1e-12));
  // by the end the wall has pushed the proxy 0.03 m past the device: the limit is reached
  EXPECT_NEAR(r.end_force_x, o.response.max_force_n, 1e-6 * o.response.max_force_n);
  // and the proxy stays outside the wall (deeper than the allowance never)
  EXPECT_LT(r.max_pen, allowance(o));
  EXPECT_LT(r.end_pen, allowance(o));
  // the contact points name the wall and push along +x
  EXPECT_GT(r.end_contact_points, 0u);
  EXPECT_EQ(r.end_contact_body, 0);
  EXPECT_GT(r.end_contact_normal.x, 0.99);
}

TEST(SimEdits, TheWallPushesTheSameInMillimetresAndKilometres) {
  const WallRun mm = runWall(1000.0, 0.05);
  const WallRun km = runWall(1e-3, 0.05);
  ASSERT_EQ(mm.force.size(), km.force.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < mm.force.size(); ++i)
    worst = std::max(worst, glm::length(mm.force[i] - km.force[i]));
  std::printf("  largest force %.4f N; largest difference mm vs km %.3g N\n", mm.max_force, worst);
  EXPECT_GT(mm.max_force, 1.0);
  EXPECT_LT(worst, 1e-6 * mm.max_force);
  EXPECT_NEAR(mm.end_pen, km.end_pen, 1e-9);
}

// A wall faster than the safe distance per tick (0.35 mm for this probe) still pushes the probe
// out: on the tick it touches the held set the proxy's first sub-step may move one more safe
// distance (the rows see every surface within two), and its further sub-steps go on while they
// push it out. At 0.9 m/s it is not run over.
TEST(SimEdits, AWallFasterThanTheSafeDistanceStillPushesTheProbeOut) {
  const sim::SimOptions o;
  const WallRun r = runWall(1.0, 0.9);
  std::printf(
      "  wall at 0.9 m/s: largest |F| %.4f N, largest penetration %.3e m, at the end %.3e m\n",
      r.max_force, r.max_pen, r.end_pen);
  EXPECT_TRUE(r.finite);
  EXPECT_LE(r.max_force, o.response.max_force_n * (1.0 + 1e-12));
  EXPECT_NEAR(r.end_force_x, o.response.max_force_n, 1e-6 * o.response.max_force_n);
  EXPECT_GT(r.min_fx_in_contact, 0.0);
  EXPECT_LT(r.max_pen, allowance(o));
  EXPECT_LT(r.end_pen, allowance(o));
}

// Faster still (2 m/s, 5.8 safe distances per tick; before the proxy's sub-steps this wall ran
// over the proxy): the forces stay finite, within the device limit and along +x.
TEST(SimEdits, AWallFasterThanTwiceTheBoundGivesFiniteBoundedForces) {
  const sim::SimOptions o;
  const WallRun r = runWall(1.0, 2.0);
  std::printf("  wall at 2 m/s: largest |F| %.4f N, largest penetration %.3e m\n", r.max_force,
              r.max_pen);
  EXPECT_TRUE(r.finite);
  EXPECT_LE(r.max_force, o.response.max_force_n * (1.0 + 1e-12));
  EXPECT_GT(r.max_force, 1.0);
  EXPECT_GT(r.min_fx_in_contact, -1e-9);
}

// ---- refused edits

struct EditScene {
  std::shared_ptr<const scene::SceneModel> model;
  // bodies: 0 floor (static), 1 kinematic, 2 dynamic, 3 inactive kinematic, 4 probe (kinematic)
};

std::shared_ptr<const scene::SceneModel> editScene() {
  scene::SceneModel sc;
  sc.bodies.push_back(box("floor", Motion::kStatic, Vec3{0, -0.05, 0}, Vec3{1.0, 0.05, 1.0}));
  sc.bodies.push_back(box("kin", Motion::kKinematic, Vec3{0.3, 0.05, 0}, Vec3{0.05}));
  sc.bodies.push_back(box("dyn", Motion::kDynamic, Vec3{-0.3, 0.05, 0}, Vec3{0.05}));
  auto gone = box("gone", Motion::kKinematic, Vec3{0.0, 0.05, 0.3}, Vec3{0.05});
  gone.active = false;
  sc.bodies.push_back(gone);
  auto probe = box("probe", Motion::kKinematic, Vec3{0.0, 0.1, 0.0}, Vec3{0.01});
  probe.probe = true;
  sc.bodies.push_back(probe);
  sc.gravity_W = Vec3{0, -9.81, 0};
  sc.length_scale = 2.9;
  return finish(sc);
}

// editScene() with the default options, stepped once with the device at `device` (nullptr,
// the test failed, when refused)
std::unique_ptr<sim::Simulation> editSimAfterOneTick(const Pose& device) {
  auto sim = makeShaped(editScene(), sim::SimOptions{});
  if (sim)
    sim->step(tick(0, device));
  return sim;
}

TEST(SimEdits, BadEditsAreRefusedWithTheirStatusAndChangeNothing) {
  const auto model = editScene();
  sim::SimOptions o;
  auto a = makeShaped(model, o);
  auto b = makeShaped(model, o);
  ASSERT_TRUE(a && b);
  const Pose device = at(0.0, 0.1, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Pose not_unit = at(0.3, 0.2, 0);
  not_unit.rotation = Quat{1.0 + 2e-6, 0.0, 0.0, 0.0};
  Pose nan_q = at(0.3, 0.2, 0);
  nan_q.rotation = Quat{nan, 0.0, 0.0, 0.0};
  const Pose good = at(0.3, 0.2, 0);
  for (std::uint64_t k = 0; k < 50; ++k) {
    const sim::TickOutput oa = a->step(tick(k, device));
    const sim::TickOutput ob = b->step(tick(k, device));
    ASSERT_TRUE(sameOutput(oa, ob)) << "tick " << k;
  }
  std::vector<Pose> before;
  for (const sim::BodyPose& bp : b->bodyPoses())
    before.push_back(bp.X_WB);
  // every bad case, on b only
  const auto n = static_cast<std::uint32_t>(model->bodies.size());
  EXPECT_EQ(b->setKinematicPose(n, good), EditStatus::kNoSuchBody);
  EXPECT_EQ(b->setKinematicPose(0xffffffffu, good), EditStatus::kNoSuchBody);
  EXPECT_EQ(b->setKinematicPose(0, good), EditStatus::kStaticBody);
  EXPECT_EQ(b->setKinematicPose(4, good), EditStatus::kHeldBody);
  EXPECT_EQ(b->setKinematicPose(2, good), EditStatus::kNotKinematic);
  EXPECT_EQ(b->setKinematicPose(3, good), EditStatus::kInactive);
  EXPECT_EQ(b->setKinematicPose(1, at(nan, 0, 0)), EditStatus::kNotFinite);
  EXPECT_EQ(b->setKinematicPose(1, at(0, inf, 0)), EditStatus::kNotFinite);
  EXPECT_EQ(b->setKinematicPose(1, not_unit), EditStatus::kNotFinite);
  EXPECT_EQ(b->setKinematicPose(1, nan_q), EditStatus::kNotFinite);
  EXPECT_EQ(b->setBodyActive(n, true, good), EditStatus::kNoSuchBody);
  EXPECT_EQ(b->setBodyActive(0, false, good), EditStatus::kStaticBody);
  EXPECT_EQ(b->setBodyActive(4, false, good), EditStatus::kHeldBody);
  EXPECT_EQ(b->setBodyActive(3, true, at(nan, 0, 0)), EditStatus::kNotFinite);
  EXPECT_EQ(b->setBodyActive(2, true, not_unit), EditStatus::kNotFinite);
  EXPECT_FALSE(b->bodyActive(3));
  EXPECT_TRUE(b->bodyActive(1));
  EXPECT_TRUE(b->bodyActive(0));
  EXPECT_FALSE(b->bodyActive(n));
  EXPECT_STREQ(sim::toString(EditStatus::kNotKinematic), "not a kinematic body");
  {
    std::size_t i = 0;
    for (const sim::BodyPose& bp : b->bodyPoses())
      EXPECT_TRUE(samePose(bp.X_WB, before[i++])) << "body " << bp.body;
  }
  // the following ticks are bitwise those of the run without the edits
  for (std::uint64_t k = 50; k < 300; ++k) {
    const sim::TickOutput oa = a->step(tick(k, device));
    const sim::TickOutput ob = b->step(tick(k, device));
    ASSERT_TRUE(sameOutput(oa, ob)) << "tick " << k;
    for (std::size_t i = 0; i < a->bodyPoses().size(); ++i)
      ASSERT_TRUE(samePose(a->bodyPoses()[i].X_WB, b->bodyPoses()[i].X_WB));
  }
}

TEST(SimEdits, BodyPosesReportTheEditedPose) {
  const Pose device = at(0.0, 0.1, 0.0);
  auto sim = editSimAfterOneTick(device);
  ASSERT_TRUE(sim);
  Pose X = at(0.31, 0.07, -0.02);
  const Quat q = axisAngle(Vec3{0, 1, 0}, 0.3);
  // a quaternion off unit by less than the tolerance is taken, normalised
  X.rotation = Quat{q.w * (1.0 + 5e-7), q.x * (1.0 + 5e-7), q.y * (1.0 + 5e-7), q.z * (1.0 + 5e-7)};
  ASSERT_EQ(sim->setKinematicPose(1, X), EditStatus::kOk);
  sim->step(tick(1, device));
  const Pose got = poseOf(*sim, 1);
  EXPECT_NEAR(got.translation.x, 0.31, 1e-12);
  EXPECT_NEAR(got.translation.y, 0.07, 1e-12);
  EXPECT_NEAR(got.translation.z, -0.02, 1e-12);
  EXPECT_NEAR(std::abs(glm::dot(got.rotation, q)), 1.0, 1e-12);
  EXPECT_NEAR(glm::length(got.rotation), 1.0, 1e-12);
  // without a new pose it stays there
  for (std::uint64_t k = 2; k < 20; ++k)
    sim->step(tick(k, device));
  EXPECT_TRUE(samePose(poseOf(*sim, 1), got));
  // an inactive body added at a pose is listed there; removed, it keeps listing its last pose
  ASSERT_EQ(sim->setBodyActive(3, true, at(0.0, 0.5, 0.3)), EditStatus::kOk);
  sim->step(tick(20, device));
  EXPECT_TRUE(sim->bodyActive(3));
  EXPECT_NEAR(poseOf(*sim, 3).translation.y, 0.5, 1e-12);
  ASSERT_EQ(sim->setKinematicPose(3, at(0.0, 0.6, 0.3)), EditStatus::kOk);
  sim->step(tick(21, device));
  EXPECT_NEAR(poseOf(*sim, 3).translation.y, 0.6, 1e-12);
  ASSERT_EQ(sim->setBodyActive(3, false, Pose{}), EditStatus::kOk);
  sim->step(tick(22, device));
  EXPECT_FALSE(sim->bodyActive(3));
  EXPECT_NEAR(poseOf(*sim, 3).translation.y, 0.6, 1e-12);
  EXPECT_EQ(sim->setKinematicPose(3, at(0.0, 0.7, 0.3)), EditStatus::kInactive);
}

// A body the probe holds (attached) cannot be moved, added or removed by a client.
TEST(SimEdits, AnAttachedBodyIsHeld) {
  scene::SceneModel sc;
  sc.bodies.push_back(box("kin", Motion::kKinematic, Vec3{0.0, 0.0, 0}, Vec3{0.05}));
  sc.length_scale = 0.2;
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  auto sim = makeShaped(finish(sc), o);
  ASSERT_TRUE(sim);
  // the probe sphere (r 0.01) resting on the box's top face, then the button pressed
  const Pose device = at(0.0, 0.0605, 0.0);
  for (std::uint64_t k = 0; k < 100; ++k)
    sim->step(tick(k, device));
  sim::TickInput in = tick(100, device);
  in.buttons = 1;
  const sim::TickOutput out = sim->step(in);
  ASSERT_EQ(out.attached_body, 0);
  EXPECT_EQ(sim->setKinematicPose(0, at(0.1, 0, 0)), EditStatus::kHeldBody);
  EXPECT_EQ(sim->setBodyActive(0, false, Pose{}), EditStatus::kHeldBody);
  in = tick(101, device);
  in.buttons = 0;
  sim->step(in);
  EXPECT_EQ(sim->setKinematicPose(0, at(0.1, 0, 0)), EditStatus::kOk);
}

// ---- inactive bodies

TEST(SimEdits, AnInactiveBoxDoesNotFallAddedItFallsAndRestsRemovedWhatRestsOnItFalls) {
  scene::SceneModel sc;
  sc.bodies.push_back(box("floor", Motion::kStatic, Vec3{0, -0.05, 0}, Vec3{1.0, 0.05, 1.0}));
  auto a = box("a", Motion::kDynamic, Vec3{0, 0.5, 0}, Vec3{0.05});
  a.active = false;
  sc.bodies.push_back(a);
  sc.bodies.push_back(box("b", Motion::kDynamic, Vec3{0.5, 0.05, 0}, Vec3{0.05}));
  sc.gravity_W = Vec3{0, -9.81, 0};
  sc.length_scale = 2.9;
  sim::SimOptions o;
  auto sim = makeShaped(finish(sc), o);
  ASSERT_TRUE(sim);
  const Pose device = at(0.0, 2.0, 0.0);  // the probe sphere far above
  std::uint64_t k = 0;
  const auto run = [&](double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 1000.0); ++i)
      sim->step(tick(k++, device));
  };
  EXPECT_FALSE(sim->bodyActive(1));
  run(0.5);
  // inactive: not integrated, no gravity
  EXPECT_EQ(poseOf(*sim, 1).translation.y, 0.5);
  // added (at 0.3): it falls onto the floor and rests there
  ASSERT_EQ(sim->setBodyActive(1, true, at(0.0, 0.3, 0.0)), EditStatus::kOk);
  run(0.1);
  EXPECT_LT(poseOf(*sim, 1).translation.y, 0.3 - 0.03);  // ~ g t^2 / 2 = 0.049
  run(1.9);
  const double rest_y = poseOf(*sim, 1).translation.y;
  std::printf("  added box rests at y %.6f (expected 0.05)\n", rest_y);
  EXPECT_NEAR(rest_y, 0.05, 5e-4);
  // move the other box onto it (b: add it again at a pose on a's top)
  ASSERT_EQ(sim->setBodyActive(2, true, at(0.0, 0.1505, 0.0)), EditStatus::kOk);
  run(1.0);
  const double b_on_a = poseOf(*sim, 2).translation.y;
  EXPECT_NEAR(b_on_a, 0.15, 5e-4);
  // remove a: b falls to the floor and rests there; a stays listed where it was
  const Pose a_last = poseOf(*sim, 1);
  ASSERT_EQ(sim->setBodyActive(1, false, Pose{}), EditStatus::kOk);
  run(1.5);
  const double b_floor = poseOf(*sim, 2).translation.y;
  std::printf("  b on a at y %.6f; a removed: b at y %.6f\n", b_on_a, b_floor);
  EXPECT_NEAR(b_floor, 0.05, 5e-4);
  EXPECT_TRUE(samePose(poseOf(*sim, 1), a_last));
  const sim::DynamicsStatus st = sim->dynamicsStatus();
  EXPECT_TRUE(std::isfinite(st.kinetic_energy_j));
}

// A scene file with extras.haptic.active false: that body starts inactive in the Simulation
// (frozen under gravity), and a client's add drops it onto the floor.
TEST(SimEdits, ASceneFileWithAnInactiveBodyStartsItInactive) {
  const std::string gltf = R"({
    "asset": {"version": "2.0"},
    "extensions": {"KHR_implicit_shapes": {"shapes": [
      {"type": "box", "box": {"size": [2.0, 0.1, 2.0]}},
      {"type": "box", "box": {"size": [0.1, 0.1, 0.1]}}]}},
    "extensionsUsed": ["KHR_implicit_shapes", "KHR_physics_rigid_bodies"],
    "nodes": [
      {"name": "Floor", "translation": [0.0, -0.05, 0.0],
       "extensions": {"KHR_physics_rigid_bodies": {"collider": {"geometry": {"shape": 0}}}}},
      {"name": "Crate", "translation": [0.0, 0.5, 0.0],
       "extensions": {"KHR_physics_rigid_bodies": {"motion": {"mass": 1.0},
                                                   "collider": {"geometry": {"shape": 1}}}},
       "extras": {"haptic": {"active": false}}}],
    "scene": 0,
    "scenes": [{"nodes": [0, 1], "extras": {"haptic": {"gravity": [0.0, -9.81, 0.0]}}}]
  })";
  const std::vector<std::uint8_t> bytes(gltf.begin(), gltf.end());
  scene::LoadReport r = scene::loadScene(bytes, "inactive.gltf");
  ASSERT_TRUE(r.ok()) << r.message();
  auto model = std::make_shared<const scene::SceneModel>(std::move(*r.scene));
  std::uint32_t crate = 0;
  for (std::uint32_t i = 0; i < model->bodies.size(); ++i) {
    if (model->bodies[i].name == "Crate")
      crate = i;
  }
  ASSERT_FALSE(model->bodies[crate].active);
  ASSERT_TRUE(model->plan.dynamics);
  sim::SimOptions o;
  auto sim = makeShaped(model, o);
  ASSERT_TRUE(sim);
  EXPECT_FALSE(sim->bodyActive(crate));
  const Pose device = at(0.0, 2.0, 0.0);
  std::uint64_t k = 0;
  for (; k < 300; ++k)
    sim->step(tick(k, device));
  EXPECT_EQ(poseOf(*sim, crate).translation.y, 0.5);
  EXPECT_EQ(sim->dynamicsStatus().kinetic_energy_j, 0.0);
  ASSERT_EQ(sim->setBodyActive(crate, true, at(0.0, 0.5, 0.0)), EditStatus::kOk);
  for (; k < 2300; ++k)
    sim->step(tick(k, device));
  EXPECT_NEAR(poseOf(*sim, crate).translation.y, 0.05, 5e-4);
}

TEST(SimEdits, TheProbePassesThroughAnInactiveBodyWithoutForce) {
  for (const bool active : {false, true}) {
    scene::SceneModel sc;
    auto wall = box("wall", Motion::kKinematic, Vec3{0, 0, 0}, Vec3{0.02, 0.1, 0.1});
    wall.active = active;
    sc.bodies.push_back(wall);
    sc.length_scale = 0.3;
    sim::SimOptions o;
    o.response.ramp_s = 0.0;
    Runner run(make(finish(sc), o), o);
    Path path({{0.0, at(-0.1, 0, 0)}, {1.0, at(0.1, 0, 0)}});
    double max_contact_force = 0.0;
    std::uint32_t contacts = 0;
    const Figures f = run.run(path, [&](const sim::TickInput&, const sim::TickOutput& out) {
      max_contact_force = std::max(max_contact_force, glm::length(out.contact_force_W_n));
      contacts = std::max(contacts, out.contacts);
      if (!active) {
        EXPECT_TRUE(run.sim().contactPoints().empty());
      }
    });
    std::printf("  wall %s: largest |F| %.4g N, contact force %.4g N, contacts %u\n",
                active ? "active" : "inactive", f.max_force_n, max_contact_force, contacts);
    if (active) {
      EXPECT_GT(f.max_force_n, 5.0);  // the same path into an active wall is felt
    } else {
      EXPECT_EQ(contacts, 0u);
      EXPECT_EQ(max_contact_force, 0.0);
      EXPECT_LT(f.max_force_n, 0.05);  // only the free coupling's lag (0.1 m/s)
    }
  }
}

// A scene built in code whose probe body is inactive is refused with a message naming it; a
// static body marked inactive is simply active (static bodies always are).
TEST(SimEdits, AnInactiveProbeIsRefusedAStaticBodyIsAlwaysActive) {
  scene::SceneModel sc;
  auto floor = box("floor", Motion::kStatic, Vec3{0, -0.05, 0}, Vec3{1.0, 0.05, 1.0});
  floor.active = false;
  sc.bodies.push_back(floor);
  auto probe = box("stick", Motion::kKinematic, Vec3{0.0, 0.1, 0.0}, Vec3{0.01});
  probe.probe = true;
  probe.active = false;
  sc.bodies.push_back(probe);
  auto created = sim::Simulation::create(finish(sc), sim::SimOptions{});
  ASSERT_FALSE(created.ok());
  EXPECT_NE(created.error().message.find("'stick': the probe body cannot be inactive"),
            std::string::npos)
      << created.error().message;
  sc.bodies[1].active = true;
  auto sim = makeShaped(finish(sc), sim::SimOptions{});
  ASSERT_TRUE(sim);
  EXPECT_TRUE(sim->bodyActive(0));
}

// ---- no allocation

TEST(SimEdits, EditsAndStepsAllocateNothingAfterTheFirstStep) {
  const Pose device = at(0.0, 0.1, 0.0);
  auto sim = editSimAfterOneTick(device);
  ASSERT_TRUE(sim);
  const std::uint64_t before = testing_alloc::count();
  std::size_t points = 0;
  for (std::uint64_t k = 1; k < 600; ++k) {
    const double t = static_cast<double>(k) * 0.001;
    (void)sim->setKinematicPose(1, at(0.3 - 0.2 * t, 0.05, 0));
    if (k % 100 == 50)
      (void)sim->setBodyActive(3, true, at(0.0, 0.2, 0.3));
    if (k % 100 == 0)
      (void)sim->setBodyActive(3, false, Pose{});
    if (k == 300)
      (void)sim->setBodyActive(2, false, Pose{});
    if (k == 400)
      (void)sim->setBodyActive(2, true, at(-0.3, 0.2, 0));
    (void)sim->setKinematicPose(0, device);  // refused
    sim->step(tick(k, at(0.0, 0.1 - 0.2 * t, 0.0)));
    points += sim->contactPoints().size();
  }
  const std::uint64_t allocations = testing_alloc::count() - before;
  std::printf("  600 ticks with edits: %llu allocations, %zu contact points seen\n",
              static_cast<unsigned long long>(allocations), points);
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(points, 0u);  // the probe was pressed into the floor: the test saw contacts
}

}  // namespace
}  // namespace hapticd::simtest
