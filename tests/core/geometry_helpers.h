#pragma once
// Small geometry the tests build their own checks and shapes from (the narrow phase's
// pair_checks.cpp, the decomposition's decomp/checks.cpp, the response and sim tests): written
// here, not taken from core/, so that the checks stay independent of the code they check.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/geometry/pose.h"

namespace hapticd::testing {

/// Distance from x to the segment [p, q] (a point when p == q).
inline double segmentDistance(const geom::Vec3& x, const geom::Vec3& p, const geom::Vec3& q) {
  const geom::Vec3 d = q - p;
  const double dd = glm::dot(d, d);
  const double s = dd > 0.0 ? std::clamp(glm::dot(x - p, d) / dd, 0.0, 1.0) : 0.0;
  return glm::length(x - (p + d * s));
}

/// The corners of a prism over a regular k-gon of circumradius r, z in [-h, h]: for each corner
/// of the k-gon (the first on +x, counter-clockwise) its bottom then its top.
inline std::vector<geom::Vec3> prism(int k, double r, double h) {
  std::vector<geom::Vec3> p;
  for (int i = 0; i < k; ++i) {
    const double t = i * 2.0 * std::numbers::pi / k;
    p.push_back({r * std::cos(t), r * std::sin(t), -h});
    p.push_back({r * std::cos(t), r * std::sin(t), h});
  }
  return p;
}

}  // namespace hapticd::testing
