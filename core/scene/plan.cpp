// The simulation plan of a scene: "simulate only the effects a scene calls for"
// (docs/architecture.md), and the notes on what the scene declares that is not simulated.
#include <algorithm>
#include <cstdio>
#include <set>

#include "core/scene/scene.h"

namespace hapticd::scene {
namespace {

/// Kinematic velocities in a scene whose dynamics do not run (no dynamic body), trigger volumes,
/// and a scene with nothing to touch. Every joint, limit and drive is simulated (core/dynamics).
std::vector<std::string> sceneNotes(const SceneModel& scene) {
  std::vector<std::string> notes;
  bool dynamic = false;
  for (const Body& b : scene.bodies)
    dynamic = dynamic || b.motion == Motion::kDynamic;
  std::size_t triggers = 0, solid = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const Body& b = scene.bodies[i];
    const bool probe = b.probe || static_cast<std::int32_t>(i) == scene.probe_body;
    if (!dynamic && b.motion == Motion::kKinematic &&
        (b.linear_velocity_W != Vec3{0.0} || b.angular_velocity_W != Vec3{0.0})) {
      notes.push_back("body '" + b.name +
                      "': kinematic velocity not simulated: the scene has no dynamic body, so no "
                      "dynamics run (it stays where clients put it)");
    }
    for (const Primitive& p : b.primitives) {
      if (p.trigger)
        ++triggers;
      else if (!probe)
        ++solid;
    }
  }
  if (triggers > 0) {
    std::string names;
    for (const Body& b : scene.bodies) {
      for (const Primitive& p : b.primitives) {
        if (p.trigger)
          names += std::string(names.empty() ? "" : ", ") + "'" + b.name + "'";
      }
    }
    notes.push_back(std::to_string(triggers) + " trigger volumes, not colliding (bodies " + names +
                    ")");
  }
  if (solid == 0)
    notes.push_back("warning: nothing to touch: the scene has no collider but the probe's");
  return notes;
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
  bool first = true;
  for (std::int32_t a : touching) {
    const Material& ma = materialOf(scene, a);
    for (std::int32_t b : all) {
      const Material& mb = materialOf(scene, b);
      const double fs = combineMaterials(ma, mb, MaterialValue::kStaticFriction);
      const double fd = combineMaterials(ma, mb, MaterialValue::kDynamicFriction);
      plan.friction_min = first ? std::min(fs, fd) : std::min({plan.friction_min, fs, fd});
      plan.friction_max = first ? std::max(fs, fd) : std::max({plan.friction_max, fs, fd});
      first = false;
      if (std::max(fs, fd) > 0.0)
        plan.friction = true;
      if (&ma == &defaultMaterial() || &mb == &defaultMaterial())
        plan.friction_default = true;
      if (dynamic.count(a) && combineMaterials(ma, mb, MaterialValue::kRestitution) > 0.0)
        plan.restitution = true;
    }
  }
  plan.joints = !scene.joints.empty() || !scene.unsimulated_joints.empty();
  plan.probe_sphere = scene.probe_body < 0;
  plan.notes = sceneNotes(scene);
  return plan;
}

std::string describePlan(const SimulationPlan& plan) {
  const auto onOff = [](bool on) { return on ? "on" : "off"; };
  std::string out;
  out += std::string("contact forces: ") + onOff(plan.contact_forces) + "\n";
  out += std::string("dynamics: ") + onOff(plan.dynamics) +
         (plan.dynamics ? " (dynamic bodies)\n" : " (no dynamic body)\n");
  out += std::string("gravity: ") + onOff(plan.gravity) + "\n";
  out += std::string("friction: ") + onOff(plan.friction);
  if (plan.friction) {
    char range[64];
    if (plan.friction_min == plan.friction_max)
      std::snprintf(range, sizeof range, " (%.3g", plan.friction_max);
    else
      std::snprintf(range, sizeof range, " (%.3g to %.3g", plan.friction_min, plan.friction_max);
    out += range;
    if (plan.friction_default) {
      char def[96];
      std::snprintf(def, sizeof def, "; %.3g for colliders without a physics material",
                    kDefaultFriction);
      out += def;
    }
    out += ")";
  }
  out += "\n";
  out += std::string("restitution: ") + onOff(plan.restitution) + "\n";
  out += std::string("joints: ") + onOff(plan.joints) + "\n";
  const std::uint32_t moving = plan.moving_primitives + (plan.probe_sphere ? 1u : 0u);
  out += "broad phase: " + std::to_string(moving) + " moving primitives" +
         (plan.probe_sphere ? " (one the probe sphere of the config)" : "") + ", " +
         std::to_string(plan.static_primitives) +
         " static primitives (static pairs never tested)\n";
  if (!plan.notes.empty()) {
    out += "notes:\n";
    for (const std::string& n : plan.notes)
      out += "  " + n + "\n";
  }
  return out;
}

}  // namespace hapticd::scene
