#pragma once
/// \file
/// The 6-DOF virtual coupling between the device and the proxy (Colgate, Stanley & Brown 1995;
/// §6.1 of Gregory et al. 2000, "a simple spring model based on the transformation from the
/// actual probe to its proxy"): a linear spring and damper between the device's handle point and
/// the proxy's, and a rotational spring and damper between their orientations. Velocities are
/// backward differences over one tick.
///
/// Passivity at the sample rate: a sampled spring K held for a tick T returns K/2 * sum(dx^2) more
/// energy than it took over a closed path (Colgate & Schenkel 1997); a damper B on the backward
/// difference takes B/T * sum(dx^2) for smooth motion. B >= K T / 2 makes the coupling passive;
/// the default B = K T (docs/response.md) keeps a factor 2 of margin. The same for rotation.

#include "core/common/state_writer.h"
#include "core/response/wrench.h"

namespace hapticd::response {

struct CouplingParams {
  double stiffness_n_per_m = 600.0;
  double damping_n_s_per_m = 0.6;
  double rot_stiffness_nm_per_rad = 1.0;
  double rot_damping_nm_s_per_rad = 0.001;
  double tick_s = 0.001;
};

/// Servo thread; no allocation.
class VirtualCoupling {
 public:
  explicit VirtualCoupling(const CouplingParams& params) : p_(params) {}

  /// The wrench on the hand: pulls the device's handle (h_dev, q_dev) toward the proxy's
  /// (h_prx, q_prx). World frame; torque about the device's handle point.
  Wrench step(const Vec3& h_dev_W, const Quat& q_dev, const Vec3& h_prx_W, const Quat& q_prx);
  /// Forget the previous tick (the next step has zero velocities).
  void reset() { have_prev_ = false; }
  const CouplingParams& params() const { return p_; }
  /// Writes the parameters and last tick's poses (for the simulation state's hash,
  /// core/sim/scene_state.h).
  void writeState(StateWriter& w) const;
  /// Changes the rotational spring and damper (the held set changed). Servo thread.
  void setRotational(double stiffness_nm_per_rad, double damping_nm_s_per_rad) {
    p_.rot_stiffness_nm_per_rad = stiffness_nm_per_rad;
    p_.rot_damping_nm_s_per_rad = damping_nm_s_per_rad;
  }

 private:
  CouplingParams p_;
  bool have_prev_ = false;
  Vec3 prev_h_dev_{0.0}, prev_h_prx_{0.0};
  Quat prev_q_dev_{1.0, 0.0, 0.0, 0.0}, prev_q_prx_{1.0, 0.0, 0.0, 0.0};
};

}  // namespace hapticd::response
