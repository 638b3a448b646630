#pragma once
/// \file
/// The one place where every wrench bound for the device is checked finite, clamped to the
/// device limits, rate limited (§5.3 of Gregory et al. 2000, "force and torque interpolation")
/// and ramped in (libfranka's rule: every command checked before it reaches the robot).
///
/// The paper's smoothing, for a scalar force F_1 following the displayed F_0 (F_1 > F_0):
///   if F_1 - F_0 > 2 F_max: F_1 = F_0 + F_max;  else if F_1 - F_0 > F_max: F_1 = (F_0 + F_1) / 2.
/// Generalised here to vectors on the difference D = F_1 - F_0: |D| > 2 F_max gives
/// F_0 + F_max D/|D|; F_max < |D| <= 2 F_max gives (F_0 + F_1) / 2. So |F_1 - F_0| <= F_max always,
/// which bounds both the change of magnitude (||F_1| - |F_0|| <= |D|) and of direction
/// (|F_0| * angle <= (pi/2) |D| for the angle between them) per tick. The same for torque.

#include <cstdint>

#include "core/response/wrench.h"

namespace hapticd::response {

/// The paper's step limit on vectors (see the file comment). Returns the vector to display;
/// sets *limited when it differs from `next`. Any thread.
Vec3 limitStep(const Vec3& prev, const Vec3& next, double max_step, bool* limited);

/// Limits of the output stage; every knob is documented in docs/response.md.
struct OutputLimits {
  double max_force_n = 10.0;
  double max_torque_nm = 1.0;
  double max_force_step_n = 0.5;     ///< F_max
  double max_torque_step_nm = 0.05;  ///< the same for torque
  double ramp_s = 0.5;               ///< zero to full scale, s
  double tick_s = 0.001;
};

/// What the output stage did this tick.
struct OutputReport {
  bool ramping = false;       ///< the ramp scale is below 1
  bool clamped = false;       ///< a device limit cut the wrench
  bool step_limited = false;  ///< F_max (or its torque twin) cut the change
  bool non_finite = false;    ///< the input was NaN or Inf: zero was sent and the ramp restarted
};

/// Wrench to the device. Servo thread: no allocation.
class OutputStage {
 public:
  explicit OutputStage(const OutputLimits& limits) : limits_(limits) {}

  /// The wrench to send for `raw` (the coupling's): non-finite input gives zero and restarts the
  /// ramp; then clamp to the limits, scale by the ramp, limit the step from the last output. When
  /// `device_ok` is false the output is zero at once (no step limit) and the ramp restarts.
  Wrench apply(const Wrench& raw, bool device_ok, OutputReport* report);

  /// Fade to zero (at the step limit) and ramp in again from there.
  void restartRamp() { ramp_ = 0.0; }
  double rampScale() const { return ramp_; }
  const Wrench& last() const { return last_; }

 private:
  OutputLimits limits_;
  Wrench last_;
  double ramp_ = 0.0;
};

}  // namespace hapticd::response
