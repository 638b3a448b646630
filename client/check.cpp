#include "client/check.h"

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <nlohmann/json.hpp>

#include "core/dynamics/scene_world.h"
#include "protocol/wire.h"  // nameOf

namespace hapticd::client {
namespace {

using scene::Motion;
using scene::ShapeSource;

// the pairs kept apart by collision filters, or overlapping, that the text report names one by
// one
constexpr std::size_t kListedPairs = 50;

// in enum order
constexpr const char* kMotionNames[] = {"static", "kinematic", "dynamic"};
constexpr const char* kSourceNames[] = {"box",         "sphere", "capsule",
                                        "cylinder",    "plane",  "mesh hull",
                                        "convex mesh", "code",   "mesh piece (non-convex mesh)"};
static_assert(std::size(kSourceNames) == static_cast<std::size_t>(ShapeSource::kMeshPiece) + 1);
constexpr const char* kJointNames[] = {"fixed", "hinge", "slider", "ball", "generic"};

const char* motionName(Motion m) {
  return proto::nameOf(m, kMotionNames, "?");
}

const char* sourceName(ShapeSource s) {
  return proto::nameOf(s, kSourceNames, "?");
}

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

std::vector<Overlap> startingOverlaps(const scene::SceneModel& s) {
  std::vector<Overlap> out;
  auto world = dynamics::buildCollisionWorld(s, collision::WorldOptions{});
  if (!world.ok())
    return out;
  world.value()->step();
  const auto size = [&](std::size_t body) {
    double r = 0.0;
    for (const scene::Primitive& p : s.bodies[body].primitives)
      r = std::max(r, p.shape->radius());
    return r;
  };
  for (const collision::Contact& c : world.value()->contacts()) {
    if (!c.answered || c.body_a >= s.bodies.size() || c.body_b >= s.bodies.size())
      continue;
    const double depth = -c.distance;
    if (!(depth > kOverlapFraction * std::min(size(c.body_a), size(c.body_b))))
      continue;
    const auto same = [&](const Overlap& o) { return o.a == c.body_a && o.b == c.body_b; };
    const auto it = std::find_if(out.begin(), out.end(), same);
    if (it == out.end())
      out.push_back({c.body_a, c.body_b, depth});
    else
      it->depth_m = std::max(it->depth_m, depth);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Overlap& x, const Overlap& y) { return x.depth_m > y.depth_m; });
  return out;
}

namespace {

std::string overlapsText(const scene::SceneModel& s) {
  const std::vector<Overlap> overlaps = startingOverlaps(s);
  std::string out;
  for (std::size_t k = 0; k < overlaps.size() && k < kListedPairs; ++k) {
    const scene::Body &a = s.bodies[overlaps[k].a], &b = s.bodies[overlaps[k].b];
    out += "  '" + a.name + "' (" + motionName(a.motion) + ") overlaps '" + b.name + "' (" +
           motionName(b.motion) + ") by " + num(overlaps[k].depth_m) + " m\n";
  }
  if (overlaps.size() > kListedPairs)
    out += "  ... and " + std::to_string(overlaps.size() - kListedPairs) + " more pairs\n";
  return out.empty() ? out
                     : "bodies that start overlapping (their first ticks push a dynamic one "
                       "out; a static or kinematic pair stays so):\n" +
                           out;
}

nlohmann::json planJson(const scene::SimulationPlan& p) {
  return {{"contact_forces", p.contact_forces},
          {"dynamics", p.dynamics},
          {"gravity", p.gravity},
          {"friction", p.friction},
          {"friction_min", p.friction_min},
          {"friction_max", p.friction_max},
          {"friction_default", p.friction_default},
          {"restitution", p.restitution},
          {"joints", p.joints},
          {"static_primitives", p.static_primitives},
          {"moving_primitives", p.moving_primitives},
          {"probe_sphere", p.probe_sphere},
          {"notes", p.notes}};
}

nlohmann::json sceneJson(const scene::SceneModel& s) {
  nlohmann::json bodies = nlohmann::json::array();
  nlohmann::json prims = nlohmann::json::array();
  for (std::size_t b = 0; b < s.bodies.size(); ++b) {
    const scene::Body& body = s.bodies[b];
    nlohmann::json jb = {{"name", body.name},
                         {"node", body.node},
                         {"motion", motionName(body.motion)},
                         {"mass_kg", body.mass},
                         {"mass_declared", body.mass_declared},
                         {"probe", body.probe},
                         {"active", body.active},
                         {"primitives", body.primitives.size()}};
    if (body.stiffness_n_per_m)
      jb["stiffness_n_per_m"] = *body.stiffness_n_per_m;
    bodies.push_back(jb);
    for (std::size_t k = 0; k < body.primitives.size(); ++k) {
      const scene::Primitive& p = body.primitives[k];
      prims.push_back({{"body", b},
                       {"index", k},
                       {"source", sourceName(p.source)},
                       {"node", p.node},
                       {"vertices", p.shape->vertices().size()},
                       {"faces", p.shape->faces().size()},
                       {"material", p.material},
                       {"group", p.group},
                       {"mask", p.mask},
                       {"trigger", p.trigger}});
    }
  }
  nlohmann::json out = {{"ok", true},
                        {"name", s.name},
                        {"bodies", bodies},
                        {"primitives", prims},
                        {"joints", s.joints.size()},
                        {"unsimulated_joints", s.unsimulated_joints.size()},
                        {"materials", s.materials.size()},
                        {"probe_body", s.probe_body},
                        {"length_scale_m", s.length_scale},
                        {"plan", planJson(s.plan)}};
  nlohmann::json overlaps = nlohmann::json::array();
  for (const Overlap& o : startingOverlaps(s))
    overlaps.push_back({{"body_a", o.a}, {"body_b", o.b}, {"depth_m", o.depth_m}});
  out["overlaps"] = overlaps;
  if (s.gravity_W)
    out["gravity"] = {s.gravity_W->x, s.gravity_W->y, s.gravity_W->z};
  return out;
}

/// The pairs of bodies (not both static) whose collision filters keep every primitive apart: the
/// first kListedPairs by name, then how many more there are.
std::string keptApart(const scene::SceneModel& s) {
  const auto apart = [&](const scene::Body& a, const scene::Body& b) {
    bool solid = false;
    for (const scene::Primitive& p : a.primitives) {
      for (const scene::Primitive& q : b.primitives) {
        if (p.trigger || q.trigger)
          continue;
        solid = true;
        if ((p.group & q.mask) && (q.group & p.mask))
          return false;
      }
    }
    return solid;
  };
  std::string out;
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    for (std::size_t j = i + 1; j < s.bodies.size(); ++j) {
      const scene::Body &a = s.bodies[i], &b = s.bodies[j];
      if ((a.motion != Motion::kStatic || b.motion != Motion::kStatic) && apart(a, b)) {
        if (pairs < kListedPairs)
          out += "  '" + a.name + "' and '" + b.name + "'\n";
        ++pairs;
      }
    }
  }
  if (pairs > kListedPairs)
    out += "  ... and " + std::to_string(pairs - kListedPairs) + " more pairs\n";
  return out.empty() ? out : "collision filters keep apart:\n" + out;
}

}  // namespace

std::string describeScene(const scene::SceneModel& s) {
  std::string out;
  out += "scene " + s.name + ": " + std::to_string(s.bodies.size()) + " bodies, length scale " +
         num(s.length_scale) + " m";
  if (s.gravity_W) {
    out += ", gravity (" + num(s.gravity_W->x) + ", " + num(s.gravity_W->y) + ", " +
           num(s.gravity_W->z) + ") m/s^2";
  }
  out += "\nbodies:\n";
  std::size_t primitives = 0;
  for (std::size_t b = 0; b < s.bodies.size(); ++b) {
    const scene::Body& body = s.bodies[b];
    out += "  " + std::to_string(b) + " '" + body.name + "' " + motionName(body.motion);
    if (body.motion == Motion::kDynamic) {
      out += ", mass " +
             (body.inverse_mass == 0.0 ? std::string("infinite") : num(body.mass) + " kg") +
             (body.mass_declared ? " (declared)" : " (computed at 1000 kg/m^3)");
    }
    if (body.probe)
      out += ", probe";
    if (!body.active)
      out += ", inactive (extras.haptic.active false: out of the scene until a client adds it)";
    if (body.stiffness_n_per_m)
      out += ", stiffness " + num(*body.stiffness_n_per_m) + " N/m";
    out += ", " + std::to_string(body.primitives.size()) + " primitives\n";
    primitives += body.primitives.size();
  }
  out += "primitives (" + std::to_string(primitives) + "):\n";
  for (std::size_t b = 0; b < s.bodies.size(); ++b) {
    const scene::Body& body = s.bodies[b];
    for (std::size_t k = 0; k < body.primitives.size(); ++k) {
      const scene::Primitive& p = body.primitives[k];
      out += "  body " + std::to_string(b) + " primitive " + std::to_string(k) + ": " +
             sourceName(p.source) + " (node " + std::to_string(p.node) + "), " +
             std::to_string(p.shape->vertices().size()) + " vertices, " +
             std::to_string(p.shape->faces().size()) + " faces" +
             (p.trigger ? ", trigger (not colliding)" : "") + "\n";
    }
  }
  out += keptApart(s);
  out += overlapsText(s);
  if (!s.joints.empty() || !s.unsimulated_joints.empty()) {
    out += "joints:\n";
    for (const auto* list : {&s.joints, &s.unsimulated_joints}) {
      for (const scene::Joint& j : *list) {
        out += "  " + std::string(kJointNames[static_cast<std::size_t>(j.kind)]) +
               " between body " + std::to_string(j.body_a) + " and " +
               (j.body_b < 0 ? std::string("the scene") : "body " + std::to_string(j.body_b)) +
               (j.drives.empty() ? "" : ", " + std::to_string(j.drives.size()) + " drives") +
               (list == &s.unsimulated_joints ? ", not yet simulated" : "") + "\n";
      }
    }
  }
  out += "plan:\n";
  const std::string plan = scene::describePlan(s.plan);
  std::size_t start = 0;
  while (start < plan.size()) {
    const std::size_t end = plan.find('\n', start);
    out += "  " + plan.substr(start, end - start) + "\n";
    if (end == std::string::npos)
      break;
    start = end + 1;
  }
  return out;
}

int runCheck(const std::filesystem::path& path,
             const CheckOptions& options,
             std::ostream& out,
             std::ostream& err) {
  const scene::LoadReport report = scene::loadSceneFile(path, options.load);
  for (const std::string& w : report.warnings)
    err << path.string() << ": warning: " << w << '\n';
  if (!report.ok()) {
    for (const scene::Problem& p : report.problems) {
      err << path.string() << ": " << p.where << ": " << p.what << '\n';
    }
    if (options.json) {
      nlohmann::json problems = nlohmann::json::array();
      for (const scene::Problem& p : report.problems) {
        problems.push_back({{"where", p.where}, {"what", p.what}});
      }
      out << nlohmann::json{{"ok", false}, {"file", path.string()}, {"problems", problems}}.dump(
                 -1, ' ', false, nlohmann::json::error_handler_t::replace)
          << '\n';
    }
    return 1;
  }
  if (options.json) {
    nlohmann::json j = sceneJson(*report.scene);
    j["file"] = path.string();
    j["warnings"] = report.warnings;
    const scene::DecompositionCounts& d = report.decomposition;
    j["decomposition"] = {{"decomposed", d.decomposed},
                          {"cache_hits", d.cache_hits},
                          {"cache_refused", d.cache_refused},
                          {"cache_written", d.cache_written},
                          {"cache_evicted", d.cache_evicted}};
    out << j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
  } else {
    out << path.string() << ": ok\n" << describeScene(*report.scene);
  }
  return 0;
}

}  // namespace hapticd::client
