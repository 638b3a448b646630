// The simulation plan of a scene: "simulate only the effects a scene calls for"
// (docs/architecture.md).
#include <algorithm>
#include <set>

#include "core/scene/scene.h"

namespace hapticd::scene {
namespace {

// KHR_physics_rigid_bodies: average if either asks, else minimum, else maximum, else multiply
double combine(double a, Combine ca, double b, Combine cb) {
  const auto either = [&](Combine c) { return ca == c || cb == c; };
  if (either(Combine::kAverage))
    return 0.5 * (a + b);
  if (either(Combine::kMinimum))
    return std::min(a, b);
  if (either(Combine::kMaximum))
    return std::max(a, b);
  return a * b;
}

// a primitive without a material: no friction, no restitution, combined by average
Material materialOf(const SceneModel& scene, std::int32_t index) {
  if (index < 0 || static_cast<std::size_t>(index) >= scene.materials.size())
    return Material{};
  return scene.materials[static_cast<std::size_t>(index)];
}

}  // namespace

SimulationPlan makePlan(const SceneModel& scene) {
  SimulationPlan plan;
  plan.contact_forces = true;
  // the materials on moving bodies that can meet any other material in the scene
  std::set<std::int32_t> all, touching, dynamic;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const Body& body = scene.bodies[b];
    const bool is_dynamic = body.motion == Motion::kDynamic;
    const bool is_probe = body.probe || static_cast<std::int32_t>(b) == scene.probe_body;
    if (is_dynamic)
      plan.dynamics = true;
    if (is_dynamic && body.gravity_factor != 0.0 && scene.gravity_W &&
        (scene.gravity_W->x != 0.0 || scene.gravity_W->y != 0.0 || scene.gravity_W->z != 0.0)) {
      plan.gravity = true;
    }
    for (const Primitive& prim : body.primitives) {
      all.insert(prim.material);
      if (is_dynamic || is_probe)
        touching.insert(prim.material);
      if (is_dynamic)
        dynamic.insert(prim.material);
      if (body.motion == Motion::kStatic) {
        ++plan.static_primitives;
      } else {
        ++plan.moving_primitives;
      }
    }
  }
  for (std::int32_t a : touching) {
    const Material ma = materialOf(scene, a);
    for (std::int32_t b : all) {
      const Material mb = materialOf(scene, b);
      const double friction = std::max(
          combine(ma.static_friction, ma.friction_combine, mb.static_friction, mb.friction_combine),
          combine(ma.dynamic_friction, ma.friction_combine, mb.dynamic_friction,
                  mb.friction_combine));
      if (friction > 0.0)
        plan.friction = true;
      if (dynamic.count(a) && combine(ma.restitution, ma.restitution_combine, mb.restitution,
                                      mb.restitution_combine) > 0.0) {
        plan.restitution = true;
      }
    }
  }
  plan.joints = !scene.joints.empty();
  return plan;
}

std::string describePlan(const SimulationPlan& plan) {
  const auto onOff = [](bool on) { return on ? "on" : "off"; };
  std::string out;
  out += std::string("contact forces: ") + onOff(plan.contact_forces) + "\n";
  out += std::string("dynamics: ") + onOff(plan.dynamics) +
         (plan.dynamics ? " (dynamic bodies)\n" : " (no dynamic body)\n");
  out += std::string("gravity: ") + onOff(plan.gravity) + "\n";
  out += std::string("friction: ") + onOff(plan.friction) + "\n";
  out += std::string("restitution: ") + onOff(plan.restitution) + "\n";
  out += std::string("joints: ") + onOff(plan.joints) + "\n";
  out += "broad phase: " + std::to_string(plan.moving_primitives) + " moving primitives, " +
         std::to_string(plan.static_primitives) +
         " static primitives (static pairs never tested)\n";
  return out;
}

}  // namespace hapticd::scene
