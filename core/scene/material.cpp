// KHR_physics_rigid_bodies' rule for combining two materials' friction and restitution, and the
// default material of a collider without one: the one implementation, used by the plan
// (plan.cpp) and by the dynamics' contacts (core/dynamics), so its own small library
// (hapticd_scene_material) that the dynamics link without the loader.
#include <algorithm>

#include "core/scene/scene.h"

namespace hapticd::scene {
namespace {

// built before main: the servo thread reads it and never constructs it
const Material kDefault = [] {
  Material m;
  m.name = "default";
  m.static_friction = m.dynamic_friction = kDefaultFriction;
  m.restitution = 0.0;
  return m;
}();

}  // namespace

const Material& defaultMaterial() {
  return kDefault;
}

const Material& materialOf(const SceneModel& scene, std::int32_t index) {
  return index >= 0 && static_cast<std::size_t>(index) < scene.materials.size()
             ? scene.materials[static_cast<std::size_t>(index)]
             : kDefault;
}

double combineMaterials(const Material& a, const Material& b, MaterialValue which) {
  const bool friction = which != MaterialValue::kRestitution;
  const auto value = [&](const Material& m) {
    return which == MaterialValue::kStaticFriction    ? m.static_friction
           : which == MaterialValue::kDynamicFriction ? m.dynamic_friction
                                                      : m.restitution;
  };
  const auto declares = [&](const Material& m, Combine c) {
    return friction ? m.friction_combine_declared && m.friction_combine == c
                    : m.restitution_combine_declared && m.restitution_combine == c;
  };
  const auto either = [&](Combine c) { return declares(a, c) || declares(b, c); };
  const double x = value(a), y = value(b);
  if (either(Combine::kAverage))
    return 0.5 * (x + y);
  if (either(Combine::kMinimum))
    return std::min(x, y);
  if (either(Combine::kMaximum))
    return std::max(x, y);
  if (either(Combine::kMultiply))
    return x * y;
  return 0.5 * (x + y);  // neither declares a mode
}

}  // namespace hapticd::scene
