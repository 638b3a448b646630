// A scene swap's prewarm (core/sim/scene_state.h prewarmState): the new scene's first ticks'
// cold work done off the servo thread.
#include "core/sim/scene_state.h"
#include "core/sim/tick.h"

namespace hapticd::sim {

PrewarmReport prewarmState(const SimModel& m,
                           SceneState& s,
                           const std::optional<geom::Pose>& X_W_device) {
  PrewarmReport report;
  // the probe sphere where the first tick puts it (step.cpp beginTick, which still runs: a
  // device that moved meanwhile is followed there, from warm caches when it moved little)
  if (X_W_device && m.info[m.probe].scene_index < 0 && geom::finite(X_W_device->translation)) {
    s.X_W_probe.translation = X_W_device->translation;
    s.world.setPose(m.probe, s.X_W_probe);
  }
  s.world.step();
  ++report.collision_steps;

  // the dynamics' first steps: contacts, warm starts; a scene at rest goes to sleep
  if (m.dynamics_active) {
    dynamics::Dynamics& dyn = *s.dynamics;
    dynamics::HeldInput held;
    held.mode = dynamics::HeldMode::kKinematic;
    held.X_WB_target = s.X_W_probe;
    const double dt = m.options.response.tick_s;
    std::uint32_t still = 0;
    while (report.dynamics_steps < kMaxPrewarmSteps && still < kPrewarmStillSteps) {
      if (report.dynamics_steps > 0) {
        s.world.step();
        ++report.collision_steps;
      }
      (void)dyn.step(s.world, dt, &held);
      ++report.dynamics_steps;
      still = dyn.stillNow(s.world) ? still + 1 : 0;
    }
    // the contacts at the poses the dynamics left
    s.world.step();
    ++report.collision_steps;
    report.at_rest = still >= kPrewarmStillSteps && dyn.sleepIfStill(s.world);
    if (dyn.syncSleep(s.world) || report.at_rest)
      s.world.relist();  // the sleeping islands' pairs no longer listed
    for (std::size_t i = 0; i < m.pose_bodies.size(); ++i) {
      const std::uint32_t id = m.pose_bodies[i];
      s.body_poses[i].X_WB =
          m.info[id].kind == collision::BodyKind::kDynamic ? dyn.pose(id) : s.world.pose(id);
    }
    // every pose read: the swap's first tick reads those given one after this only
    s.body_poses_stale = false;
    s.world.clearPosed();
  }
  s.world.prewarm();
  detail::gatherRows(m, s);
  return report;
}

ColdWork coldWork(const SceneState& s) {
  const collision::CollisionWorld::ColdCounters c = s.world.coldCounters();
  return {c.cold_queries, c.full_sorts, c.position_rebuilds};
}

}  // namespace hapticd::sim
