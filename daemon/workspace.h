#pragma once
/// \file
/// The device-to-scene workspace mapping (config [device] workspace_*): a scene pose of the
/// device frame D and a uniform scale. A device point p_D maps to p_S = t_SD + R_SD (s p_D); a
/// device rotation q_D to q_SD q_D. Forces map back so that power is preserved
/// (F_S . v_S = F_D . v_D): F_D = s R_SD^T F_S, and torques tau_D = R_SD^T tau_S.
/// Identity by default. Pure; any thread (servo thread included: no allocation).

#include "core/geometry/pose.h"
#include "core/response/output_stage.h"

namespace hapticd::daemon {

struct WorkspaceMapping {
  geom::Pose X_SD;     ///< pose of the device frame in the scene
  double scale = 1.0;  ///< scene metres per device metre, > 0

  geom::Pose toScene(const geom::Pose& X_D) const noexcept {
    return {X_SD.translation + X_SD.rotation * (scale * X_D.translation),
            X_SD.rotation * X_D.rotation};
  }
  geom::Pose toDevice(const geom::Pose& X_S) const noexcept {
    const geom::Quat q_inv = glm::conjugate(X_SD.rotation);
    return {(q_inv * (X_S.translation - X_SD.translation)) / scale, q_inv * X_S.rotation};
  }
  geom::Vec3 velocityToDevice(const geom::Vec3& v_S) const noexcept {
    return (glm::conjugate(X_SD.rotation) * v_S) / scale;
  }
  geom::Vec3 angularToDevice(const geom::Vec3& w_S) const noexcept {
    return glm::conjugate(X_SD.rotation) * w_S;
  }
  /// Forces and torques to the device frame (F_D = s R_SD^T F_S, tau_D = R_SD^T tau_S), as the
  /// output stage's frame: the stage maps the wrench and clamps it in the device frame.
  response::OutputFrame outputFrame() const noexcept {
    return {glm::conjugate(X_SD.rotation), scale};
  }
  geom::Vec3 forceToScene(const geom::Vec3& F_D) const noexcept {
    return (X_SD.rotation * F_D) / scale;
  }
  geom::Vec3 torqueToScene(const geom::Vec3& tau_D) const noexcept { return X_SD.rotation * tau_D; }
};

}  // namespace hapticd::daemon
