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

Wrench OutputStage::apply(const Wrench& raw, bool device_ok, OutputReport* report) {
  OutputReport r;
  if (!device_ok) {
    ramp_ = 0.0;
    last_ = Wrench{};
    r.ramping = true;
    *report = r;
    return last_;
  }
  Wrench target = raw;
  if (!isFinite(target.force_n) || !isFinite(target.torque_nm)) {
    r.non_finite = true;
    ramp_ = 0.0;
    target = Wrench{};
  }
  target.force_n = clampLength(target.force_n, limits_.max_force_n, &r.clamped);
  target.torque_nm = clampLength(target.torque_nm, limits_.max_torque_nm, &r.clamped);
  target.force_n *= ramp_;
  target.torque_nm *= ramp_;
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
