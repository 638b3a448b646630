#include "core/decomp/cut.h"

#include <algorithm>
#include <cmath>

namespace hapticd::decomp {
namespace {

bool lexLess(const Vec3& a, const Vec3& b) {
  if (a.x != b.x)
    return a.x < b.x;
  if (a.y != b.y)
    return a.y < b.y;
  return a.z < b.z;
}

// where edge uv crosses the plane, from the lexicographically smaller end
Vec3 crossing(const Vec3& u, double du, const Vec3& v, double dv) {
  if (lexLess(v, u))
    return crossing(v, dv, u, du);
  const double t = du / (du - dv);
  return u + (v - u) * t;
}

// signed distance with |d| <= eps snapped to 0
double side(const Plane& plane, const Vec3& x, double eps) {
  const double d = plane.signedDistance(x);
  return std::abs(d) <= eps ? 0.0 : d;
}

// Sutherland–Hodgman against both half-spaces at once
void clipLoop(const std::vector<Vec3>& loop,
              const Plane& plane,
              double eps,
              std::vector<Vec3>& below,
              std::vector<Vec3>& above,
              std::vector<Vec3>* on) {
  below.clear();
  above.clear();
  const std::size_t n = loop.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& u = loop[i];
    const Vec3& v = loop[(i + 1) % n];
    const double du = side(plane, u, eps), dv = side(plane, v, eps);
    if (du <= 0.0)
      below.push_back(u);
    if (du >= 0.0)
      above.push_back(u);
    if (du == 0.0 && on != nullptr)
      on->push_back(u);
    if ((du < 0.0 && dv > 0.0) || (du > 0.0 && dv < 0.0)) {
      const Vec3 x = crossing(u, du, v, dv);
      below.push_back(x);
      above.push_back(x);
      if (on != nullptr)
        on->push_back(x);
    }
  }
}

// the section points as a convex loop (sorted by angle about their mean in the plane)
std::vector<Vec3> sectionLoop(std::vector<Vec3> pts, const Plane& plane) {
  sortUnique(pts);
  if (pts.size() < 3)
    return {};
  Vec3 c{0.0};
  for (const Vec3& p : pts)
    c += p;
  c /= static_cast<double>(pts.size());
  const Vec3 helper = std::abs(plane.n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 a = glm::normalize(glm::cross(plane.n, helper));
  const Vec3 b = glm::cross(plane.n, a);
  std::vector<std::pair<double, Vec3>> keyed;
  keyed.reserve(pts.size());
  for (const Vec3& p : pts)
    keyed.push_back({std::atan2(glm::dot(p - c, b), glm::dot(p - c, a)), p});
  std::sort(keyed.begin(), keyed.end(), [](const auto& x, const auto& y) {
    return x.first != y.first ? x.first < y.first : lexLess(x.second, y.second);
  });
  std::vector<Vec3> loop;
  loop.reserve(keyed.size());
  for (const auto& k : keyed)
    loop.push_back(k.second);
  return loop;
}

}  // namespace

void Polygons::add(const std::vector<Vec3>& loop) {
  pts.insert(pts.end(), loop.begin(), loop.end());
  start.push_back(static_cast<std::uint32_t>(pts.size()));
}

Cell boxCell(const Vec3& lo, const Vec3& hi) {
  auto v = [&](int i) {
    return Vec3{i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
  };
  return {{v(0), v(2), v(3), v(1)}, {v(4), v(5), v(7), v(6)}, {v(0), v(1), v(5), v(4)},
          {v(2), v(6), v(7), v(3)}, {v(0), v(4), v(6), v(2)}, {v(1), v(3), v(7), v(5)}};
}

namespace {

// a polygon lying in the plane: +1 when it faces along the plane's normal (so belongs below)
int inPlaneFacing(const Polygons& in, std::size_t k, const Plane& plane, double eps) {
  const std::uint32_t s = in.start[k], e = in.start[k + 1];
  for (std::uint32_t i = s; i < e; ++i)
    if (side(plane, in.pts[i], eps) != 0.0)
      return 0;
  Vec3 normal{0.0};
  for (std::uint32_t i = s + 1; i + 1 < e; ++i)
    normal += glm::cross(in.pts[i] - in.pts[s], in.pts[i + 1] - in.pts[s]);
  return glm::dot(normal, plane.n) >= 0.0 ? 1 : -1;
}

}  // namespace

void splitPolygons(const Polygons& in,
                   const Plane& plane,
                   double eps,
                   Polygons& below,
                   Polygons& above) {
  std::vector<Vec3> loop, b, a;
  for (std::size_t k = 0; k < in.size(); ++k) {
    loop.assign(in.pts.begin() + in.start[k], in.pts.begin() + in.start[k + 1]);
    if (const int facing = inPlaneFacing(in, k, plane, eps); facing != 0) {
      (facing > 0 ? below : above).add(loop);
      continue;
    }
    clipLoop(loop, plane, eps, b, a, nullptr);
    if (b.size() >= 3)
      below.add(b);
    if (a.size() >= 3)
      above.add(a);
  }
}

void sectionPoints(const Polygons& in,
                   const Plane& plane,
                   double eps,
                   std::vector<Vec3>& both,
                   std::vector<Vec3>& below,
                   std::vector<Vec3>& above) {
  for (std::size_t k = 0; k < in.size(); ++k) {
    const std::uint32_t s = in.start[k], e = in.start[k + 1];
    bool touches = false, has_below = false, has_above = false;
    for (std::uint32_t i = s; i < e; ++i) {
      const Vec3& u = in.pts[i];
      const Vec3& v = in.pts[i + 1 < e ? i + 1 : s];
      const double du = side(plane, u, eps), dv = side(plane, v, eps);
      if ((du < 0.0 && dv > 0.0) || (du > 0.0 && dv < 0.0))
        both.push_back(crossing(u, du, v, dv));
      touches = touches || du == 0.0;
      has_below = has_below || du < 0.0;
      has_above = has_above || du > 0.0;
    }
    if (!touches)
      continue;
    // a vertex on the plane belongs to the sides its polygon reaches (in-plane: by facing)
    const int facing = inPlaneFacing(in, k, plane, eps);
    std::vector<Vec3>& to = facing > 0 || (facing == 0 && !has_above) ? below
                            : facing < 0 || !has_below                ? above
                                                                      : both;
    for (std::uint32_t i = s; i < e; ++i)
      if (side(plane, in.pts[i], eps) == 0.0)
        to.push_back(in.pts[i]);
  }
}

void splitCell(const Cell& in,
               const Plane& plane,
               Cell& below,
               Cell& above,
               std::vector<Vec3>& section) {
  below.clear();
  above.clear();
  std::vector<Vec3> on, b, a;
  for (const auto& face : in) {
    clipLoop(face, plane, 0.0, b, a, &on);
    if (b.size() >= 3)
      below.push_back(b);
    if (a.size() >= 3)
      above.push_back(a);
  }
  std::vector<Vec3> loop = sectionLoop(on, plane);
  section = loop;
  if (loop.size() >= 3) {
    below.push_back(loop);
    above.push_back(loop);
  }
}

std::vector<Vec3> cellSection(const Cell& in, const Plane& plane) {
  std::vector<Vec3> on, b, a;
  for (const auto& face : in)
    clipLoop(face, plane, 0.0, b, a, &on);
  return sectionLoop(on, plane);
}

void sortUnique(std::vector<Vec3>& pts) {
  std::sort(pts.begin(), pts.end(), lexLess);
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
}

}  // namespace hapticd::decomp
