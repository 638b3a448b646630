#pragma once
// Points spread evenly on a sphere (a golden-angle spiral), for hulls that stand in for a sphere:
// the probe sphere of a scene without one, the study's probes.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/geometry/pose.h"

namespace hapticd::geom {

/// n points on the sphere of `radius` about the origin, from the +Y pole to the -Y pole along a
/// golden-angle spiral (equal areas per point); their hull is within about 2 / n of the radius.
inline std::vector<Vec3> spiralSpherePoints(double radius, int n) {
  std::vector<Vec3> pts;
  pts.reserve(static_cast<std::size_t>(std::max(n, 0)));
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
    const double a = golden * i;
    pts.push_back(radius * Vec3{r * std::cos(a), y, r * std::sin(a)});
  }
  return pts;
}

}  // namespace hapticd::geom
