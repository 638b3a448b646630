#include "core/scene/shapes.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hapticd::scene::detail {
namespace {

constexpr double kPi = std::numbers::pi;

// distance from the origin to the plane through three points (0 when degenerate)
double planeDistance(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = glm::cross(b - a, c - a);
  const double len = glm::length(n);
  if (len <= 0.0)
    return 0.0;
  return std::abs(glm::dot(n, a)) / len;
}

Vec3 gridPoint(std::uint32_t ring, std::uint32_t bands, std::uint32_t j, std::uint32_t segments) {
  const double theta = kPi * static_cast<double>(ring) / static_cast<double>(bands);
  const double phi = 2.0 * kPi * static_cast<double>(j) / static_cast<double>(segments);
  return {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
}

// the deviation of a hull scaled out by 2 / (2 - d) from the unit sphere or circle it was
// inscribed in with deviation d: vertices stick out by as much as the faces sink in
double straddled(double inscribed) {
  return inscribed / (2.0 - inscribed);
}

}  // namespace

Result<SphereGrid> sphereGridFor(double tolerance, std::uint32_t max_vertices) {
  if (!(tolerance > 0.0) || !(tolerance < 0.5)) {
    return Error{"tessellation_tolerance " + std::to_string(tolerance) + " must be in (0, 0.5)"};
  }
  for (std::uint32_t bands = 2;; ++bands) {
    const std::uint64_t vertices =
        2 + static_cast<std::uint64_t>(bands - 1) * 2ull * static_cast<std::uint64_t>(bands);
    if (vertices > max_vertices || bands > 4096) {
      return Error{"tessellation_tolerance " + std::to_string(tolerance) + " needs more than " +
                   std::to_string(std::min<std::uint64_t>(vertices - 1, max_vertices)) +
                   " hull vertices (max_hull_vertices) for a sphere"};
    }
    const std::uint32_t segments = 2 * bands;
    // the hull's faces are the grid's cells: polar triangles and planar trapezoids
    double min_distance = 1.0;
    for (std::uint32_t ring = 0; ring < bands; ++ring) {
      const Vec3 a = gridPoint(ring, bands, 0, segments);
      const Vec3 b = gridPoint(ring + 1, bands, 0, segments);
      const Vec3 c =
          ring == 0 ? gridPoint(ring + 1, bands, 1, segments) : gridPoint(ring, bands, 1, segments);
      min_distance = std::min(min_distance, planeDistance(a, b, c));
    }
    const double inscribed = 1.0 - min_distance;
    if (straddled(inscribed) <= tolerance)
      return SphereGrid{bands, inscribed};
  }
}

Result<std::uint32_t> circleSegmentsFor(double tolerance, std::uint32_t max_vertices) {
  if (!(tolerance > 0.0) || !(tolerance < 0.5)) {
    return Error{"tessellation_tolerance " + std::to_string(tolerance) + " must be in (0, 0.5)"};
  }
  for (std::uint32_t n = 3;; ++n) {
    if (2ull * n > max_vertices || n > 1000000) {
      return Error{"tessellation_tolerance " + std::to_string(tolerance) + " needs more than " +
                   std::to_string(max_vertices) +
                   " hull vertices (max_hull_vertices) for a cylinder"};
    }
    const double inscribed = 1.0 - std::cos(kPi / static_cast<double>(n));
    if (straddled(inscribed) <= tolerance)
      return n;
  }
}

std::vector<Vec3> boxPoints(const Vec3& size) {
  const Vec3 h = 0.5 * size;
  std::vector<Vec3> out;
  out.reserve(8);
  for (int i = 0; i < 8; ++i) {
    out.push_back({(i & 1) ? h.x : -h.x, (i & 2) ? h.y : -h.y, (i & 4) ? h.z : -h.z});
  }
  return out;
}

std::vector<Vec3> spherePoints(double radius, const SphereGrid& grid) {
  const double scale = radius * 2.0 / (2.0 - grid.inscribed_deviation);
  const std::uint32_t segments = 2 * grid.bands;
  std::vector<Vec3> out;
  out.reserve(2 + static_cast<std::size_t>(grid.bands - 1) * segments);
  out.push_back({0.0, scale, 0.0});
  out.push_back({0.0, -scale, 0.0});
  for (std::uint32_t ring = 1; ring < grid.bands; ++ring) {
    for (std::uint32_t j = 0; j < segments; ++j) {
      out.push_back(scale * gridPoint(ring, grid.bands, j, segments));
    }
  }
  return out;
}

std::vector<Vec3> capsulePoints(double height,
                                double radius_top,
                                double radius_bottom,
                                const SphereGrid& grid) {
  std::vector<Vec3> out;
  const auto add = [&](double radius, double y) {
    if (radius <= 0.0) {
      out.push_back({0.0, y, 0.0});
      return;
    }
    for (const Vec3& p : spherePoints(radius, grid))
      out.push_back(p + Vec3{0.0, y, 0.0});
  };
  add(radius_top, 0.5 * height);
  add(radius_bottom, -0.5 * height);
  return out;
}

std::vector<Vec3> cylinderPoints(double height,
                                 double radius_top,
                                 double radius_bottom,
                                 std::uint32_t segments) {
  const double inscribed = 1.0 - std::cos(kPi / static_cast<double>(segments));
  const double scale = 2.0 / (2.0 - inscribed);
  std::vector<Vec3> out;
  out.reserve(2ull * segments);
  const auto ring = [&](double radius, double y) {
    if (radius <= 0.0) {
      out.push_back({0.0, y, 0.0});
      return;
    }
    for (std::uint32_t j = 0; j < segments; ++j) {
      const double phi = 2.0 * kPi * static_cast<double>(j) / static_cast<double>(segments);
      out.push_back({radius * scale * std::cos(phi), y, radius * scale * std::sin(phi)});
    }
  };
  ring(radius_top, 0.5 * height);
  ring(radius_bottom, -0.5 * height);
  return out;
}

double convexityViolation(const Polytope& hull,
                          std::span<const Vec3> points,
                          std::span<const std::uint32_t> triangles) {
  const double size = std::max(hull.radius(), 1e-300);
  double worst = 0.0;
  std::uint32_t hint = 0;
  const auto vertices = hull.vertices();
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const Vec3& a = points[triangles[t]];
    const Vec3& b = points[triangles[t + 1]];
    const Vec3& c = points[triangles[t + 2]];
    const Vec3 n = glm::cross(b - a, c - a);
    const double len = glm::length(n);
    // a degenerate (zero-area) triangle has no plane to test
    if (!(len > 1e-12 * size * size))
      continue;
    const Vec3 u = n / len;
    hint = hull.support(u, hint);
    const double front = glm::dot(u, vertices[hint].p - a);
    const std::uint32_t back_vertex = hull.support(-u, hint);
    const double back = glm::dot(-u, vertices[back_vertex].p - a);
    worst = std::max(worst, std::min(front, back));
  }
  return worst;
}

void splitRigid(const Mat3& A, Mat3* R, Mat3* S) {
  const double scale = std::max({glm::length(A[0]), glm::length(A[1]), glm::length(A[2])});
  const double tiny = scale * 1e-12;
  Vec3 x = A[0];
  if (!(glm::length(x) > tiny))
    x = Vec3{1.0, 0.0, 0.0};
  x = glm::normalize(x);
  Vec3 y = A[1] - glm::dot(A[1], x) * x;
  if (!(glm::length(y) > tiny)) {
    y = std::abs(x.x) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
    y = y - glm::dot(y, x) * x;
  }
  y = glm::normalize(y);
  const Vec3 z = glm::cross(x, y);
  *R = Mat3(x, y, z);
  *S = glm::transpose(*R) * A;
}

double boundingDiagonal(std::span<const Vec3> points) {
  if (points.empty())
    return 0.0;
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return glm::length(hi - lo);
}

std::optional<Vec3> flatNormal(std::span<const Vec3> points,
                               std::span<const std::uint32_t> triangles,
                               double relative_tolerance) {
  const double size = boundingDiagonal(points);
  if (!(size > 0.0))
    return std::nullopt;
  // the triangles' area-weighted normal; when they cancel out, a plane through three far points
  Vec3 n{0.0};
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const Vec3& a = points[triangles[t]];
    n += glm::cross(points[triangles[t + 1]] - a, points[triangles[t + 2]] - a);
  }
  const Vec3& p0 = points[0];
  if (!(glm::length(n) > 1e-9 * size * size)) {
    std::size_t i1 = 0, i2 = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (glm::length(points[i] - p0) > glm::length(points[i1] - p0))
        i1 = i;
    }
    const Vec3 u = points[i1] - p0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (glm::length(glm::cross(u, points[i] - p0)) > glm::length(glm::cross(u, points[i2] - p0)))
        i2 = i;
    }
    n = glm::cross(u, points[i2] - p0);
    if (!(glm::length(n) > 1e-12 * size * size))
      return std::nullopt;  // collinear
  }
  n = glm::normalize(n);
  for (const Vec3& p : points) {
    if (std::abs(glm::dot(p - p0, n)) > relative_tolerance * size)
      return std::nullopt;
  }
  return n;
}

double thickenFlat(const Vec3& normal,
                   double thickness,
                   std::vector<Vec3>* points,
                   std::vector<std::uint32_t>* triangles) {
  const std::size_t n = points->size(), t = triangles->size();
  double area = 0.0;
  for (std::size_t i = 0; i + 2 < t; i += 3) {
    const Vec3& a = (*points)[(*triangles)[i]];
    area += 0.5 * glm::length(glm::cross((*points)[(*triangles)[i + 1]] - a,
                                         (*points)[(*triangles)[i + 2]] - a));
  }
  for (std::size_t i = 0; i < n; ++i)
    points->push_back((*points)[i] - thickness * normal);
  const auto back = static_cast<std::uint32_t>(n);
  for (std::size_t i = 0; i + 2 < t; i += 3) {
    triangles->insert(triangles->end(), {back + (*triangles)[i], back + (*triangles)[i + 2],
                                         back + (*triangles)[i + 1]});
  }
  return area;
}

}  // namespace hapticd::scene::detail
