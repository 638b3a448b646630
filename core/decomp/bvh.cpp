#include "core/decomp/bvh.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <utility>

namespace hapticd::decomp {
namespace {

constexpr std::uint32_t kLeafSize = 4;
// an edge whose two faces' unit normals sum to less than this (a dihedral angle under 0.06
// degrees) folds the surface flat onto itself: no pseudonormal side there
constexpr double kFoldedEdge = 1e-3;

double boxDistanceSq(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 d = glm::max(glm::max(lo - p, p - hi), Vec3{0.0});
  return glm::dot(d, d);
}

bool rayHitsBox(const Vec3& p, const Vec3& inv_dir, const Vec3& lo, const Vec3& hi) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    double ta = (lo[a] - p[a]) * inv_dir[a];
    double tb = (hi[a] - p[a]) * inv_dir[a];
    if (ta > tb)
      std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1)
      return false;
  }
  return true;
}

// the ray p + t·d, t > 0, through triangle abc (Möller–Trumbore): +1 leaving (d along the normal),
// -1 entering, 0 missing
int rayCrossing(const Vec3& p, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 h = glm::cross(d, e2);
  const double det = glm::dot(e1, h);
  if (det == 0.0)
    return 0;
  const double inv = 1.0 / det;
  const Vec3 s = p - a;
  const double u = glm::dot(s, h) * inv;
  if (u < 0.0 || u > 1.0)
    return 0;
  const Vec3 q = glm::cross(s, e1);
  const double v = glm::dot(d, q) * inv;
  if (v < 0.0 || u + v > 1.0)
    return 0;
  const double t = glm::dot(e2, q) * inv;
  if (t <= 0.0)
    return 0;
  return det < 0.0 ? 1 : -1;  // det = -dot(d, e1 x e2)
}

// every undirected edge used as often from a to b as from b to a (a 2-cycle: its boundary is zero)
bool balancedEdges(std::span<const Triangle> triangles) {
  if (triangles.empty())
    return false;
  // directed edge (min, max) with +1 when it runs min -> max
  std::vector<std::pair<std::uint64_t, int>> edges;
  edges.reserve(3 * triangles.size());
  for (const Triangle& t : triangles)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      const std::uint64_t key = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
      edges.emplace_back(key, a < b ? 1 : -1);
    }
  std::sort(edges.begin(), edges.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  for (std::size_t i = 0; i < edges.size();) {
    int sum = 0;
    std::size_t j = i;
    for (; j < edges.size() && edges[j].first == edges[i].first; ++j)
      sum += edges[j].second;
    if (sum != 0)
      return false;
    i = j;
  }
  return true;
}

// segment pq through triangle abc (not touching at an end)
bool segmentCrosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = glm::cross(b - a, c - a);
  const double dp = glm::dot(n, p - a), dq = glm::dot(n, q - a);
  if ((dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || dp == dq)
    return false;
  const Vec3 x = p + (q - p) * (dp / (dp - dq));
  const double s1 = glm::dot(n, glm::cross(b - a, x - a));
  const double s2 = glm::dot(n, glm::cross(c - b, x - b));
  const double s3 = glm::dot(n, glm::cross(a - c, x - c));
  return (s1 > 0.0 && s2 > 0.0 && s3 > 0.0) || (s1 < 0.0 && s2 < 0.0 && s3 < 0.0);
}

}  // namespace

namespace {

// Ericson §5.1.5, with the feature the closest point lies on
Vec3 closestOnTriangle(const Vec3& p,
                       const Vec3& a,
                       const Vec3& b,
                       const Vec3& c,
                       std::uint8_t& feature) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0)
    return feature = 1, a;
  const Vec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3)
    return feature = 2, b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
    return feature = 4, a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6)
    return feature = 3, c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
    return feature = 6, a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return feature = 5, b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0.0))
    return feature = 1, a;  // a degenerate triangle
  const double v = vb / denom, w = vc / denom;
  return feature = 0, a + ab * v + ac * w;
}

}  // namespace

Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  std::uint8_t feature = 0;
  return closestOnTriangle(p, a, b, c, feature);
}

void TriangleBvh::pseudonormals(std::span<const Vec3> positions,
                                std::span<const Triangle> triangles) {
  // closed and manifold with consistent winding: every directed edge once, its reverse once
  std::vector<std::pair<std::uint64_t, std::uint32_t>> directed;
  directed.reserve(triangles.size() * 3);
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (std::size_t e = 0; e < 3; ++e)
      directed.push_back(
          {static_cast<std::uint64_t>(triangles[t][e]) << 32 | triangles[t][(e + 1) % 3], t});
  std::sort(directed.begin(), directed.end());
  for (std::size_t i = 1; i < directed.size(); ++i)
    if (directed[i].first == directed[i - 1].first)
      return;  // an edge used twice the same way
  auto twin = [&](std::uint32_t a, std::uint32_t b) -> std::int64_t {
    const std::uint64_t key = static_cast<std::uint64_t>(b) << 32 | a;
    const auto it = std::lower_bound(directed.begin(), directed.end(), std::make_pair(key, 0u));
    return it != directed.end() && it->first == key ? static_cast<std::int64_t>(it->second) : -1;
  };
  std::vector<Vec3> face(triangles.size());
  std::vector<Vec3> vertex(positions.size(), Vec3{0.0});
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tr = triangles[t];
    const Vec3 n =
        glm::cross(positions[tr[1]] - positions[tr[0]], positions[tr[2]] - positions[tr[0]]);
    face[t] = glm::length(n) > 0.0 ? glm::normalize(n) : Vec3{0.0};
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3 e1 = positions[tr[(k + 1) % 3]] - positions[tr[k]];
      const Vec3 e2 = positions[tr[(k + 2) % 3]] - positions[tr[k]];
      const double l = glm::length(e1) * glm::length(e2);
      if (l > 0.0)
        vertex[tr[k]] += face[t] * std::acos(std::clamp(glm::dot(e1, e2) / l, -1.0, 1.0));
    }
  }
  std::vector<std::array<Vec3, 7>> normals(tris_.size());
  for (std::size_t i = 0; i < tris_.size(); ++i) {
    const std::uint32_t t = tris_[i].source;
    const Triangle& tr = triangles[t];
    normals[i][0] = face[t];
    for (std::size_t k = 0; k < 3; ++k) {
      normals[i][1 + k] = vertex[tr[k]];
      const std::int64_t o = twin(tr[k], tr[(k + 1) % 3]);
      if (o < 0)
        return;  // an open edge
      normals[i][4 + k] = face[t] + face[static_cast<std::size_t>(o)];
      // a fold flat onto itself (a flat part closed by the hole filling into a shell of no
      // volume): the edge's pseudonormal vanishes and its vertices' are rounding noise, so their
      // side says nothing
      if (glm::length(normals[i][4 + k]) < kFoldedEdge)
        return;
    }
  }
  normals_ = std::move(normals);
}

bool TriangleBvh::inside(const Vec3& p, const Closest& closest) const {
  if (normals_.empty() || !(closest.distance > 0.0))
    return inside(p);
  return glm::dot(p - closest.point, normals_[closest.triangle][closest.feature]) < 0.0;
}

TriangleBvh::TriangleBvh(std::span<const Vec3> positions, std::span<const Triangle> triangles) {
  tris_.reserve(triangles.size());
  std::vector<Vec3> centroids;
  centroids.reserve(triangles.size());
  for (const Triangle& t : triangles) {
    tris_.push_back({positions[t[0]], positions[t[1]], positions[t[2]], t,
                     static_cast<std::uint32_t>(tris_.size())});
    centroids.push_back((positions[t[0]] + positions[t[1]] + positions[t[2]]) / 3.0);
  }
  nodes_.reserve(2 * triangles.size() / kLeafSize + 2);
  nodes_.push_back({});
  if (!tris_.empty())
    build(0, 0, static_cast<std::uint32_t>(tris_.size()), centroids);
  pseudonormals(positions, triangles);
  buildDipoles();
  cycle_ = balancedEdges(triangles);
}

void TriangleBvh::build(std::uint32_t index,
                        std::uint32_t first,
                        std::uint32_t count,
                        std::vector<Vec3>& centroids) {
  Vec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};
  Vec3 clo = lo, chi = hi;
  for (std::uint32_t i = first; i < first + count; ++i) {
    const Tri& t = tris_[i];
    lo = glm::min(glm::min(lo, t.a), glm::min(t.b, t.c));
    hi = glm::max(glm::max(hi, t.a), glm::max(t.b, t.c));
    clo = glm::min(clo, centroids[i]);
    chi = glm::max(chi, centroids[i]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return;
  }
  const Vec3 ext = chi - clo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const std::uint32_t half = count / 2;
  // the median by centroid along the axis, ties by position in the array: deterministic
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), first);
  std::nth_element(order.begin(), order.begin() + half, order.end(),
                   [&](std::uint32_t i, std::uint32_t j) {
                     if (centroids[i][axis] != centroids[j][axis])
                       return centroids[i][axis] < centroids[j][axis];
                     return i < j;
                   });
  std::vector<Tri> tmp_t(count);
  std::vector<Vec3> tmp_c(count);
  for (std::uint32_t k = 0; k < count; ++k)
    tmp_t[k] = tris_[order[k]], tmp_c[k] = centroids[order[k]];
  std::copy(tmp_t.begin(), tmp_t.end(), tris_.begin() + first);
  std::copy(tmp_c.begin(), tmp_c.end(), centroids.begin() + first);
  const auto left = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  nodes_.push_back({});
  nodes_[index].first = left;
  nodes_[index].count = 0;
  build(left, first, half, centroids);
  build(left + 1, first + half, count - half, centroids);
}

TriangleBvh::Closest TriangleBvh::closest(const Vec3& p, double max_distance) const {
  Closest best;
  double best_sq = max_distance * max_distance;
  if (tris_.empty())
    return best;
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (boxDistanceSq(p, n.lo, n.hi) >= best_sq)
      continue;
    if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
        const Tri& t = tris_[i];
        std::uint8_t feature = 0;
        const Vec3 c = closestOnTriangle(p, t.a, t.b, t.c, feature);
        const Vec3 d = c - p;
        const double dsq = glm::dot(d, d);
        if (dsq < best_sq) {
          best_sq = dsq;
          best.point = c;
          best.triangle = i;
          best.feature = feature;
          best.distance = std::sqrt(dsq);
        }
      }
      continue;
    }
    const std::uint32_t l = n.first, r = n.first + 1;
    const double dl = boxDistanceSq(p, nodes_[l].lo, nodes_[l].hi);
    const double dr = boxDistanceSq(p, nodes_[r].lo, nodes_[r].hi);
    if (top + 2 > 64)
      continue;  // cannot happen for a balanced tree of < 2^60 triangles
    if (dl < dr) {
      stack[top++] = r;
      stack[top++] = l;
    } else {
      stack[top++] = l;
      stack[top++] = r;
    }
  }
  return best;
}

double TriangleBvh::farthestFrom(std::uint32_t index, std::span<const Vec3> points) const {
  const Tri& t = tris_[index];
  double worst = 0.0;
  for (const Vec3& p : points)
    worst = std::max(worst, glm::length(closestPointOnTriangle(p, t.a, t.b, t.c) - p));
  return worst;
}

int TriangleBvh::windingAlongRay(const Vec3& p, const Vec3& dir) const {
  if (tris_.empty())
    return 0;
  const Vec3 inv{1.0 / dir.x, 1.0 / dir.y, 1.0 / dir.z};
  int winding = 0;
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!rayHitsBox(p, inv, n.lo, n.hi))
      continue;
    if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i)
        winding += rayCrossing(p, dir, tris_[i].a, tris_[i].b, tris_[i].c);
      continue;
    }
    if (top + 2 > 64)
      continue;
    stack[top++] = n.first;
    stack[top++] = n.first + 1;
  }
  return winding;
}

void TriangleBvh::buildDipoles() {
  dipoles_.assign(nodes_.size(), {});
  std::vector<double> area(nodes_.size(), 0.0);
  // children come after their parent: fill bottom-up
  for (std::size_t k = nodes_.size(); k-- > 0;) {
    const Node& n = nodes_[k];
    Dipole& d = dipoles_[k];
    if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
        const Tri& t = tris_[i];
        const Vec3 cr = glm::cross(t.b - t.a, t.c - t.a) * 0.5;
        const double a = glm::length(cr);
        d.normal += cr;
        d.centre += (t.a + t.b + t.c) * (a / 3.0);
        area[k] += a;
      }
    } else {
      for (std::uint32_t c : {n.first, n.first + 1}) {
        d.normal += dipoles_[c].normal;
        d.centre += dipoles_[c].centre * area[c];
        area[k] += area[c];
      }
    }
    d.centre = area[k] > 0.0 ? d.centre / area[k] : (n.lo + n.hi) * 0.5;
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 v{corner & 1 ? n.hi.x : n.lo.x, corner & 2 ? n.hi.y : n.lo.y,
                   corner & 4 ? n.hi.z : n.lo.z};
      d.radius = std::max(d.radius, glm::length(v - d.centre));
    }
  }
}

double TriangleBvh::windingNumber(const Vec3& p) const {
  if (tris_.empty())
    return 0.0;
  constexpr double kBeta = 2.0;
  double omega = 0.0;
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t k = stack[--top];
    const Node& n = nodes_[k];
    const Dipole& d = dipoles_[k];
    const Vec3 r = d.centre - p;
    const double dist = glm::length(r);
    if (dist > kBeta * d.radius) {
      omega += glm::dot(d.normal, r) / (dist * dist * dist);
      continue;
    }
    if (n.count > 0) {
      // Van Oosterom and Strackee, IEEE TBME 30(2) 1983: the solid angle of one triangle
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
        const Vec3 a = tris_[i].a - p, b = tris_[i].b - p, c = tris_[i].c - p;
        const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
        const double num = glm::dot(a, glm::cross(b, c));
        const double den =
            la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
        omega += 2.0 * std::atan2(num, den);
      }
      continue;
    }
    if (top + 2 > 64)
      continue;
    stack[top++] = n.first;
    stack[top++] = n.first + 1;
  }
  return omega / (4.0 * std::numbers::pi);
}

bool TriangleBvh::insideByRays(const Vec3& p) const {
  // three fixed directions, none along an axis or a diagonal (meshes are full of those)
  static constexpr std::array<std::array<double, 3>, 3> kDirs{
      {{0.5773502691896258, 0.6172133998483676, 0.5345224838248488},
       {-0.7071067811865476, 0.2672612419124244, 0.6546536707079771},
       {0.2182178902359924, -0.8728715609439696, -0.4364357804719848}}};
  int votes = 0;
  for (const auto& d : kDirs) {
    if (windingAlongRay(p, Vec3{d[0], d[1], d[2]}) > 0)
      ++votes;
    if (votes >= 2)
      return true;
  }
  return false;
}

std::size_t TriangleBvh::countCrossingPairs(std::size_t max_pairs_tested, bool* capped) const {
  std::size_t crossings = 0, tested = 0;
  *capped = false;
  std::vector<std::uint32_t> stack;
  for (std::uint32_t i = 0; i < tris_.size(); ++i) {
    const Tri& ti = tris_[i];
    const Vec3 lo = glm::min(glm::min(ti.a, ti.b), ti.c), hi = glm::max(glm::max(ti.a, ti.b), ti.c);
    stack.assign(1, 0);
    while (!stack.empty()) {
      const Node& n = nodes_[stack.back()];
      stack.pop_back();
      if (glm::any(glm::lessThan(n.hi, lo)) || glm::any(glm::greaterThan(n.lo, hi)))
        continue;
      if (n.count == 0) {
        stack.push_back(n.first);
        stack.push_back(n.first + 1);
        continue;
      }
      for (std::uint32_t j = n.first; j < n.first + n.count; ++j) {
        if (j <= i)
          continue;
        const Tri& tj = tris_[j];
        bool shared = false;
        for (std::uint32_t a : ti.v)
          for (std::uint32_t b : tj.v)
            shared = shared || a == b;
        if (shared)
          continue;
        if (++tested > max_pairs_tested) {
          *capped = true;
          return crossings;
        }
        const bool cross = segmentCrosses(ti.a, ti.b, tj.a, tj.b, tj.c) ||
                           segmentCrosses(ti.b, ti.c, tj.a, tj.b, tj.c) ||
                           segmentCrosses(ti.c, ti.a, tj.a, tj.b, tj.c) ||
                           segmentCrosses(tj.a, tj.b, ti.a, ti.b, ti.c) ||
                           segmentCrosses(tj.b, tj.c, ti.a, ti.b, ti.c) ||
                           segmentCrosses(tj.c, tj.a, ti.a, ti.b, ti.c);
        if (cross)
          ++crossings;
      }
    }
  }
  return crossings;
}

}  // namespace hapticd::decomp
