#pragma once
// Test harness of the simulation: scenes built in code, pose paths sampled tick by tick on
// simulated time, and the per-tick invariants every hard case must keep (issue 5): finite output,
// |F| and |T| within the limits, force step within F_max, proxy penetration within a bound,
// passivity over a closed path, no chatter of the normal force while the device is still.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/sim/output_shaping.h"
#include "core/sim/simulation.h"

namespace hapticd::simtest {

using geom::Pose;
using geom::Quat;
using geom::Vec3;

std::shared_ptr<const geom::Polytope> boxShape(const Vec3& half);
std::shared_ptr<const geom::Polytope> hullShape(const std::vector<Vec3>& points);

/// A body of one primitive (or several), pose X_WB.
scene::Body makeBody(const std::string& name,
                     scene::Motion motion,
                     const Pose& X_WB,
                     std::vector<std::shared_ptr<const geom::Polytope>> shapes,
                     std::vector<Pose> X_BP = {});

/// Sets probe_body, the plan (by hand: makePlan lives in the scene library) and length_scale.
std::shared_ptr<const scene::SceneModel> finish(scene::SceneModel s);

Quat axisAngle(const Vec3& axis, double angle_rad);

/// The pose at (x, y, z) turned by q (unturned by default).
Pose at(double x, double y, double z, Quat q = Quat{1, 0, 0, 0});

/// sim::Simulation::create; a refusal fails the test (with its message) and gives nullptr.
std::unique_ptr<sim::Simulation> make(std::shared_ptr<const scene::SceneModel> s,
                                      const sim::SimOptions& o);
/// make() with the daemon's output stage after it (sim::withOutputStage): the wrench a device
/// would be sent.
std::unique_ptr<sim::Simulation> makeShaped(std::shared_ptr<const scene::SceneModel> s,
                                            const sim::SimOptions& o);

/// Default options, the ramp off, with the response's lengths (stiffness, speed, penetration
/// allowance, attach distance, torques: N per scene unit) for a scene whose unit is s metres: the
/// same relative behaviour at any scale.
sim::SimOptions scaledResponseOptions(double s);

/// Keyframed device path: piecewise linear positions, slerped rotations, held buttons.
struct Key {
  double t_s;
  Pose X;
  std::uint32_t buttons = 0;
};
class Path {
 public:
  explicit Path(std::vector<Key> keys) : keys_(std::move(keys)) {}
  Pose at(double t) const;
  std::uint32_t buttonsAt(double t) const;
  double duration() const { return keys_.back().t_s; }

 private:
  std::vector<Key> keys_;
};

/// Reads a pose stream (protocol/pose_stream.h, the strict dialect, quaternions within 1e-3 of
/// unit length). Empty keys when the file cannot be read or is malformed.
std::vector<Key> readPoseStream(const std::string& file);

/// What a run showed.
struct Figures {
  std::uint64_t ticks = 0;
  double max_force_n = 0.0, max_torque_nm = 0.0;
  double max_force_step_n = 0.0, max_torque_step_nm = 0.0;
  double max_penetration = 0.0;
  double energy_to_hand_j = 0.0;  // sum F . dx (+ T . dtheta): what the device gives the hand
  double energy_abs_j = 0.0;      // sum |F . dx| + |T . dtheta|
  std::uint32_t longest_alternation = 0;  // still device: longest run of sign flips of dF_n
  std::uint32_t still_ticks = 0;
  std::uint32_t max_contacts = 0;
  bool all_finite = true;
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a over every output's bytes
  void print(const char* name) const;
};

/// Drives a Simulation along a path, tick by tick, checking the invariants as it goes. The
/// simulation runs with the daemon's output stage after it (sim::withOutputStage): the wrench
/// checked is the one a device would be sent.
class Runner {
 public:
  Runner(std::unique_ptr<sim::Simulation> sim, const sim::SimOptions& options)
      : sim_(sim::withOutputStage(std::move(sim), options.response)), options_(options) {}
  /// Runs the whole path; `each` (if set) sees every tick's input and output.
  template <class F>
  Figures run(const Path& path, F&& each) {
    const double dt = options_.response.tick_s;
    const auto n = static_cast<std::uint64_t>(std::llround(path.duration() / dt));
    for (std::uint64_t k = 0; k <= n; ++k) {
      sim::TickInput in;
      in.t_s = static_cast<double>(k) * dt;
      in.X_W_device = path.at(in.t_s);
      in.buttons = path.buttonsAt(in.t_s);
      const sim::TickOutput out = sim_->step(in);
      account(in, out);
      each(in, out);
    }
    return fig_;
  }
  Figures run(const Path& path) {
    return run(path, [](const sim::TickInput&, const sim::TickOutput&) {});
  }
  sim::Simulation& sim() { return *sim_; }
  /// The direction along which chatter is measured (the expected contact normal).
  void setNormal(const Vec3& n) { normal_ = n; }

 private:
  void account(const sim::TickInput& in, const sim::TickOutput& out);
  std::unique_ptr<sim::Simulation> sim_;
  sim::SimOptions options_;
  Figures fig_;
  bool have_prev_ = false;
  sim::TickInput prev_in_;
  sim::TickOutput prev_out_;
  Vec3 normal_{0.0, 1.0, 0.0};
  int last_sign_ = 0;
  std::uint32_t run_ = 0;
  std::uint32_t still_run_ = 0;
};

/// Asserts the invariants of issue 5 on a run's figures (gtest EXPECTs).
void expectInvariants(const Figures& f, const sim::SimOptions& o, double penetration_bound);

}  // namespace hapticd::simtest
