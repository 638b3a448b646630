#include "core/collision/pair_query.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/collision/segment.h"

namespace hapticd::collision {
namespace {

// Exact distance by brute force (vertex-face and edge-edge pairs). Only reached when the walk hits
// its iteration cap, which the tests show never happens; kept so that a bug cannot give a wrong
// answer. Any thread.
void bruteDistance(const Polytope& a, const Polytope& b, const Transform& X_AB, PairResult& r) {
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](const Vec3& pa, const Vec3& pb, Feature fa, Feature fb) {
    const Vec3 d = pb - pa;
    const double d2 = glm::dot(d, d);
    if (d2 < best)
      best = d2, r.point_a = pa, r.point_b = pb, r.fa = fa, r.fb = fb;
  };
  for (std::uint32_t i = 0; i < a.edges().size(); ++i) {
    const auto& ea = a.edges()[i];
    for (std::uint32_t j = 0; j < b.edges().size(); ++j) {
      const auto& eb = b.edges()[j];
      const auto s = detail::closestSegments(a.vertices()[ea.tail].p, a.vertices()[ea.head].p,
                                             X_AB.apply(b.vertices()[eb.tail].p),
                                             X_AB.apply(b.vertices()[eb.head].p));
      consider(s.c1, s.c2, Feature::edge(i), Feature::edge(j));
    }
  }
  auto pointFace = [](const Polytope& p, std::uint32_t f, const Vec3& x, Vec3& out) {
    for (const auto& fe : p.faceEdges(f)) {
      if (glm::dot(x - p.vertices()[fe.vertex].p, fe.side) < 0.0)
        return false;
    }
    out = x - p.faces()[f].normal * (glm::dot(p.faces()[f].normal, x) - p.faces()[f].offset);
    return true;
  };
  const Transform X_BA = X_AB.inverse();
  for (std::uint32_t v = 0; v < a.vertices().size(); ++v) {
    const Vec3 x = X_BA.apply(a.vertices()[v].p);
    for (std::uint32_t f = 0; f < b.faces().size(); ++f) {
      Vec3 q;
      if (pointFace(b, f, x, q))
        consider(a.vertices()[v].p, X_AB.apply(q), Feature::vertex(v), Feature::face(f));
    }
  }
  for (std::uint32_t v = 0; v < b.vertices().size(); ++v) {
    const Vec3 x = X_AB.apply(b.vertices()[v].p);
    for (std::uint32_t f = 0; f < a.faces().size(); ++f) {
      Vec3 q;
      if (pointFace(a, f, x, q))
        consider(q, x, Feature::face(f), Feature::vertex(v));
    }
  }
  r.distance = std::sqrt(best);
  const Vec3 d = r.point_b - r.point_a;
  r.normal = r.distance > 0.0 ? d / r.distance : Vec3{1.0, 0.0, 0.0};
}

// The feature of p (placed in A's frame by X) holding x (A's frame) within tol, among vertex v
// and the edges and faces around it, lowest dimension first; none when x is not on them. A depth
// result's witness lies in the support set along its normal, which holds its support vertex v.
Feature featureAt(const Polytope& p,
                  const Transform& X,
                  std::uint32_t v,
                  const Vec3& x_A,
                  double tol) {
  if (v >= p.vertices().size())
    return {};
  const Vec3 x = X.inverse().apply(x_A);
  const Vec3& pv = p.vertices()[v].p;
  if (glm::length(x - pv) <= tol)
    return Feature::vertex(v);
  for (const auto& ve : p.vertexEdges(v)) {
    const Vec3& q = p.vertices()[ve.other].p;
    if (glm::length(x - (pv + (q - pv) * detail::closestOnSegment(x, pv, q))) <= tol) {
      return Feature::edge(ve.edge);
    }
  }
  for (const auto& ve : p.vertexEdges(v)) {
    for (const std::uint32_t f : p.edges()[ve.edge].face) {
      const auto& face = p.faces()[f];
      bool inside = std::abs(glm::dot(face.normal, x) - face.offset) <= tol;
      for (const auto& fe : p.faceEdges(f)) {
        inside = inside && glm::dot(x - p.vertices()[fe.vertex].p, fe.side) >= -tol;
      }
      if (inside)
        return Feature::face(f);
    }
  }
  return {};
}

// The depth: the coherent method's when the cache has a tracker.
DepthResult depthOf(const Polytope& a,
                    const Polytope& b,
                    const Transform& X_AB,
                    PairCache& cache,
                    DepthScratch& scratch) {
  return cache.tracker != nullptr
             ? penetrationDepthCoherent(a, b, X_AB, *cache.tracker, cache.depth, scratch)
             : penetrationDepth(a, b, X_AB, cache.depth, scratch);
}

// The answer of an overlapping pair from its minimal translation.
void penetrating(const Polytope& a,
                 const Polytope& b,
                 const Transform& X_AB,
                 const DepthResult& d,
                 PairResult& r) {
  r.status = ContactStatus::kPenetrating;
  r.distance = -d.depth;
  r.normal = d.normal;
  r.point_a = d.point_a;
  r.point_b = d.point_b;
  r.fa = d.kind == DepthFeature::kFaceB   ? Feature{}
         : d.kind == DepthFeature::kFaceA ? Feature::face(d.ia)
                                          : Feature::edge(d.ia);
  r.fb = d.kind == DepthFeature::kFaceA   ? Feature{}
         : d.kind == DepthFeature::kFaceB ? Feature::face(d.ib)
                                          : Feature::edge(d.ib);
  r.manifold = manifoldFromDepth(a, b, X_AB, d);
}

// The normal, witnesses, closest features and manifold of `r` from the walk's answer `c`.
inline void fromWalk(const Polytope& a,
                     const Polytope& b,
                     const Transform& X_AB,
                     const ClosestResult& c,
                     PairResult& r) {
  r.normal = c.normal;
  r.point_a = c.point_a;
  r.point_b = c.point_b;
  r.fa = c.fa;
  r.fb = c.fb;
  manifoldFromClosest(a, b, X_AB, c, r.manifold);
}

}  // namespace

PairResult queryPair(const Polytope& a,
                     const Polytope& b,
                     const Transform& X_AB,
                     PairCache& cache,
                     const QueryOptions& options) {
  return queryPair(a, b, X_AB, cache, DepthScratch::forThisThread(), options);
}

PairResult queryPair(const Polytope& a,
                     const Polytope& b,
                     const Transform& X_AB,
                     PairCache& cache,
                     DepthScratch& scratch,
                     const QueryOptions& options) {
  PairResult r;
  queryPair(a, b, X_AB, cache, scratch, options, r);
  return r;
}

void queryPair(const Polytope& a,
               const Polytope& b,
               const Transform& X_AB,
               PairCache& cache,
               DepthScratch& scratch,
               const QueryOptions& options,
               PairResult& r) {
  const double tol = options.touch_tolerance * std::max(a.radius(), b.radius());
  r.iterations = 0;
  if (cache.penetrating) {
    // overlapping last tick: the depth first; the walk only once they come apart
    const DepthResult d = depthOf(a, b, X_AB, cache, scratch);
    if (d.depth > tol) {
      penetrating(a, b, X_AB, d, r);
      return;
    }
    cache.penetrating = false;
  }
  const ClosestResult c = closestFeatures(a, b, X_AB, cache.features, options);
  r.iterations = c.iterations;
  if (c.end == WalkEnd::kConverged && c.distance > tol) {
    r.status = ContactStatus::kSeparated;
    r.distance = c.distance;
    fromWalk(a, b, X_AB, c, r);
    return;
  }
  // touching, overlapping, or a walk that gave up: the separating-axis answer decides
  const DepthResult d = depthOf(a, b, X_AB, cache, scratch);
  if (d.depth > tol) {
    penetrating(a, b, X_AB, d, r);
    cache.penetrating = true;
    return;
  }
  if (c.end == WalkEnd::kConverged) {
    // touching: the walk's exact pair, the separating axis's normal
    r.status = ContactStatus::kTouching;
    r.distance = d.depth > 0.0 ? -d.depth : c.distance;
    ClosestResult cn = c;
    cn.normal = d.normal;
    fromWalk(a, b, X_AB, cn, r);
    return;
  }
  if (d.depth >= 0.0) {
    // overlapping by no more than the tolerance: touching
    r.status = ContactStatus::kTouching;
    r.distance = -d.depth;
    r.normal = d.normal;
    r.point_a = d.point_a;
    r.point_b = d.point_b;
    // the closest features: those holding the witnesses (the walk stopped at a crossing)
    const double on = 1e-10 * std::max(a.radius(), b.radius());
    r.fa = featureAt(a, Transform{}, d.support_a, d.point_a, on);
    r.fb = featureAt(b, X_AB, d.support_b, d.point_b, on);
    ManifoldOptions touching;
    touching.touching = true;
    r.manifold = manifoldFromDepth(a, b, X_AB, d, touching);
    return;
  }
  // the walk claimed penetration (or gave up) but a separating axis exists
  bruteDistance(a, b, X_AB, r);
  r.status = r.distance > tol ? ContactStatus::kSeparated : ContactStatus::kTouching;
  if (r.status == ContactStatus::kTouching)
    r.normal = d.normal;
  ClosestResult cn;
  cn.fa = r.fa, cn.fb = r.fb, cn.point_a = r.point_a, cn.point_b = r.point_b;
  cn.normal = r.normal, cn.distance = r.distance;
  manifoldFromClosest(a, b, X_AB, cn, r.manifold);
}

}  // namespace hapticd::collision
