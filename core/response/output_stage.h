#pragma once
/// \file
/// The one output stage: every wrench bound for the device passes here, once per tick, in this
/// order (docs/response.md "The output stage"; libfranka's rule: every command checked before it
/// reaches the robot):
///
///  1. non-finite input: zero target, the ramp-in restarts, OutputReport::non_finite (the servo
///     loop latches its not_finite fault);
///  2. the world (scene) to device frame transform the caller supplies (OutputFrame);
///  3. one clamp to the device limits, in the device frame;
///  4. the gain: ramp-in (0 to 1 over ramp_s) x fade (1 to 0 over fault_fade_s on a fault,
///     hold_fade_s on a disarm or stop) x the caller's gate scale. It scales the clamped wrench, so
///     that a ramp or a fade takes its whole time whatever the wrench (and cannot leave the
///     limits);
///  5. one step limit from the last output (§5.3 of Gregory et al. 2000, limitStep below);
///  6. the last output remembered for the next step limit.
/// A lost device (OutputInputs::device_ok false) gives zero at once (no step limit: nothing can be
/// displayed) and restarts the ramp.
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

/// Limits and times of the output stage (one set for the daemon: config [device] max_force_n,
/// max_torque_nm, max_force_step_n, max_torque_step_nm; [servo] ramp_in_s, fault_fade_s,
/// stop_ramp_s); every knob is documented in docs/response.md.
struct OutputLimits {
  double max_force_n = 10.0;         ///< device frame
  double max_torque_nm = 1.0;        ///< device frame
  double max_force_step_n = 0.5;     ///< F_max
  double max_torque_step_nm = 0.05;  ///< the same for torque
  double ramp_s = 0.5;               ///< ramp-in: zero to full scale, s
  double fault_fade_s = 0.05;        ///< a fault: the gain fades from 1 to 0 over this, s
  double hold_fade_s = 0.2;          ///< a disarm or a stop: the same, s
  double tick_s = 0.001;
};

/// The world (scene) frame to the device frame: F_D = force_scale (q_DW F_W), T_D = q_DW T_W (the
/// workspace mapping's, daemon/workspace.h; the identity for offline users).
struct OutputFrame {
  Quat q_DW{1.0, 0.0, 0.0, 0.0};
  double force_scale = 1.0;
};

/// What drives the gain this tick.
struct OutputInputs {
  bool device_ok = true;    ///< false: zero at once, no step limit; the ramp-in restarts
  bool fault = false;       ///< a latched fault: the fade runs to zero over fault_fade_s
  bool hold = false;        ///< disarmed or stopping: the fade runs to zero over hold_fade_s
  double gate_scale = 1.0;  ///< an outside scale in [0, 1] (the protocol's command gate)
};

/// What the output stage did this tick.
struct OutputReport {
  bool ramping = false;       ///< the ramp scale is below 1
  bool clamped = false;       ///< a device limit cut the wrench
  bool step_limited = false;  ///< F_max (or its torque twin) cut the change
  bool non_finite = false;    ///< the input was NaN or Inf: zero was sent and the ramp restarted
};

/// Wrench to the device. Servo thread: no allocation, lock or log.
class OutputStage {
 public:
  /// `armed` false: the fade starts at zero (rearm() brings it to 1).
  explicit OutputStage(const OutputLimits& limits, bool armed = true)
      : limits_(limits), fade_(armed ? 1.0 : 0.0) {}

  /// The device-frame wrench to send for `raw_W` (the simulation's, world frame), in the order of
  /// the file comment.
  Wrench apply(const Wrench& raw_W,
               const OutputInputs& in,
               const OutputFrame& frame,
               OutputReport* report);
  /// The same with the identity frame, armed, no gate.
  Wrench apply(const Wrench& raw, bool device_ok, OutputReport* report) {
    OutputInputs in;
    in.device_ok = device_ok;
    return apply(raw, in, OutputFrame{}, report);
  }

  /// Fade to zero (at the step limit) and ramp in again from there.
  void restartRamp() {
    ramp_ = 0.0;
    ++ramp_restarts_;
  }
  /// An arm: the fade back to 1 and the ramp-in from zero (so the force comes back smoothly).
  void rearm() {
    fade_ = 1.0;
    restartRamp();
  }
  /// The last output was not displayed (a failed write, the end of a stream): it is zero.
  void zeroLast() { last_ = Wrench{}; }

  double rampScale() const { return ramp_; }
  double fadeGain() const { return fade_; }
  /// The last output, device frame.
  const Wrench& last() const { return last_; }
  /// Faded out and zero written: the output is held at zero.
  bool atZero() const {
    return fade_ == 0.0 && last_.force_n == Vec3(0.0) && last_.torque_nm == Vec3(0.0);
  }
  /// Times the ramp-in started again (non-finite input, a device loss, restartRamp, rearm).
  std::uint64_t rampRestarts() const { return ramp_restarts_; }

 private:
  void fade(const OutputInputs& in);

  OutputLimits limits_;
  Wrench last_;
  double ramp_ = 0.0;
  double fade_ = 1.0;
  bool device_ok_ = true;
  std::uint64_t ramp_restarts_ = 0;
};

}  // namespace hapticd::response
