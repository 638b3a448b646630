// Penetration depth by GJK and EPA on the Minkowski difference M = A - B (Gilbert, Johnson,
// Keerthi 1988; van den Bergen, "Proximity Queries and Penetration Depth Computation on 3D Game
// Objects", GDC 2001), with supports climbed over the vertex graphs from last tick's, and an
// answer that is certified or refused: the final polytope is checked to be convex and to hold the
// origin, so that its nearest face plane bounds the depth from below, while that face's support
// bounds it from above. A refusal sends the caller to the separating-axis method.
#include <array>
#include <cmath>
#include <limits>

#include "core/collision/penetration.h"

namespace hapticd::collision {
namespace {

constexpr int kMaxVerts = 128;
constexpr int kMaxFaces = 256;
constexpr int kMaxIterations = 96;

struct SupportPoint {
  Vec3 w;                // a - b, in A's frame
  std::uint32_t ia, ib;  // vertex indices
};

struct Minkowski {
  const Polytope& a;
  const Polytope& b;
  const Transform& X_AB;
  Transform X_BA;
  std::uint32_t ha, hb;
  SupportPoint support(const Vec3& d) {
    ha = a.support(d, ha);
    hb = b.support(X_BA.rotate(-d), hb);
    return {a.vertices()[ha].p - X_AB.apply(b.vertices()[hb].p), ha, hb};
  }
};

// GJK's boolean test: a tetrahedron of support points that holds the origin in its interior.
// The simplex is kept with its newest point last (the classic "do simplex" of the GJK literature).
bool gjkSimplex(Minkowski& m, Vec3 d, std::array<SupportPoint, 4>& s, double eps) {
  if (!(glm::dot(d, d) > 0.0))
    d = Vec3{1.0, 0.0, 0.0};
  s[0] = m.support(d);
  int n = 1;
  d = -s[0].w;
  auto triangle = [&]() {  // s = [c, b, a], a newest; sets d; may drop to a line
    const Vec3 a = s[2].w, b = s[1].w, c = s[0].w;
    const Vec3 ab = b - a, ac = c - a, ao = -a, abc = glm::cross(ab, ac);
    if (glm::dot(glm::cross(abc, ac), ao) > 0.0) {
      s[1] = s[2];  // [c, a]
      n = 2;
      d = glm::cross(glm::cross(ac, ao), ac);
    } else if (glm::dot(glm::cross(ab, abc), ao) > 0.0) {
      s[0] = s[1];  // [b, a]
      s[1] = s[2];
      n = 2;
      d = glm::cross(glm::cross(ab, ao), ab);
    } else if (glm::dot(abc, ao) > 0.0) {
      d = abc;  // origin above [c, b, a]
    } else {
      std::swap(s[0], s[1]);  // [b, c, a]: origin above
      d = -abc;
    }
  };
  for (int it = 0; it < 64; ++it) {
    if (!(glm::length(d) > eps))
      return false;  // the origin is on the simplex: touching
    const SupportPoint p = m.support(d);
    if (glm::dot(p.w, d) <= eps * glm::length(d))
      return false;  // the origin is not inside M
    s[static_cast<std::size_t>(n++)] = p;
    if (n == 2) {
      const Vec3 ab = s[0].w - s[1].w, ao = -s[1].w;
      d = glm::cross(glm::cross(ab, ao), ab);
    } else if (n == 3) {
      triangle();
    } else {
      // s = [d, c, b, a]; the origin is above triangle [d, c, b] (toward a)
      const Vec3 a = s[3].w, b = s[2].w, c = s[1].w, dd = s[0].w, ao = -a;
      const Vec3 abc = glm::cross(b - a, c - a), acd = glm::cross(c - a, dd - a),
                 adb = glm::cross(dd - a, b - a);
      if (glm::dot(abc, ao) > 0.0) {
        s[0] = s[1], s[1] = s[2], s[2] = s[3];  // [c, b, a]
        n = 3;
        triangle();
      } else if (glm::dot(acd, ao) > 0.0) {
        s[2] = s[3];  // [d, c, a]
        n = 3;
        triangle();
      } else if (glm::dot(adb, ao) > 0.0) {
        s[1] = s[0], s[0] = s[2], s[2] = s[3];  // [b, d, a]
        n = 3;
        triangle();
      } else {
        return true;
      }
    }
  }
  return false;
}

struct Face {
  std::array<int, 3> v;  // counter-clockwise seen from outside
  Vec3 n;                // outward unit normal
  double dist;           // plane distance from the origin
};

// EPA's polytope P inside A - B: fixed capacities, no allocation (the arrays are left
// uninitialised: only [0, nv) and [0, nf) are ever read)
struct ExpandingPolytope {
  std::array<SupportPoint, kMaxVerts> verts;
  std::array<Face, kMaxFaces> faces;
  int nv = 0, nf = 0;
  Vec3 inner{0.0};  // a point inside P (the first tetrahedron's centroid)
  double eps = 0.0, size = 0.0;

  const SupportPoint& vert(int i) const { return verts[static_cast<std::size_t>(i)]; }
  const Face& face(int f) const { return faces[static_cast<std::size_t>(f)]; }

  // the face (i, j, k) oriented outward; false for a sliver or when full
  bool makeFace(int i, int j, int k) {
    if (nf >= kMaxFaces)
      return false;
    const Vec3& p = vert(i).w;
    Vec3 n = glm::cross(vert(j).w - p, vert(k).w - p);
    const double len = glm::length(n);
    if (!(len > eps * size))
      return false;  // a sliver face: refuse
    n /= len;
    Face f{{i, j, k}, n, glm::dot(n, p)};
    if (glm::dot(n, p - inner) < 0.0) {  // orient outward (the inner point is inside P)
      std::swap(f.v[1], f.v[2]);
      f.n = -n;
      f.dist = -f.dist;
    }
    faces[static_cast<std::size_t>(nf++)] = f;
    return true;
  }

  // the tetrahedron GJK found
  bool start(const std::array<SupportPoint, 4>& tet) {
    for (const auto& p : tet)
      verts[static_cast<std::size_t>(nv++)] = p;
    inner = (verts[0].w + verts[1].w + verts[2].w + verts[3].w) * 0.25;
    return makeFace(0, 1, 2) && makeFace(0, 1, 3) && makeFace(0, 2, 3) && makeFace(1, 2, 3);
  }

  // adds point w to P: removes the faces it sees and closes the hole from the horizon to w.
  // Returns false when P cannot stay a valid polytope (then the caller refuses).
  bool insert(const SupportPoint& w) {
    if (nv >= kMaxVerts)
      return false;
    std::array<std::array<int, 2>, 3 * static_cast<std::size_t>(kMaxFaces)> edges;
    int ne = 0;
    for (int f = 0; f < nf;) {
      const Face fc = faces[static_cast<std::size_t>(f)];
      if (glm::dot(fc.n, w.w - vert(fc.v[0]).w) <= eps) {
        ++f;
        continue;
      }
      faces[static_cast<std::size_t>(f)] = faces[static_cast<std::size_t>(--nf)];  // remove it
      for (int e = 0; e < 3; ++e) {
        const int i = fc.v[static_cast<std::size_t>(e)],
                  j = fc.v[static_cast<std::size_t>((e + 1) % 3)];
        bool shared = false;
        for (int k = 0; k < ne; ++k) {
          if (edges[static_cast<std::size_t>(k)][0] == j &&
              edges[static_cast<std::size_t>(k)][1] == i) {
            edges[static_cast<std::size_t>(k)] = edges[static_cast<std::size_t>(--ne)];
            shared = true;
            break;
          }
        }
        if (!shared)
          edges[static_cast<std::size_t>(ne++)] = {i, j};
      }
    }
    if (ne == 0)
      return true;  // w is inside P: nothing to do
    if (ne < 3)
      return false;
    verts[static_cast<std::size_t>(nv)] = w;
    for (int k = 0; k < ne; ++k) {
      if (!makeFace(edges[static_cast<std::size_t>(k)][0], edges[static_cast<std::size_t>(k)][1],
                    nv))
        return false;
    }
    ++nv;
    return true;
  }

  // the face nearest the origin, -1 when there is none
  int nearest() const {
    int best = -1;
    for (int f = 0; f < nf; ++f) {
      if (best < 0 || face(f).dist < face(best).dist)
        best = f;
    }
    return best;
  }

  // the certificate: P is convex and holds the origin, so the nearest face plane is a lower bound
  bool convexAroundOrigin() const {
    for (int f = 0; f < nf; ++f) {
      const Face& fc = face(f);
      if (fc.dist < -eps)
        return false;
      const Vec3& p0 = vert(fc.v[0]).w;
      for (int v = 0; v < nv; ++v) {
        if (glm::dot(fc.n, vert(v).w - p0) > 1e-11 * size)
          return false;
      }
    }
    return true;
  }
};

// The Minkowski feature of the answer along n: a face of A or of B parallel to the normal, else
// two edges (at each support vertex, the edge most perpendicular to the normal).
void mtdFeature(const Polytope& a,
                const Polytope& b,
                const Transform& X_BA,
                const Vec3& n,
                const SupportPoint& p0,
                DepthResult& out) {
  out.kind = DepthFeature::kEdgeEdge;
  out.ia = out.ib = 0;
  double best_a = -2.0, best_b = -2.0;
  std::uint32_t fa = 0, fb = 0;
  const std::uint32_t sa = a.support(n, p0.ia);
  for (const auto& ve : a.vertexEdges(sa)) {
    for (const std::uint32_t f : a.edges()[ve.edge].face) {
      const double c = glm::dot(a.faces()[f].normal, n);
      if (c > best_a)
        best_a = c, fa = f;
    }
  }
  const Vec3 n_b = X_BA.rotate(-n);
  const std::uint32_t sb = b.support(n_b, p0.ib);
  for (const auto& ve : b.vertexEdges(sb)) {
    for (const std::uint32_t f : b.edges()[ve.edge].face) {
      const double c = glm::dot(b.faces()[f].normal, n_b);
      if (c > best_b)
        best_b = c, fb = f;
    }
  }
  if (best_a >= 1.0 - 1e-12 && best_a >= best_b) {
    out.kind = DepthFeature::kFaceA, out.ia = fa;
  } else if (best_b >= 1.0 - 1e-12) {
    out.kind = DepthFeature::kFaceB, out.ib = fb;
  } else {
    double ca = 2.0, cb = 2.0;
    for (const auto& ve : a.vertexEdges(sa)) {
      const double c = std::abs(glm::dot(ve.out, n));
      if (c < ca)
        ca = c, out.ia = ve.edge;
    }
    for (const auto& ve : b.vertexEdges(sb)) {
      const double c = std::abs(glm::dot(ve.out, n_b));
      if (c < cb)
        cb = c, out.ib = ve.edge;
    }
  }
}

// The answer from the nearest face bf: depth, normal, witness points from its barycentric
// coordinates. B translated by t leaves A - B - t; the origin leaves it first across the nearest
// face, so B moves by depth along that face's outward normal n.
void answer(const Polytope& a,
            const Polytope& b,
            const Transform& X_AB,
            const ExpandingPolytope& P,
            const Face& bf,
            DepthResult& out) {
  const double depth = bf.dist;
  const Vec3 n = bf.n;
  const SupportPoint& p0 = P.vert(bf.v[0]);
  const SupportPoint& p1 = P.vert(bf.v[1]);
  const SupportPoint& p2 = P.vert(bf.v[2]);
  const Vec3 q = n * depth;
  const Vec3 e0 = p1.w - p0.w, e1 = p2.w - p0.w, e2 = q - p0.w;
  const double d00 = glm::dot(e0, e0), d01 = glm::dot(e0, e1), d11 = glm::dot(e1, e1);
  const double d20 = glm::dot(e2, e0), d21 = glm::dot(e2, e1);
  const double den = d00 * d11 - d01 * d01;
  double l1 = den > 0.0 ? (d11 * d20 - d01 * d21) / den : 0.0;
  double l2 = den > 0.0 ? (d00 * d21 - d01 * d20) / den : 0.0;
  double l0 = 1.0 - l1 - l2;
  const Vec3 pa =
      a.vertices()[p0.ia].p * l0 + a.vertices()[p1.ia].p * l1 + a.vertices()[p2.ia].p * l2;
  const Vec3 pb = X_AB.apply(b.vertices()[p0.ib].p * l0 + b.vertices()[p1.ib].p * l1 +
                             b.vertices()[p2.ib].p * l2);
  out.depth = depth;
  out.normal = n;
  out.support_a = p0.ia;  // the final face's points are supports along n
  out.support_b = p0.ib;
  out.point_a = pa;
  out.point_b = pb;
}

// keep the points of P nearest the answer's plane (normal n) for the next tick
void keepWarm(const ExpandingPolytope& P, const Vec3& n, DepthCache& cache) {
  std::array<int, DepthCache::kWarm> keep{};
  int kept = 0;
  for (int v = 0; v < P.nv; ++v) {
    const double hv = glm::dot(P.vert(v).w, n);
    int at = kept < DepthCache::kWarm ? kept++ : DepthCache::kWarm;
    while (at > 0 && glm::dot(P.vert(keep[static_cast<std::size_t>(at - 1)]).w, n) < hv) {
      if (at < DepthCache::kWarm)
        keep[static_cast<std::size_t>(at)] = keep[static_cast<std::size_t>(at - 1)];
      --at;
    }
    if (at < DepthCache::kWarm)
      keep[static_cast<std::size_t>(at)] = v;
  }
  cache.warm_count = static_cast<std::uint8_t>(kept);
  for (int k = 0; k < kept; ++k) {
    cache.warm_a[static_cast<std::size_t>(k)] = P.vert(keep[static_cast<std::size_t>(k)]).ia;
    cache.warm_b[static_cast<std::size_t>(k)] = P.vert(keep[static_cast<std::size_t>(k)]).ib;
  }
}

}  // namespace

bool penetrationDepthEpa(const Polytope& a,
                         const Polytope& b,
                         const Transform& X_AB,
                         DepthCache& cache,
                         DepthResult& out) {
  const double size = std::max(a.radius(), b.radius());
  const double eps = 1e-13 * size;
  Minkowski m{a,
              b,
              X_AB,
              X_AB.inverse(),
              cache.support_a < a.vertices().size() ? cache.support_a : 0,
              cache.support_b < b.vertices().size() ? cache.support_b : 0};
  std::array<SupportPoint, 4> tet{};
  const Vec3 guess = cache.kind != DepthFeature::kNone && glm::dot(cache.normal, cache.normal) > 0.0
                         ? cache.normal
                         : a.centroid() - X_AB.apply(b.centroid());
  if (!gjkSimplex(m, guess, tet, eps))
    return false;

  ExpandingPolytope P;
  P.eps = eps;
  P.size = size;
  if (!P.start(tet))
    return false;
  // last tick's polytope near the answer, at this tick's pose: EPA then starts close to the end
  for (std::uint8_t k = 0; k < cache.warm_count; ++k) {
    const std::uint32_t ia = cache.warm_a[k], ib = cache.warm_b[k];
    if (ia >= a.vertices().size() || ib >= b.vertices().size())
      break;
    if (!P.insert({a.vertices()[ia].p - X_AB.apply(b.vertices()[ib].p), ia, ib}))
      return false;
  }

  int best = -1;
  double upper = std::numeric_limits<double>::infinity();
  Vec3 upper_n{0.0};
  for (int it = 0; it < kMaxIterations; ++it) {
    best = P.nearest();
    if (best < 0)
      return false;
    const Face& bf = P.face(best);
    if (bf.dist < -eps)
      return false;  // the origin is outside P
    // climb from the face's own vertex: it is a support point for a nearby direction
    m.ha = P.vert(bf.v[0]).ia;
    m.hb = P.vert(bf.v[0]).ib;
    const SupportPoint w = m.support(bf.n);
    const double h = glm::dot(bf.n, w.w);
    if (h < upper)
      upper = h, upper_n = bf.n;
    if (h - bf.dist <= eps)
      break;  // converged
    if (it + 1 == kMaxIterations)
      return false;
    if (!P.insert(w))
      return false;
  }
  if (best < 0)
    return false;
  const Face& bf = P.face(best);
  if (!P.convexAroundOrigin())
    return false;
  if (!(upper - bf.dist <= 1e-11 * size))
    return false;

  answer(a, b, X_AB, P, bf, out);
  mtdFeature(a, b, m.X_BA, bf.n, P.vert(bf.v[0]), out);
  cache.kind = out.kind;
  cache.ia = out.ia;
  cache.ib = out.ib;
  cache.support_a = m.ha;
  cache.support_b = m.hb;
  cache.normal = bf.n;
  keepWarm(P, bf.n, cache);
  return true;
}

}  // namespace hapticd::collision
