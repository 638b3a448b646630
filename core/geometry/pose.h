#pragma once
/// \file
/// Rigid poses. A Pose X_AB maps points from frame B into frame A: p_A = X_AB * p_B.

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace hapticd::geom {

using Vec3 = glm::dvec3;
using Mat3 = glm::dmat3;
using Quat = glm::dquat;

/// A rigid transform as a rotation matrix and a translation: p_A = R * p_B + t.
/// Used inside the inner loops (no quaternion products per point).
struct Transform {
  Mat3 R{1.0};
  Vec3 t{0.0};

  Vec3 apply(const Vec3& p) const { return R * p + t; }
  Vec3 rotate(const Vec3& v) const { return R * v; }
  /// The inverse transform (R^T, -R^T t).
  Transform inverse() const {
    const Mat3 Rt = glm::transpose(R);
    return {Rt, -(Rt * t)};
  }
  /// Composition: (this * o)(p) = this(o(p)).
  Transform operator*(const Transform& o) const { return {R * o.R, R * o.t + t}; }
};

/// A rigid pose: translation (metres or any unit) and unit rotation quaternion.
/// glm::dquat stores (w, x, y, z) in its constructor; glTF order is (x, y, z, w): use fromXyzw.
struct Pose {
  Vec3 translation{0.0};
  Quat rotation{1.0, 0.0, 0.0, 0.0};

  static Pose fromXyzw(const Vec3& t, double qx, double qy, double qz, double qw) {
    return {t, glm::normalize(Quat(qw, qx, qy, qz))};
  }
  Transform toTransform() const { return {glm::mat3_cast(rotation), translation}; }
};

/// X_AB = X_WA^-1 * X_WB, computed so that large common translations cancel first.
inline Transform relativeTransform(const Pose& X_WA, const Pose& X_WB) {
  const Quat qa_inv = glm::conjugate(X_WA.rotation);
  const Vec3 dt = X_WB.translation - X_WA.translation;
  return {glm::mat3_cast(qa_inv * X_WB.rotation), qa_inv * dt};
}

}  // namespace hapticd::geom
