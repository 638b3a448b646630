#include "core/collision/penetration.h"

#include <cmath>
#include <limits>

#include "core/collision/segment.h"

namespace hapticd::collision {

namespace {

// The Minkowski-face test of Gauss-map arcs (Gregorius, "The Separating Axis Test between Convex
// Polyhedra", GDC 2013): arc (a, b) of an edge of A and arc (c, d) of an edge of -B intersect.
inline bool isMinkowskiFace(const Vec3& a, const Vec3& b, const Vec3& b_x_a, const Vec3& c,
                            const Vec3& d, const Vec3& d_x_c) {
  const double cba = glm::dot(c, b_x_a);
  const double dba = glm::dot(d, b_x_a);
  const double adc = glm::dot(a, d_x_c);
  const double bdc = glm::dot(b, d_x_c);
  return cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0;
}

}  // namespace

DepthResult penetrationDepthExact(const Polytope& a, const Polytope& b, const Transform& X_AB,
                                  DepthCache& cache) {
  const Transform X_BA = X_AB.inverse();
  DepthResult best;
  best.depth = std::numeric_limits<double>::infinity();
  std::uint32_t hint_a = cache.support_a < a.vertices().size() ? cache.support_a : 0;
  std::uint32_t hint_b = cache.support_b < b.vertices().size() ? cache.support_b : 0;
  std::uint32_t best_support = 0;

  // faces of A: B moves along the face normal
  const auto fa = a.faces();
  for (std::uint32_t i = 0; i < fa.size(); ++i) {
    const Vec3& n = fa[i].normal;
    hint_b = b.support(X_BA.rotate(-n), hint_b);
    const double d = fa[i].offset - glm::dot(n, X_AB.apply(b.vertices()[hint_b].p));
    if (d < best.depth) {
      best.depth = d, best.normal = n, best.kind = DepthFeature::kFaceA, best.ia = i;
      best_support = hint_b;
      if (d < 0.0) break;
    }
  }
  // faces of B: B moves against its face normal
  const auto fb = b.faces();
  if (best.depth >= 0.0) {
    for (std::uint32_t j = 0; j < fb.size(); ++j) {
      const Vec3 m = X_AB.rotate(fb[j].normal);
      hint_a = a.support(-m, hint_a);
      const double d = fb[j].offset + glm::dot(m, X_AB.t) - glm::dot(m, a.vertices()[hint_a].p);
      if (d < best.depth) {
        best.depth = d, best.normal = -m, best.kind = DepthFeature::kFaceB, best.ib = j;
        best_support = hint_a;
        if (d < 0.0) break;
      }
    }
  }
  // edge pairs whose Gauss-map arcs cross
  if (best.depth >= 0.0) {
    const auto ea = a.edges();
    const auto eb = b.edges();
    for (std::uint32_t j = 0; j < eb.size() && best.depth >= 0.0; ++j) {
      const Vec3 c = -X_AB.rotate(fb[eb[j].face[0]].normal);
      const Vec3 d = -X_AB.rotate(fb[eb[j].face[1]].normal);
      const Vec3 d_x_c = glm::cross(d, c);
      const Vec3 dir_b = X_AB.rotate(eb[j].dir);
      const Vec3 pb = X_AB.apply(b.vertices()[eb[j].tail].p);
      for (std::uint32_t i = 0; i < ea.size(); ++i) {
        const Vec3& na = fa[ea[i].face[0]].normal;
        const Vec3& nb = fa[ea[i].face[1]].normal;
        if (!isMinkowskiFace(na, nb, glm::cross(nb, na), c, d, d_x_c)) continue;
        Vec3 axis = glm::cross(ea[i].dir, dir_b);
        const double len = glm::length(axis);
        if (len < 1e-9) continue;  // parallel edges: covered by the face normals
        axis /= len;
        if (glm::dot(axis, na + nb) < 0.0) axis = -axis;
        const double depth = glm::dot(axis, a.vertices()[ea[i].tail].p - pb);
        if (depth < best.depth) {
          best.depth = depth, best.normal = axis, best.kind = DepthFeature::kEdgeEdge;
          best.ia = i, best.ib = j;
          if (depth < 0.0) break;
        }
      }
    }
  }

  // witness points
  switch (best.kind) {
    case DepthFeature::kFaceA:
      best.point_b = X_AB.apply(b.vertices()[best_support].p);
      best.point_a = best.point_b + best.normal * best.depth;
      cache.support_b = best_support;
      break;
    case DepthFeature::kFaceB:
      best.point_a = a.vertices()[best_support].p;
      best.point_b = best.point_a - best.normal * best.depth;
      cache.support_a = best_support;
      break;
    case DepthFeature::kEdgeEdge: {
      const auto& e1 = a.edges()[best.ia];
      const auto& e2 = b.edges()[best.ib];
      const auto s = detail::closestSegments(
          a.vertices()[e1.tail].p, a.vertices()[e1.head].p,
          X_AB.apply(b.vertices()[e2.tail].p), X_AB.apply(b.vertices()[e2.head].p));
      best.point_a = s.c1;
      best.point_b = s.c2;
      break;
    }
    case DepthFeature::kNone:
      break;
  }
  cache.kind = best.kind;
  cache.ia = best.ia;
  cache.ib = best.ib;
  return best;
}

double depthAlong(const Polytope& a, const Polytope& b, const Transform& X_AB, const Vec3& dir,
                  std::uint32_t& hint_a, std::uint32_t& hint_b) {
  hint_a = a.support(dir, hint_a);
  const Vec3 dir_b = glm::transpose(X_AB.R) * (-dir);
  hint_b = b.support(dir_b, hint_b);
  return glm::dot(dir, a.vertices()[hint_a].p) - glm::dot(dir, X_AB.apply(b.vertices()[hint_b].p));
}

}  // namespace hapticd::collision
