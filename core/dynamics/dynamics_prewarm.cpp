// The dynamics' part of a scene swap's prewarm (core/sim/scene_state.h prewarmState): the sleep
// test asked once, and a scene found at rest put to sleep at once.
#include "core/dynamics/dynamics.h"
#include "core/dynamics/dynamics_internal.h"

namespace hapticd::dynamics {

bool Dynamics::stillNow(const collision::CollisionWorld& world) const {
  if (!active_ || !(options_.sleep_time_s > 0.0))
    return false;
  // the bodies updateSleep() watches, with its threshold
  for (const BodyState& b : bodies_) {
    if (b.motion == scene::Motion::kStatic || b.driven || !b.enabled ||
        (b.motion == scene::Motion::kKinematic && !b.coast))
      continue;
    const double speed = glm::length(b.v_W) + glm::length(b.w_W) * b.size;
    if (!(speed <= options_.sleep_speed_fraction * b.size))
      return false;
  }
  return !(held_kinematic_ && heldTouchesDynamic(world));
}

bool Dynamics::sleepIfStill(const collision::CollisionWorld& world) {
  if (asleep_ || !stillNow(world))
    return asleep_;
  // still now: a whole sleep time of rest at once
  updateSleep(options_.sleep_time_s);
  return asleep_;
}

}  // namespace hapticd::dynamics
