#include "daemon/device/sim_device.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/geometry/rotation.h"

namespace hapticd::device {

namespace {

using geom::quatFromRotationVector;
using geom::rotationVector;

// periods of the idle path, seconds (pairwise incommensurate so the path does not repeat soon)
constexpr double kIdlePeriodX_s = 7.0;
constexpr double kIdlePeriodY_s = 11.0;
constexpr double kIdlePeriodZ_s = 13.0;
constexpr double kIdlePeriodPitch_s = 17.0;
constexpr double kIdlePeriodYaw_s = 19.0;
// the target blends from the last command into the idle path over this time
constexpr double kIdleBlend_s = 2.0;
// a longer gap between reads is integrated as this much (the rest of the time is skipped)
constexpr double kMaxGap_s = 0.1;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double smoothstep(double x) noexcept {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}
double smoothstepDerivative(double x) noexcept {
  if (x <= 0.0 || x >= 1.0)
    return 0.0;
  return 6.0 * x * (1.0 - x);
}

}  // namespace

IdleMotion simIdleMotion(const Pose& X_W_home,
                         double amplitude_m,
                         double angle_rad,
                         double t_s) noexcept {
  IdleMotion m;
  const double wx = kTwoPi / kIdlePeriodX_s;
  const double wy = kTwoPi / kIdlePeriodY_s;
  const double wz = kTwoPi / kIdlePeriodZ_s;
  // a closed Lissajous curve starting at the home pose (offset zero at t = 0)
  m.X_W.translation =
      X_W_home.translation +
      amplitude_m * Vec3(std::sin(wx * t_s), std::sin(wy * t_s), 0.5 * std::sin(wz * t_s));
  m.v_W = amplitude_m *
          Vec3(wx * std::cos(wx * t_s), wy * std::cos(wy * t_s), 0.5 * wz * std::cos(wz * t_s));
  // rotation: yaw beta about world Z after pitch alpha about world X, both applied before home
  const double wa = kTwoPi / kIdlePeriodPitch_s;
  const double wb = kTwoPi / kIdlePeriodYaw_s;
  const double alpha = angle_rad * std::sin(wa * t_s);
  const double beta = angle_rad * std::sin(wb * t_s);
  const double alpha_dot = angle_rad * wa * std::cos(wa * t_s);
  const double beta_dot = angle_rad * wb * std::cos(wb * t_s);
  const geom::Quat qx(std::cos(0.5 * alpha), std::sin(0.5 * alpha), 0.0, 0.0);
  const geom::Quat qz(std::cos(0.5 * beta), 0.0, 0.0, std::sin(0.5 * beta));
  m.X_W.rotation = glm::normalize(qz * qx * X_W_home.rotation);
  m.w_W = beta_dot * Vec3(0.0, 0.0, 1.0) + qz * (alpha_dot * Vec3(1.0, 0.0, 0.0));
  return m;
}

SimDevice::SimDevice(const DeviceOptions& options)
    : options_(options),
      p_W_(options.sim_home.translation),
      q_WH_(glm::normalize(options.sim_home.rotation)) {
  info_.name = "sim";
  info_.capabilities =
      kCapPosition | kCapOrientation | kCapForce | kCapTorque | kCapButtons | kCapPoseCommands;
  info_.limits = options.limits;
  command_.X_W_target = Pose{options.sim_home.translation, q_WH_};
}

void SimDevice::target(double t_s,
                       Pose& X_W_target,
                       Vec3& v_W_target,
                       Vec3& w_W_target) const noexcept {
  const double idle_start_s = command_t_s_ + options_.sim_idle_motion_after_s;
  if (!(t_s > idle_start_s)) {  // also when sim_idle_motion_after_s is +inf
    X_W_target = command_.X_W_target;
    v_W_target = has_command_ ? command_.linear_velocity : Vec3(0.0);
    w_W_target = has_command_ ? command_.angular_velocity : Vec3(0.0);
    return;
  }
  // the idle path's own clock starts when the idle motion starts, so it leaves from its home
  const IdleMotion idle = simIdleMotion(options_.sim_home, options_.sim_idle_amplitude_m,
                                        options_.sim_idle_angle_rad, t_s - idle_start_s);
  const Pose& X_idle = idle.X_W;
  const Vec3& v_idle = idle.v_W;
  const Vec3& w_idle = idle.w_W;
  const double x = (t_s - idle_start_s) / kIdleBlend_s;
  const double s = smoothstep(x);
  const double s_dot = smoothstepDerivative(x) / kIdleBlend_s;
  const Pose& X_cmd = command_.X_W_target;
  X_W_target.translation = X_cmd.translation + s * (X_idle.translation - X_cmd.translation);
  X_W_target.rotation = geom::slerp(X_cmd.rotation, X_idle.rotation, s);
  v_W_target = s * v_idle + s_dot * (X_idle.translation - X_cmd.translation);
  w_W_target =
      s * w_idle + s_dot * rotationVector(X_idle.rotation * glm::conjugate(X_cmd.rotation));
}

void SimDevice::step(double t_s, double h_s) noexcept {
  Pose X_t;
  Vec3 v_t;
  Vec3 w_t;
  target(t_s, X_t, v_t, w_t);
  // translation: symplectic Euler with the damper taken implicitly (stable for any damping)
  const double m = options_.sim_hand_mass_kg;
  const double k = options_.sim_hand_stiffness_n_per_m;
  const double c = options_.sim_hand_damping_n_s_per_m;
  const Vec3 f_explicit = k * (X_t.translation - p_W_) + c * v_t + force_W_;
  v_W_ = (v_W_ + (h_s / m) * f_explicit) / (1.0 + h_s * c / m);
  p_W_ += h_s * v_W_;
  // rotation: the same scheme on the rotation vector of the orientation error (world frame);
  // the inertia is isotropic, so there is no gyroscopic term
  const double inertia = options_.sim_hand_inertia_kg_m2;
  const double kr = options_.sim_hand_rot_stiffness_nm_per_rad;
  const double cr = options_.sim_hand_rot_damping_nm_s_per_rad;
  const Vec3 e_W = rotationVector(X_t.rotation * glm::conjugate(q_WH_));
  const Vec3 t_explicit = kr * e_W + cr * w_t + torque_W_;
  w_W_ = (w_W_ + (h_s / inertia) * t_explicit) / (1.0 + h_s * cr / inertia);
  q_WH_ = glm::normalize(quatFromRotationVector(h_s * w_W_) * q_WH_);
}

DeviceStatus SimDevice::read(double t_s, DeviceSample& out) noexcept {
  if (!std::isfinite(t_s))
    t_s = t_s_;  // a bad clock reading does not advance time
  if (!started_) {
    started_ = true;
    t_s_ = t_s;
    command_t_s_ = has_command_ ? command_t_s_ : t_s;
  } else if (t_s > t_s_) {
    const double gap_s = std::min(t_s - t_s_, kMaxGap_s);
    const double steps = std::ceil(gap_s / options_.sim_max_step_s);
    const int n = static_cast<int>(std::max(1.0, steps));
    const double h_s = gap_s / n;
    const double t0_s = t_s - gap_s;
    for (int i = 1; i <= n; ++i)
      step(t0_s + i * h_s, h_s);
    t_s_ = t_s;
  }
  out.X_WD = Pose{p_W_, q_WH_};
  out.linear_velocity = v_W_;
  out.angular_velocity = w_W_;
  out.buttons = buttons_;
  return DeviceStatus::kOk;
}

DeviceStatus SimDevice::write(const Vec3& force_n, const Vec3& torque_nm) noexcept {
  // the loop checks and clamps; a non-finite value here would still poison the state
  force_W_ = geom::finite(force_n) ? force_n : Vec3(0.0);
  torque_W_ = geom::finite(torque_nm) ? torque_nm : Vec3(0.0);
  return DeviceStatus::kOk;
}

void SimDevice::command(const PoseCommand& cmd) noexcept {
  if (!geom::finite(cmd.X_W_target.translation) || !geom::finite(cmd.linear_velocity) ||
      !geom::finite(cmd.angular_velocity))
    return;
  const geom::Quat& q = cmd.X_W_target.rotation;
  const double n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
  if (!(n2 > 0.25 && n2 < 4.0))
    return;  // also refuses NaN
  command_ = cmd;
  command_.X_W_target.rotation = glm::normalize(q);
  has_command_ = true;
  command_t_s_ = t_s_;
  buttons_ = cmd.buttons;
}

double SimDevice::energy() const noexcept {
  Pose X_t;
  Vec3 v_t;
  Vec3 w_t;
  target(t_s_, X_t, v_t, w_t);
  const Vec3 dp = X_t.translation - p_W_;
  const Vec3 dv = v_W_ - v_t;
  const Vec3 dw = w_W_ - w_t;
  const Vec3 e = rotationVector(X_t.rotation * glm::conjugate(q_WH_));
  return 0.5 * options_.sim_hand_mass_kg * glm::dot(dv, dv) +
         0.5 * options_.sim_hand_inertia_kg_m2 * glm::dot(dw, dw) +
         0.5 * options_.sim_hand_stiffness_n_per_m * glm::dot(dp, dp) +
         0.5 * options_.sim_hand_rot_stiffness_nm_per_rad * glm::dot(e, e);
}

Result<std::unique_ptr<Device>> makeSimDevice(const DeviceOptions& o) {
  struct Check {
    const char* name;
    double value;
    bool positive;  // else: >= 0
  };
  const Check checks[] = {
      {"sim_hand_mass_kg", o.sim_hand_mass_kg, true},
      {"sim_hand_stiffness_n_per_m", o.sim_hand_stiffness_n_per_m, false},
      {"sim_hand_damping_n_s_per_m", o.sim_hand_damping_n_s_per_m, false},
      {"sim_hand_inertia_kg_m2", o.sim_hand_inertia_kg_m2, true},
      {"sim_hand_rot_stiffness_nm_per_rad", o.sim_hand_rot_stiffness_nm_per_rad, false},
      {"sim_hand_rot_damping_nm_s_per_rad", o.sim_hand_rot_damping_nm_s_per_rad, false},
      {"sim_idle_amplitude_m", o.sim_idle_amplitude_m, false},
      {"sim_idle_angle_rad", o.sim_idle_angle_rad, false},
      {"sim_max_step_s", o.sim_max_step_s, true},
  };
  for (const Check& c : checks) {
    if (!std::isfinite(c.value) || c.value < 0.0 || (c.positive && c.value == 0.0))
      return Error{std::string("device 'sim': ") + c.name + " must be a finite number " +
                   (c.positive ? "> 0" : ">= 0") + ", got " + std::to_string(c.value)};
  }
  if (std::isnan(o.sim_idle_motion_after_s) || o.sim_idle_motion_after_s < 0.0)
    return Error{"device 'sim': sim_idle_motion_after_s must be >= 0 (inf: never), got " +
                 std::to_string(o.sim_idle_motion_after_s)};
  if (!geom::finite(o.sim_home.translation))
    return Error{"device 'sim': sim_home translation is not finite"};
  const geom::Quat& q = o.sim_home.rotation;
  const double n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
  if (!(n2 > 0.25 && n2 < 4.0))
    return Error{"device 'sim': sim_home rotation is not a (near) unit quaternion"};
  return std::unique_ptr<Device>(std::make_unique<SimDevice>(o));
}

}  // namespace hapticd::device
