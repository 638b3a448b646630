#pragma once
/// \file
/// Spreads short impulses over a window so that they can be felt (§6.2 of Gregory et al. 2000:
/// "the impulsive ones currently feel like small blips ... force expansion over time").
///
/// An impulse J (N s) given at tick 0 becomes the force J * w_k / dt on ticks k = 0..N-1,
/// N = round(window / dt), with the Hann weights w_k = integral over tick k of
/// (1/window)(1 - cos(2 pi t / window)): sum w_k == 1, so the force record integrates to J
/// exactly; its peak is 2 J / window (at window / 2), against J / dt for the bare impulse. The
/// filter is linear: a steady stream of impulses F dt per tick comes out as the steady force F
/// (after the window's ramp). Torque impulses are spread the same way.

#include <cstdint>
#include <vector>

#include "core/common/state_writer.h"
#include "core/geometry/pose.h"

namespace hapticd::dynamics {

class ImpulseSpreader {
 public:
  ImpulseSpreader() = default;
  /// A window of window_s seconds at a tick of tick_s seconds (both > 0; a window shorter than
  /// one tick gives one tick: the impulse returns as J / dt). Allocates: off the servo thread.
  ImpulseSpreader(double window_s, double tick_s);

  /// Adds an impulse (N s) and an angular impulse (N m s) received this tick. Servo thread.
  void add(const geom::Vec3& impulse_ns, const geom::Vec3& angular_impulse_nms);
  /// The force (N) and torque (N m) to render this tick; moves on to the next tick. Servo thread.
  void pop(geom::Vec3* force_n, geom::Vec3* torque_nm);
  /// Forgets everything pending. Servo thread.
  void clear();

  /// Writes what is pending (for the simulation state's hash, core/sim/scene_state.h).
  void writeState(StateWriter& w) const;

 private:
  double tick_s_ = 0.001;
  std::vector<double> weights_{1.0};
  std::vector<geom::Vec3> force_{geom::Vec3{0.0}}, torque_{geom::Vec3{0.0}};
  std::uint32_t head_ = 0;
};

}  // namespace hapticd::dynamics
