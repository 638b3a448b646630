// The dynamics through the Simulation tick (issue 6): they run exactly when the scene's plan has
// dynamics; the dynamic demo scene for 10 minutes simulated; the probe pushing a dynamic box; an
// impact on the held body spread over 0, 10, 20 and 40 ms; two runs bitwise identical.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "core/common/sanitizers.h"
#include "core/scene/loader.h"
#include "tests/core/sim/demo_streams.h"
#include "tests/core/sim/harness.h"

namespace hapticd::simtest {
namespace {

using scene::Motion;

std::shared_ptr<const geom::Polytope> sphereShape(double r) {
  std::vector<Vec3> pts;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < 80; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / 80.0;
    const double rr = std::sqrt(std::max(0.0, 1.0 - y * y));
    pts.push_back(r * Vec3{rr * std::cos(golden * i), y, rr * std::sin(golden * i)});
  }
  return hullShape(pts);
}

std::vector<Key> demoStream(const std::string& name) {
  return readPoseStream(std::string(HAPTICD_SOURCE_DIR) + "/tests/streams/" + name + ".csv");
}

// A scene without dynamic bodies never steps the dynamics; one with them does.
TEST(SimDynamics, PegInHoleNeverStepsTheDynamics) {
  for (const char* name : {"peg_in_hole", "dynamic"}) {
    auto model = loadDemo(name);
    ASSERT_TRUE(model) << name;
    auto keys = demoStream(name);
    ASSERT_GE(keys.size(), 2u);
    sim::SimOptions o;
    auto created = sim::Simulation::create(model, o);
    ASSERT_TRUE(created.ok()) << created.error().message;
    Runner run(std::move(created).value(), o);
    std::uint64_t ticks_with_dynamics = 0, points = 0;
    run.run(Path(keys), [&](const sim::TickInput&, const sim::TickOutput& out) {
      ticks_with_dynamics += (out.flags & sim::kTickDynamics) != 0 ? 1u : 0u;
      points += out.dynamics_contact_points;
    });
    const sim::DynamicsStatus st = run.sim().dynamicsStatus();
    std::printf("  %s: plan.dynamics %d, ticks with dynamics %llu of %llu, contact points %llu\n",
                name, model->plan.dynamics ? 1 : 0,
                static_cast<unsigned long long>(ticks_with_dynamics),
                static_cast<unsigned long long>(run.sim().bodyPoses().size() > 0 ? st.ticks : 0),
                static_cast<unsigned long long>(points));
    if (std::string(name) == "peg_in_hole") {
      EXPECT_FALSE(model->plan.dynamics);
      EXPECT_FALSE(st.active);
      EXPECT_EQ(st.ticks, 0u);
      EXPECT_EQ(ticks_with_dynamics, 0u);
      EXPECT_EQ(points, 0u);
    } else {
      EXPECT_TRUE(st.active);
      EXPECT_GT(ticks_with_dynamics, 0u);
      EXPECT_EQ(st.ticks, ticks_with_dynamics);
    }
  }
}

struct DemoRun {
  std::uint64_t hash = 1469598103934665603ull;
  double lowest_margin = 1e9;  // lowest vertex of a dynamic body above the floor's top (m)
  double max_kinetic = 0.0, max_total = -1e9, start_total = 0.0;
  double min_potential = 1e9;
  bool finite = true;
  double sim_s = 0.0;
  Figures f;
};

void mix(std::uint64_t& h, const void* p, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(p);
  for (std::size_t i = 0; i < n; ++i)
    h = (h ^ b[i]) * 1099511628211ull;
}

// The dynamic demo with its stream, looped `loops` times (each loop starts where the stream
// starts; the device jumps back to the stream's start between loops only through the proxy's
// safe distance, as a real device would be moved back).
DemoRun runDynamicDemo(int loops) {
  DemoRun r;
  auto model = loadDemo("dynamic");
  if (!model)
    return r;
  auto keys = demoStream("dynamic");
  // the floor: the static body whose top is lowest-lying and widest; its top face
  double floor_top = -1e9;
  for (const auto& b : model->bodies) {
    if (b.motion != Motion::kStatic || b.name.find("loor") == std::string::npos)
      continue;
    for (const auto& p : b.primitives) {
      const geom::Transform X = b.X_WB.toTransform() * p.X_BP.toTransform();
      for (const auto& v : p.shape->vertices())
        floor_top = std::max(floor_top, X.apply(v.p).y);
    }
  }
  sim::SimOptions o;
  auto created = sim::Simulation::create(model, o);
  if (!created.ok())
    return r;
  Runner run(std::move(created).value(), o);
  run.sim().prepareThread();
  const Path path(keys);
  const double dt = o.response.tick_s;
  const auto n = static_cast<std::uint64_t>(std::llround(path.duration() / dt));
  const sim::DynamicsStatus st0 = run.sim().dynamicsStatus();
  r.start_total = st0.kinetic_energy_j + st0.potential_energy_j;
  std::uint64_t tick = 0;
  for (int loop = 0; loop < loops; ++loop) {
    for (std::uint64_t k = 0; k <= n; ++k, ++tick) {
      sim::TickInput in;
      in.t_s = static_cast<double>(tick) * dt;
      in.X_W_device = path.at(static_cast<double>(k) * dt);
      in.buttons = path.buttonsAt(static_cast<double>(k) * dt);
      const sim::TickOutput out = run.sim().step(in);
      const double fo[6] = {out.force_W_n.x,   out.force_W_n.y,   out.force_W_n.z,
                            out.torque_W_nm.x, out.torque_W_nm.y, out.torque_W_nm.z};
      mix(r.hash, fo, sizeof fo);
      for (double v : fo)
        r.finite = r.finite && std::isfinite(v);
      for (const sim::BodyPose& bp : run.sim().bodyPoses()) {
        const double pq[7] = {bp.X_WB.translation.x, bp.X_WB.translation.y, bp.X_WB.translation.z,
                              bp.X_WB.rotation.w,    bp.X_WB.rotation.x,    bp.X_WB.rotation.y,
                              bp.X_WB.rotation.z};
        mix(r.hash, pq, sizeof pq);
        for (double v : pq)
          r.finite = r.finite && std::isfinite(v);
        const scene::Body& b = model->bodies[bp.body];
        if (b.motion != Motion::kDynamic || static_cast<std::int32_t>(bp.body) == model->probe_body)
          continue;
        if (tick % 10 != 0)
          continue;  // the floor check every 10 ms (vertices of 320-face bodies are many)
        const geom::Transform XB = bp.X_WB.toTransform();
        for (const auto& p : b.primitives) {
          const geom::Transform X = XB * p.X_BP.toTransform();
          for (const auto& v : p.shape->vertices())
            r.lowest_margin = std::min(r.lowest_margin, X.apply(v.p).y - floor_top);
        }
      }
      const sim::DynamicsStatus st = run.sim().dynamicsStatus();
      r.max_kinetic = std::max(r.max_kinetic, st.kinetic_energy_j);
      r.max_total = std::max(r.max_total, st.kinetic_energy_j + st.potential_energy_j);
      r.min_potential = std::min(r.min_potential, st.potential_energy_j);
    }
  }
  r.sim_s = static_cast<double>(tick) * dt;
  return r;
}

constexpr double kDemoSeconds = hapticd::kAddressSanitizer ? 60.0 : 600.0;

// 10 minutes simulated (the 19.5 s stream looped): no NaN, no body through the floor, the energy
// bounded. Bound: the stick's points move at most as fast as its stream moves them (the proxy
// keeps up with the device in free space: the stream's peak point speed, under 1 m/s), so a body
// struck by it leaves at most at twice that; the energy (kinetic + potential) of the dynamic bodies
// never exceeds what they had at the start plus the kinetic energy of all of them at 1 m/s, and the
// kinetic energy alone never exceeds that plus all the potential energy gravity could give.
TEST(SimDynamics, DynamicDemoTenMinutesNoNanNoBodyThroughTheFloorBoundedEnergy) {
  auto model = loadDemo("dynamic");
  ASSERT_TRUE(model);
  const double stream_s = demoStream("dynamic").back().t_s;
  const int loops = static_cast<int>(std::ceil(kDemoSeconds / stream_s));
  const DemoRun r = runDynamicDemo(loops);
  double mass = 0.0, size = 1e9;
  for (const auto& b : model->bodies) {
    if (b.motion != Motion::kDynamic)
      continue;
    mass += b.mass;  // the held stick's too: it moves (at most at the stream's speed)
    for (const auto& p : b.primitives)
      size = std::min(size, p.shape->radius());
  }
  // the stream's peak speed of a point of the stick (linear + angular times its radius)
  const auto keys = demoStream("dynamic");
  const scene::Body& stick = model->bodies[static_cast<std::size_t>(model->probe_body)];
  double stick_radius = 0.0, v_stream = 0.0;
  for (const auto& p : stick.primitives)
    stick_radius = std::max(stick_radius, glm::length(p.X_BP.translation) + p.shape->radius());
  for (std::size_t i = 1; i < keys.size(); ++i) {
    const double dt = keys[i].t_s - keys[i - 1].t_s;
    const double turn = glm::length(
        geom::rotationVector(keys[i].X.rotation * glm::conjugate(keys[i - 1].X.rotation)));
    v_stream = std::max(v_stream, (glm::length(keys[i].X.translation - keys[i - 1].X.translation) +
                                   turn * stick_radius) /
                                      dt);
  }
  const double v_bound = 2.0 * v_stream;
  const double ke_bound = 0.5 * mass * v_bound * v_bound;
  std::printf(
      "  %.0f s simulated (%d loops of %.1f s): finite %d; lowest vertex %.3f mm from the floor "
      "(%.2f%% of the smallest body's radius); stream's point speed %.3f m/s; kinetic energy at "
      "most %.4g J (bound %.4g J); "
      "total at most %.4g J, start %.4g J\n",
      r.sim_s, loops, stream_s, r.finite ? 1 : 0, 1e3 * r.lowest_margin,
      100.0 * r.lowest_margin / size, v_stream, r.max_kinetic, ke_bound, r.max_total,
      r.start_total);
  EXPECT_GE(r.sim_s, kDemoSeconds - 1e-9);
  EXPECT_TRUE(r.finite);
  // nothing through the floor: no vertex deeper than 1% of the smallest body's radius
  EXPECT_GT(r.lowest_margin, -0.01 * size);
  EXPECT_LE(r.max_kinetic, ke_bound + std::max(0.0, r.start_total - r.min_potential));
  EXPECT_LE(r.max_total, r.start_total + ke_bound + 1e-9);
}

TEST(SimDynamics, TwoRunsOfTheDynamicDemoAreBitwiseIdentical) {
  const DemoRun a = runDynamicDemo(1), b = runDynamicDemo(1);
  std::printf("  hashes %016llx %016llx\n", static_cast<unsigned long long>(a.hash),
              static_cast<unsigned long long>(b.hash));
  EXPECT_EQ(a.hash, b.hash);
  EXPECT_NE(a.hash, DemoRun{}.hash);
}

// The probe sphere pushes a box (0.2 kg, friction 0.5 on the floor) along x at 0.1 m/s: the box
// moves with it and the hand feels the friction opposing the push, mu m g.
TEST(SimDynamics, ProbePushingADynamicBoxMovesItAndFeelsItOpposeThePush) {
  scene::SceneModel s;
  scene::Material m;
  m.name = "rough";
  m.static_friction = m.dynamic_friction = 0.5;
  s.materials.push_back(m);
  s.bodies.push_back(
      makeBody("floor", Motion::kStatic, at(0, -0.05, 0), {boxShape(Vec3{0.3, 0.05, 0.3})}));
  s.bodies.push_back(makeBody("box", Motion::kDynamic, at(0, 0.02, 0), {boxShape(Vec3{0.02})}));
  s.bodies[0].primitives[0].material = 0;
  s.bodies[1].primitives[0].material = 0;
  s.bodies[1].mass = 0.2;
  s.gravity_W = Vec3{0.0, -9.81, 0.0};
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  const double r = o.probe_sphere_radius_m;
  Runner run(sim::Simulation::create(finish(s), o).value(), o);
  const double x0 = -0.02 - r - 0.002;  // 2 mm left of the box
  Path path({{0.0, at(x0, 0.02, 0)},
             {0.5, at(x0, 0.02, 0)},        // the box settles
             {1.5, at(x0 + 0.1, 0.02, 0)},  // push 10 cm at 0.1 m/s
             {1.6, at(x0 + 0.1, 0.02, 0)}});
  double fx_sum = 0.0, fx_impact_sum = 0.0;
  int n = 0;
  const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
    if (in.t_s > 0.8 && in.t_s < 1.45) {  // the steady part of the push
      fx_sum += out.force_W_n.x;
      fx_impact_sum += out.impact_force_W_n.x;
      ++n;
    }
  });
  const Vec3 box = run.sim().bodyPoses()[0].X_WB.translation;
  const double mu_m_g = 0.5 * 0.2 * 9.81;
  std::printf(
      "  box moved %.2f mm (device 100 mm); mean force on the hand while pushing %.4f N "
      "(spread dynamics feedback %.4f N), mu m g = %.4f N\n",
      1e3 * box.x, fx_sum / n, fx_impact_sum / n, mu_m_g);
  f.print("probe pushes a box");
  EXPECT_TRUE(f.all_finite);
  EXPECT_GT(box.x, 0.09);  // it moved (about the device's 100 mm less the 2 mm gap)
  EXPECT_LT(box.x, 0.1);
  EXPECT_NEAR(box.y, 0.02, 1e-3);  // slid on the floor
  // the hand feels the push opposed: mu m g within 10% on average
  EXPECT_NEAR(fx_sum / n, -mu_m_g, 0.1 * mu_m_g);
  EXPECT_LE(f.max_force_step_n, o.response.max_force_step_n * (1.0 + 1e-9));
}

// A 1 g ball dropped 1 cm onto the held paddle (inelastic): the force record with the impulse
// spread over 0, 10, 20 and 40 ms: the same integral, a falling peak.
TEST(SimDynamics, ImpactOnTheHeldBodyIsASpreadPulseInTheForceRecord) {
  struct Row {
    double window_s, peak_n, peak_t_s, integral_ns;
  };
  std::vector<Row> rows;
  for (double window : {0.0, 0.010, 0.020, 0.040}) {
    scene::SceneModel s;
    s.bodies.push_back(
        makeBody("paddle", Motion::kKinematic, at(0, 0, 0), {boxShape(Vec3{0.05, 0.005, 0.05})}));
    s.bodies[0].probe = true;
    s.bodies.push_back(
        makeBody("ball", Motion::kDynamic, at(0, 0.005 + 0.005 + 0.01, 0), {sphereShape(0.005)}));
    s.bodies[1].mass = 0.001;
    // frictionless (without a material both would have the default friction): the ball comes
    // to rest at once, so the impulses at the end of the record are its steady weight
    s.materials.push_back(scene::Material{});
    s.bodies[0].primitives[0].material = s.bodies[1].primitives[0].material = 0;
    s.gravity_W = Vec3{0.0, -9.81, 0.0};
    sim::SimOptions o;
    o.response.ramp_s = 0.0;
    o.dynamics_impulse_window_s = window;
    Runner run(sim::Simulation::create(finish(s), o).value(), o);
    Path path({{0.0, at(0, 0, 0)}, {0.3, at(0, 0, 0)}});
    double peak = 0.0, peak_t = 0.0, integral = 0.0;
    const Figures f = run.run(path, [&](const sim::TickInput& in, const sim::TickOutput& out) {
      // the force on the hand is down (the ball pushes the paddle down)
      const double fy = -out.force_W_n.y;
      integral += fy * o.response.tick_s;
      if (fy > peak)
        peak = fy, peak_t = in.t_s;
    });
    EXPECT_TRUE(f.all_finite);
    EXPECT_EQ(f.max_force_step_n <= o.response.max_force_step_n * (1.0 + 1e-9), true);
    rows.push_back({window, peak, peak_t, integral});
  }
  std::printf("  | window | peak force | peak at | integral over 0.3 s |\n");
  for (const Row& r : rows)
    std::printf("  | %.0f ms | %.4f N | %.3f s | %.9f N s |\n", 1e3 * r.window_s, r.peak_n,
                r.peak_t_s, r.integral_ns);
  // the ball's weight (it rests on the paddle from the impact on, about 0.25 s) and its momentum
  // at the impact: sqrt(2 g h) m
  const double expected = 0.001 * (std::sqrt(2.0 * 9.81 * 0.01) + 9.81 * (0.3 - rows[0].peak_t_s));
  std::printf("  expected about %.6f N s (impact m v + weight m g over the rest)\n", expected);
  // the same integral: the impulses are the same (the dynamics do not depend on the window),
  // less what is still in the window at the end of the record: the resting ball's weight
  // m g dt per tick, of which (N - 1) / 2 ticks' worth is still to come (Hann weights over N
  // ticks, the first delivered on the tick of the impulse)
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double n_ticks = std::round(rows[i].window_s / 0.001);
    const double in_flight = 0.001 * 9.81 * 0.001 * (n_ticks - 1.0) / 2.0;
    std::printf("  window %.0f ms: integral + still in the window %.9f N s\n",
                1e3 * rows[i].window_s, rows[i].integral_ns + in_flight);
    EXPECT_NEAR(rows[i].integral_ns + in_flight, rows[0].integral_ns, 1e-4 * rows[0].integral_ns)
        << "window " << rows[i].window_s;
    EXPECT_LT(rows[i].peak_n, rows[i - 1].peak_n) << "window " << rows[i].window_s;
  }
  EXPECT_NEAR(rows[0].integral_ns, expected, 0.1 * expected);
}

// [response] dynamics_velocity_iterations and dynamics_position_iterations reach the solver: three
// 20 mm boxes stacked on a floor under gravity, each started 2 mm into the one below (far beyond
// the slop, so the split impulses have work), 0.3 s with the defaults (12, 6), with one velocity
// iteration, and with no drift correction; each changes where the top box ends, and without the
// drift correction the boxes stay inside each other.
TEST(SimDynamics, IterationOptionsReachTheSolver) {
  const auto topY = [](std::uint32_t velocity, std::uint32_t position) {
    scene::SceneModel s;
    s.bodies.push_back(
        makeBody("floor", Motion::kStatic, at(0, -0.01, 0), {boxShape(Vec3{0.2, 0.01, 0.2})}));
    for (int i = 0; i < 3; ++i) {
      s.bodies.push_back(makeBody("box", Motion::kDynamic, at(0.002 * i, 0.01 + 0.018 * i, 0),
                                  {boxShape(Vec3{0.01})}));
      s.bodies.back().mass = 0.01;
    }
    s.gravity_W = Vec3{0.0, -9.81, 0.0};
    sim::SimOptions o;
    o.dynamics_sleep_time_s = 0.0;
    o.dynamics_velocity_iterations = velocity;
    o.dynamics_position_iterations = position;
    auto created = sim::Simulation::create(finish(s), o);
    EXPECT_TRUE(created.ok()) << created.error().message;
    auto simulation = std::move(created).value();
    sim::TickInput in;
    in.X_W_device = at(0.0, 0.3, 0.0);  // the probe sphere far above
    for (int k = 0; k < 300; ++k) {
      in.t_s = 0.001 * k;
      (void)simulation->step(in);
    }
    for (const sim::BodyPose& b : simulation->bodyPoses()) {
      if (b.body == 3)
        return b.X_WB.translation.y;
    }
    return std::nan("");
  };
  const double defaults = topY(12, 6), one = topY(1, 6), none = topY(12, 0);
  std::printf("  top box at y = %.9f m (12, 6), %.9f m (1, 6), %.9f m (12, 0)\n", defaults, one,
              none);
  ASSERT_TRUE(std::isfinite(defaults) && std::isfinite(one) && std::isfinite(none));
  // pushed out to near its stacked height (centre at 50 mm) with the defaults; left about 4 mm
  // deep (46 mm) without the drift correction
  EXPECT_NEAR(defaults, 0.05, 0.001);
  EXPECT_LT(none, 0.048);
  EXPECT_NE(one, defaults);
  EXPECT_EQ(topY(12, 6), defaults);  // and the same options give the same run
}

TEST(SimDynamics, BadDynamicsOptionsAreRefusedWithAMessage) {
  scene::SceneModel s;
  s.bodies.push_back(makeBody("box", Motion::kDynamic, at(0, 0, 0), {boxShape(Vec3{0.01})}));
  const auto model = finish(s);
  sim::SimOptions o;
  o.dynamics_impulse_window_s = -0.01;
  auto a = sim::Simulation::create(model, o);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("[response] impulse_window_s"), std::string::npos)
      << a.error().message;
  for (const auto& [velocity, position, key] :
       {std::tuple{0u, 6u, "[response] dynamics_velocity_iterations must be in [1, 1000]"},
        std::tuple{1001u, 6u, "[response] dynamics_velocity_iterations must be in [1, 1000]"},
        std::tuple{12u, 1001u, "[response] dynamics_position_iterations must be in [0, 1000]"}}) {
    o = sim::SimOptions{};
    o.dynamics_velocity_iterations = velocity;
    o.dynamics_position_iterations = position;
    auto it = sim::Simulation::create(model, o);
    ASSERT_FALSE(it.ok()) << velocity << " / " << position;
    EXPECT_NE(it.error().message.find(key), std::string::npos) << it.error().message;
  }
  o = sim::SimOptions{};
  o.response.dynamic_backstop_fraction = std::nan("");
  auto b = sim::Simulation::create(model, o);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("dynamic_backstop_fraction"), std::string::npos);
  o = sim::SimOptions{};
  scene::SceneModel bad = s;
  bad.bodies[0].mass = -1.0;
  auto c = sim::Simulation::create(finish(bad), o);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("box"), std::string::npos) << c.error().message;
}

}  // namespace
}  // namespace hapticd::simtest
