#include "core/sim/simulation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/collision/collision_world.h"
#include "core/collision/penetration.h"
#include "core/dynamics/dynamics.h"
#include "core/geometry/rotation.h"
#include "core/response/coupling.h"
#include "core/response/face_contact.h"
#include "core/response/output_stage.h"
#include "core/response/proxy.h"
#include "core/response/shading.h"

namespace hapticd::sim {
namespace {

using collision::BodyKind;
using collision::CollisionWorld;
using geom::Quat;
using geom::Transform;
using response::ContactRow;

constexpr std::uint32_t kNone = 0xffffffffu;
constexpr std::int32_t kRoleHeld = -2, kRoleFixed = -1;
// faces within ~18 degrees of the pair's normal on both sides make a face-face contact
constexpr double kFaceCosTolerance = 0.95;

enum class Mode : std::uint8_t { kFree = 0, kGrab = 1, kRim = 2, kCentre = 3 };

bool finitePositive(double v) {
  return std::isfinite(v) && v > 0.0;
}

bool finitePose(const Vec3& p, const Quat& q) {
  return geom::finite(p) && geom::finite(q);
}

// A finite pose with a unit quaternion (|‖q‖ − 1| <= kUnitTolerance), normalised into *out.
constexpr double kUnitTolerance = 1e-6;
bool unitPose(const geom::Pose& in, geom::Pose* out) {
  if (!finitePose(in.translation, in.rotation))
    return false;
  const Quat& q = in.rotation;
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!std::isfinite(n) || std::abs(n - 1.0) > kUnitTolerance)
    return false;
  out->translation = in.translation;
  out->rotation = Quat{q.w / n, q.x / n, q.y / n, q.z / n};
  return true;
}

Vec3 rotate(const Quat& q, const Vec3& v) {
  return q * v;
}

// Points on a sphere (golden-angle spiral), for the probe sphere's hull.
std::vector<Vec3> spherePoints(double radius, int n) {
  std::vector<Vec3> pts;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
    const double a = golden * i;
    pts.push_back(radius * Vec3{r * std::cos(a), y, r * std::sin(a)});
  }
  return pts;
}

struct BodyInfo {
  std::int32_t scene_index = -1;  // -1: the probe sphere
  BodyKind kind = BodyKind::kStatic;
  Vec3 com_B{0.0};
  double stiffness = 0.0;      // felt stiffness of this body's surfaces (N per scene unit)
  double origin_radius = 0.0;  // largest distance of its points from its origin (scene units)
  // a hinge to the scene frame (or to a static body), for the attach modes
  bool hinge = false;
  Vec3 hinge_o_B{0.0}, hinge_a_B{0.0};          // in this body's frame at its initial pose
  double hinge_radius = 0.0;                    // largest distance of its points from the axis
  std::vector<response::ShadingTable> shading;  // per primitive (empty: shading off)
};

class SimulationImpl final : public Simulation {
 public:
  SimulationImpl(std::shared_ptr<const scene::SceneModel> scene, const SimOptions& options)
      : scene_(std::move(scene)),
        options_(options),
        coupling_(response::CouplingParams{}),
        output_(outputLimits(options.response)) {}

  static collision::WorldOptions worldOptions(const SimOptions& o) {
    collision::WorldOptions w;
    const double delta = o.response.max_speed_m_per_s * o.response.tick_s;
    // pairs within the predictive distance plus one tick's travel are found; with dynamics, at
    // least the margin within which the dynamics see contacts before they touch (time of impact)
    // (buildCollisionWorld raises it to the dynamics' margin when the scene has dynamic bodies)
    w.box_margin = 2.0 * delta;
    w.budget.max_pairs = o.max_pairs_per_tick;
    // a pair of bodies that did not move keeps its exact answer
    w.skip_unmoved_pairs = true;
    return w;
  }
  static response::OutputLimits outputLimits(const ResponseOptions& r) {
    response::OutputLimits l;
    l.max_force_n = r.max_force_n;
    l.max_torque_nm = r.max_torque_nm;
    l.max_force_step_n = r.max_force_step_n;
    l.max_torque_step_nm = r.max_torque_step_nm;
    l.ramp_s = r.ramp_s;
    l.tick_s = r.tick_s;
    return l;
  }

  Result<bool> build();

  TickOutput step(const TickInput& input) override;
  std::span<const BodyPose> bodyPoses() const override { return body_poses_; }
  void restartRamp() override { output_.restartRamp(); }
  DynamicsStatus dynamicsStatus() const override;
  const scene::SceneModel& scene() const override { return *scene_; }
  void prepareThread() override;
  EditStatus setKinematicPose(std::uint32_t body, const Pose& X_WB) override;
  // the checks both edits share: in range, not static, not held (kOk when editable)
  EditStatus editable(std::uint32_t body) const;
  EditStatus setBodyActive(std::uint32_t body, bool active, const Pose& X_WB) override;
  bool bodyActive(std::uint32_t body) const override {
    return body < scene_->bodies.size() && active_[body] != 0;
  }
  std::span<const ContactPoint> contactPoints() const override { return contact_points_; }

 private:
  bool isHeld(std::uint32_t body) const {
    for (std::uint32_t i = 0; i < held_count_; ++i) {
      if (held_[i] == body)
        return true;
    }
    return false;
  }
  std::int32_t role(std::uint32_t body) const {
    if (isHeld(body))
      return kRoleHeld;
    for (std::uint32_t d = 0; d < driven_count_; ++d) {
      if (driven_ids_[d] == body)
        return static_cast<std::int32_t>(d);
    }
    return kRoleFixed;
  }
  void updateDriven();
  bool excluded(std::uint32_t a, std::uint32_t b) const {
    for (const auto& [x, y] : excluded_pairs_) {
      if ((x == a && y == b) || (x == b && y == a))
        return true;
    }
    return false;
  }
  Vec3 comW(std::uint32_t body) const {
    const geom::Pose& X = world_.pose(body);
    return X.translation + rotate(X.rotation, info_[body].com_B);
  }
  double radiusAbout(std::uint32_t body, const Vec3& c_W) const;
  double heldRadius(const Vec3& c_W) const;
  void gatherRows(double* max_penetration);
  const geom::Polytope& primShape(std::uint32_t body, std::uint32_t prim) const;
  Transform primTransform(std::uint32_t body, std::uint32_t prim) const;
  void applyStep(const response::ProxyStep& s);
  void updateAttachment(const TickInput& input);
  void attach(std::uint32_t body);
  void detach();
  void setHeldPoses();
  void setRotationalStiffness();
  void pushRow(const ContactRow& row, std::uint32_t env) {
    const std::size_t n = rows_.rows().size();
    rows_.push(row);
    if (rows_.rows().size() > n)
      row_env_.push_back(env);
  }
  void fillContactPoints(TickOutput* out);

  // a dynamic body the dynamics move (not held, not driven by this tick's proxy step)
  bool movedByDynamics(std::uint32_t body) const {
    return dyn_active_ && info_[body].kind == BodyKind::kDynamic && role(body) == kRoleFixed;
  }

  std::shared_ptr<const scene::SceneModel> scene_;
  SimOptions options_;
  CollisionWorld world_;
  std::unique_ptr<dynamics::Dynamics> dyn_;  // only when the plan has dynamics
  bool dyn_active_ = false;
  double backstop_ = 0.0;  // depth into a dynamic body beyond which its penalty rows act
  response::VirtualCoupling coupling_;
  response::OutputStage output_;
  response::ProxyParams proxy_params_;
  std::shared_ptr<const geom::Polytope> probe_sphere_;
  std::vector<BodyInfo> info_;  // per world body
  std::vector<std::pair<std::uint32_t, std::uint32_t>> excluded_pairs_;
  std::vector<BodyPose> body_poses_;
  std::vector<std::uint32_t> pose_bodies_;  // world ids of body_poses_
  response::ContactRows rows_;
  std::vector<std::uint32_t> row_env_;        // per row of rows_: the environment body's world id
  std::vector<ContactPoint> contact_points_;  // contactPoints(): capacity fixed in build()
  // scene edits: per world body 1 active, 0 out of the scene (setBodyActive)
  std::vector<std::uint8_t> active_;
  // an edit changed the collision world since the last gatherRows: the next step() runs the
  // collision step once before the proxy's, so that the proxy sees the edit (moved, added or
  // removed bodies) instead of stepping on stale rows
  bool world_dirty_ = false;
  // with dynamics: a kinematic target given to the dynamics, which move the body in this tick's
  // dynamics step (the collision world sees it from the next tick on)
  bool kinematic_target_pending_ = false;
  // per world body: how far (scene units) its points moved by setKinematicPose since the last
  // collision step that saw the move; a pusher moving faster than the proxy's safe distance
  // raises the proxy's travel bound by this on the tick it touches the held set
  std::vector<double> edit_travel_;
  // a dynamic body grabbed rigidly (kGrab): its mass properties for its weight and inertia at
  // the hand (grab_mass_ 0: nothing of the kind is grabbed)
  double grab_mass_ = 0.0;
  Vec3 grab_gravity_W_{0.0};
  Vec3 grab_com_B_{0.0};
  geom::Mat3 grab_inertia_B_{0.0};
  Vec3 grab_r_P_{0.0};  // its centre of mass from the handle point, in the probe's frame
  std::uint32_t grab_history_ = 0;          // device poses seen since the grab (up to 2)
  Vec3 grab_c1_{0.0}, grab_c2_{0.0};        // the device-side centre of mass, last two ticks
  Quat grab_q1_{1.0, 0.0, 0.0, 0.0};        // the device's rotation, last tick
  Vec3 grab_w1_{0.0};                       // the device's angular velocity, last tick
  Vec3 grab_a_f_{0.0}, grab_alpha_f_{0.0};  // low-passed accelerations
  double grab_beta_ = 1.0;                  // the low-pass's gain per tick
  double delta_ = 0.0;                      // this tick's predictive distance
  double max_travel_ = 0.0;                 // safe distance per tick
  double speed_decay_ = 0.0;
  double v_c_ = 0.0;  // current speed bound of the held body's points
  bool have_prev_device_ = false;
  Vec3 prev_h_dev_{0.0};
  Quat prev_q_dev_{1.0, 0.0, 0.0, 0.0};
  double k_s_ = 0.0;     // felt stiffness at the device
  double k_c_ = 0.0;     // coupling stiffness
  double ratio_ = 50.0;  // proxy contact stiffness / k_s
  double probe_radius_ = 0.0;

  // the held set: the probe body first, then an attached body
  std::uint32_t probe_ = 0;
  std::array<std::uint32_t, 2> held_{};
  std::uint32_t held_count_ = 1;
  Mode mode_ = Mode::kFree;
  std::uint32_t attached_ = kNone;
  Transform X_probe_attached_;                 // kGrab: the attached body in the probe's frame
  Transform X_attached_probe_;                 // kRim: the probe in the attached body's frame
  Quat q_attached_probe_{1.0, 0.0, 0.0, 0.0};  // kCentre: the probe's rotation relative to the body
  Vec3 centre_h_W_{0.0};                       // kCentre: the fixed handle point
  Vec3 hinge_o_W_{0.0}, hinge_a_W_{0.0};
  double held_radius_ = 0.0;
  std::uint32_t last_buttons_ = 0;
  // bodies on a hinge to the scene that the held set may turn (quasi-static coordinates)
  std::array<std::uint32_t, response::ProxyProblem::kMaxDriven> driven_ids_{};
  std::uint32_t driven_count_ = 0;
  std::array<geom::Pose, response::ProxyProblem::kMaxDriven> driven_before_{};
  bool first_step_ = true;
  const geom::Polytope* max_shape_ = nullptr;  // the polytope with the most faces
  std::size_t max_faces_ = 0;
  double last_penetration_ = 0.0;  // of the rows at the current proxy pose
  geom::Pose X_W_probe_;           // the proxy: the probe body's pose
};

double SimulationImpl::radiusAbout(std::uint32_t body, const Vec3& c_W) const {
  const Transform X = world_.pose(body).toTransform();
  double r = 0.0;
  if (info_[body].scene_index < 0) {
    for (const auto& v : probe_sphere_->vertices())
      r = std::max(r, glm::length(X.apply(v.p) - c_W));
    return r;
  }
  for (const auto& p :
       scene_->bodies[static_cast<std::size_t>(info_[body].scene_index)].primitives) {
    const Transform XP = X * p.X_BP.toTransform();
    for (const auto& v : p.shape->vertices())
      r = std::max(r, glm::length(XP.apply(v.p) - c_W));
  }
  return r;
}

double SimulationImpl::heldRadius(const Vec3& c_W) const {
  double r = 0.0;
  for (std::uint32_t i = 0; i < held_count_; ++i)
    r = std::max(r, radiusAbout(held_[i], c_W));
  return r;
}

Result<bool> SimulationImpl::build() {
  const ResponseOptions& r = options_.response;
  if (!finitePositive(r.stiffness_n_per_m))
    return Error{"response.stiffness must be > 0"};
  if (!finitePositive(r.tick_s))
    return Error{"response.tick must be > 0"};
  if (!finitePositive(r.max_force_n))
    return Error{"response.max_force must be > 0"};
  if (!finitePositive(r.max_torque_nm))
    return Error{"response.max_torque must be > 0"};
  if (!finitePositive(r.max_force_step_n))
    return Error{"response.max_force_step must be > 0"};
  if (!finitePositive(r.max_torque_step_nm))
    return Error{"response.max_torque_step must be > 0"};
  if (!std::isfinite(r.ramp_s) || r.ramp_s < 0.0)
    return Error{"response.ramp must be >= 0"};
  if (!finitePositive(r.max_speed_m_per_s))
    return Error{"response.max_speed must be > 0"};
  if (!std::isfinite(r.speed_decay_s) || r.speed_decay_s < 0.0)
    return Error{"response.speed_decay must be >= 0"};
  if (!std::isfinite(r.min_predictive_fraction) || r.min_predictive_fraction <= 0.0 ||
      r.min_predictive_fraction > 1.0)
    return Error{"response.min_predictive_fraction must be in (0, 1]"};
  if (!std::isfinite(r.proxy_stiffness_ratio) || r.proxy_stiffness_ratio <= 1.0)
    return Error{"response.proxy_stiffness_ratio must be > 1"};
  if (!std::isfinite(r.coupling_damping_factor) || r.coupling_damping_factor < 0.0)
    return Error{"response.coupling_damping_factor must be >= 0"};
  if (!std::isfinite(r.rot_stiffness_nm_per_rad) || r.rot_stiffness_nm_per_rad < 0.0)
    return Error{"response.rot_stiffness must be >= 0"};
  if (!finitePositive(r.penetration_allowance_m))
    return Error{"response.penetration_allowance must be > 0"};
  if (!std::isfinite(r.crease_angle_deg) || r.crease_angle_deg < 0.0 || r.crease_angle_deg >= 90.0)
    return Error{"response.crease_angle must be in [0, 90) degrees"};
  if (!std::isfinite(r.dynamic_backstop_fraction) || r.dynamic_backstop_fraction < 0.0 ||
      r.dynamic_backstop_fraction > 1.0)
    return Error{"response.dynamic_backstop_fraction must be in [0, 1]"};
  if (!std::isfinite(options_.dynamics_impulse_window_s) ||
      options_.dynamics_impulse_window_s < 0.0)
    return Error{"dynamics impulse window must be >= 0 s"};
  if (!std::isfinite(options_.dynamics_sleep_time_s) || options_.dynamics_sleep_time_s < 0.0)
    return Error{"dynamics sleep time must be >= 0 s"};
  if (!std::isfinite(r.attach_distance_m) || r.attach_distance_m < 0.0)
    return Error{"response.attach_distance must be >= 0"};
  if (!std::isfinite(r.grab_inertia_filter_s) || r.grab_inertia_filter_s < 0.0)
    return Error{"response.grab_inertia_filter must be >= 0 s"};
  grab_beta_ =
      r.grab_inertia_filter_s > 0.0 ? 1.0 - std::exp(-r.tick_s / r.grab_inertia_filter_s) : 1.0;
  const scene::SceneModel& sc = *scene_;
  if (sc.probe_body >= static_cast<std::int32_t>(sc.bodies.size()))
    return Error{"scene: probe body " + std::to_string(sc.probe_body) + " out of range (" +
                 std::to_string(sc.bodies.size()) + " bodies)"};
  if (sc.probe_body < 0 && !finitePositive(options_.probe_sphere_radius_m))
    return Error{"probe sphere radius must be > 0"};

  max_travel_ = r.max_speed_m_per_s * r.tick_s;
  speed_decay_ = r.speed_decay_s > 0.0 ? std::exp(-r.tick_s / r.speed_decay_s) : 0.0;
  k_s_ = r.stiffness_n_per_m;
  ratio_ = r.proxy_stiffness_ratio;
  // series springs: k_c in series with ratio * k_s gives k_s
  k_c_ = k_s_ * ratio_ / (ratio_ - 1.0);
  const double crease = r.crease_angle_deg * std::numbers::pi / 180.0;

  // the probe sphere, when the scene marks no probe body: a world body after the scene's
  collision::BodyDesc sphere;
  if (sc.probe_body < 0) {
    auto hull = geom::Polytope::fromPoints(spherePoints(options_.probe_sphere_radius_m, 64));
    if (!hull.ok())
      return Error{"probe sphere: " + hull.error().message};
    probe_sphere_ = std::make_shared<const geom::Polytope>(std::move(hull).value());
    sphere.kind = BodyKind::kProbe;
    sphere.group = sphere.mask = ~0u;  // unfiltered, as a scene's unfiltered collider
    sphere.primitives.push_back({probe_sphere_, Transform{}});
  }
  auto built = dynamics::buildCollisionWorld(sc, worldOptions(options_),
                                             sc.probe_body < 0 ? &sphere : nullptr);
  if (!built.ok())
    return built.error();
  world_ = std::move(*built.value());

  for (std::size_t i = 0; i < sc.bodies.size(); ++i) {
    const scene::Body& b = sc.bodies[i];
    BodyInfo info;
    info.scene_index = static_cast<std::int32_t>(i);
    info.kind = world_.kind(static_cast<std::uint32_t>(i));
    info.com_B = b.com_B;
    info.stiffness = b.stiffness_n_per_m.has_value() ? std::min(*b.stiffness_n_per_m, k_s_) : k_s_;
    for (const scene::Primitive& p : b.primitives) {
      const Transform X = p.X_BP.toTransform();
      for (const auto& v : p.shape->vertices())
        info.origin_radius = std::max(info.origin_radius, glm::length(X.apply(v.p)));
    }
    if (!(info.stiffness > 0.0))
      return Error{"body '" + b.name + "': stiffness must be > 0"};
    if (crease > 0.0) {
      for (const scene::Primitive& p : b.primitives)
        info.shading.emplace_back(*p.shape, crease);
    }
    info_.push_back(std::move(info));
    active_.push_back(world_.enabled(static_cast<std::uint32_t>(i)) ? 1 : 0);
  }
  if (sc.probe_body < 0) {
    BodyInfo info;
    info.kind = BodyKind::kProbe;
    info.stiffness = k_s_;
    if (crease > 0.0)
      info.shading.emplace_back(*probe_sphere_, crease);
    probe_ = static_cast<std::uint32_t>(sc.bodies.size());
    info_.push_back(std::move(info));
    active_.push_back(1);
  } else {
    probe_ = static_cast<std::uint32_t>(sc.probe_body);
  }

  // joints: hinges to the scene frame (or a static body) for the attach modes; pairs that the
  // joint keeps from colliding
  for (const scene::Joint& j : sc.joints) {
    const auto nb = static_cast<std::int32_t>(sc.bodies.size());
    if (j.body_a < 0 || j.body_a >= nb || j.body_b >= nb)
      return Error{"joint: body out of range"};
    if (j.body_b >= 0 && !j.enable_collision)
      excluded_pairs_.emplace_back(static_cast<std::uint32_t>(j.body_a),
                                   static_cast<std::uint32_t>(j.body_b));
    if (j.kind != scene::JointKind::kHinge || j.hinge_axis > 2)
      continue;
    const bool to_ground = j.body_b < 0 || sc.bodies[static_cast<std::size_t>(j.body_b)].motion ==
                                               scene::Motion::kStatic;
    if (!to_ground)
      continue;
    BodyInfo& info = info_[static_cast<std::size_t>(j.body_a)];
    info.hinge = true;
    info.hinge_o_B = j.X_AJ.translation;
    Vec3 axis{0.0};
    axis[j.hinge_axis] = 1.0;
    info.hinge_a_B = glm::normalize(rotate(j.X_AJ.rotation, axis));
  }

  // the polytope with the most faces (prepareThread)
  for (std::uint32_t id = 0; id < info_.size(); ++id) {
    const BodyInfo& bi = info_[id];
    const std::size_t count =
        bi.scene_index < 0 ? 1
                           : sc.bodies[static_cast<std::size_t>(bi.scene_index)].primitives.size();
    for (std::uint32_t k = 0; k < count; ++k) {
      const geom::Polytope& shape = primShape(id, k);
      if (shape.faces().size() > max_faces_)
        max_faces_ = shape.faces().size(), max_shape_ = &shape;
    }
  }

  // capacities: as the world's, every pair a moving primitive can make
  const std::size_t pairs = world_.reservedPairs();
  rows_.reserve(pairs * collision::Manifold::kMaxPoints);
  row_env_.reserve(pairs * collision::Manifold::kMaxPoints);
  contact_points_.reserve(response::kMaxRows);
  edit_travel_.assign(info_.size(), 0.0);
  for (std::uint32_t id = 0; id < info_.size(); ++id) {
    if (info_[id].kind == BodyKind::kStatic)
      continue;
    if (info_[id].scene_index < 0)
      continue;
    pose_bodies_.push_back(id);
    body_poses_.push_back({static_cast<std::uint32_t>(info_[id].scene_index), world_.pose(id)});
  }

  // the dynamics, exactly when the plan asks (world ids are the scene's body indices, the probe
  // sphere, if any, right after them)
  if (sc.plan.dynamics) {
    dynamics::DynamicsOptions dopt;
    dopt.tick_s = r.tick_s;
    dopt.held_max_force_n = r.max_force_n;
    dopt.impulse_window_s = options_.dynamics_impulse_window_s;
    dopt.sleep_time_s = options_.dynamics_sleep_time_s;
    if (sc.probe_body < 0)
      dopt.extra_probe_body = static_cast<std::int32_t>(sc.bodies.size());
    auto created = dynamics::Dynamics::create(sc, world_, dopt);
    if (!created.ok())
      return created.error();
    dyn_ = std::move(created).value();
    dyn_active_ = dyn_->active();
    backstop_ = r.dynamic_backstop_fraction * r.penetration_allowance_m;
  }

  // the bodies no stage moves sleep, so that their pairs with each other and with static bodies
  // cost nothing: without dynamics every non-static body but the probe (an attached body wakes
  // while it is held); with dynamics the kinematic ones only (the dynamic bodies stay awake: the
  // dynamics read their contacts every tick and have their own whole-scene sleep)
  for (std::uint32_t id = 0; id < info_.size(); ++id) {
    if (id == probe_ || info_[id].kind == BodyKind::kStatic)
      continue;
    if (dyn_active_ && info_[id].kind == BodyKind::kDynamic)
      continue;
    world_.setAsleep(id, true);
  }
  // bodies on a hinge are quasi-static coordinates that the held set may turn: they stay awake
  for (std::uint32_t id = 0; id < info_.size(); ++id) {
    BodyInfo& bi = info_[id];
    if (!bi.hinge || id == probe_ || bi.kind == BodyKind::kStatic)
      continue;
    const geom::Pose& X = world_.pose(id);
    const Vec3 o = X.translation + rotate(X.rotation, bi.hinge_o_B);
    const Vec3 a = glm::normalize(rotate(X.rotation, bi.hinge_a_B));
    double hr = 0.0;
    const Transform XB = X.toTransform();
    for (const auto& p : sc.bodies[static_cast<std::size_t>(bi.scene_index)].primitives) {
      const Transform XP = XB * p.X_BP.toTransform();
      for (const auto& v : p.shape->vertices()) {
        const Vec3 d = XP.apply(v.p) - o;
        hr = std::max(hr, glm::length(d - glm::dot(d, a) * a));
      }
    }
    bi.hinge_radius = hr;
  }

  // the probe starts at its scene pose (the sphere at the origin) and is coupled to the device
  X_W_probe_ = world_.pose(probe_);
  held_[0] = probe_;
  held_count_ = 1;
  updateDriven();
  probe_radius_ = std::max(radiusAbout(probe_, comW(probe_)), 1e-9);
  held_radius_ = probe_radius_;
  delta_ = r.predictive ? std::min(max_travel_, r.min_predictive_fraction * held_radius_) : 0.0;

  response::CouplingParams cp;
  cp.tick_s = r.tick_s;
  cp.stiffness_n_per_m = k_c_;
  cp.damping_n_s_per_m = r.coupling_damping_factor * k_c_ * r.tick_s;
  cp.rot_stiffness_nm_per_rad = r.rot_stiffness_nm_per_rad > 0.0
                                    ? r.rot_stiffness_nm_per_rad
                                    : k_c_ * probe_radius_ * probe_radius_;
  cp.rot_damping_nm_s_per_rad = r.coupling_damping_factor * cp.rot_stiffness_nm_per_rad * r.tick_s;
  coupling_ = response::VirtualCoupling(cp);

  proxy_params_.coupling_stiffness = cp.stiffness_n_per_m;
  proxy_params_.rot_coupling_stiffness = cp.rot_stiffness_nm_per_rad;
  proxy_params_.delta = delta_;
  proxy_params_.max_travel = max_travel_;
  proxy_params_.max_force_n = r.max_force_n;
  proxy_params_.max_torque_nm = r.max_torque_nm;

  world_.step();
  double pen = 0.0;
  gatherRows(&pen);
  return true;
}

const geom::Polytope& SimulationImpl::primShape(std::uint32_t body, std::uint32_t prim) const {
  const BodyInfo& bi = info_[body];
  if (bi.scene_index < 0)
    return *probe_sphere_;
  return *scene_->bodies[static_cast<std::size_t>(bi.scene_index)].primitives[prim].shape;
}

Transform SimulationImpl::primTransform(std::uint32_t body, std::uint32_t prim) const {
  const BodyInfo& bi = info_[body];
  const Transform X_WB = world_.pose(body).toTransform();
  if (bi.scene_index < 0)
    return X_WB;
  return X_WB * scene_->bodies[static_cast<std::size_t>(bi.scene_index)]
                    .primitives[prim]
                    .X_BP.toTransform();
}

void SimulationImpl::gatherRows(double* max_penetration) {
  rows_.clear();
  row_env_.clear();
  double pen = 0.0;
  response::FaceContact fc;
  for (const collision::Contact& c : world_.contacts()) {
    if (!c.answered)
      continue;
    // roles: the held set (-2), a driven hinge (d >= 0), fixed (-1); a row's first side is the
    // held set if either side is, else a driven hinge; its second side is the other
    const std::int32_t ra = role(c.body_a), rb = role(c.body_b);
    if (ra == kRoleHeld && rb == kRoleHeld)
      continue;
    if (ra == kRoleFixed && rb == kRoleFixed)
      continue;
    if (excluded(c.body_a, c.body_b))
      continue;
    const bool ha = ra == kRoleHeld || (rb != kRoleHeld && ra >= 0);  // side a is the first
    const bool hb = !ha;
    const std::int32_t first = ha ? ra : rb, second = ha ? rb : ra;
    const std::uint32_t env = ha ? c.body_b : c.body_a;
    const std::uint32_t env_prim = ha ? c.prim_b : c.prim_a;
    const std::uint32_t held = ha ? c.body_a : c.body_b;
    const std::uint32_t held_prim = ha ? c.prim_a : c.prim_b;
    const geom::Feature env_feature = ha ? c.feature_b : c.feature_a;
    const geom::Feature held_feature = ha ? c.feature_a : c.feature_b;
    const std::int32_t row_first = first == kRoleHeld ? -1 : first;
    const std::int32_t row_second = second < 0 ? -1 : second;
    pen = std::max(pen, -c.distance);
    // a body the dynamics move: its contacts with the held set are the dynamics' (impulses on
    // the held body, spread, reach the hand in step()). Its penalty rows act only behind a
    // backstop, the held set deeper than backstop_ into it: when the dynamics cannot push it out
    // of the way (wedged against something fixed), the proxy stops there as at a fixed body
    // (docs/dynamics.md, "In the Simulation")
    const double shift = movedByDynamics(env) ? backstop_ : 0.0;
    // a pair farther than the largest delta plus what one step can close (one safe distance
    // per moving side) cannot act next tick: no rows
    const double sides = second >= 0 ? 2.0 : 1.0;
    if (c.distance + shift > max_travel_ * (1.0 + sides))
      continue;
    // the pair's stiffness: the environment body's felt stiffness k_f through the proxy's
    // contact spring k_p = k_f k_c / (k_c - k_f), so that k_c and k_p in series give k_f
    const double kf = info_[env].stiffness;
    const double kp = kf * k_c_ / (k_c_ - kf);
    const double sign = hb ? 1.0 : -1.0;  // normals run from a to b: out of the environment
    const BodyInfo& ei = info_[env];
    const response::ShadingTable* table =
        env_prim < ei.shading.size() ? &ei.shading[env_prim] : nullptr;
    const geom::Polytope& env_shape = primShape(env, env_prim);
    const Transform X_WE = primTransform(env, env_prim);
    const Vec3 n_pair = sign * c.normal;

    // a face against a face: the whole clipped region, each point with its own gap
    if (response::faceContact(env_shape, X_WE, env_feature, primShape(held, held_prim),
                              primTransform(held, held_prim), held_feature, n_pair,
                              kFaceCosTolerance, &fc)) {
      for (std::uint32_t i = 0; i < fc.count; ++i)
        pen = std::max(pen, -fc.gap[i]);
      for (std::uint32_t i = 0; i < fc.count; ++i) {
        ContactRow row;
        row.p_W = fc.p_W[i];
        row.n_W = fc.n_W;
        if (table != nullptr) {
          const Vec3 x_E = glm::transpose(X_WE.R) * (fc.p_W[i] - X_WE.t);
          row.n_W = X_WE.rotate(table->shadedNormalOnFace(env_shape, fc.env_face, x_E));
        }
        row.gap = fc.gap[i] + shift;
        row.stiffness = kp / static_cast<double>(fc.count);
        row.first = row_first;
        row.second = row_second;
        pushRow(row, env);
      }
      continue;
    }

    auto shade = [&](const Vec3& p_W, const Vec3& n_W) {
      if (table == nullptr)
        return n_W;
      const Vec3 x_P = glm::transpose(X_WE.R) * (p_W - X_WE.t);
      const Vec3 n_P = glm::transpose(X_WE.R) * n_W;
      return X_WE.R * table->shadedNormal(env_shape, x_P, n_P, env_feature);
    };
    const std::size_t m = c.manifold.count;
    if (m == 0) {
      ContactRow row;
      row.p_W = 0.5 * (c.point_a + c.point_b);
      row.n_W = shade(row.p_W, n_pair);
      row.gap = c.distance + shift;
      row.stiffness = kp;
      row.first = row_first;
      row.second = row_second;
      pushRow(row, env);
      continue;
    }
    for (std::size_t i = 0; i < m; ++i) {
      const collision::ContactPoint& cp = c.manifold.points[i];
      ContactRow row;
      row.p_W = cp.point;
      row.n_W = shade(cp.point, sign * cp.normal);
      row.gap = -cp.depth + shift;
      row.stiffness = kp / static_cast<double>(m);
      row.first = row_first;
      row.second = row_second;
      pushRow(row, env);
    }
  }
  *max_penetration = pen;
  last_penetration_ = pen;
}

void SimulationImpl::setHeldPoses() {
  world_.setPose(probe_, X_W_probe_);
  if (mode_ == Mode::kFree || attached_ == kNone)
    return;
  if (mode_ == Mode::kGrab) {
    const Transform T = X_W_probe_.toTransform() * X_probe_attached_;
    geom::Pose X;
    X.translation = T.t;
    X.rotation = glm::normalize(glm::quat_cast(T.R));
    world_.setPose(attached_, X);
  }
}

void SimulationImpl::applyStep(const response::ProxyStep& s) {
  for (std::uint32_t d = 0; d < driven_count_; ++d) {
    if (s.driven_angle[d] == 0.0)
      continue;  // unmoved: its pairs keep their answers
    const std::uint32_t id = driven_ids_[d];
    const BodyInfo& bi = info_[id];
    geom::Pose X = world_.pose(id);
    const Vec3 o = X.translation + rotate(X.rotation, bi.hinge_o_B);
    const Vec3 a = glm::normalize(rotate(X.rotation, bi.hinge_a_B));
    const Quat dq = geom::quatFromRotationVector(a * s.driven_angle[d]);
    X.rotation = glm::normalize(dq * X.rotation);
    X.translation = o + rotate(dq, X.translation - o);
    world_.setPose(id, X);
  }
  if (mode_ == Mode::kFree || mode_ == Mode::kGrab) {
    const Vec3 c = comW(probe_);
    const Quat dq = geom::quatFromRotationVector(s.dtheta_W);
    X_W_probe_.rotation = glm::normalize(dq * X_W_probe_.rotation);
    X_W_probe_.translation = c + s.dc_W + rotate(dq, X_W_probe_.translation - c);
    setHeldPoses();
    return;
  }
  // a hinge: turn the attached body about its axis by the step's one coordinate
  const Quat dq = geom::quatFromRotationVector(hinge_a_W_ * s.x[0]);
  geom::Pose Xb = world_.pose(attached_);
  Xb.rotation = glm::normalize(dq * Xb.rotation);
  Xb.translation = hinge_o_W_ + rotate(dq, Xb.translation - hinge_o_W_);
  world_.setPose(attached_, Xb);
  if (mode_ == Mode::kRim) {
    const Transform T = Xb.toTransform() * X_attached_probe_;
    X_W_probe_.translation = T.t;
    X_W_probe_.rotation = glm::normalize(glm::quat_cast(T.R));
  } else {
    X_W_probe_.rotation = glm::normalize(Xb.rotation * q_attached_probe_);
    X_W_probe_.translation = centre_h_W_ - rotate(X_W_probe_.rotation, info_[probe_].com_B);
  }
  world_.setPose(probe_, X_W_probe_);
}

void SimulationImpl::attach(std::uint32_t body) {
  const BodyInfo& bi = info_[body];
  attached_ = body;
  world_.setAsleep(body, false);
  if (dyn_active_)
    dyn_->setDriven(body, true);  // the proxy step moves it now; the dynamics see it as held
  held_[1] = body;
  held_count_ = 2;
  updateDriven();
  const geom::Pose& Xb = world_.pose(body);
  if (!bi.hinge) {
    mode_ = Mode::kGrab;
    X_probe_attached_ = geom::relativeTransform(X_W_probe_, Xb);
    held_radius_ = heldRadius(comW(probe_));
    setRotationalStiffness();
    grab_mass_ = 0.0;
    if (dyn_active_ && bi.kind == BodyKind::kDynamic) {
      const dynamics::MassProperties mp = dyn_->massProperties(body);
      if (mp.mass > 0.0 && std::isfinite(mp.mass)) {
        grab_mass_ = mp.mass;
        grab_gravity_W_ = dyn_->gravity(body);
        grab_com_B_ = mp.com_B;
        grab_inertia_B_ = mp.inertia_B;
        const Vec3 c = Xb.translation + rotate(Xb.rotation, grab_com_B_);
        grab_r_P_ = rotate(glm::conjugate(X_W_probe_.rotation), c - comW(probe_));
        grab_history_ = 0;
        grab_a_f_ = grab_alpha_f_ = Vec3{0.0};
      }
    }
    return;
  }
  hinge_o_W_ = Xb.translation + rotate(Xb.rotation, bi.hinge_o_B);
  hinge_a_W_ = glm::normalize(rotate(Xb.rotation, bi.hinge_a_B));
  const Vec3 h = comW(probe_);
  const Vec3 rel = h - hinge_o_W_;
  const Vec3 radial = rel - glm::dot(rel, hinge_a_W_) * hinge_a_W_;
  const double body_radius = radiusAbout(body, comW(body));
  using HA = ResponseOptions::HingeAttach;
  const HA choice = options_.response.hinge_attach;
  const bool centre =
      choice == HA::kCentre ||
      (choice == HA::kAuto &&
       glm::length(radial) < options_.response.centre_radius_fraction * body_radius);
  if (centre) {
    mode_ = Mode::kCentre;
    centre_h_W_ = h;
    q_attached_probe_ = glm::normalize(glm::conjugate(Xb.rotation) * X_W_probe_.rotation);
  } else {
    mode_ = Mode::kRim;
    X_attached_probe_ = geom::relativeTransform(Xb, X_W_probe_);
  }
  held_radius_ = heldRadius(comW(body));
  setRotationalStiffness();
}

void SimulationImpl::updateDriven() {
  driven_count_ = 0;
  for (std::uint32_t id = 0; id < info_.size(); ++id) {
    const BodyInfo& bi = info_[id];
    if (!bi.hinge || isHeld(id) || bi.kind == BodyKind::kStatic || active_[id] == 0)
      continue;
    if (dyn_active_ && bi.kind == BodyKind::kDynamic)
      continue;  // the dynamics turn it on its hinge joint, with its inertia
    if (driven_count_ == driven_ids_.size())
      break;  // more stay fixed (docs/response.md)
    driven_ids_[driven_count_++] = id;
    world_.setAsleep(id, false);
  }
}

void SimulationImpl::detach() {
  if (attached_ != kNone && dyn_active_)
    dyn_->setDriven(attached_, false);
  if (attached_ != kNone && !info_[attached_].hinge &&
      !(dyn_active_ && info_[attached_].kind == BodyKind::kDynamic))
    world_.setAsleep(attached_, true);
  mode_ = Mode::kFree;
  attached_ = kNone;
  grab_mass_ = 0.0;
  held_count_ = 1;
  held_radius_ = probe_radius_;
  setRotationalStiffness();
  updateDriven();
}

void SimulationImpl::setRotationalStiffness() {
  // k_r = k_c r^2, unless the options fix it: r is the held set's radius when a body is grabbed
  // or attached at its centre (its feel comes through the handle's torque), the probe's own when
  // free or attached at a rim (the hand does not turn with a rim: the probe's orientation does)
  const ResponseOptions& r = options_.response;
  const double radius =
      mode_ == Mode::kGrab || mode_ == Mode::kCentre ? held_radius_ : probe_radius_;
  const double kr =
      r.rot_stiffness_nm_per_rad > 0.0 ? r.rot_stiffness_nm_per_rad : k_c_ * radius * radius;
  coupling_.setRotational(kr, r.coupling_damping_factor * kr * r.tick_s);
  proxy_params_.rot_coupling_stiffness = kr;
}

void SimulationImpl::updateAttachment(const TickInput& input) {
  const std::uint32_t mask = options_.response.attach_button_mask;
  const bool down = (input.buttons & mask) != 0, was = (last_buttons_ & mask) != 0;
  last_buttons_ = input.buttons;
  if (down && !was && mode_ == Mode::kFree) {
    // the nearest non-static body the probe touches
    std::uint32_t best = kNone;
    double best_d = options_.response.attach_distance_m;
    for (const collision::Contact& c : world_.contacts()) {
      if (!c.answered)
        continue;
      if (c.body_a != probe_ && c.body_b != probe_)
        continue;
      const std::uint32_t other = c.body_a == probe_ ? c.body_b : c.body_a;
      if (info_[other].kind == BodyKind::kStatic || excluded(probe_, other))
        continue;
      if (c.distance <= best_d)
        best_d = c.distance, best = other;
    }
    if (best != kNone) {
      attach(best);
      double pen = 0.0;
      gatherRows(&pen);
    }
  } else if (!down && was && mode_ != Mode::kFree) {
    detach();
    double pen = 0.0;
    gatherRows(&pen);
  }
}

// the most faces this thread's narrow-phase scratch has been sized for
thread_local std::size_t t_prepared_faces = 0;

void SimulationImpl::prepareThread() {
  if (t_prepared_faces >= max_faces_ || max_shape_ == nullptr)
    return;
  // the exact depth sizes its scratch by the faces of both polytopes before any work: the
  // largest with itself, placed well apart so that the first separating face ends the query
  collision::DepthCache cache;
  Transform X;
  X.t = Vec3{4.0 * max_shape_->radius(), 0.0, 0.0};
  (void)collision::penetrationDepthExact(*max_shape_, *max_shape_, X, cache);
  t_prepared_faces = max_faces_;
}

TickOutput SimulationImpl::step(const TickInput& input) {
  TickOutput out;
  if (t_prepared_faces < max_faces_)
    prepareThread();
  if (first_step_ && info_[probe_].scene_index < 0 && geom::finite(input.X_W_device.translation)) {
    // the probe sphere has no pose in the scene: it starts where the device is
    X_W_probe_.translation = input.X_W_device.translation;
    world_.setPose(probe_, X_W_probe_);
    world_.step();
    double pen = 0.0;
    gatherRows(&pen);
  }
  first_step_ = false;
  // a scene edit since the last tick: the collision world and the rows see it before the proxy
  // steps (a kinematic body moved into the proxy pushes it out from this tick's rows)
  std::uint32_t edit_pairs_tested = 0;
  double pusher_travel = 0.0;  // the farthest a kinematic body touching the held set was moved
  if (world_dirty_) {
    world_dirty_ = false;
    edit_pairs_tested = world_.step().pairs_tested;
    double pen = 0.0;
    gatherRows(&pen);
    const auto rows = rows_.rows();
    for (std::size_t i = 0; i < rows.size() && i < row_env_.size(); ++i) {
      if (rows[i].first < 0)
        pusher_travel = std::max(pusher_travel, edit_travel_[row_env_[i]]);
    }
    std::fill(edit_travel_.begin(), edit_travel_.end(), 0.0);
    // at most one more safe distance: the rows see every surface within two of them (pairs
    // within max_travel * (1 + sides) get rows), so the proxy never steps past one it has no
    // row for, even when a client teleports a body touching it
    pusher_travel = std::min(pusher_travel, max_travel_);
  }
  updateAttachment(input);

  // the device's handle: the probe body's centre of mass placed at the device pose
  const Vec3 com_probe = info_[probe_].com_B;
  const Vec3 h_dev = input.X_W_device.translation + rotate(input.X_W_device.rotation, com_probe);
  const Quat q_dev = input.X_W_device.rotation;

  // the predictive distance (§5.2): delta = v_c dt, v_c bounding the speed of the held points
  if (have_prev_device_ && finitePose(h_dev, q_dev)) {
    const double v = glm::length(h_dev - prev_h_dev_) / options_.response.tick_s +
                     glm::length(geom::rotationVector(q_dev * glm::conjugate(prev_q_dev_))) /
                         options_.response.tick_s * held_radius_;
    v_c_ = std::max(std::isfinite(v) ? v : 0.0, v_c_ * speed_decay_);
  }
  if (finitePose(h_dev, q_dev)) {
    have_prev_device_ = true;
    prev_h_dev_ = h_dev;
    prev_q_dev_ = q_dev;
  }
  delta_ = options_.response.predictive
               ? std::clamp(v_c_ * options_.response.tick_s,
                            std::min(max_travel_,
                                     options_.response.min_predictive_fraction * held_radius_),
                            max_travel_)
               : 0.0;
  proxy_params_.delta = delta_;

  response::ProxyProblem pb;
  pb.h_W = comW(probe_);
  pb.q_handle = X_W_probe_.rotation;
  pb.h_target_W = h_dev;
  pb.q_target = q_dev;
  pb.radius = held_radius_;
  if (mode_ == Mode::kRim || mode_ == Mode::kCentre) {
    pb.c_W = comW(attached_);
    pb.basis = response::ProxyBasis::hinge(hinge_o_W_, hinge_a_W_, pb.c_W);
    pb.handle_fixed = mode_ == Mode::kCentre;
  } else {
    pb.c_W = pb.h_W;
  }
  const bool finite_input = finitePose(h_dev, q_dev);
  if (!finite_input) {
    // a bad pose moves nothing: hold the proxy where it is
    pb.h_target_W = pb.h_W;
    pb.q_target = pb.q_handle;
  }
  // a grabbed dynamic body's weight at its centre of mass: the proxy's target shifted by what
  // the coupling needs to carry it, so that the hand feels m g in free space and a surface the
  // held set rests on takes it (docs/dynamics.md)
  Vec3 grab_weight{0.0};
  if (grab_mass_ > 0.0 && mode_ == Mode::kGrab && options_.response.grab_weight && finite_input) {
    const geom::Pose& Xb = world_.pose(attached_);
    const Vec3 c = Xb.translation + rotate(Xb.rotation, grab_com_B_);
    grab_weight = grab_mass_ * grab_gravity_W_;
    const Vec3 torque = glm::cross(c - pb.h_W, grab_weight);
    const double kc = proxy_params_.coupling_stiffness, kr = proxy_params_.rot_coupling_stiffness;
    if (kc > 0.0)
      pb.h_target_W = h_dev + grab_weight / kc;
    if (kr > 0.0)
      pb.q_target = glm::normalize(geom::quatFromRotationVector(torque / kr) * q_dev);
  }

  const geom::Pose probe_before = X_W_probe_;
  const geom::Pose attached_before = attached_ == kNone ? geom::Pose{} : world_.pose(attached_);
  pb.driven_count = driven_count_;
  for (std::uint32_t d = 0; d < driven_count_; ++d) {
    const std::uint32_t id = driven_ids_[d];
    const BodyInfo& bi = info_[id];
    const geom::Pose& X = world_.pose(id);
    driven_before_[d] = X;
    pb.driven[d].o_W = X.translation + rotate(X.rotation, bi.hinge_o_B);
    pb.driven[d].a_W = glm::normalize(rotate(X.rotation, bi.hinge_a_B));
    pb.driven[d].radius = bi.hinge_radius;
    // a faint hold, so that an untouched hinge stays put: 1e-6 of the coupling at its radius
    pb.driven[d].drag = 1e-6 * k_c_ * std::max(bi.hinge_radius * bi.hinge_radius, 1e-12);
  }
  const double pen_before = last_penetration_;
  // a kinematic body pushing the held set moves it as far as it moved itself, so that a pusher
  // faster than the safe distance does not run over the proxy (docs/dynamics.md)
  proxy_params_.max_travel = max_travel_ + pusher_travel;
  response::ProxyStep s = solveProxyStep(pb, rows_.rows(), proxy_params_);
  proxy_params_.max_travel = max_travel_;
  applyStep(s);
  collision::StepStats stats = world_.step();
  double pen = 0.0;
  gatherRows(&pen);
  // a step that went too deep (a contact the linearisation missed): bisect back
  // (only when this step made it deeper by a jump, a twentieth of the allowance or more: a proxy
  // pressed into several surfaces at once may rest deeper, and creeps there slowly)
  const double allowance = options_.response.penetration_allowance_m;
  for (int k = 0; k < 3 && pen > allowance && pen - pen_before > 0.05 * allowance; ++k) {
    out.flags |= kTickBackedOff;
    X_W_probe_ = probe_before;
    if (attached_ != kNone)
      world_.setPose(attached_, attached_before);
    for (std::uint32_t d = 0; d < driven_count_; ++d)
      world_.setPose(driven_ids_[d], driven_before_[d]);
    for (std::size_t d = 0; d < s.driven_angle.size(); ++d)
      s.driven_angle[d] *= 0.5;
    world_.setPose(probe_, X_W_probe_);
    for (std::size_t q = 0; q < 6; ++q)
      s.x[q] *= 0.5;
    s.dc_W *= 0.5;
    s.dtheta_W *= 0.5;
    applyStep(s);
    const collision::StepStats again = world_.step();
    stats.pairs_tested += again.pairs_tested;
    stats.pairs_skipped = again.pairs_skipped;
    gatherRows(&pen);
  }

  // the dynamics (only when the plan asks): after this tick's collision step, with the held body
  // (and an attached dynamic body) following the proxy with infinite mass
  Vec3 impact_force{0.0}, impact_torque{0.0};
  if (dyn_active_) {
    if (attached_ != kNone && info_[attached_].kind == BodyKind::kDynamic)
      dyn_->setKinematicPose(attached_, world_.pose(attached_));
    dynamics::HeldInput held;
    held.mode = dynamics::HeldMode::kKinematic;
    held.X_WB_target = X_W_probe_;
    const dynamics::StepReport dr = dyn_->step(options_.response.tick_s, &held);
    if ((dr.flags & dynamics::kStepAsleep) == 0)
      out.flags |= kTickDynamics;
    if ((dr.flags & dynamics::kStepCapacityFull) != 0)
      out.flags |= kTickCapacityFull;
    out.dynamics_contact_points = dr.contact_points;
    const dynamics::HeldFeedback& fb = dyn_->heldFeedback();
    impact_force = fb.force_W_n;
    impact_torque = fb.torque_W_nm;
    if (kinematic_target_pending_) {
      // the dynamics moved a kinematic body to its new target in this step
      kinematic_target_pending_ = false;
      world_dirty_ = true;
    }
  }

  // the coupling between the device and the proxy, then the one output stage
  const Vec3 h_prx = mode_ == Mode::kCentre ? centre_h_W_ : comW(probe_);
  response::Wrench raw = coupling_.step(h_dev, q_dev, h_prx, X_W_probe_.rotation);
  if (dyn_active_) {
    // the spread impulses on the held set, moved from its centre of mass to the handle point
    const Vec3 c_fb = dyn_->heldFeedback().com_W;
    impact_torque += glm::cross(c_fb - h_prx, impact_force);
    raw.force_n += impact_force;
    raw.torque_nm += impact_torque;
  }
  Vec3 grab_inertia_force{0.0}, grab_inertia_torque{0.0};
  if (grab_mass_ > 0.0 && mode_ == Mode::kGrab && options_.response.grab_inertia) {
    if (!finite_input) {
      grab_history_ = 0;
      grab_a_f_ = grab_alpha_f_ = Vec3{0.0};
    } else {
      // the body rigidly at the device's pose: its centre of mass, the device's rotation
      const double dt = options_.response.tick_s;
      const Vec3 c_dev = h_dev + rotate(q_dev, grab_r_P_);
      Vec3 w_dev{0.0};
      if (grab_history_ >= 1)
        w_dev = geom::rotationVector(q_dev * glm::conjugate(grab_q1_)) / dt;
      if (grab_history_ >= 2) {
        const Vec3 a = (c_dev - 2.0 * grab_c1_ + grab_c2_) / (dt * dt);
        const Vec3 alpha = (w_dev - grab_w1_) / dt;
        if (geom::finite(a) && geom::finite(alpha)) {
          grab_a_f_ += grab_beta_ * (a - grab_a_f_);
          grab_alpha_f_ += grab_beta_ * (alpha - grab_alpha_f_);
        }
      }
      grab_c2_ = grab_c1_;
      grab_c1_ = c_dev;
      grab_q1_ = q_dev;
      grab_w1_ = w_dev;
      grab_history_ = std::min<std::uint32_t>(grab_history_ + 1, 2);
      const geom::Mat3 R = glm::mat3_cast(world_.pose(attached_).rotation);
      const geom::Mat3 I_W = R * grab_inertia_B_ * glm::transpose(R);
      grab_inertia_force = -grab_mass_ * grab_a_f_;
      grab_inertia_torque = -(I_W * grab_alpha_f_ + glm::cross(w_dev, I_W * w_dev)) +
                            glm::cross(c_dev - h_dev, grab_inertia_force);
      if (geom::finite(grab_inertia_force) && geom::finite(grab_inertia_torque)) {
        raw.force_n += grab_inertia_force;
        raw.torque_nm += grab_inertia_torque;
      } else {
        grab_inertia_force = grab_inertia_torque = Vec3{0.0};
      }
    }
  }
  response::OutputReport rep;
  const response::Wrench w = output_.apply(raw, input.device_ok && finite_input, &rep);
  if (!input.device_ok || !finite_input)
    coupling_.reset();

  const Vec3 c_ref = mode_ == Mode::kRim || mode_ == Mode::kCentre ? comW(attached_) : comW(probe_);
  const response::Wrench pw = response::penaltyWrench(rows_.rows(), c_ref, delta_);
  out.force_W_n = w.force_n;
  out.torque_W_nm = w.torque_nm;
  out.contact_force_W_n = pw.force_n;
  out.contact_torque_W_nm = pw.torque_nm;
  out.impact_force_W_n = impact_force;
  out.impact_torque_W_nm = impact_torque;
  out.grab_weight_W_n = grab_weight;
  out.grab_inertia_force_W_n = grab_inertia_force;
  out.grab_inertia_torque_W_nm = grab_inertia_torque;
  out.X_W_proxy = X_W_probe_;
  std::uint32_t active = 0;
  for (const ContactRow& r : rows_.rows())
    active += r.gap < delta_ && r.first < 0 ? 1u : 0u;
  out.contacts = active;
  out.max_penetration_m = std::max(0.0, pen);
  out.pairs_tested = stats.pairs_tested + edit_pairs_tested;
  out.pairs_skipped = stats.pairs_skipped;
  if (rep.ramping)
    out.flags |= kTickRamping;
  if (rep.clamped)
    out.flags |= kTickForceClamped;
  if (rep.step_limited)
    out.flags |= kTickStepLimited;
  if (rep.non_finite)
    out.flags |= kTickNonFinite;
  if (stats.pairs_skipped > 0)
    out.flags |= kTickPairsSkipped;
  if (rows_.full() || s.rows_dropped)
    out.flags |= kTickCapacityFull;
  out.attach_mode = static_cast<std::uint8_t>(mode_);
  out.attached_body = attached_ == kNone ? -1 : info_[attached_].scene_index;
  out.travel_limited = s.travel_limited;
  out.delta_m = delta_;
  for (std::size_t i = 0; i < pose_bodies_.size(); ++i) {
    const std::uint32_t id = pose_bodies_[i];
    body_poses_[i].X_WB =
        dyn_active_ && info_[id].kind == BodyKind::kDynamic ? dyn_->pose(id) : world_.pose(id);
  }
  fillContactPoints(&out);
  return out;
}

void SimulationImpl::fillContactPoints(TickOutput* out) {
  // the rows the response used this tick (the held set's, within delta), as TickOutput::contacts
  // counts them; the depth without the backstop's shift
  contact_points_.clear();
  const auto rows = rows_.rows();
  for (std::size_t i = 0; i < rows.size() && i < row_env_.size(); ++i) {
    const ContactRow& r = rows[i];
    if (!(r.gap < delta_ && r.first < 0))
      continue;
    if (contact_points_.size() == contact_points_.capacity()) {
      out->flags |= kTickCapacityFull;
      break;
    }
    const std::uint32_t env = row_env_[i];
    const double shift = movedByDynamics(env) ? backstop_ : 0.0;
    ContactPoint cp;
    cp.p_W = r.p_W;
    cp.n_W = r.n_W;
    cp.depth_m = -(r.gap - shift);
    cp.body = info_[env].scene_index;
    contact_points_.push_back(cp);
  }
}

EditStatus SimulationImpl::editable(std::uint32_t body) const {
  if (body >= scene_->bodies.size())
    return EditStatus::kNoSuchBody;
  if (info_[body].kind == BodyKind::kStatic)
    return EditStatus::kStaticBody;
  if (body == probe_ || isHeld(body))
    return EditStatus::kHeldBody;
  return EditStatus::kOk;
}

EditStatus SimulationImpl::setKinematicPose(std::uint32_t body, const Pose& X_WB) {
  if (const EditStatus st = editable(body); st != EditStatus::kOk)
    return st;
  const BodyInfo& bi = info_[body];
  if (bi.kind != BodyKind::kKinematic)
    return EditStatus::kNotKinematic;
  if (active_[body] == 0)
    return EditStatus::kInactive;
  geom::Pose X;
  if (!unitPose(X_WB, &X))
    return EditStatus::kNotFinite;
  {
    const geom::Pose& from = world_.pose(body);
    const double angle =
        glm::length(geom::rotationVector(X.rotation * glm::conjugate(from.rotation)));
    const double travel =
        glm::length(X.translation - from.translation) + angle * info_[body].origin_radius;
    if (std::isfinite(travel))
      edit_travel_[body] += travel;
  }
  if (dyn_active_) {
    // the dynamics move it there in the next step with the velocity that takes it there, so
    // that it pushes the dynamic bodies in its way; the collision world follows
    dyn_->setKinematicPose(body, X);
    kinematic_target_pending_ = true;
  } else {
    // no dynamics: the collision world has it there in the next step, before the proxy moves
    // (asleep as before: its pairs with static and other resting bodies stay untested; its pair
    // with the awake probe is tested again because it moved)
    world_.setPose(body, X);
    world_dirty_ = true;
  }
  return EditStatus::kOk;
}

EditStatus SimulationImpl::setBodyActive(std::uint32_t body, bool active, const Pose& X_WB) {
  if (const EditStatus st = editable(body); st != EditStatus::kOk)
    return st;
  const BodyInfo& bi = info_[body];
  geom::Pose X;
  if (active && !unitPose(X_WB, &X))
    return EditStatus::kNotFinite;
  active_[body] = active ? 1 : 0;
  world_.setEnabled(body, active);
  if (active)
    world_.setPose(body, X);
  if (dyn_active_)
    dyn_->setEnabled(body, active, X);
  if (bi.hinge)
    updateDriven();
  world_dirty_ = true;
  return EditStatus::kOk;
}

DynamicsStatus SimulationImpl::dynamicsStatus() const {
  DynamicsStatus st;
  if (!dyn_)
    return st;
  st.active = dyn_active_;
  st.ticks = dyn_->counters().ticks;
  st.ticks_asleep = dyn_->counters().ticks_asleep;
  st.kinetic_energy_j = dyn_->kineticEnergy();
  st.potential_energy_j = dyn_->potentialEnergy();
  return st;
}

}  // namespace

Result<std::unique_ptr<Simulation>> Simulation::create(
    std::shared_ptr<const scene::SceneModel> scene,
    const SimOptions& options) {
  if (!scene)
    return Error{"no scene"};
  auto sim = std::make_unique<SimulationImpl>(std::move(scene), options);
  auto built = sim->build();
  if (!built.ok())
    return built.error();
  return std::unique_ptr<Simulation>(std::move(sim));
}

}  // namespace hapticd::sim
