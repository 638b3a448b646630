#include "client/polygon.h"

#include <algorithm>
#include <cmath>

namespace hapticd::client {
namespace {

using decomp::Triangle;
using decomp::Vec3;

// larger polygons are fanned (ear clipping is quadratic to cubic in the corners)
constexpr std::size_t kMaxEarClipped = 256;

struct P2 {
  double x = 0.0, y = 0.0;
};

double cross(const P2& o, const P2& a, const P2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

void fan(std::span<const std::uint32_t> poly, std::vector<Triangle>& out) {
  for (std::size_t k = 1; k + 1 < poly.size(); ++k)
    out.push_back({poly[0], poly[k], poly[k + 1]});
}

}  // namespace

void triangulatePolygon(std::span<const Vec3> positions,
                        std::span<const std::uint32_t> poly,
                        std::vector<Triangle>& out) {
  const std::size_t n = poly.size();
  if (n < 3)
    return;
  if (n == 3 || n > kMaxEarClipped || std::any_of(poly.begin(), poly.end(), [&](std::uint32_t i) {
        return i >= positions.size();
      })) {
    fan(poly, out);
    return;
  }
  // the polygon's plane: Newell's normal, which follows the winding
  Vec3 normal{0.0};
  Vec3 lo = positions[poly[0]], hi = lo;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& a = positions[poly[k]];
    const Vec3& b = positions[poly[(k + 1) % n]];
    normal += Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
    lo = glm::min(lo, a);
    hi = glm::max(hi, a);
  }
  const double length = glm::length(normal);
  if (!(length > 0.0) || !std::isfinite(length)) {
    fan(poly, out);
    return;
  }
  normal /= length;
  const Vec3 helper = std::abs(normal.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 u = glm::normalize(glm::cross(normal, helper));
  const Vec3 v = glm::cross(normal, u);
  const Vec3 centre = 0.5 * (lo + hi);
  std::vector<P2> p(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 d = positions[poly[k]] - centre;
    p[k] = {glm::dot(d, u), glm::dot(d, v)};
  }
  // counter-clockwise about the normal; a corner turning by less than this (relative to the
  // polygon's size) is straight, neither convex nor reflex
  const double size = glm::length(hi - lo);
  const double straight = 1e-12 * size * size;
  bool convex = true;
  for (std::size_t k = 0; k < n && convex; ++k)
    convex = cross(p[(k + n - 1) % n], p[k], p[(k + 1) % n]) >= -straight;
  if (convex) {
    fan(poly, out);  // as every reader does: the same triangles as before for convex faces
    return;
  }
  std::vector<std::size_t> left(n);
  for (std::size_t k = 0; k < n; ++k)
    left[k] = k;
  while (left.size() > 3) {
    bool clipped = false;
    const std::size_t m = left.size();
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t a = left[(j + m - 1) % m], b = left[j], c = left[(j + 1) % m];
      if (cross(p[a], p[b], p[c]) <= straight)
        continue;  // reflex or straight: no ear
      bool holds = false;
      for (std::size_t q : left) {
        if (q == a || q == b || q == c)
          continue;
        const P2& x = p[q];
        // a corner at the same place as one of the ear's (a polygon touching itself) is not in it
        if ((x.x == p[a].x && x.y == p[a].y) || (x.x == p[b].x && x.y == p[b].y) ||
            (x.x == p[c].x && x.y == p[c].y))
          continue;
        if (cross(p[a], p[b], x) >= -straight && cross(p[b], p[c], x) >= -straight &&
            cross(p[c], p[a], x) >= -straight) {
          holds = true;
          break;
        }
      }
      if (holds)
        continue;
      out.push_back({poly[a], poly[b], poly[c]});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(j));
      clipped = true;
      break;
    }
    if (!clipped)
      break;
  }
  std::vector<std::uint32_t> rest(left.size());
  for (std::size_t k = 0; k < left.size(); ++k)
    rest[k] = poly[left[k]];
  fan(rest, out);
}

}  // namespace hapticd::client
