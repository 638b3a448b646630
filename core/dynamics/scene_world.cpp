#include "core/dynamics/scene_world.h"

#include <algorithm>

namespace hapticd::dynamics {

double recommendedBoxMargin(const scene::SceneModel& scene) {
  return 0.005 * (scene.length_scale > 0.0 ? scene.length_scale : 1.0);
}

double bodySize(const scene::Body& body, const geom::Vec3& com_B) {
  double size = 0.0;
  for (const scene::Primitive& p : body.primitives) {
    if (!p.shape)
      continue;
    const geom::Vec3 c = p.X_BP.translation + p.X_BP.rotation * p.shape->centroid();
    size = std::max(size, glm::length(c - com_B) + p.shape->radius());
  }
  return size;
}

double reachMargin(double least, double reach, double box_margin) {
  return std::max(least, std::min(box_margin, 2.0 * reach));
}

double freeBodyMargin(double size, double reach, double box_margin) {
  return reachMargin(std::min(box_margin, kBodyMarginFraction * size), reach, box_margin);
}

collision::BodyKind worldKind(const scene::SceneModel& scene, std::size_t body) {
  using collision::BodyKind;
  const scene::Motion motion = scene.bodies[body].motion;
  return static_cast<std::int32_t>(body) == scene.probe_body ? BodyKind::kProbe
         : motion == scene::Motion::kStatic                  ? BodyKind::kStatic
         : motion == scene::Motion::kKinematic               ? BodyKind::kKinematic
                                                             : BodyKind::kDynamic;
}

Result<std::unique_ptr<collision::CollisionWorld>> buildCollisionWorld(
    const scene::SceneModel& scene,
    collision::WorldOptions options,
    const collision::BodyDesc* extra_probe) {
  using collision::BodyKind;
  const bool any_dynamic =
      std::any_of(scene.bodies.begin(), scene.bodies.end(),
                  [](const scene::Body& b) { return b.motion == scene::Motion::kDynamic; });
  if (any_dynamic)
    options.box_margin = std::max(options.box_margin, recommendedBoxMargin(scene));
  auto world = std::make_unique<collision::CollisionWorld>(options);
  std::size_t total_prims = 0, moving_prims = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const scene::Body& b = scene.bodies[i];
    const bool is_probe = static_cast<std::int32_t>(i) == scene.probe_body;
    collision::BodyDesc desc;
    desc.kind = worldKind(scene, i);
    desc.group = ~0u;  // the primitives' filters alone decide
    desc.mask = ~0u;
    for (const scene::Primitive& p : b.primitives) {
      if (!p.shape)
        return Error{"body '" + b.name + "': a primitive has no shape"};
      desc.primitives.push_back({p.shape, p.X_BP.toTransform(), p.group, p.mask});
    }
    total_prims += b.primitives.size();
    if (desc.kind == BodyKind::kDynamic && !(b.mass_declared && b.mass == 0.0) &&
        b.linear_velocity_W == geom::Vec3{0.0} && b.angular_velocity_W == geom::Vec3{0.0}) {
      // at rest: its own margin (the dynamics set it from its speed at every step)
      desc.margin = freeBodyMargin(bodySize(b, b.com_B), 0.0, options.box_margin);
    }
    if (desc.kind != BodyKind::kStatic)
      moving_prims += b.primitives.size();
    const std::uint32_t id = world->addBody(desc, b.X_WB);
    if (id != i)
      return Error{"collision world: unexpected body id"};
    // extras.haptic.active false: out of the scene until a scene edit adds it (static bodies
    // are always active; the probe cannot be inactive)
    const bool starts_active = b.active || desc.kind == BodyKind::kStatic;
    if (!starts_active && is_probe)
      return Error{"body '" + b.name + "': the probe body cannot be inactive"};
    if (!starts_active)
      world->setEnabled(id, false);
  }
  if (extra_probe != nullptr) {
    world->addBody(*extra_probe, geom::Pose{});
    total_prims += extra_probe->primitives.size();
    moving_prims += extra_probe->primitives.size();
  }
  // capacities: every pair a moving primitive can make, bounded
  const std::size_t pairs = std::min<std::size_t>(moving_prims * total_prims + 64, 1u << 16);
  world->reserve(total_prims + 1, pairs);
  return world;
}

}  // namespace hapticd::dynamics
