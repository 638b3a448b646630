#include "core/dynamics/impulse_spreader.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hapticd::dynamics {

ImpulseSpreader::ImpulseSpreader(double window_s, double tick_s) : tick_s_(tick_s) {
  const double ticks = tick_s > 0.0 && std::isfinite(window_s / tick_s) ? window_s / tick_s : 1.0;
  const auto n = static_cast<std::uint32_t>(std::clamp(std::round(ticks), 1.0, 1e6));
  weights_.assign(n, 0.0);
  const double two_pi = 2.0 * std::numbers::pi;
  for (std::uint32_t k = 0; k < n; ++k) {
    // integral of (1/N)(1 - cos(2 pi s / N)) over s in [k, k + 1]
    weights_[k] = 1.0 / n - (std::sin(two_pi * (k + 1) / n) - std::sin(two_pi * k / n)) / two_pi;
  }
  force_.assign(n, geom::Vec3{0.0});
  torque_.assign(n, geom::Vec3{0.0});
  head_ = 0;
}

void ImpulseSpreader::add(const geom::Vec3& impulse_ns, const geom::Vec3& angular_impulse_nms) {
  const auto n = static_cast<std::uint32_t>(weights_.size());
  std::uint32_t slot = head_;
  for (std::uint32_t k = 0; k < n; ++k) {
    const double s = weights_[k] / tick_s_;
    force_[slot] += impulse_ns * s;
    torque_[slot] += angular_impulse_nms * s;
    if (++slot == n)
      slot = 0;
  }
}

void ImpulseSpreader::pop(geom::Vec3* force_n, geom::Vec3* torque_nm) {
  *force_n = force_[head_];
  *torque_nm = torque_[head_];
  force_[head_] = geom::Vec3{0.0};
  torque_[head_] = geom::Vec3{0.0};
  if (++head_ == weights_.size())
    head_ = 0;
}

void ImpulseSpreader::clear() {
  std::fill(force_.begin(), force_.end(), geom::Vec3{0.0});
  std::fill(torque_.begin(), torque_.end(), geom::Vec3{0.0});
  head_ = 0;
}

void ImpulseSpreader::writeState(StateWriter& w) const {
  w.f64(tick_s_);
  w.integer(head_);
  w.integer(weights_.size());
  for (std::size_t k = 0; k < weights_.size(); ++k) {
    w.f64(weights_[k]);
    w.glm(force_[k]);
    w.glm(torque_[k]);
  }
}

}  // namespace hapticd::dynamics
