// Scene edits between ticks (protocol SceneUpdate): kinematic bodies moved, bodies added to and
// removed from the scene. They take effect in the next step.
#include <cmath>

#include "core/geometry/rotation.h"
#include "core/sim/tick.h"

namespace hapticd::sim {
namespace {

using collision::BodyKind;

// A finite pose with a unit quaternion (|‖q‖ − 1| <= kUnitTolerance), normalised into *out.
constexpr double kUnitTolerance = 1e-6;
bool unitPose(const geom::Pose& in, geom::Pose* out) {
  if (!geom::finite(in.translation) || !geom::finite(in.rotation))
    return false;
  const geom::Quat& q = in.rotation;
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!std::isfinite(n) || std::abs(n - 1.0) > kUnitTolerance)
    return false;
  out->translation = in.translation;
  out->rotation = geom::Quat{q.w / n, q.x / n, q.y / n, q.z / n};
  return true;
}

// the checks both edits share: in range, not static, not held (kOk when editable)
EditStatus editable(const SimModel& m, const SceneState& s, std::uint32_t body) {
  if (body >= m.scene->bodies.size())
    return EditStatus::kNoSuchBody;
  if (m.info[body].kind == BodyKind::kStatic)
    return EditStatus::kStaticBody;
  if (body == m.probe || detail::isHeld(s, body))
    return EditStatus::kHeldBody;
  return EditStatus::kOk;
}

}  // namespace

EditStatus setKinematicPose(const SimModel& m,
                            SceneState& s,
                            std::uint32_t body,
                            const Pose& X_WB) {
  if (const EditStatus st = editable(m, s, body); st != EditStatus::kOk)
    return st;
  if (m.info[body].kind != BodyKind::kKinematic)
    return EditStatus::kNotKinematic;
  if (s.active[body] == 0)
    return EditStatus::kInactive;
  geom::Pose X;
  if (!unitPose(X_WB, &X))
    return EditStatus::kNotFinite;
  const geom::Pose& from = s.world.pose(body);
  const double angle =
      glm::length(geom::rotationVector(X.rotation * glm::conjugate(from.rotation)));
  const double travel =
      glm::length(X.translation - from.translation) + angle * m.info[body].origin_radius;
  if (std::isfinite(travel))
    s.edit_travel[body] += travel;
  if (m.dynamics_active) {
    // the dynamics move it there in the next step with the velocity that takes it there, so
    // that it pushes the dynamic bodies in its way; the collision world follows
    s.dynamics->setKinematicPose(body, X);
    s.kinematic_target_pending = true;
  } else {
    // no dynamics: the collision world has it there in the next step, before the proxy moves
    // (asleep as before: its pairs with static and other resting bodies stay untested; its pair
    // with the awake probe is tested again because it moved)
    s.world.setPose(body, X);
    s.world_dirty = true;
  }
  return EditStatus::kOk;
}

EditStatus setBodyActive(const SimModel& m,
                         SceneState& s,
                         std::uint32_t body,
                         bool active,
                         const Pose& X_WB) {
  if (const EditStatus st = editable(m, s, body); st != EditStatus::kOk)
    return st;
  geom::Pose X;
  if (active && !unitPose(X_WB, &X))
    return EditStatus::kNotFinite;
  s.active[body] = active ? 1 : 0;
  s.world.setEnabled(body, active);
  if (active)
    s.world.setPose(body, X);
  if (m.dynamics_active)
    s.dynamics->setEnabled(body, active, X);
  if (m.info[body].hinge)
    detail::updateDriven(m, s);
  s.world_dirty = true;
  return EditStatus::kOk;
}

}  // namespace hapticd::sim
