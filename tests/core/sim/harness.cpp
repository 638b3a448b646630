#include "tests/core/sim/harness.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "core/geometry/rotation.h"
#include "protocol/pose_stream.h"

namespace hapticd::simtest {

std::shared_ptr<const geom::Polytope> hullShape(const std::vector<Vec3>& points) {
  return std::make_shared<const geom::Polytope>(geom::Polytope::fromPoints(points).value());
}

std::shared_ptr<const geom::Polytope> boxShape(const Vec3& h) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i)
    p.push_back(Vec3{i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z});
  return hullShape(p);
}

scene::Body makeBody(const std::string& name,
                     scene::Motion motion,
                     const Pose& X_WB,
                     std::vector<std::shared_ptr<const geom::Polytope>> shapes,
                     std::vector<Pose> X_BP) {
  scene::Body b;
  b.name = name;
  b.motion = motion;
  b.X_WB = X_WB;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    scene::Primitive p;
    p.shape = shapes[i];
    if (i < X_BP.size())
      p.X_BP = X_BP[i];
    b.primitives.push_back(p);
  }
  if (motion == scene::Motion::kDynamic)
    b.mass = 1.0;
  return b;
}

std::shared_ptr<const scene::SceneModel> finish(scene::SceneModel s) {
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    if (s.bodies[i].probe)
      s.probe_body = static_cast<std::int32_t>(i);
  }
  s.plan = scene::SimulationPlan{};
  s.plan.contact_forces = true;
  for (const auto& b : s.bodies) {
    if (b.motion == scene::Motion::kDynamic)
      s.plan.dynamics = true;
    (b.motion == scene::Motion::kStatic ? s.plan.static_primitives : s.plan.moving_primitives) +=
        static_cast<std::uint32_t>(b.primitives.size());
  }
  s.plan.joints = !s.joints.empty();
  return std::make_shared<const scene::SceneModel>(std::move(s));
}

Quat axisAngle(const Vec3& axis, double a) {
  return glm::angleAxis(a, glm::normalize(axis));
}

Pose Path::at(double t) const {
  if (t <= keys_.front().t_s)
    return keys_.front().X;
  for (std::size_t i = 1; i < keys_.size(); ++i) {
    if (t <= keys_[i].t_s) {
      const Key& a = keys_[i - 1];
      const Key& b = keys_[i];
      const double s = (t - a.t_s) / (b.t_s - a.t_s);
      Pose X;
      X.translation = a.X.translation + s * (b.X.translation - a.X.translation);
      X.rotation = glm::normalize(glm::slerp(a.X.rotation, b.X.rotation, s));
      return X;
    }
  }
  return keys_.back().X;
}

std::uint32_t Path::buttonsAt(double t) const {
  std::uint32_t b = keys_.front().buttons;
  for (const Key& k : keys_) {
    if (k.t_s <= t)
      b = k.buttons;
  }
  return b;
}

std::vector<Key> readPoseStream(const std::string& file) {
  auto text = proto::readPoseStreamFile(file);
  if (!text)
    return {};
  auto rows = proto::parsePoseStream(text.value(), file, 1e-3, proto::PoseStreamDialect::kStrict);
  if (!rows)
    return {};
  std::vector<Key> keys;
  keys.reserve(rows.value().size());
  for (const proto::PoseStreamRow& r : rows.value())
    keys.push_back({r.t_s, r.X_WD, r.buttons});
  return keys;
}

void Figures::print(const char* name) const {
  std::printf(
      "[%s] ticks %llu | max |F| %.4f N, max |T| %.5f N m | max step %.4f N, %.5f N m | max "
      "penetration %.4g | energy to hand %.4g J of %.4g J (%.3f%%) | still ticks %u, longest "
      "alternation %u | max contacts %u | hash %016llx\n",
      name, static_cast<unsigned long long>(ticks), max_force_n, max_torque_nm, max_force_step_n,
      max_torque_step_nm, max_penetration, energy_to_hand_j, energy_abs_j,
      energy_abs_j > 0 ? 100.0 * energy_to_hand_j / energy_abs_j : 0.0, still_ticks,
      longest_alternation, max_contacts, static_cast<unsigned long long>(hash));
}

Pose at(double x, double y, double z, Quat q) {
  return Pose{Vec3{x, y, z}, q};
}

std::unique_ptr<sim::Simulation> make(std::shared_ptr<const scene::SceneModel> s,
                                      const sim::SimOptions& o) {
  auto created = sim::Simulation::create(std::move(s), o);
  EXPECT_TRUE(created.ok()) << (created.ok() ? "" : created.error().message);
  return created.ok() ? std::move(created).value() : nullptr;
}

std::unique_ptr<sim::Simulation> makeShaped(std::shared_ptr<const scene::SceneModel> s,
                                            const sim::SimOptions& o) {
  auto sim = make(std::move(s), o);
  return sim ? sim::withOutputStage(std::move(sim), o.response) : nullptr;
}

sim::SimOptions scaledResponseOptions(double s) {
  sim::SimOptions o;
  o.response.ramp_s = 0.0;
  o.response.stiffness_n_per_m /= s;
  o.response.max_speed_m_per_s *= s;
  o.response.penetration_allowance_m *= s;
  o.response.attach_distance_m *= s;
  o.response.max_torque_nm *= s;
  o.response.max_torque_step_nm *= s;
  return o;
}

namespace {
void hashBytes(std::uint64_t& h, const void* p, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(p);
  for (std::size_t i = 0; i < n; ++i)
    h = (h ^ b[i]) * 1099511628211ull;
}
void hashVec(std::uint64_t& h, const Vec3& v) {
  const double d[3] = {v.x, v.y, v.z};
  hashBytes(h, d, sizeof d);
}
}  // namespace

void Runner::account(const sim::TickInput& in, const sim::TickOutput& out) {
  ++fig_.ticks;
  const bool fin = geom::finite(out.force_W_n) && geom::finite(out.torque_W_nm) &&
                   geom::finite(out.X_W_proxy.translation) &&
                   std::isfinite(out.X_W_proxy.rotation.w) && std::isfinite(out.max_penetration_m);
  fig_.all_finite = fig_.all_finite && fin;
  fig_.max_force_n = std::max(fig_.max_force_n, glm::length(out.force_W_n));
  fig_.max_torque_nm = std::max(fig_.max_torque_nm, glm::length(out.torque_W_nm));
  fig_.max_penetration = std::max(fig_.max_penetration, out.max_penetration_m);
  fig_.max_contacts = std::max(fig_.max_contacts, out.contacts);
  hashVec(fig_.hash, out.force_W_n);
  hashVec(fig_.hash, out.torque_W_nm);
  hashVec(fig_.hash, out.X_W_proxy.translation);
  const double q[4] = {out.X_W_proxy.rotation.w, out.X_W_proxy.rotation.x, out.X_W_proxy.rotation.y,
                       out.X_W_proxy.rotation.z};
  hashBytes(fig_.hash, q, sizeof q);
  hashBytes(fig_.hash, &out.contacts, sizeof out.contacts);
  if (have_prev_) {
    fig_.max_force_step_n =
        std::max(fig_.max_force_step_n, glm::length(out.force_W_n - prev_out_.force_W_n));
    fig_.max_torque_step_nm =
        std::max(fig_.max_torque_step_nm, glm::length(out.torque_W_nm - prev_out_.torque_W_nm));
    // the force of the previous tick was held while the device moved from there to here
    const Vec3 dx = in.X_W_device.translation - prev_in_.X_W_device.translation;
    const Vec3 dth =
        geom::rotationVector(in.X_W_device.rotation * glm::conjugate(prev_in_.X_W_device.rotation));
    const double e = glm::dot(prev_out_.force_W_n, dx) + glm::dot(prev_out_.torque_W_nm, dth);
    fig_.energy_to_hand_j += e;
    fig_.energy_abs_j += std::abs(glm::dot(prev_out_.force_W_n, dx)) +
                         std::abs(glm::dot(prev_out_.torque_W_nm, dth));
    // chatter: while the device is still, the normal force must not flip its step's sign tick
    // after tick (a limit cycle); steps below 1e-9 of the force limit are numerical noise
    const bool still = glm::length(dx) == 0.0 && glm::length(dth) == 0.0;
    if (still) {
      ++fig_.still_ticks;
      ++still_run_;
      const double dfn = glm::dot(out.force_W_n - prev_out_.force_W_n, normal_);
      const double noise = 1e-9 * options_.response.max_force_n;
      const int sign = dfn > noise ? 1 : dfn < -noise ? -1 : 0;
      if (sign != 0 && last_sign_ != 0 && sign != last_sign_) {
        ++run_;
        fig_.longest_alternation = std::max(fig_.longest_alternation, run_);
      } else if (sign != 0) {
        run_ = 0;
      }
      if (sign != 0)
        last_sign_ = sign;
    } else {
      still_run_ = 0;
      run_ = 0;
      last_sign_ = 0;
    }
  }
  have_prev_ = true;
  prev_in_ = in;
  prev_out_ = out;
}

void expectInvariants(const Figures& f, const sim::SimOptions& o, double penetration_bound) {
  const auto& r = o.response;
  EXPECT_TRUE(f.all_finite);
  EXPECT_LE(f.max_force_n, r.max_force_n * (1.0 + 1e-12));
  EXPECT_LE(f.max_torque_nm, r.max_torque_nm * (1.0 + 1e-12));
  EXPECT_LE(f.max_force_step_n, r.max_force_step_n * (1.0 + 1e-9));
  EXPECT_LE(f.max_torque_step_nm, r.max_torque_step_nm * (1.0 + 1e-9));
  EXPECT_LE(f.max_penetration, penetration_bound);
  EXPECT_LE(f.energy_to_hand_j, 0.02 * f.energy_abs_j);
  // no limit cycle: at most 3 sign flips of the normal force step in a row while still
  EXPECT_LE(f.longest_alternation, 3u);
}

}  // namespace hapticd::simtest
