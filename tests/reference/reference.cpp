// The brute-force reference. Everything here is recomputed from the Polytope's vertex, edge and
// face lists (positions, edge endpoints, face loops): no face normal, Voronoi plane, support climb
// or any other routine of the code under test is used. Arithmetic is in long double (64-bit
// mantissa on x86-64) so that the reference is more accurate than the double code it checks. Every
// answer is a scan over all feature pairs (the distance scans only skip pairs whose bounding
// spheres are already farther apart than the best pair found, which changes no answer).
#include "tests/reference/reference.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

// The reference runs inside the Debug (-O0) test binaries, where its scans over all feature pairs
// would dominate the run time; optimising this file alone changes no result (no -ffast-math).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("O2")
#endif

namespace hapticd::reference {
namespace {

using Real = long double;

struct R3 {
  Real x, y, z;
};
inline R3 operator+(const R3& a, const R3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline R3 operator-(const R3& a, const R3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline R3 operator-(const R3& a) {
  return {-a.x, -a.y, -a.z};
}
inline R3 operator*(const R3& a, Real s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline Real dot(const R3& a, const R3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline R3 cross(const R3& a, const R3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Real norm2(const R3& a) {
  return dot(a, a);
}
inline R3 toR3(const Vec3& v) {
  return {v.x, v.y, v.z};
}
inline Vec3 toVec3(const R3& v) {
  return {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)};
}
inline R3 normalized(const R3& a) {
  return a * (1.0L / std::sqrt(norm2(a)));
}

// A rigid transform in long double: p -> R p + t (glm matrices are column-major: R[col][row]).
struct RTransform {
  Real m[3][3];  // m[row][col]
  R3 t;
  explicit RTransform(const Transform& X) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c)
        m[r][c] = X.R[c][r];
    }
    t = toR3(X.t);
  }
  R3 rotate(const R3& p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z,
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z,
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z};
  }
  R3 apply(const R3& p) const { return rotate(p) + t; }
};

// One polytope's lists placed in A's frame.
struct Placed {
  std::vector<R3> v;                              // vertices
  std::vector<std::array<std::uint32_t, 2>> e;    // edges: tail, head
  std::vector<std::vector<std::uint32_t>> loops;  // face boundaries (vertex indices)
  std::vector<R3> n;  // outward unit face normals (Newell, from the loop)
  std::vector<R3> c;  // face centroids
};

Placed place(const Polytope& p, const Transform& X) {
  const RTransform T(X);
  Placed out;
  out.v.reserve(p.vertices().size());
  for (const auto& v : p.vertices())
    out.v.push_back(T.apply(toR3(v.p)));
  for (const auto& e : p.edges())
    out.e.push_back({e.tail, e.head});
  for (std::uint32_t f = 0; f < p.faces().size(); ++f) {
    std::vector<std::uint32_t> loop;
    for (const auto& fe : p.faceEdges(f))
      loop.push_back(fe.vertex);
    R3 newell{0, 0, 0}, centroid{0, 0, 0};
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const R3& a = out.v[loop[k]];
      const R3& b = out.v[loop[(k + 1) % loop.size()]];
      newell = newell + cross(a, b);
      centroid = centroid + a;
    }
    centroid = centroid * (1.0L / static_cast<Real>(loop.size()));
    R3 nrm = normalized(newell);
    // outward: the vertex farthest from the face plane must lie below it
    Real lo = 0, hi = 0;
    for (const R3& x : out.v) {
      const Real h = dot(nrm, x - centroid);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
    if (hi > -lo)
      nrm = -nrm;
    out.loops.push_back(std::move(loop));
    out.n.push_back(nrm);
    out.c.push_back(centroid);
  }
  return out;
}

// Squared distance from x to segment [p, q] and the closest point.
Real pointSegment2(const R3& x, const R3& p, const R3& q, R3& closest) {
  const R3 d = q - p;
  const Real dd = norm2(d);
  Real s = dd > 0 ? dot(x - p, d) / dd : 0;
  s = s < 0 ? 0 : s > 1 ? 1 : s;
  closest = p + d * s;
  return norm2(x - closest);
}

// Squared distance from x to the convex polygon `f` of P, boundary included, and the closest point.
Real pointPolygon2(const Placed& P, std::size_t f, const R3& x, R3& closest) {
  const auto& loop = P.loops[f];
  const R3& n = P.n[f];
  bool inside = true;
  for (std::size_t k = 0; k < loop.size() && inside; ++k) {
    const R3& q0 = P.v[loop[k]];
    const R3& q1 = P.v[loop[(k + 1) % loop.size()]];
    inside = dot(cross(q1 - q0, x - q0), n) >= 0;
  }
  if (inside) {
    const Real h = dot(n, x - P.c[f]);
    closest = x - n * h;
    return h * h;
  }
  Real best = std::numeric_limits<Real>::infinity();
  for (std::size_t k = 0; k < loop.size(); ++k) {
    R3 c;
    const Real d2 = pointSegment2(x, P.v[loop[k]], P.v[loop[(k + 1) % loop.size()]], c);
    if (d2 < best)
      best = d2, closest = c;
  }
  return best;
}

// Squared distance of segments [p1, q1] and [p2, q2] and their closest points: the minimum of a
// convex function over the unit square lies at the interior critical point of the two lines (when
// it is inside the square) or on the square's boundary (an endpoint against the other segment).
Real segmentSegment2(const R3& p1, const R3& q1, const R3& p2, const R3& q2, R3& c1, R3& c2) {
  Real best = std::numeric_limits<Real>::infinity();
  R3 c;
  auto consider = [&](Real d2, const R3& a, const R3& b) {
    if (d2 < best)
      best = d2, c1 = a, c2 = b;
  };
  consider(pointSegment2(p1, p2, q2, c), p1, c);
  consider(pointSegment2(q1, p2, q2, c), q1, c);
  consider(pointSegment2(p2, p1, q1, c), c, p2);
  consider(pointSegment2(q2, p1, q1, c), c, q2);
  const R3 d1 = q1 - p1, d2 = q2 - p2, r = p2 - p1;
  const R3 n = cross(d1, d2);
  const Real nn = norm2(n);
  if (nn > 0) {
    const Real s = dot(cross(r, d2), n) / nn;
    const Real t = dot(cross(r, d1), n) / nn;
    if (s > 0 && s < 1 && t > 0 && t < 1) {
      const R3 a = p1 + d1 * s, b = p2 + d2 * t;
      consider(norm2(a - b), a, b);
    }
  }
  return best;
}

struct Closest {
  Real d2 = std::numeric_limits<Real>::infinity();
  R3 pa{0, 0, 0}, pb{0, 0, 0};
};

// Bounding spheres of a polytope's faces and edges: exact lower bounds that let the scans below
// skip a pair that cannot beat the best distance found so far (no answer changes).
struct Bounds {
  std::vector<R3> face_c, edge_c;
  std::vector<Real> face_r, edge_r;
  explicit Bounds(const Placed& P) {
    for (std::size_t f = 0; f < P.loops.size(); ++f) {
      Real r = 0;
      for (const std::uint32_t v : P.loops[f])
        r = std::max(r, std::sqrt(norm2(P.v[v] - P.c[f])));
      face_c.push_back(P.c[f]);
      face_r.push_back(r * (1 + 1e-15L));
    }
    for (const auto& e : P.e) {
      edge_c.push_back((P.v[e[0]] + P.v[e[1]]) * 0.5L);
      edge_r.push_back(std::sqrt(norm2(P.v[e[1]] - P.v[e[0]])) * 0.5L * (1 + 1e-15L));
    }
  }
};

// true when the spheres (c1, r1), (c2, r2) are surely farther apart than sqrt(best2)
inline bool beyond(const R3& c1, Real r1, const R3& c2, Real r2, Real best2) {
  const Real sum = r1 + r2;
  const Real d2 = norm2(c1 - c2);
  if (d2 <= sum * sum)
    return false;
  const Real gap = std::sqrt(d2) - sum;
  return gap * gap > best2 * (1 + 1e-12L);
}

// Distance between the surfaces of A and B: every vertex against every polygon both ways, every
// edge against every edge. Starts from the closest vertex pair (an upper bound).
Closest closestPair(const Placed& A, const Placed& B) {
  Closest out;
  for (const R3& x : A.v) {
    for (const R3& y : B.v) {
      const Real d2 = norm2(x - y);
      if (d2 < out.d2)
        out.d2 = d2, out.pa = x, out.pb = y;
    }
  }
  const Bounds ba(A), bb(B);
  R3 c, c2;
  // every vertex of P against every face of Q (bounds qb); a_is_p: P is A
  auto vertexFace = [&](const Placed& P, const Placed& Q, const Bounds& qb, bool a_is_p) {
    for (const R3& x : P.v) {
      for (std::size_t f = 0; f < Q.loops.size(); ++f) {
        if (beyond(x, 0, qb.face_c[f], qb.face_r[f], out.d2))
          continue;
        const Real d2 = pointPolygon2(Q, f, x, c);
        if (d2 < out.d2)
          out.d2 = d2, out.pa = a_is_p ? x : c, out.pb = a_is_p ? c : x;
      }
    }
  };
  vertexFace(A, B, bb, true);
  vertexFace(B, A, ba, false);
  for (std::size_t i = 0; i < A.e.size(); ++i) {
    for (std::size_t j = 0; j < B.e.size(); ++j) {
      if (beyond(ba.edge_c[i], ba.edge_r[i], bb.edge_c[j], bb.edge_r[j], out.d2))
        continue;
      const Real d2 =
          segmentSegment2(A.v[A.e[i][0]], A.v[A.e[i][1]], B.v[B.e[j][0]], B.v[B.e[j][1]], c, c2);
      if (d2 < out.d2)
        out.d2 = d2, out.pa = c, out.pb = c2;
    }
  }
  return out;
}

// Smallest and largest u.x over n points. Plain pointers and comparisons: the library templates
// (iterators, std::min) are not inlined in the -O0 build, and this loop is most of the run time.
void extent(const R3* x, std::size_t n, const R3& u, Real& lo, Real& hi) {
  for (std::size_t i = 0; i < n; ++i) {
    const Real d = u.x * x[i].x + u.y * x[i].y + u.z * x[i].z;
    if (d < lo)
      lo = d;
    if (d > hi)
      hi = d;
  }
}

// The smallest translation depth over a set of axes: along unit u, B must move by
// max_A(u.x) - min_B(u.x); along -u by max_B(u.x) - min_A(u.x). Both orientations are tried.
struct AxisScan {
  Real best = std::numeric_limits<Real>::infinity();
  R3 axis{1, 0, 0};

  void consider(const Placed& A, const Placed& B, const R3& u) {
    Real loA = std::numeric_limits<Real>::infinity(), hiA = -loA, loB = loA, hiB = -loA;
    extent(A.v.data(), A.v.size(), u, loA, hiA);
    extent(B.v.data(), B.v.size(), u, loB, hiB);
    if (hiA - loB < best)
      best = hiA - loB, axis = u;
    if (hiB - loA < best)
      best = hiB - loA, axis = -u;
  }
};

// Edge directions whose sine of angle is below this give no axis (their cross product has no
// reliable direction). Skipping them is safe: every axis's depth is an upper bound on the minimal
// translation, and the Minkowski face of a nearly parallel edge pair is within its sine times the
// edge length of its neighbours.
constexpr Real kParallelSine = 1e-12L;

bool crossAxis(const R3& da, const R3& db, R3& u) {
  const R3 c = cross(da, db);
  const Real cc = norm2(c);
  if (!(cc > kParallelSine * kParallelSine * norm2(da) * norm2(db)))
    return false;
  u = c * (1.0L / std::sqrt(cc));
  return true;
}

// Minimal translation over every face normal of A and B and every edge-pair cross product.
AxisScan allAxes(const Placed& A, const Placed& B) {
  AxisScan scan;
  for (const R3& n : A.n)
    scan.consider(A, B, n);
  for (const R3& n : B.n)
    scan.consider(A, B, n);
  std::vector<R3> db;
  db.reserve(B.e.size());
  for (const auto& eb : B.e)
    db.push_back(B.v[eb[1]] - B.v[eb[0]]);
  for (const auto& ea : A.e) {
    const R3 da = A.v[ea[1]] - A.v[ea[0]];
    for (const R3& d : db) {
      R3 u;
      if (crossAxis(da, d, u))
        scan.consider(A, B, u);
    }
  }
  return scan;
}

// For each edge, the normals of the two faces holding it (from the face loops).
std::vector<std::array<R3, 2>> edgeFaceNormals(const Placed& P) {
  std::vector<std::array<R3, 2>> out(P.e.size(), {R3{0, 0, 0}, R3{0, 0, 0}});
  std::vector<int> seen(P.e.size(), 0);
  // edge lookup by its endpoints
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> by_vertex(P.v.size());
  for (std::uint32_t i = 0; i < P.e.size(); ++i) {
    by_vertex[std::min(P.e[i][0], P.e[i][1])].push_back({std::max(P.e[i][0], P.e[i][1]), i});
  }
  for (std::size_t f = 0; f < P.loops.size(); ++f) {
    const auto& loop = P.loops[f];
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const std::uint32_t a = loop[k], b = loop[(k + 1) % loop.size()];
      for (const auto& [other, i] : by_vertex[std::min(a, b)]) {
        if (other == std::max(a, b) && seen[i] < 2)
          out[i][static_cast<std::size_t>(seen[i]++)] = P.n[f];
      }
    }
  }
  return out;
}

}  // namespace

RefAnswer bruteForce(const Polytope& a, const Polytope& b, const Transform& X_AB) {
  const Placed A = place(a, Transform{});
  const Placed B = place(b, X_AB);
  RefAnswer out;
  const AxisScan scan = allAxes(A, B);
  if (scan.best > 0) {
    out.overlapping = true;
    out.signed_distance = -static_cast<double>(scan.best);
    out.normal = toVec3(scan.axis);
    return out;
  }
  const Closest c = closestPair(A, B);
  const Real d = std::sqrt(c.d2);
  out.signed_distance = static_cast<double>(d);
  out.point_a = toVec3(c.pa);
  out.point_b = toVec3(c.pb);
  out.normal = d > 0 ? toVec3((c.pb - c.pa) * (1.0L / d)) : toVec3(scan.axis);
  return out;
}

double bruteSeparatedDistance(const Polytope& a, const Polytope& b, const Transform& X_AB) {
  return static_cast<double>(std::sqrt(closestPair(place(a, Transform{}), place(b, X_AB)).d2));
}

double bruteMinkowskiDepth(const Polytope& a,
                           const Polytope& b,
                           const Transform& X_AB,
                           Vec3* normal) {
  const Placed A = place(a, Transform{});
  const Placed B = place(b, X_AB);
  AxisScan scan;
  for (const R3& n : A.n)
    scan.consider(A, B, n);
  for (const R3& n : B.n)
    scan.consider(A, B, n);
  // edge pairs whose Gauss-map arcs cross (Gregorius 2013): A's arc between its edge's face
  // normals, B's between its negated face normals; touching arcs count (an extra axis only adds
  // an upper bound)
  const auto na = edgeFaceNormals(A);
  const auto nb = edgeFaceNormals(B);
  for (std::size_t i = 0; i < A.e.size(); ++i) {
    const R3& n1 = na[i][0];
    const R3& n2 = na[i][1];
    const R3 da = A.v[A.e[i][1]] - A.v[A.e[i][0]];
    const R3 n2xn1 = cross(n2, n1);
    for (std::size_t j = 0; j < B.e.size(); ++j) {
      const R3 m1 = -nb[j][0], m2 = -nb[j][1];
      const R3 m2xm1 = cross(m2, m1);
      const Real cba = dot(m1, n2xn1), dba = dot(m2, n2xn1);
      const Real adc = dot(n1, m2xm1), bdc = dot(n2, m2xm1);
      if (cba * dba <= 0 && adc * bdc <= 0 && cba * bdc >= 0) {
        R3 u;
        if (crossAxis(da, B.v[B.e[j][1]] - B.v[B.e[j][0]], u))
          scan.consider(A, B, u);
      }
    }
  }
  if (normal != nullptr)
    *normal = toVec3(scan.axis);
  return static_cast<double>(scan.best);
}

double bruteDepthAlong(const Polytope& a,
                       const Polytope& b,
                       const Transform& X_AB,
                       const Vec3& dir) {
  const RTransform T(X_AB);
  const R3 u = toR3(dir);
  Real hiA = -std::numeric_limits<Real>::infinity(), loB = std::numeric_limits<Real>::infinity();
  for (const auto& v : a.vertices()) {
    const Real d = dot(u, toR3(v.p));
    if (d > hiA)
      hiA = d;
  }
  for (const auto& v : b.vertices()) {
    const Real d = dot(u, T.apply(toR3(v.p)));
    if (d < loB)
      loB = d;
  }
  return static_cast<double>(hiA - loB);
}

bool depthAgreesWithFull(const Polytope& a,
                         const Polytope& b,
                         const Transform& X_AB,
                         double depth,
                         const Vec3& normal,
                         double full_depth,
                         double tol) {
  const Real len = std::sqrt(norm2(toR3(normal)));
  if (!(std::abs(len - 1) <= 1e-12L))
    return false;
  const Real along = bruteDepthAlong(a, b, X_AB, normal);
  return std::abs(along - depth) <= tol && depth <= full_depth + tol;
}

std::vector<Vec3> ellipsoidPoints(std::size_t n,
                                  double ax,
                                  double ay,
                                  double az,
                                  std::uint64_t seed) {
  // (the benchmark's hulls: keep this sequence stable)
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> pts;
  pts.reserve(n);
  while (pts.size() < n) {
    const Vec3 v{g(rng), g(rng), g(rng)};
    const double len = glm::length(v);
    if (len < 1e-6)
      continue;
    pts.push_back(v / len * Vec3{ax, ay, az});
  }
  return pts;
}

std::vector<Vec3> randomPointSet(std::mt19937_64& rng, std::size_t n, double size) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  n = std::max<std::size_t>(n, 4);
  const Vec3 axes{size * (0.3 + 0.7 * u(rng)), size * (0.3 + 0.7 * u(rng)),
                  size * (0.3 + 0.7 * u(rng))};
  auto inCube = [&] { return Vec3{u(rng), u(rng), u(rng)} * 2.0 - 1.0; };
  std::vector<Vec3> pts;
  pts.reserve(n + 8);
  switch (static_cast<int>(u(rng) * 8.0)) {
    case 0:  // on an ellipsoid
      return ellipsoidPoints(n, axes.x, axes.y, axes.z, rng());
    case 1: {  // box corners (parallel faces, parallel edges), the rest of the points inside
      for (int i = 0; i < 8; ++i) {
        pts.push_back(
            Vec3{i & 1 ? axes.x : -axes.x, i & 2 ? axes.y : -axes.y, i & 4 ? axes.z : -axes.z});
      }
      while (pts.size() < n)
        pts.push_back(inCube() * axes * 0.99);
      return pts;
    }
    case 2:  // a random cloud in a box
      while (pts.size() < n)
        pts.push_back(inCube() * axes);
      return pts;
    case 3:  // a random cloud in an ellipsoid (ball volume)
      while (pts.size() < n) {
        const Vec3 v = inCube();
        if (glm::dot(v, v) <= 1.0)
          pts.push_back(v * axes);
      }
      return pts;
    case 4: {  // a plate: one axis thinner by up to 1e4
      const double thin = std::pow(10.0, -1.0 - 3.0 * u(rng));
      while (pts.size() < n)
        pts.push_back(inCube() * Vec3{axes.x, axes.y, size * thin});
      return pts;
    }
    case 5: {  // a needle: two axes thinner by up to 1e4
      const double thin = std::pow(10.0, -1.0 - 3.0 * u(rng));
      while (pts.size() < n) {
        pts.push_back(inCube() * Vec3{size, size * thin * (0.5 + 0.5 * u(rng)), size * thin});
      }
      return pts;
    }
    case 6: {  // a prism over a regular polygon (parallel caps, parallel side edges)
      const std::size_t k = std::max<std::size_t>(3, n / 2);
      const double phase = u(rng);
      for (std::size_t i = 0; i < k; ++i) {
        const double t =
            (static_cast<double>(i) + phase) * 2.0 * std::numbers::pi / static_cast<double>(k);
        pts.push_back({axes.x * std::cos(t), axes.y * std::sin(t), -axes.z});
        pts.push_back({axes.x * std::cos(t), axes.y * std::sin(t), axes.z});
      }
      return pts;
    }
    default: {  // a sliver: a random cloud squeezed by up to 1e4 along a random direction
      const double thin = std::pow(10.0, -1.0 - 3.0 * u(rng));
      const Vec3 dir = glm::normalize(Vec3{g(rng), g(rng), g(rng)} + Vec3{1e-9, 0.0, 0.0});
      while (pts.size() < n) {
        const Vec3 v = inCube() * axes;
        pts.push_back(v - dir * (glm::dot(v, dir) * (1.0 - thin)));
      }
      return pts;
    }
  }
}

geom::Quat randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  geom::Quat q(1.0, 0.0, 0.0, 0.0);
  for (double len = 0.0; len < 1e-6;) {
    q = geom::Quat(g(rng), g(rng), g(rng), g(rng));
    len = glm::length(q);
  }
  return glm::normalize(q);
}

}  // namespace hapticd::reference
