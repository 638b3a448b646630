#pragma once
/// \file
/// The one scene -> CollisionWorld builder: the world the Simulation (and so the daemon) steps,
/// which the dynamics tests and benchmarks build the same way.
///
/// Threads: off the servo thread (allocates).

#include <memory>

#include "core/collision/collision_world.h"
#include "core/common/result.h"
#include "core/scene/scene.h"

namespace hapticd::dynamics {

/// The CollisionWorld box margin (scene units) the dynamics wants: contacts within it are seen
/// before they touch, so impacts up to margin / dt fast get their exact time of impact (faster
/// ones are found overlapping, see DynamicsOptions::max_travel_fraction). 0.5% of the scene's
/// length scale. Any thread.
double recommendedBoxMargin(const scene::SceneModel& scene);

/// A body's size: the farthest point of its primitives from `com_B` (its frame), 0 without
/// primitives. Any thread.
double bodySize(const scene::Body& body, const geom::Vec3& com_B);

/// A free dynamic body's own margin (BodyDesc::margin, CollisionWorld::setMargin): the pairs it
/// may touch within a tick are found, and no more. At least kBodyMarginFraction of its size
/// (`size`: the farthest point of it from its centre of mass) and twice `reach` (how far it may
/// travel in the next tick), at most `box_margin` (the world's, relative to the scene's size).
/// A body of the scene's size keeps the world's margin; a 5 mm part on a 40 m floor is not near
/// every piece within 0.2 m (the world's margin there) but within its own 0.3 mm, or as far as
/// its speed carries it. Any thread.
double freeBodyMargin(double size, double reach, double box_margin);
/// A moving body's margin: `least`, or twice `reach` (how far it may travel in the next tick)
/// capped by `box_margin`, whichever is larger. freeBodyMargin is this with least = its size's
/// share capped by box_margin; the held body's least is its base margin. Any thread.
double reachMargin(double least, double reach, double box_margin);
/// The least margin of a free dynamic body, as a fraction of its size.
inline constexpr double kBodyMarginFraction = 0.1;

/// The kind of scene body `body` in the collision world: kProbe for SceneModel::probe_body, else
/// its motion's. Any thread.
collision::BodyKind worldKind(const scene::SceneModel& scene, std::size_t body);

/// The collision world of `scene`: one body per scene body, in order (world id == scene body
/// index), of the kind its motion says (SceneModel::probe_body: kProbe); every primitive with its
/// own collision filter, the body's passing everything, so that two primitives collide exactly
/// when (a.group & b.mask) && (b.group & a.mask) (docs/scenes.md); bodies that start inactive
/// (Body::active false, never a static one) disabled. `extra_probe`, when given, is added after
/// them at the identity pose (the Simulation's probe sphere for a scene without a probe body).
/// Capacities are reserved for every pair a moving primitive can make (at most 65536), so that
/// step() never allocates. `options.box_margin` is raised to recommendedBoxMargin when the
/// scene has a dynamic body; a dynamic body at rest (no initial velocity, a finite mass, not the
/// probe) starts with its own margin, freeBodyMargin(its size, 0, that). Errors: a primitive
/// without a shape, an inactive probe body.
Result<std::unique_ptr<collision::CollisionWorld>> buildCollisionWorld(
    const scene::SceneModel& scene,
    collision::WorldOptions options,
    const collision::BodyDesc* extra_probe = nullptr);

}  // namespace hapticd::dynamics
