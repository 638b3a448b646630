#include "core/decomp/measure.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hapticd::decomp {
namespace {

constexpr std::uint32_t kNoTriangle = std::numeric_limits<std::uint32_t>::max();

struct Cell {
  Vec3 a, b, c;
  double upper;
  std::uint32_t tri;  // the surface triangle nearest to the centroid
};
bool lessUpper(const Cell& x, const Cell& y) {
  return x.upper < y.upper;
}

double circumradiusAbout(const Vec3& m, const Vec3& a, const Vec3& b, const Vec3& c) {
  return std::max({glm::length(a - m), glm::length(b - m), glm::length(c - m)});
}

class ExcessSearch {
 public:
  ExcessSearch(const ModelView& model, const ExcessOptions& o) : model_(model), o_(o) {}

  // evaluates the excess at the triangle's centroid; keeps the triangle if it may hold more
  void visit(const Vec3& a, const Vec3& b, const Vec3& c, std::uint32_t parent_tri) {
    const Vec3 m = (a + b + c) / 3.0;
    const double r = circumradiusAbout(m, a, b, c);
    bool covered = false;
    for (const HullPlanes& other : o_.others) {
      if (glm::any(glm::lessThan(m, other.lo)) || glm::any(glm::greaterThan(m, other.hi)))
        continue;
      const double depth = other.depth(m);
      if (depth >= r)
        return;  // the whole triangle is inside another piece
      covered = covered || depth > 0.0;
    }
    // a small triangle on the edge of another piece holds points of the union's boundary
    const bool finest = r <= o_.resolution;
    if (finest)
      covered = false;
    ++out_.evaluations;
    const TriangleBvh::Closest cl = model_.bvh->closest(m);
    const double d = cl.distance;
    // Lipschitz about the centroid, or convexity of the distance to one triangle of the surface
    const std::array<Vec3, 3> corners{a, b, c};
    double up = std::min(d + r, model_.bvh->farthestFrom(cl.triangle, corners));
    if (parent_tri != cl.triangle && parent_tri != kNoTriangle)
      up = std::min(up, model_.bvh->farthestFrom(parent_tri, corners));
    // the sign matters when the centroid may be deep inside, or may raise the largest excess
    if (d > r || (d > out_.lower && !covered)) {
      if (model_.bvh->inside(m, cl)) {
        up = std::min(up, std::max(0.0, r - d));
      } else if (!covered && d > out_.lower) {
        out_.lower = d;
        out_.worst_q = m;
        out_.worst_p = cl.point;
      }
    }
    if (up <= done() || finest)
      return;
    heap_.push_back({a, b, c, up, cl.triangle});
    std::push_heap(heap_.begin(), heap_.end(), lessUpper);
  }

  // bounds at most this need no more work
  double done() const { return std::max(out_.lower, o_.floor) + o_.tolerance; }

  ExcessBound run() {
    while (!heap_.empty()) {
      const Cell top = heap_.front();
      if (top.upper <= done())
        break;
      if (out_.lower > o_.stop_above) {
        out_.aborted = true;
        break;
      }
      if (out_.evaluations >= o_.max_evaluations)
        break;
      std::pop_heap(heap_.begin(), heap_.end(), lessUpper);
      heap_.pop_back();
      const Vec3 ab = (top.a + top.b) * 0.5, bc = (top.b + top.c) * 0.5, ca = (top.c + top.a) * 0.5;
      visit(top.a, ab, ca, top.tri);
      visit(ab, top.b, bc, top.tri);
      visit(ca, bc, top.c, top.tri);
      visit(ab, bc, ca, top.tri);
    }
    const bool converged = heap_.empty() || heap_.front().upper <= done();
    out_.capped = !converged && !out_.aborted;
    out_.upper = converged ? std::max(out_.lower, o_.floor) + o_.tolerance
                           : std::max(out_.lower, heap_.front().upper);
    out_.sampled_radius = o_.resolution;
    for (const Cell& c : heap_)
      out_.sampled_radius =
          std::max(out_.sampled_radius, circumradiusAbout((c.a + c.b + c.c) / 3.0, c.a, c.b, c.c));
    if (out_.lower > o_.stop_above)
      out_.aborted = true;
    return out_;
  }

 private:
  const ModelView& model_;
  const ExcessOptions& o_;
  ExcessBound out_;
  std::vector<Cell> heap_;
};

}  // namespace

double HullPlanes::depth(const Vec3& q) const {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < normal.size(); ++i)
    d = std::min(d, offset[i] - glm::dot(normal[i], q));
  return d;
}

HullPlanes HullPlanes::of(const HullMesh& hull) {
  HullPlanes h;
  h.lo = Vec3{std::numeric_limits<double>::max()};
  h.hi = Vec3{-std::numeric_limits<double>::max()};
  for (const Vec3& v : hull.vertices)
    h.lo = glm::min(h.lo, v), h.hi = glm::max(h.hi, v);
  for (const Triangle& t : hull.triangles) {
    const Vec3& a = hull.vertices[t[0]];
    const Vec3 n = glm::cross(hull.vertices[t[1]] - a, hull.vertices[t[2]] - a);
    const double len = glm::length(n);
    if (!(len > 0.0))
      continue;
    h.normal.push_back(n / len);
    h.offset.push_back(glm::dot(n / len, a));
  }
  return h;
}

ExcessBound hullExcess(const ModelView& model, const HullMesh& hull, const ExcessOptions& options) {
  ExcessSearch search(model, options);
  for (const Triangle& t : hull.triangles)
    search.visit(hull.vertices[t[0]], hull.vertices[t[1]], hull.vertices[t[2]], kNoTriangle);
  return search.run();
}

double distanceToHull(const Vec3& q, const HullMesh& hull, const HullPlanes& planes) {
  if (planes.depth(q) >= 0.0)
    return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : hull.triangles) {
    const Vec3 c =
        closestPointOnTriangle(q, hull.vertices[t[0]], hull.vertices[t[1]], hull.vertices[t[2]]);
    best = std::min(best, glm::length(c - q));
  }
  return best;
}

double surfaceCoverage(std::span<const Vec3> positions,
                       std::span<const Triangle> triangles,
                       std::span<const HullMesh> hulls,
                       std::span<const HullPlanes> planes,
                       double tolerance) {
  double lower = 0.0, dropped = 0.0;
  std::vector<Cell> stack;
  // the bound over a triangle: min over hulls of the largest corner distance (convexity)
  auto bound = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 lo = glm::min(glm::min(a, b), c), hi = glm::max(glm::max(a, b), c);
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < hulls.size() && best > 0.0; ++i) {
      const double slack = best == std::numeric_limits<double>::infinity() ? 0.0 : best;
      if (glm::any(glm::lessThan(hi + slack, planes[i].lo)) ||
          glm::any(glm::greaterThan(lo - slack, planes[i].hi)))
        continue;
      const double da = distanceToHull(a, hulls[i], planes[i]);
      if (da >= best)
        continue;
      const double db = distanceToHull(b, hulls[i], planes[i]);
      if (db >= best)
        continue;
      best = std::min(best, std::max({da, db, distanceToHull(c, hulls[i], planes[i])}));
    }
    return best;
  };
  auto pointDistance = [&](const Vec3& q) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < hulls.size() && best > 0.0; ++i)
      best = std::min(best, distanceToHull(q, hulls[i], planes[i]));
    return best;
  };
  for (const Triangle& t : triangles) {
    stack.push_back({positions[t[0]], positions[t[1]], positions[t[2]], 0.0, kNoTriangle});
    while (!stack.empty()) {
      const Cell cell = stack.back();
      stack.pop_back();
      const double up = bound(cell.a, cell.b, cell.c);
      if (up <= lower + tolerance) {
        dropped = std::max(dropped, up);
        continue;
      }
      const Vec3 m = (cell.a + cell.b + cell.c) / 3.0;
      lower = std::max(lower, pointDistance(m));
      if (circumradiusAbout(m, cell.a, cell.b, cell.c) <= 0.5 * tolerance) {
        dropped = std::max(dropped, std::min(up, lower + tolerance));
        continue;
      }
      const Vec3 ab = (cell.a + cell.b) * 0.5, bc = (cell.b + cell.c) * 0.5,
                 ca = (cell.c + cell.a) * 0.5;
      stack.push_back({cell.a, ab, ca, 0.0, kNoTriangle});
      stack.push_back({ab, cell.b, bc, 0.0, kNoTriangle});
      stack.push_back({ca, bc, cell.c, 0.0, kNoTriangle});
      stack.push_back({ab, bc, ca, 0.0, kNoTriangle});
    }
  }
  return std::max(lower, dropped);
}

}  // namespace hapticd::decomp
