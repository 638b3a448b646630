#include "core/response/output_stage.h"

#include <algorithm>

namespace hapticd::response {
namespace {

Vec3 clampLength(const Vec3& v, double max_length, bool* clamped) {
  const double l = std::sqrt(glm::dot(v, v));
  if (l <= max_length)
    return v;
  *clamped = true;
  return v * (max_length / l);
}

}  // namespace

Vec3 limitStep(const Vec3& prev, const Vec3& next, double max_step, bool* limited) {
  const Vec3 d = next - prev;
  const double l = std::sqrt(glm::dot(d, d));
  if (l > 2.0 * max_step) {
    *limited = true;
    return prev + d * (max_step / l);
  }
  if (l > max_step) {
    *limited = true;
    return 0.5 * (prev + next);
  }
  return next;
}

void OutputStage::fade(const OutputInputs& in) {
  // a fault, a disarm and a stop fade the gain to zero; rearm() sets it back to 1
  if ((in.fault || in.hold) && fade_ > 0.0) {
    const double fade_s = in.fault ? limits_.fault_fade_s : limits_.hold_fade_s;
    fade_ = std::max(0.0, fade_ - (fade_s > 0.0 ? limits_.tick_s / fade_s : 1.0));
  }
}

Wrench OutputStage::apply(const Wrench& raw_W,
                          const OutputInputs& in,
                          const OutputFrame& frame,
                          OutputReport* report) {
  OutputReport r;
  fade(in);
  if (!in.device_ok) {
    if (device_ok_)
      ++ramp_restarts_;
    device_ok_ = false;
    ramp_ = 0.0;
    last_ = Wrench{};
    r.ramping = true;
    *report = r;
    return last_;
  }
  device_ok_ = true;
  Wrench target = raw_W;
  if (!isFinite(target.force_n) || !isFinite(target.torque_nm)) {
    r.non_finite = true;
    restartRamp();
    target = Wrench{};
  }
  target.force_n = frame.force_scale * (frame.q_DW * target.force_n);
  target.torque_nm = frame.q_DW * target.torque_nm;
  target.force_n = clampLength(target.force_n, limits_.max_force_n, &r.clamped);
  target.torque_nm = clampLength(target.torque_nm, limits_.max_torque_nm, &r.clamped);
  const double gain = ramp_ * fade_ * in.gate_scale;
  target.force_n *= gain;
  target.torque_nm *= gain;
  r.ramping = ramp_ < 1.0;
  Wrench out;
  out.force_n = limitStep(last_.force_n, target.force_n, limits_.max_force_step_n, &r.step_limited);
  out.torque_nm =
      limitStep(last_.torque_nm, target.torque_nm, limits_.max_torque_step_nm, &r.step_limited);
  // last_ and target are within the limits, so their blend is too; non-finite cannot reach here
  last_ = out;
  ramp_ = limits_.ramp_s > 0.0 ? std::min(1.0, ramp_ + limits_.tick_s / limits_.ramp_s) : 1.0;
  *report = r;
  return out;
}

}  // namespace hapticd::response
