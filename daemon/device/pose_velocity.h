#pragma once
/// \file
/// Velocities of a device that reports only poses: the backward difference between one read and
/// the previous one (linear, and the rotation vector of q q_prev^-1 over the interval). Zero at the
/// first read and when the time did not advance. Servo thread (no allocation).

#include "core/geometry/pose.h"
#include "core/geometry/rotation.h"

namespace hapticd::device {

class PoseVelocity {
 public:
  /// The pose X at time t_s (seconds); sets v (m/s) and w (rad/s, the pose's frame).
  void update(double t_s, const geom::Pose& X, geom::Vec3& v, geom::Vec3& w) noexcept {
    v = w = geom::Vec3(0.0);
    if (has_previous_ && t_s > previous_t_s_) {
      const double dt = t_s - previous_t_s_;
      v = (X.translation - previous_.translation) / dt;
      w = geom::rotationVector(X.rotation * glm::conjugate(previous_.rotation)) / dt;
    }
    has_previous_ = true;
    previous_t_s_ = t_s;
    previous_ = X;
  }
  /// Forgets the previous read (after a reconnection).
  void reset() noexcept { has_previous_ = false; }

 private:
  bool has_previous_ = false;
  double previous_t_s_ = 0.0;
  geom::Pose previous_;
};

}  // namespace hapticd::device
