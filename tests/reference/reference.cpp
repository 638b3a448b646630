#include "tests/reference/reference.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapticd::reference {
namespace {

// Closest point parameters of segments [p1, q1], [p2, q2] (Ericson §5.1.9), written here again on
// purpose: the reference shares no code with the implementation under test.
double segmentDistance2(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2, Vec3& c1,
                        Vec3& c2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
  const double c = glm::dot(d1, r), b = glm::dot(d1, d2);
  const double denom = a * e - b * b;
  double s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  c1 = p1 + d1 * s;
  c2 = p2 + d2 * t;
  return glm::dot(c1 - c2, c1 - c2);
}

// Distance from x to the convex polygon face f of p when x projects inside it; else -1.
double pointFaceInside(const Polytope& p, std::uint32_t f, const Vec3& x, Vec3& foot) {
  const auto& face = p.faces()[f];
  const auto fe = p.faceEdges(f);
  for (std::size_t k = 0; k < fe.size(); ++k) {
    const Vec3& v0 = p.vertices()[fe[k].vertex].p;
    const Vec3& v1 = p.vertices()[fe[(k + 1) % fe.size()].vertex].p;
    if (glm::dot(glm::cross(v1 - v0, x - v0), face.normal) < 0.0) return -1.0;
  }
  const double h = glm::dot(face.normal, x) - face.offset;
  foot = x - face.normal * h;
  return std::abs(h);
}

struct Extent {
  double lo, hi;
};
Extent extent(const Polytope& p, const Transform& X, const Vec3& u) {
  Extent e{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const auto& v : p.vertices()) {
    const double d = glm::dot(u, X.apply(v.p));
    e.lo = std::min(e.lo, d);
    e.hi = std::max(e.hi, d);
  }
  return e;
}

}  // namespace

double bruteMinkowskiDepth(const Polytope& a, const Polytope& b, const Transform& X_AB,
                           Vec3* normal) {
  double best = std::numeric_limits<double>::infinity();
  auto axis = [&](const Vec3& u) {
    const double d = extent(a, Transform{}, u).hi - extent(b, X_AB, u).lo;
    if (d < best) {
      best = d;
      if (normal != nullptr) *normal = u;
    }
  };
  for (const auto& f : a.faces()) axis(f.normal);
  for (const auto& f : b.faces()) axis(-X_AB.rotate(f.normal));
  // an edge pair is a face of A - B when the arc of A's edge (between its face normals) crosses
  // the arc of B's edge negated: the two great circles cross inside both arcs
  for (const auto& e1 : a.edges()) {
    const Vec3 n1 = a.faces()[e1.face[0]].normal, n2 = a.faces()[e1.face[1]].normal;
    for (const auto& e2 : b.edges()) {
      const Vec3 m1 = -X_AB.rotate(b.faces()[e2.face[0]].normal);
      const Vec3 m2 = -X_AB.rotate(b.faces()[e2.face[1]].normal);
      const Vec3 p1 = glm::cross(n1, n2), p2 = glm::cross(m1, m2);
      Vec3 u = glm::cross(p1, p2);
      const double len = glm::length(u);
      if (len < 1e-12) continue;
      u /= len;
      if (glm::dot(u, n1 + n2) < 0.0) u = -u;
      // u must lie between n1 and n2, and between m1 and m2
      const bool on1 = glm::dot(glm::cross(n1, u), p1) >= 0.0 && glm::dot(glm::cross(u, n2), p1) >= 0.0;
      const bool on2 = glm::dot(glm::cross(m1, u), p2) >= 0.0 && glm::dot(glm::cross(u, m2), p2) >= 0.0;
      if (on1 && on2) axis(u);
    }
  }
  return best;
}

double bruteSeparatedDistance(const Polytope& a, const Polytope& b, const Transform& X_AB) {
  double d2 = std::numeric_limits<double>::infinity();
  const Transform X_BA = X_AB.inverse();
  Vec3 foot, c1, c2;
  for (const auto& v : a.vertices()) {
    const Vec3 x = X_BA.apply(v.p);
    for (std::uint32_t f = 0; f < b.faces().size(); ++f) {
      const double h = pointFaceInside(b, f, x, foot);
      if (h >= 0.0) d2 = std::min(d2, h * h);
    }
  }
  for (const auto& v : b.vertices()) {
    const Vec3 x = X_AB.apply(v.p);
    for (std::uint32_t f = 0; f < a.faces().size(); ++f) {
      const double h = pointFaceInside(a, f, x, foot);
      if (h >= 0.0) d2 = std::min(d2, h * h);
    }
  }
  std::vector<std::pair<Vec3, Vec3>> eb;
  for (const auto& e2 : b.edges()) {
    eb.emplace_back(X_AB.apply(b.vertices()[e2.tail].p), X_AB.apply(b.vertices()[e2.head].p));
  }
  for (const auto& e1 : a.edges()) {
    for (const auto& [t, h] : eb) {
      d2 = std::min(d2, segmentDistance2(a.vertices()[e1.tail].p, a.vertices()[e1.head].p, t, h, c1, c2));
    }
  }
  return std::sqrt(d2);
}

RefAnswer bruteForce(const Polytope& a, const Polytope& b, const Transform& X_AB) {
  const Transform I{};
  RefAnswer out;
  // separating axes: the overlap along u (B moving along +u) is max_A(u.x) - min_B(u.x)
  double best = std::numeric_limits<double>::infinity();
  Vec3 best_u{0.0};
  auto axis = [&](Vec3 u) {
    const double len = glm::length(u);
    if (len < 1e-9) return;
    u /= len;
    for (int sign = 0; sign < 2; ++sign) {
      const Extent ea = extent(a, I, u), eb = extent(b, X_AB, u);
      const double overlap = ea.hi - eb.lo;
      if (overlap < best) best = overlap, best_u = u;
      u = -u;
    }
  };
  for (const auto& f : a.faces()) axis(f.normal);
  for (const auto& f : b.faces()) axis(X_AB.rotate(f.normal));
  for (const auto& e1 : a.edges()) {
    for (const auto& e2 : b.edges()) axis(glm::cross(e1.dir, X_AB.rotate(e2.dir)));
  }
  if (best > 0.0) {
    out.overlapping = true;
    out.signed_distance = -best;
    out.normal = best_u;
    return out;
  }
  // separated: the minimum over vertex-face and edge-edge pairs
  double d2 = std::numeric_limits<double>::infinity();
  auto consider = [&](double dd, const Vec3& pa, const Vec3& pb) {
    if (dd < d2) d2 = dd, out.point_a = pa, out.point_b = pb;
  };
  const Transform X_BA = X_AB.inverse();
  for (const auto& v : a.vertices()) {
    const Vec3 x = X_BA.apply(v.p);
    for (std::uint32_t f = 0; f < b.faces().size(); ++f) {
      Vec3 foot;
      const double h = pointFaceInside(b, f, x, foot);
      if (h >= 0.0) consider(h * h, v.p, X_AB.apply(foot));
    }
  }
  for (const auto& v : b.vertices()) {
    const Vec3 x = X_AB.apply(v.p);
    for (std::uint32_t f = 0; f < a.faces().size(); ++f) {
      Vec3 foot;
      const double h = pointFaceInside(a, f, x, foot);
      if (h >= 0.0) consider(h * h, foot, x);
    }
  }
  for (const auto& e1 : a.edges()) {
    for (const auto& e2 : b.edges()) {
      Vec3 c1, c2;
      const double dd = segmentDistance2(a.vertices()[e1.tail].p, a.vertices()[e1.head].p,
                                         X_AB.apply(b.vertices()[e2.tail].p),
                                         X_AB.apply(b.vertices()[e2.head].p), c1, c2);
      consider(dd, c1, c2);
    }
  }
  out.signed_distance = std::sqrt(d2);
  const Vec3 d = out.point_b - out.point_a;
  out.normal = out.signed_distance > 0.0 ? d / out.signed_distance : best_u;
  return out;
}

double bruteDepthAlong(const Polytope& a, const Polytope& b, const Transform& X_AB,
                       const Vec3& dir) {
  return extent(a, Transform{}, dir).hi - extent(b, X_AB, dir).lo;
}

std::vector<Vec3> ellipsoidPoints(std::size_t n, double ax, double ay, double az,
                                  std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> pts;
  pts.reserve(n);
  while (pts.size() < n) {
    const Vec3 v{g(rng), g(rng), g(rng)};
    const double len = glm::length(v);
    if (len < 1e-6) continue;
    pts.push_back(v / len * Vec3{ax, ay, az});
  }
  return pts;
}

std::vector<Vec3> randomPointSet(std::mt19937_64& rng, std::size_t n, double size) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> pts;
  const int family = static_cast<int>(u(rng) * 4.0);
  const Vec3 axes{size * (0.3 + 0.7 * u(rng)), size * (0.3 + 0.7 * u(rng)), size * (0.3 + 0.7 * u(rng))};
  switch (family) {
    case 0:  // on an ellipsoid
      return ellipsoidPoints(std::max<std::size_t>(n, 4), axes.x, axes.y, axes.z,
                             static_cast<std::uint64_t>(rng()));
    case 1:  // box corners (parallel faces, parallel edges)
      for (int i = 0; i < 8; ++i) {
        pts.push_back(Vec3{i & 1 ? axes.x : -axes.x, i & 2 ? axes.y : -axes.y, i & 4 ? axes.z : -axes.z});
      }
      return pts;
    case 2:  // a random cloud in a box
      for (std::size_t i = 0; i < std::max<std::size_t>(n, 4); ++i) {
        pts.push_back((Vec3{u(rng), u(rng), u(rng)} * 2.0 - 1.0) * axes);
      }
      return pts;
    default: {  // a sliver: aspect up to 1e4
      const double thin = std::pow(10.0, -1.0 - 3.0 * u(rng));
      for (std::size_t i = 0; i < std::max<std::size_t>(n, 6); ++i) {
        const Vec3 v = (Vec3{u(rng), u(rng), u(rng)} * 2.0 - 1.0);
        pts.push_back(Vec3{v.x * size, v.y * size * thin, v.z * size * (i % 2 ? thin : 0.3)});
      }
      return pts;
    }
  }
}

geom::Quat randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  geom::Quat q(g(rng), g(rng), g(rng), g(rng));
  return glm::normalize(q);
}

}  // namespace hapticd::reference
