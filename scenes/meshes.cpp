#include "scenes/meshes.h"

#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace hapticd::scenes {
namespace {

using Tri = std::array<std::uint32_t, 3>;

double involute(double alpha) {
  return std::tan(alpha) - alpha;
}

}  // namespace

MeshData boxMesh(const Vec3& size) {
  const Vec3 h = 0.5 * size;
  MeshData m;
  // vertex i: bit 0 -> +x, bit 1 -> +y, bit 2 -> +z
  for (std::uint32_t i = 0; i < 8; ++i)
    m.positions.push_back({(i & 1u) ? h.x : -h.x, (i & 2u) ? h.y : -h.y, (i & 4u) ? h.z : -h.z});
  m.triangles = {
      Tri{0, 4, 6}, Tri{0, 6, 2},  // -x
      Tri{1, 3, 7}, Tri{1, 7, 5},  // +x
      Tri{0, 1, 5}, Tri{0, 5, 4},  // -y
      Tri{2, 6, 7}, Tri{2, 7, 3},  // +y
      Tri{0, 2, 3}, Tri{0, 3, 1},  // -z
      Tri{4, 5, 7}, Tri{4, 7, 6},  // +z
  };
  return m;
}

MeshData icosphereMesh(const Vec3& radii, int levels) {
  const double phi = 0.5 * (1.0 + std::sqrt(5.0));
  std::vector<Vec3> v = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                         {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                         {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  for (Vec3& p : v)
    p = glm::normalize(p);
  std::vector<Tri> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                        {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                        {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                        {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoints.find(key);
      if (it != midpoints.end())
        return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      const auto index = static_cast<std::uint32_t>(v.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<Tri> next;
    next.reserve(t.size() * 4);
    for (const Tri& f : t) {
      const std::uint32_t ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  MeshData m;
  m.positions.reserve(v.size());
  for (const Vec3& p : v)
    m.positions.push_back(p * radii);
  m.triangles = std::move(t);
  return m;
}

MeshData prismMesh(const std::vector<Vec2>& polygon_ccw, double width) {
  const auto n = static_cast<std::uint32_t>(polygon_ccw.size());
  if (n < 3)
    throw std::invalid_argument("scene generator: prism of fewer than 3 points");
  MeshData m;
  for (const Vec2& p : polygon_ccw)
    m.positions.push_back({p.x, p.y, -0.5 * width});
  for (const Vec2& p : polygon_ccw)
    m.positions.push_back({p.x, p.y, 0.5 * width});
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
  }
  for (std::uint32_t i = 1; i + 1 < n; ++i) {
    m.triangles.push_back({0, i + 1, i});          // -z cap, seen from -z
    m.triangles.push_back({n, n + i, n + i + 1});  // +z cap
  }
  return m;
}

namespace {

/// A closed mesh built face by face from convex planar quads: vertices shared by exact position,
/// each quad wound counter-clockwise seen along its outward normal.
class QuadMesh {
 public:
  void quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& outward) {
    std::array<std::uint32_t, 4> v = {index(a), index(b), index(c), index(d)};
    if (glm::dot(glm::cross(b - a, c - a), outward) < 0.0)
      std::swap(v[1], v[3]);
    mesh_.triangles.push_back({v[0], v[1], v[2]});
    mesh_.triangles.push_back({v[0], v[2], v[3]});
  }
  /// An axis-aligned rectangle on the plane `axis` = `at` from `lo` to `hi` in the other two
  /// axes (in cyclic order), facing `sign` along `axis`.
  void rect(int axis, double at, Vec2 lo, Vec2 hi, double sign) {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    auto point = [&](double pu, double pw) {
      Vec3 p{0.0};
      p[axis] = at;
      p[u] = pu;
      p[w] = pw;
      return p;
    };
    Vec3 n{0.0};
    n[axis] = sign;
    quad(point(lo.x, lo.y), point(hi.x, lo.y), point(hi.x, hi.y), point(lo.x, hi.y), n);
  }
  MeshData take() { return std::move(mesh_); }

 private:
  std::uint32_t index(const Vec3& p) {
    const auto key = std::make_tuple(p.x, p.y, p.z);
    const auto [it, added] =
        index_.emplace(key, static_cast<std::uint32_t>(mesh_.positions.size()));
    if (added)
      mesh_.positions.push_back(p);
    return it->second;
  }
  MeshData mesh_;
  std::map<std::tuple<double, double, double>, std::uint32_t> index_;
};

}  // namespace

MeshData pinCellMesh(double tile_side, double tile_thickness, double pin_side, double pin_length) {
  const double t = 0.5 * tile_side, p = 0.5 * pin_side, top = tile_thickness;
  QuadMesh m;
  // the tile: top, four sides, and the bottom as a ring of four trapezoids around the pin
  m.rect(1, top, {-t, -t}, {t, t}, 1.0);  // (z, x)
  for (double s : {-1.0, 1.0}) {
    m.rect(0, s * t, {0.0, -t}, {top, t}, s);  // (y, z)
    m.rect(2, s * t, {-t, 0.0}, {t, top}, s);  // (x, y)
  }
  const Vec3 down{0.0, -1.0, 0.0};
  const Vec3 outer[4] = {{-t, 0.0, -t}, {t, 0.0, -t}, {t, 0.0, t}, {-t, 0.0, t}};
  const Vec3 inner[4] = {{-p, 0.0, -p}, {p, 0.0, -p}, {p, 0.0, p}, {-p, 0.0, p}};
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    m.quad(outer[i], outer[j], inner[j], inner[i], down);
  }
  // the pin: four sides and its end
  for (double s : {-1.0, 1.0}) {
    m.rect(0, s * p, {-pin_length, -p}, {0.0, p}, s);
    m.rect(2, s * p, {-p, -pin_length}, {p, 0.0}, s);
  }
  m.rect(1, -pin_length, {-p, -p}, {p, p}, -1.0);
  return m.take();
}

MeshData ridgeCellMesh(double cell,
                       double ridge_width,
                       double ridge_height,
                       double base_thickness) {
  const double c = 0.5 * cell, r = 0.5 * ridge_width, h = ridge_height;
  const double bottom = -(ridge_height + base_thickness);
  QuadMesh m;
  // rect(1, ...) takes (z, x); rect(0, ...) takes (y, z); rect(2, ...) takes (x, y)
  m.rect(1, 0.0, {-c, -r}, {c, r}, 1.0);    // ridge top
  m.rect(0, -r, {-h, -c}, {0.0, c}, -1.0);  // ridge sides
  m.rect(0, r, {-h, -c}, {0.0, c}, 1.0);
  m.rect(1, -h, {-c, -c}, {c, -r}, 1.0);  // shoulders
  m.rect(1, -h, {-c, r}, {c, c}, 1.0);
  m.rect(0, -c, {bottom, -c}, {-h, c}, -1.0);  // base sides along Z
  m.rect(0, c, {bottom, -c}, {-h, c}, 1.0);
  // the bottom and the two T-shaped ends, split at the ridge's edges so that no vertex lies on
  // another face's edge
  const double xs[4] = {-c, -r, r, c};
  for (int k = 0; k < 3; ++k) {
    m.rect(1, bottom, {-c, xs[k]}, {c, xs[k + 1]}, -1.0);
    for (double s : {-1.0, 1.0})
      m.rect(2, s * c, {xs[k], bottom}, {xs[k + 1], -h}, s);
  }
  for (double s : {-1.0, 1.0})
    m.rect(2, s * c, {-r, -h}, {r, 0.0}, s);
  return m.take();
}

double SpurGear::baseRadius() const {
  return pitchRadius() * std::cos(pressure_angle_rad);
}

double SpurGear::toothHalfAngle(double r) const {
  const double rp = pitchRadius();
  const double rb = baseRadius();
  const double thickness_at_pitch = 0.5 * std::numbers::pi * module_m - 0.5 * backlash_m;
  const double half_at_pitch = 0.5 * thickness_at_pitch / rp;
  const double at_base = half_at_pitch + involute(pressure_angle_rad);
  if (r <= rb)
    return at_base;
  return at_base - involute(std::acos(rb / r));
}

std::vector<Vec2> SpurGear::toothPolygon(double centre_rad) const {
  const double rb = baseRadius();
  const double ra = tipRadius();
  const double r0 = rootRadius() - root_inset_m;
  if (!(rb > r0))
    throw std::invalid_argument("scene generator: base circle inside the root");
  // right flank (clockwise side) from the root up: radii and polar half-angles
  std::vector<std::pair<double, double>> flank;  // (radius, half-angle)
  flank.emplace_back(r0, toothHalfAngle(r0));
  flank.emplace_back(rb, toothHalfAngle(rb));
  // involute points at equal roll angles: r = rb * sqrt(1 + s^2), s up to tan(alpha_tip)
  const double roll_tip = std::sqrt((ra / rb) * (ra / rb) - 1.0);
  for (int i = 1; i <= flank_samples; ++i) {
    const double s = roll_tip * i / flank_samples;
    const double r = (i == flank_samples) ? ra : rb * std::sqrt(1.0 + s * s);
    flank.emplace_back(r, toothHalfAngle(r));
  }
  std::vector<Vec2> poly;
  poly.reserve(2 * flank.size());
  for (const auto& [r, half] : flank)
    poly.push_back({r * std::cos(centre_rad - half), r * std::sin(centre_rad - half)});
  for (auto it = flank.rbegin(); it != flank.rend(); ++it)
    poly.push_back({it->first * std::cos(centre_rad + it->second),
                    it->first * std::sin(centre_rad + it->second)});
  return poly;
}

std::vector<Vec2> SpurGear::hubPolygon(double first_tooth_rad) const {
  const double pitch = 2.0 * std::numbers::pi / teeth;
  const double rf = rootRadius();
  std::vector<Vec2> poly;
  for (int k = 0; k < teeth; ++k) {
    const double a = first_tooth_rad + (k + 0.5) * pitch;
    poly.push_back({rf * std::cos(a), rf * std::sin(a)});
  }
  return poly;
}

}  // namespace hapticd::scenes
