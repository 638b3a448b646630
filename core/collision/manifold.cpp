#include "core/collision/manifold.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/collision/clip.h"

namespace hapticd::collision {
namespace {

constexpr std::size_t kMaxPolygon = 256;

// A fixed-capacity polygon (no allocation). Points beyond the capacity are dropped and flagged.
struct Polygon {
  std::array<Vec3, kMaxPolygon> p;
  std::size_t n = 0;
  bool overflow = false;
  /// Copies only the points in use (the arrays are large).
  void copyFrom(const Polygon& o) {
    n = o.n;
    overflow = o.overflow;
    std::copy(o.p.begin(), o.p.begin() + static_cast<std::ptrdiff_t>(o.n), p.begin());
  }
  void push(const Vec3& v) {
    if (n < kMaxPolygon) {
      p[n++] = v;
    } else {
      overflow = true;
    }
  }
};

// The part of `in` with (x - o)·m >= -tol (clip.h); `out` keeps `in`'s overflow flag.
void clipPolygon(const Polygon& in, const Vec3& o, const Vec3& m, double tol, Polygon& out) {
  out.n = 0;
  out.overflow = in.overflow;
  detail::clipAgainstPlane(in, o, m, tol, out);
}

// A face seen in A's frame: plane and side planes.
struct FaceView {
  const Polytope* p = nullptr;
  const Transform* X = nullptr;  // p's frame -> A's frame
  std::uint32_t f = 0;
  Vec3 normal() const { return X->rotate(p->faces()[f].normal); }
};

void facePolygon(const FaceView& v, Polygon& out) {
  out.n = 0;
  for (const auto& fe : v.p->faceEdges(v.f))
    out.push(v.X->apply(v.p->vertices()[fe.vertex].p));
}

// Clips `poly` (in A's frame) against the side planes of face `ref`, `tol` outside them kept.
void clipToFace(const FaceView& ref, Polygon& poly, Polygon& scratch, double tol) {
  for (const auto& fe : ref.p->faceEdges(ref.f)) {
    clipPolygon(poly, ref.X->apply(ref.p->vertices()[fe.vertex].p), ref.X->rotate(fe.side), tol,
                scratch);
    poly.copyFrom(scratch);
    if (poly.n == 0)
      return;
  }
}

// Reduces to at most 4 well-spread points, the deepest always kept (Bullet's and Box2D's idea:
// deepest, farthest from it, then largest triangle, then largest quadrilateral).
void reduce(ContactPoint* in, std::size_t n, double merge, Manifold& m) {
  m.count = 0;
  if (n == 0)
    return;
  // merge coincident points (degenerate overlaps), keeping the deeper
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bool dup = false;
    for (std::size_t j = 0; j < kept && !dup; ++j) {
      if (glm::length(in[i].point - in[j].point) <= merge) {
        if (in[i].depth > in[j].depth)
          in[j] = in[i];
        dup = true;
      }
    }
    if (!dup)
      in[kept++] = in[i];
  }
  n = kept;
  if (n <= Manifold::kMaxPoints) {
    for (std::size_t i = 0; i < n; ++i)
      m.points[m.count++] = in[i];
    return;
  }
  std::array<std::size_t, 4> pick{};
  std::size_t deepest = 0;
  for (std::size_t i = 1; i < n; ++i) {
    if (in[i].depth > in[deepest].depth)
      deepest = i;
  }
  pick[0] = deepest;
  double best = -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 d = in[i].point - in[pick[0]].point;
    if (glm::dot(d, d) > best)
      best = glm::dot(d, d), pick[1] = i;
  }
  const Vec3 nrm = in[deepest].normal;
  best = -1.0;
  double signed_area = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double area = glm::dot(
        glm::cross(in[pick[1]].point - in[pick[0]].point, in[i].point - in[pick[0]].point), nrm);
    if (std::abs(area) > best)
      best = std::abs(area), pick[2] = i, signed_area = area;
  }
  // the fourth point: most area on the other side of the first edge
  best = -1.0;
  pick[3] = pick[0];
  for (std::size_t i = 0; i < n; ++i) {
    if (i == pick[0] || i == pick[1] || i == pick[2])
      continue;
    double area = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3& p0 = in[pick[k]].point;
      const Vec3& p1 = in[pick[(k + 1) % 3]].point;
      const double a = glm::dot(glm::cross(p1 - p0, in[i].point - p0), nrm);
      // outside the triangle's edge (orientation by the triangle's sign)
      if ((signed_area >= 0.0 ? -a : a) > area)
        area = signed_area >= 0.0 ? -a : a;
    }
    if (area > best)
      best = area, pick[3] = i;
  }
  std::size_t count = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    bool dup = false;
    for (std::size_t j = 0; j < k; ++j)
      dup = dup || pick[j] == pick[k];
    if (!dup)
      m.points[count++] = in[pick[k]];
  }
  m.count = static_cast<std::uint8_t>(count);
}

// The face among those incident to feature f of p whose normal is most aligned with `dir_p`
// (in p's own frame); returns its cosine.
double bestIncidentFace(const Polytope& p, Feature f, const Vec3& dir_p, std::uint32_t& face) {
  double best = -2.0;
  auto consider = [&](std::uint32_t k) {
    const double c = glm::dot(p.faces()[k].normal, dir_p);
    if (c > best)
      best = c, face = k;
  };
  switch (f.type) {
    case FeatureType::kFace:
      consider(f.index);
      break;
    case FeatureType::kEdge:
      consider(p.edges()[f.index].face[0]);
      consider(p.edges()[f.index].face[1]);
      break;
    case FeatureType::kVertex:
      for (const auto& ve : p.vertexEdges(f.index)) {
        consider(p.edges()[ve.edge].face[0]);
        consider(p.edges()[ve.edge].face[1]);
      }
      break;
    case FeatureType::kNone:
      break;
  }
  return best;
}

// The edge incident to feature f most perpendicular to `dir_p` (p's frame); returns |cos|.
double bestIncidentEdge(const Polytope& p, Feature f, const Vec3& dir_p, std::uint32_t& edge) {
  double best = 2.0;
  auto consider = [&](std::uint32_t k) {
    const double c = std::abs(glm::dot(p.edges()[k].dir, dir_p));
    if (c < best)
      best = c, edge = k;
  };
  switch (f.type) {
    case FeatureType::kEdge:
      consider(f.index);
      break;
    case FeatureType::kVertex:
      for (const auto& ve : p.vertexEdges(f.index))
        consider(ve.edge);
      break;
    case FeatureType::kFace:
      for (const auto& fe : p.faceEdges(f.index))
        consider(fe.edge);
      break;
    case FeatureType::kNone:
      break;
  }
  return best;
}

// False when no face or edge incident to feature f of p (a vertex: its edges and faces; an edge:
// itself and its two faces) can lie in the contact plane of normal dir_p (p's frame), i.e. when
// contactFeature() can only give the witness point and parallelEdges() cannot pick an edge here.
// A face within sin_tol of the plane (cosine >= sqrt(1 - sin_tol^2)) has every edge within
// sin_tol of it (|edge·dir| <= sin_tol), so edges all steeper than twice that (the factor covers
// rounding) rule the faces out too. A face feature is not tested (true). One dot product per
// edge: most near-contact pairs (a vertex against a face, crossing edges) end here.
bool mayLieInPlane(const Polytope& p, Feature f, const Vec3& dir_p, double sin_tol) {
  const double steep = 2.0 * sin_tol;
  switch (f.type) {
    case FeatureType::kVertex:
      for (const auto& ve : p.vertexEdges(f.index)) {
        if (std::abs(glm::dot(ve.out, dir_p)) <= steep)
          return true;
      }
      return false;
    case FeatureType::kEdge:
      return std::abs(glm::dot(p.edges()[f.index].dir, dir_p)) <= steep;
    case FeatureType::kFace:
      return true;
    case FeatureType::kNone:
      break;
  }
  return false;
}

// An edge against an edge whose manifold can only be the closest pair: neither edge has a face
// within sin_tol of the contact plane (normal n in A's frame, n_b in B's; A's faces facing along
// n, B's against it, as contactFeature() takes them) and the two edges do not both lie in the
// plane parallel to each other (parallelEdges()). The same verdict as the general path below,
// from four dot products and a cross product: crossing edges are half of a near-contact path, and
// their closest pair's normal, the edges' common perpendicular, always passes mayLieInPlane().
bool crossingEdgesOnly(const Polytope& a,
                       std::uint32_t ea_i,
                       const Vec3& n,
                       const Polytope& b,
                       std::uint32_t eb_i,
                       const Vec3& n_b,
                       const Transform& X_AB,
                       double sin_tol) {
  // a face is in the plane when its cosine is >= sqrt(1 - sin_tol^2), which is >= 1 - sin_tol:
  // cosines below that bound are out without the square root (it was a third of this test)
  const double below = 1.0 - sin_tol;
  const auto& ea = a.edges()[ea_i];
  const auto& eb = b.edges()[eb_i];
  double cos = -2.0;
  for (const std::uint32_t f : ea.face)
    cos = std::max(cos, glm::dot(a.faces()[f].normal, n));
  for (const std::uint32_t f : eb.face)
    cos = std::max(cos, glm::dot(b.faces()[f].normal, -n_b));
  if (cos >= below && cos >= std::sqrt(std::max(0.0, 1.0 - sin_tol * sin_tol)))
    return false;
  const bool in_plane =
      std::abs(glm::dot(ea.dir, n)) <= sin_tol && std::abs(glm::dot(eb.dir, n_b)) <= sin_tol;
  if (!in_plane)
    return true;
  // not parallel: |ea x eb| > sin_tol, decided without the square root when clearly so
  const Vec3 c = glm::cross(ea.dir, X_AB.rotate(eb.dir));
  const double c2 = glm::dot(c, c);
  return c2 > 4.0 * sin_tol * sin_tol || std::sqrt(c2) > sin_tol;
}

// The contact feature of one side, `dir` pointing from this side toward the other (A's frame):
// a face parallel to the contact plane (polygon); else, when `want_edge`, an edge lying in the
// contact plane (segment); else the witness point.
void contactFeature(const Polytope& p,
                    const Transform& X,
                    Feature f,
                    const Vec3& witness,
                    const Vec3& dir,
                    double sin_tol,
                    bool want_edge,
                    Polygon& out,
                    FaceView& face_out,
                    bool& is_face) {
  is_face = false;
  out.n = 0;
  std::uint32_t face = 0;
  const double cos_tol = std::sqrt(std::max(0.0, 1.0 - sin_tol * sin_tol));
  const Vec3 dir_p = glm::transpose(X.R) * dir;
  if (bestIncidentFace(p, f, dir_p, face) >= cos_tol) {
    face_out = FaceView{&p, &X, face};
    facePolygon(face_out, out);
    is_face = true;
    return;
  }
  std::uint32_t edge = 0;
  if (want_edge && f.type != FeatureType::kFace && bestIncidentEdge(p, f, dir_p, edge) <= sin_tol) {
    const auto& e = p.edges()[edge];
    out.push(X.apply(p.vertices()[e.tail].p));
    out.push(X.apply(p.vertices()[e.head].p));
    return;
  }
  out.push(witness);
}

// Among the edges incident to fa (on A) and fb (on B), a pair lying in the contact plane (normal
// n in A's frame, n_b in B's) and parallel to each other.
bool parallelEdges(const Polytope& a,
                   Feature fa,
                   const Vec3& n,
                   const Polytope& b,
                   Feature fb,
                   const Vec3& n_b,
                   const Transform& X_AB,
                   double sin_tol,
                   std::uint32_t& ea,
                   std::uint32_t& eb) {
  auto incident = [](const Polytope& p, Feature f, auto&& visit) {
    if (f.type == FeatureType::kEdge) {
      visit(f.index);
    } else if (f.type == FeatureType::kVertex) {
      for (const auto& ve : p.vertexEdges(f.index))
        visit(ve.edge);
    }
  };
  bool found = false;
  incident(a, fa, [&](std::uint32_t i) {
    if (found || std::abs(glm::dot(a.edges()[i].dir, n)) > sin_tol)
      return;
    incident(b, fb, [&](std::uint32_t j) {
      if (found || std::abs(glm::dot(b.edges()[j].dir, n_b)) > sin_tol)
        return;
      if (glm::length(glm::cross(a.edges()[i].dir, X_AB.rotate(b.edges()[j].dir))) > sin_tol)
        return;
      ea = i, eb = j, found = true;
    });
  });
  return found;
}

// Builds the manifold: the other side's contact feature clipped to `ref` (a face) or, for two
// segments, their overlap. Depth of each point measured along n (A toward B). `size`: the pair's
// size; points closer than 1e-9 of it merge, and clipping keeps what lies less than that outside
// a side plane. Why the clip's tolerance is the merge distance: where two faces meet edge on edge
// (a box resting exactly on one of its size, boxes side by side), the incident edge lies along
// the side plane, turned and shifted from it by rounding, and where it crosses the plane is
// anywhere along it; clipped at 1e-12 of the size (the closest-feature walk's plane tolerance),
// a stack's resting contact now and then named a point 4% of the edge in from a corner instead of
// the corner, its warm start no longer fitted, and the solve jolted the whole stack (the dropped
// frictionless pyramid of Stack.FrictionlessDroppedPyramidStands turned at up to 5.3e-4 rad/s,
// now 3.3e-6; with a solver change tried, a tower of ten 5 mm boxes spun at 1.5e-3 rad/s at 7 s,
// and at 1e-10 jolts of 1.2e-3 rad/s were left on a frictionless pyramid of touching boxes). A
// point kept up to 1e-9 of the size beyond a side plane is one the merge could not tell from a
// point on it (docs/dynamics.md Limits).
Manifold assemble(const Polygon& pa,
                  bool a_face,
                  const FaceView& fa,
                  const Polygon& pb,
                  bool b_face,
                  const FaceView& fb,
                  const Vec3& n,
                  double fallback_depth,
                  const Vec3& fallback_point,
                  double size) {
  const double merge = 1e-9 * size;
  const double clip_tol = merge;
  Manifold m;
  Polygon work, scratch;
  // the clipped points before reduction, left uninitialised (only the first `count` are read):
  // zeroing all 256 cost more than a small pair's clipping (Tick/decomposed, bench/README.md)
  union Points {
    Points() {}  // NOLINT(modernize-use-equals-default): = default would zero the points
    ContactPoint at[kMaxPolygon];
  } pts;
  std::size_t count = 0;
  // choose the reference: a face when there is one; the other side is clipped to it
  if (a_face || b_face) {
    const bool ref_is_a = a_face && (!b_face || pa.n >= pb.n);
    const FaceView& ref = ref_is_a ? fa : fb;
    work.copyFrom(ref_is_a ? pb : pa);
    clipToFace(ref, work, scratch, clip_tol);
    const Vec3 rn = ref.normal();  // outward of the reference face
    const double off =
        glm::dot(rn, ref.X->apply(ref.p->vertices()[ref.p->faceEdges(ref.f)[0].vertex].p));
    for (std::size_t k = 0; k < work.n; ++k) {
      // gap from the reference plane to the incident point, along the reference's outward normal
      const double gap = glm::dot(rn, work.p[k]) - off;
      const Vec3 mid = work.p[k] - rn * (gap * 0.5);
      pts.at[count++] = ContactPoint{mid, n, -gap};
    }
  } else if (pa.n == 2 && pb.n == 2) {
    // parallel edges: the overlap of B's segment projected on A's
    const Vec3 d = pa.p[1] - pa.p[0];
    const double dd = glm::dot(d, d);
    double lo = glm::dot(pb.p[0] - pa.p[0], d) / dd;
    double hi = glm::dot(pb.p[1] - pa.p[0], d) / dd;
    if (lo > hi)
      std::swap(lo, hi);
    lo = std::max(lo, 0.0);
    hi = std::min(hi, 1.0);
    if (lo <= hi) {
      for (const double s : {lo, hi}) {
        const Vec3 on_a = pa.p[0] + d * s;
        const Vec3 on_b =
            pb.p[0] +
            (pb.p[1] - pb.p[0]) * std::clamp(glm::dot(on_a - pb.p[0], pb.p[1] - pb.p[0]) /
                                                 glm::dot(pb.p[1] - pb.p[0], pb.p[1] - pb.p[0]),
                                             0.0, 1.0);
        pts.at[count++] = ContactPoint{(on_a + on_b) * 0.5, n, -glm::dot(on_b - on_a, n)};
        if (hi - lo <= 0.0)
          break;
      }
    }
  }
  if (count == 0) {
    m.points[0] = ContactPoint{fallback_point, n, fallback_depth};
    m.count = 1;
    return m;
  }
  m.truncated = pa.overflow || pb.overflow || work.overflow;
  // the deepest point is the pair's depth: keep it exact
  reduce(pts.at, count, merge, m);
  return m;
}

}  // namespace

Manifold manifoldFromClosest(const Polytope& a,
                             const Polytope& b,
                             const Transform& X_AB,
                             const ClosestResult& closest,
                             const ManifoldOptions& options) {
  Manifold m;
  manifoldFromClosest(a, b, X_AB, closest, m, options);
  return m;
}

void manifoldFromClosest(const Polytope& a,
                         const Polytope& b,
                         const Transform& X_AB,
                         const ClosestResult& closest,
                         Manifold& out,
                         const ManifoldOptions& options) {
  const Transform I{};
  const Vec3& n = closest.normal;
  const double sin_tol = options.parallel_tolerance;
  // the closest pair alone: one point midway between the witnesses
  auto single = [&] {
    out.points[0] = ContactPoint{(closest.point_a + closest.point_b) * 0.5, n, -closest.distance};
    out.count = 1;
    out.truncated = false;
  };

  // a side whose contact feature can only be its witness point, or crossing edges: the closest
  // pair alone
  const Vec3 n_b = glm::transpose(X_AB.R) * n;
  if (closest.fa.type == FeatureType::kEdge && closest.fb.type == FeatureType::kEdge &&
      crossingEdgesOnly(a, closest.fa.index, n, b, closest.fb.index, n_b, X_AB, sin_tol)) {
    single();
    return;
  }
  if (!mayLieInPlane(a, closest.fa, n, sin_tol) || !mayLieInPlane(b, closest.fb, n_b, sin_tol)) {
    single();
    return;
  }

  Polygon pa, pb;
  FaceView fa, fb;
  bool a_face = false, b_face = false;
  // faces first; an edge only counts against a face of the other side
  contactFeature(a, I, closest.fa, closest.point_a, n, sin_tol, false, pa, fa, a_face);
  contactFeature(b, X_AB, closest.fb, closest.point_b, -n, sin_tol, a_face, pb, fb, b_face);
  if (b_face && !a_face) {
    contactFeature(a, I, closest.fa, closest.point_a, n, sin_tol, true, pa, fa, a_face);
  }
  if (!a_face && !b_face) {
    // parallel edges, both in the contact plane, around the closest features: the overlap segment
    std::uint32_t ea = 0, eb = 0;
    if (!parallelEdges(a, closest.fa, n, b, closest.fb, n_b, X_AB, sin_tol, ea, eb)) {
      single();
      return;
    }
    pa.n = pb.n = 0;
    pa.push(a.vertices()[a.edges()[ea].tail].p);
    pa.push(a.vertices()[a.edges()[ea].head].p);
    pb.push(X_AB.apply(b.vertices()[b.edges()[eb].tail].p));
    pb.push(X_AB.apply(b.vertices()[b.edges()[eb].head].p));
  }
  if (pa.n <= 1 || pb.n <= 1) {
    single();
    return;
  }
  const Vec3 mid = (closest.point_a + closest.point_b) * 0.5;
  const Manifold m = assemble(pa, a_face, fa, pb, b_face, fb, n, -closest.distance, mid,
                              std::max(a.radius(), b.radius()));
  // the closest pair is exact: the manifold's deepest point must say so
  std::size_t deepest = 0;
  for (std::size_t i = 1; i < m.count; ++i) {
    if (m.points[i].depth > m.points[deepest].depth)
      deepest = i;
  }
  if (std::abs(m.points[deepest].depth + closest.distance) >
      1e-9 * std::max(a.radius(), b.radius())) {
    single();  // clipping lost the closest pair (features not really parallel)
    return;
  }
  out = m;
}

Manifold manifoldFromDepth(const Polytope& a,
                           const Polytope& b,
                           const Transform& X_AB,
                           const DepthResult& depth,
                           const ManifoldOptions& options) {
  const Transform I{};
  const Vec3& n = depth.normal;
  const Vec3 mid = (depth.point_a + depth.point_b) * 0.5;
  Manifold m;
  if (depth.kind == DepthFeature::kEdgeEdge || depth.kind == DepthFeature::kNone) {
    m.points[0] = ContactPoint{mid, n, depth.depth};
    m.count = 1;
    return m;
  }
  // the reference face is the MTD's face; the incident face is the other side's face most
  // opposed to it, found around the support vertex
  Polygon pa, pb;
  FaceView fa, fb;
  bool a_face = false, b_face = false;
  const Transform X_BA = X_AB.inverse();
  if (depth.kind == DepthFeature::kFaceA) {
    fa = FaceView{&a, &I, depth.ia};
    facePolygon(fa, pa);
    a_face = true;
    std::uint32_t inc = 0;
    bestIncidentFace(b, Feature::vertex(b.support(X_BA.rotate(-n), depth.support_b)),
                     X_BA.rotate(-n), inc);
    facePolygon(FaceView{&b, &X_AB, inc}, pb);
  } else {
    fb = FaceView{&b, &X_AB, depth.ib};
    facePolygon(fb, pb);
    b_face = true;
    std::uint32_t inc = 0;
    bestIncidentFace(a, Feature::vertex(a.support(n, depth.support_a)), n, inc);
    facePolygon(FaceView{&a, &I, inc}, pa);
  }
  if (pa.n <= 1 && pb.n <= 1) {
    m.points[0] = ContactPoint{mid, n, depth.depth};
    m.count = 1;
    return m;
  }
  const double size = std::max(a.radius(), b.radius());
  m = assemble(pa, a_face, fa, pb, b_face, fb, n, depth.depth, mid, size);
  // keep only penetrating points (a touching pair's within the parallel tolerance too), and never
  // lose the deepest (the MTD itself)
  const double lowest = options.touching ? -options.parallel_tolerance * size : 0.0;
  std::size_t kept = 0;
  double deepest = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < m.count; ++i) {
    deepest = std::max(deepest, m.points[i].depth);
    if (m.points[i].depth >= lowest)
      m.points[kept++] = m.points[i];
  }
  if (kept == 0 || std::abs(deepest - depth.depth) > 1e-9 * size) {
    m.points[0] = ContactPoint{mid, n, depth.depth};
    kept = 1;
  }
  m.count = static_cast<std::uint8_t>(kept);
  return m;
}

}  // namespace hapticd::collision
