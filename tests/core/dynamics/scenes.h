#pragma once
// Scenes built in code for the dynamics tests: boxes, icospheres, ellipsoids, gears; a world
// with one collision body per scene body, in order.
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "core/dynamics/dynamics.h"

namespace hapticd::dynamics::testing {

using scene::Body;
using scene::Material;
using scene::Motion;
using scene::Primitive;
using scene::SceneModel;

inline std::shared_ptr<const geom::Polytope> hull(const std::vector<Vec3>& pts) {
  return std::make_shared<const geom::Polytope>(geom::Polytope::fromPoints(pts).value());
}

inline std::shared_ptr<const geom::Polytope> boxShape(const Vec3& half) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) {
    p.push_back(Vec3{i & 1 ? half.x : -half.x, i & 2 ? half.y : -half.y, i & 4 ? half.z : -half.z});
  }
  return hull(p);
}

// icosahedron subdivided `levels` times (2: 162 vertices, 320 faces), scaled to semi-axes
inline std::shared_ptr<const geom::Polytope> ellipsoidShape(const Vec3& axes, int levels = 2) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vec3& p : v)
    p = glm::normalize(p);
  for (int l = 0; l < levels; ++l) {
    std::vector<std::array<int, 3>> g;
    auto mid = [&](int a, int b) {
      v.push_back(glm::normalize(v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]));
      return static_cast<int>(v.size() - 1);
    };
    for (const auto& tri : f) {
      const int a = mid(tri[0], tri[1]), b = mid(tri[1], tri[2]), c = mid(tri[2], tri[0]);
      g.push_back({tri[0], a, c});
      g.push_back({tri[1], b, a});
      g.push_back({tri[2], c, b});
      g.push_back({a, b, c});
    }
    f = g;
  }
  for (Vec3& p : v)
    p *= axes;
  return hull(v);  // duplicates of shared midpoints are merged by the hull
}

// a prism over a convex polygon (x, y) of thickness 2 * half_z
inline std::shared_ptr<const geom::Polytope> prismShape(const std::vector<glm::dvec2>& poly,
                                                        double half_z) {
  std::vector<Vec3> p;
  for (const auto& q : poly) {
    p.push_back(Vec3{q.x, q.y, -half_z});
    p.push_back(Vec3{q.x, q.y, half_z});
  }
  return hull(p);
}

inline Pose at(const Vec3& t, const Quat& q = Quat{1, 0, 0, 0}) {
  return Pose{t, q};
}

/// A joint of `kind` between bodies a and b (-1: the world), its frame at anchor_A in a and at
/// anchor_B in b (unturned), `axis` its free axis (kHinge, kSlider).
inline scene::Joint joint(scene::JointKind kind,
                          std::int32_t a,
                          std::int32_t b,
                          const Vec3& anchor_A,
                          const Vec3& anchor_B,
                          std::uint8_t axis = 0) {
  scene::Joint j;
  j.kind = kind;
  j.body_a = a;
  j.body_b = b;
  j.X_AJ = at(anchor_A);
  j.X_BJ = at(anchor_B);
  j.hinge_axis = axis;
  return j;
}

inline Body staticBody(const std::string& name,
                       std::shared_ptr<const geom::Polytope> s,
                       const Pose& X,
                       std::int32_t material = -1) {
  Body b;
  b.name = name;
  b.motion = Motion::kStatic;
  b.X_WB = X;
  b.primitives.push_back(Primitive{s, Pose{}, scene::ShapeSource::kCode, -1, material});
  return b;
}

// a dynamic body of the given primitives, mass and inertia from their shapes at `density`
inline Body compoundBody(const std::string& name,
                         std::vector<Primitive> primitives,
                         const Pose& X,
                         double density) {
  Body b;
  b.name = name;
  b.motion = Motion::kDynamic;
  b.X_WB = X;
  b.primitives = std::move(primitives);
  const MassProperties mp = computeMassProperties(b.primitives, density);
  b.mass = mp.mass;
  b.com_B = mp.com_B;
  b.inertia_B = mp.inertia_B;
  b.mass_declared = b.inertia_declared = true;
  return b;
}

// a dynamic body of one primitive, mass and inertia from the shape at `density`
inline Body dynamicBody(const std::string& name,
                        std::shared_ptr<const geom::Polytope> s,
                        const Pose& X,
                        double density,
                        std::int32_t material = -1) {
  return compoundBody(
      name, {Primitive{std::move(s), Pose{}, scene::ShapeSource::kCode, -1, material}}, X, density);
}

inline double lengthScale(const SceneModel& s) {
  Vec3 lo{1e300}, hi{-1e300};
  for (const Body& b : s.bodies) {
    for (const Primitive& p : b.primitives) {
      for (const auto& v : p.shape->vertices()) {
        const Vec3 w =
            b.X_WB.translation + b.X_WB.rotation * (p.X_BP.translation + p.X_BP.rotation * v.p);
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
      }
    }
  }
  return glm::length(hi - lo);
}

// the world and the stage, built as the Simulation builds them
struct Rig {
  std::shared_ptr<SceneModel> scene;
  std::unique_ptr<collision::CollisionWorld> world;
  std::unique_ptr<Dynamics> dyn;

  explicit Rig(SceneModel s, const DynamicsOptions& o = {}) {
    s.length_scale = lengthScale(s);
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      if (s.bodies[i].probe)
        s.probe_body = static_cast<std::int32_t>(i);
    }
    scene = std::make_shared<SceneModel>(std::move(s));
    world = buildCollisionWorld(*scene, collision::WorldOptions{}).value();
    auto r = Dynamics::create(*scene, *world, o);
    if (!r.ok())
      throw std::runtime_error(r.error().message);
    dyn = std::move(r).value();
  }
  StepReport tick(double dt = 0.001, const HeldInput* held = nullptr) {
    world->step();
    return dyn->step(*world, dt, held);
  }
  /// n ticks of dt.
  void run(int n, double dt = 0.001) {
    for (int k = 0; k < n; ++k)
      tick(dt);
  }
  double energy() const { return dyn->kineticEnergy() + dyn->potentialEnergy(); }
};

inline Material material(double mu, double e, scene::Combine c = scene::Combine::kAverage) {
  Material m;
  m.static_friction = m.dynamic_friction = mu;
  m.restitution = e;
  m.friction_combine = m.restitution_combine = c;
  m.friction_combine_declared = m.restitution_combine_declared = true;  // as a file declares it
  return m;
}

}  // namespace hapticd::dynamics::testing
