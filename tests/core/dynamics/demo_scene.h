#pragma once
// The dynamic demo scene of §6.2 (Color Plate III), built in code, and the checks its tests share.
#include "tests/core/dynamics/scenes.h"

namespace hapticd::dynamics::testing {

inline constexpr double kFloorTop = 0.0;
inline constexpr double kHalf = 0.6;  // half the inner width of the walled floor

inline SceneModel demoScene(bool held_stick) {
  SceneModel s;
  s.name = "dynamic-demo";
  s.gravity_W = Vec3{0, -9.81, 0};
  s.materials.push_back(material(0.5, 0.4));
  s.bodies.push_back(staticBody("floor", boxShape(Vec3{kHalf + 0.2, 0.1, kHalf + 0.2}),
                                at(Vec3{0, kFloorTop - 0.1, 0}), 0));
  const double wall_h = 0.15;
  for (int k = 0; k < 4; ++k) {
    const bool x = k < 2;
    const double sign = k % 2 ? 1.0 : -1.0;
    const Vec3 c =
        x ? Vec3{sign * (kHalf + 0.05), wall_h, 0} : Vec3{0, wall_h, sign * (kHalf + 0.05)};
    const Vec3 h = x ? Vec3{0.05, wall_h, kHalf + 0.1} : Vec3{kHalf + 0.1, wall_h, 0.05};
    s.bodies.push_back(staticBody("wall", boxShape(h), at(c), 0));
  }
  const auto cube = boxShape(Vec3{0.04});
  const auto sphere = ellipsoidShape(Vec3{0.04});
  const auto ellipsoid = ellipsoidShape(Vec3{0.06, 0.035, 0.03});
  for (int i = 0; i < 12; ++i) {
    const auto& shape = i < 4 ? cube : i < 8 ? sphere : ellipsoid;
    const Vec3 c{-0.3 + 0.2 * (i % 4), 0.1 + 0.12 * (i / 4), -0.25 + 0.17 * (i % 3)};
    Body b = dynamicBody(i < 4   ? "cube"
                         : i < 8 ? "sphere"
                                 : "ellipsoid",
                         shape, at(c, glm::angleAxis(0.4 * i, glm::normalize(Vec3{1, 1 + i, 2}))),
                         700.0, 0);
    b.linear_velocity_W = Vec3{std::sin(1.3 * i), 0.5 * std::cos(0.7 * i), std::cos(2.1 * i)} * 0.8;
    b.angular_velocity_W = Vec3{std::cos(i), std::sin(2.0 * i), 1.0} * 4.0;
    s.bodies.push_back(b);
  }
  // held: it starts where the probe's path starts
  Body stick = dynamicBody("stick", boxShape(Vec3{0.15, 0.015, 0.015}),
                           at(held_stick ? Vec3{0.3, 0.06, 0} : Vec3{0, 0.45, 0}), 700.0, 0);
  stick.probe = held_stick;
  s.bodies.push_back(stick);
  return s;
}

inline constexpr std::uint32_t kFirstMoving = 5;

struct Watch {
  double worst_energy = -1e300;
  double deepest = 0.0;  // lowest vertex below the floor, relative to the body size
  double fastest = 0.0;
  bool finite = true;
};

inline void check(const Rig& rig, Watch& w) {
  const std::uint32_t n = rig.dyn->bodyCount();
  for (std::uint32_t b = kFirstMoving; b < n; ++b) {
    const Pose X = rig.dyn->pose(b);
    const Vec3 v = rig.dyn->linearVelocity(b), om = rig.dyn->angularVelocity(b);
    for (int k = 0; k < 3; ++k) {
      w.finite = w.finite && std::isfinite(X.translation[k]) && std::isfinite(v[k]) &&
                 std::isfinite(om[k]);
    }
    const auto& shape = *rig.scene->bodies[b].primitives[0].shape;
    const Vec3 down = glm::conjugate(X.rotation) * Vec3{0, -1, 0};
    const Vec3 low = X.translation + X.rotation * shape.vertices()[shape.support(down, 0)].p;
    w.deepest = std::max(w.deepest, (kFloorTop - low.y) / shape.radius());
    w.fastest = std::max(w.fastest, glm::length(v));
  }
  w.worst_energy = std::max(w.worst_energy, rig.energy());
}

}  // namespace hapticd::dynamics::testing
