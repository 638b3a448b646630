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

bool Dynamics::syncSleep(collision::CollisionWorld& world) const {
  bool woke = false;
  if (!active_)
    return woke;
  // the bodies whose sleep is the dynamics' (the held and driven ones stay as the Simulation
  // sets them, a disabled one until it is back)
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    const BodyState& b = bodies_[i];
    if (b.driven || !b.enabled || static_cast<std::int32_t>(i) == held_)
      continue;
    if (b.motion == scene::Motion::kKinematic) {
      // a kinematic body the dynamics move (a target, a velocity) is awake in the world from
      // then on, so that its pairs with sleeping bodies are asked (it may push them)
      const bool moving =
          b.has_target || (b.coast && (b.v_coast != Vec3{0.0} || b.w_coast != Vec3{0.0}));
      if (moving && world.asleep(i)) {
        world.setAsleep(i, false);
        woke = true;
      }
      continue;
    }
    if (b.motion != scene::Motion::kDynamic || world.asleep(i) == b.asleep)
      continue;
    woke = woke || !b.asleep;
    world.setAsleep(i, b.asleep);
  }
  return woke;
}

}  // namespace hapticd::dynamics
