#include "core/collision/penetration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/collision/clip.h"
#include "core/collision/segment.h"
#include "core/geometry/rotation.h"

namespace hapticd::collision {

namespace {

// The Minkowski-face test of Gauss-map arcs (Gregorius, "The Separating Axis Test between Convex
// Polyhedra", GDC 2013): arc (a, b) of an edge of A and arc (c, d) of an edge of -B intersect.
inline bool isMinkowskiFace(const Vec3& a,
                            const Vec3& b,
                            const Vec3& b_x_a,
                            const Vec3& c,
                            const Vec3& d,
                            const Vec3& d_x_c) {
  const double cba = glm::dot(c, b_x_a);
  const double dba = glm::dot(d, b_x_a);
  const double adc = glm::dot(a, d_x_c);
  const double bdc = glm::dot(b, d_x_c);
  return cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0;
}

// The faces of B whose sides a lost edge walk computes once each (edgeArc); B with more faces
// takes the test pair by pair.
constexpr std::size_t kSideCap = 256;

// A fixed-capacity convex polygon for the witness search (no allocation). A vertex beyond the
// capacity is dropped, which leaves a convex subset of the polygon.
struct WitnessPolygon {
  static constexpr std::size_t kCap = 256;
  std::array<Vec3, kCap> p;
  std::size_t n = 0;
  void push(const Vec3& v) {
    if (n < kCap)
      p[n++] = v;
  }
};

// Sutherland-Hodgman: the part of `in` (a closed polygon, or a segment when it has 2 points) with
// (x - o)·m >= -tol.
void clipWitness(const WitnessPolygon& in,
                 const Vec3& o,
                 const Vec3& m,
                 double tol,
                 WitnessPolygon& out) {
  out.n = 0;
  detail::clipAgainstPlane(in, o, m, tol, out);
  if (in.n == 1 && glm::dot(in.p[0] - o, m) + tol >= 0.0)
    out.push(in.p[0]);
}

// Witness on Q of a face MTD (face f of P against Q's support set), in P's frame (T_PQ: Q's frame
// to P's): a point of Q's support set against the face normal whose projection onto the face
// plane lies in the face. The origin's projection onto the nearest face of A - B lies in that
// face, so a unique support vertex s projects into the face; only ties (a face or an edge of Q
// parallel to the face within tol, where the climb returns any of its vertices) need a search:
// the tied feature is clipped against the face's side planes and the mean of what is left taken.
// `held` tells whether the face holds the witness so found; if not (the face is a tie-grid pick
// that does not hold the origin's projection, see witnesses()), s's point moved into the face
// along its plane.
Vec3 faceWitness(const Polytope& p,
                 std::uint32_t f,
                 const Polytope& q,
                 const Transform& T_PQ,
                 std::uint32_t s,
                 double tol,
                 bool& held) {
  held = true;
  const auto sides = p.faceEdges(f);
  const Vec3 q0 = T_PQ.apply(q.vertices()[s].p);
  bool inside = true;
  for (const auto& fe : sides) {
    if (glm::dot(q0 - p.vertices()[fe.vertex].p, fe.side) < -tol) {
      inside = false;
      break;
    }
  }
  if (inside)
    return q0;
  // Q's support set along d_q (its own frame): the vertices within tol of s's height
  const Vec3 d_q = glm::transpose(T_PQ.R) * (-p.faces()[f].normal);
  const double h0 = glm::dot(d_q, q.vertices()[s].p);
  auto tied = [&](std::uint32_t v) { return glm::dot(d_q, q.vertices()[v].p) >= h0 - tol; };
  double best = -2.0;
  std::uint32_t face = 0;
  for (const auto& ve : q.vertexEdges(s)) {
    for (const std::uint32_t k : q.edges()[ve.edge].face) {
      const double c = glm::dot(q.faces()[k].normal, d_q);
      if (c > best)
        best = c, face = k;
    }
  }
  WitnessPolygon poly, scratch;
  const auto loop = q.faceEdges(face);
  bool face_tied = true;
  for (const auto& fe : loop)
    face_tied = face_tied && tied(fe.vertex);
  if (face_tied) {
    // a face larger than the capacity: evenly spaced vertices (a convex polygon inside it)
    const std::size_t stride = (loop.size() + WitnessPolygon::kCap - 1) / WitnessPolygon::kCap;
    for (std::size_t k = 0; k < loop.size(); k += stride) {
      poly.push(T_PQ.apply(q.vertices()[loop[k].vertex].p));
    }
  } else {
    for (const auto& ve : q.vertexEdges(s)) {
      if (!tied(ve.other))
        continue;
      poly.push(q0);
      poly.push(T_PQ.apply(q.vertices()[ve.other].p));
      break;
    }
  }
  // nothing tied projects into the face (a tie-grid pick within a grid step of the least
  // depth): s's point moved into the face along its plane, by projecting onto its side planes
  // in turn (off Q's surface by the tilt of Q's nearly parallel face times the move)
  auto intoFace = [&] {
    held = false;
    Vec3 x = q0;
    for (int pass = 0; pass < 8; ++pass) {
      bool moved = false;
      for (const auto& fe : sides) {
        const double out = glm::dot(x - p.vertices()[fe.vertex].p, fe.side);
        if (out < 0.0) {
          x -= fe.side * out;
          moved = true;
        }
      }
      if (!moved)
        break;
    }
    return x;
  };
  if (poly.n < 2)
    return intoFace();
  for (const auto& fe : sides) {
    clipWitness(poly, p.vertices()[fe.vertex].p, fe.side, tol, scratch);
    poly.n = scratch.n;
    std::copy(scratch.p.begin(), scratch.p.begin() + static_cast<std::ptrdiff_t>(scratch.n),
              poly.p.begin());
    if (poly.n == 0)
      return intoFace();
  }
  Vec3 mean{0.0};
  for (std::size_t k = 0; k < poly.n; ++k)
    mean += poly.p[k];
  return mean / static_cast<double>(poly.n);
}

}  // namespace

namespace {

// Where the exact method leaves every candidate's depth (the coherent method's certificate
// data): per face of A and of B, and per edge of A the least depth over its arc's crossings.
struct DepthRecord {
  double* value_a = nullptr;
  double* value_b = nullptr;
  std::uint32_t* support_b = nullptr;  // per face of B: A's support vertex against it
  double* edge_min = nullptr;
};

// Ties between candidates (parallel faces of a resting stack give A's face and B's face at one
// depth) are broken on a grid, so that the coherent method can prove the full method's choice
// (docs/narrow-phase.md, "Ties"): a candidate's depth d falls in the cell floor(d / step) of
// step kTieStep times the depths' scale, and the answer is the candidate of the lowest cell,
// the first of that cell in the order face of A, face of B, edge pair (then by index). Its depth
// exceeds the least by less than the step.
constexpr double kTieStep = 1e-12;
// A depth within this fraction of a step from a cell's edge could fall in the next cell when
// computed from another tied support vertex (rounding: a few 1e-15 of the scale).
constexpr double kTieGuard = 0.02;

// The magnitude of the coordinates the depths are computed from (their rounding's scale).
double depthScale(const Polytope& a, const Polytope& b, const Transform& X_AB) {
  return glm::length(a.centroid()) + a.radius() + glm::length(X_AB.t) + glm::length(b.centroid()) +
         b.radius();
}

// Whether candidate (kind, ia, ib) comes before `r`'s within a cell.
inline bool rankBefore(DepthFeature kind,
                       std::uint32_t ia,
                       std::uint32_t ib,
                       const DepthResult& r) {
  if (kind != r.kind)
    return kind < r.kind;
  return ia != r.ia ? ia < r.ia : ib < r.ib;
}

// The nearest Minkowski face plane found so far (by the tie grid), and its support vertex hint.
struct DepthSearch {
  DepthResult best;
  std::uint32_t best_support = 0;
  double step = 0.0;  // the tie grid's step
  double best_cell = std::numeric_limits<double>::infinity();
  explicit DepthSearch(double tie_step) : step(tie_step) {
    best.depth = std::numeric_limits<double>::infinity();
  }
  double above = std::numeric_limits<double>::infinity();  // depths beyond: a higher cell
  // Inlined into the edge walks, so kept to the test that rejects nearly every candidate; the
  // grid's arithmetic is out of line (inlined, it made the walks' crossing test a call per
  // edge pair: the exact method on boxes 34 % slower in Tick/stack100).
  void consider(double d,
                const Vec3& n,
                DepthFeature kind,
                std::uint32_t ia,
                std::uint32_t ib,
                std::uint32_t support) {
    if (d > above)
      return;  // two steps above the best: certainly a higher cell (division is monotone)
    place(d, n, kind, ia, ib, support);
  }
  [[gnu::noinline]] void place(double d,
                               const Vec3& n,
                               DepthFeature kind,
                               std::uint32_t ia,
                               std::uint32_t ib,
                               std::uint32_t support) {
    const double cell = std::floor(d / step);
    if (cell < best_cell || (cell == best_cell && rankBefore(kind, ia, ib, best))) {
      best.depth = d, best.normal = n, best.kind = kind, best.ia = ia, best.ib = ib;
      best_support = support;
      best_cell = cell;
      above = d + 2.0 * step;
    }
  }
};

// Faces of A (breadth-first, so each support climb starts next to its answer): per face, B's
// support vertex against its normal, the region of B's Gauss map that holds the face normal.
void facesOfA(const Polytope& a,
              const Polytope& b,
              const Transform& X_AB,
              const Transform& X_BA,
              std::uint32_t& hint_b,
              std::vector<std::uint32_t>& support_of_face,
              DepthSearch& s,
              DepthRecord* rec) {
  const auto fa = a.faces();
  for (const std::uint32_t i : a.faceOrder()) {
    const Vec3& n = fa[i].normal;
    hint_b = b.support(X_BA.rotate(-n), hint_b);
    support_of_face[i] = hint_b;
    const double d = fa[i].offset - glm::dot(n, X_AB.apply(b.vertices()[hint_b].p));
    if (rec != nullptr)
      rec->value_a[i] = d;
    s.consider(d, n, DepthFeature::kFaceA, i, 0, hint_b);
  }
}

// Faces of B: B moves against its face normal; -(normals of B's faces) in A's frame are kept.
void facesOfB(const Polytope& a,
              const Polytope& b,
              const Transform& X_AB,
              std::uint32_t& hint_a,
              std::vector<Vec3>& neg_normal_b,
              DepthSearch& s,
              DepthRecord* rec) {
  const auto fb = b.faces();
  for (const std::uint32_t j : b.faceOrder()) {
    const Vec3 m = X_AB.rotate(fb[j].normal);
    neg_normal_b[j] = -m;
    hint_a = a.support(-m, hint_a);
    const double d = fb[j].offset + glm::dot(m, X_AB.t) - glm::dot(m, a.vertices()[hint_a].p);
    if (rec != nullptr)
      rec->value_b[j] = d, rec->support_b[j] = hint_a;
    s.consider(d, -m, DepthFeature::kFaceB, 0, j, hint_a);
  }
}

// Edge i of A against B's Gauss map. Its arc runs from the normal of face[0] to that of face[1];
// walking over B's vertex graph from the region holding the first (s0, B's support vertex
// against it) to the region holding the second (s1) crosses exactly the arcs of the edges of B
// it meets. Each crossing edge pair (a face of A - B) is offered: offer(depth, axis, j).
// `neg_normal(k)`: minus the normal of B's face k in A's frame. Returns false when the arc has
// no lower bound from its crossings (a degenerate crossing: the walk was lost at an arc through
// a vertex of the map, or a parallel edge pair was met); `arc_min` is the least offered depth.
template <class NegNormal, class Offer>
bool edgeArc(const Polytope& a,
             const Polytope& b,
             const Transform& X_AB,
             std::uint32_t i,
             std::uint32_t s0,
             std::uint32_t s1,
             NegNormal&& neg_normal,
             Offer&& offer,
             double& arc_min) {
  arc_min = std::numeric_limits<double>::infinity();
  if (s0 == s1)
    return true;  // the whole arc lies in one region: no crossing
  const auto fa = a.faces();
  const auto ea = a.edges();
  const auto eb = b.edges();
  const Vec3& na = fa[ea[i].face[0]].normal;
  const Vec3& nb = fa[ea[i].face[1]].normal;
  const Vec3 b_x_a = glm::cross(nb, na);
  bool regular = true;
  // the crossing's depth, once edge j's arc is known to cross this one
  auto crossing = [&](std::uint32_t j) {
    Vec3 axis = glm::cross(ea[i].dir, X_AB.rotate(eb[j].dir));
    const double len = glm::length(axis);
    if (len < 1e-9) {
      regular = false;
      return;  // parallel edges: covered by the face normals
    }
    axis /= len;
    if (glm::dot(axis, na + nb) < 0.0)
      axis = -axis;
    const Vec3 pb = X_AB.apply(b.vertices()[eb[j].tail].p);
    const double depth = glm::dot(axis, a.vertices()[ea[i].tail].p - pb);
    arc_min = std::min(arc_min, depth);
    offer(depth, axis, j);
  };
  auto edgePair = [&](std::uint32_t j) {
    const Vec3 c = neg_normal(eb[j].face[0]);
    const Vec3 d = neg_normal(eb[j].face[1]);
    if (!isMinkowskiFace(na, nb, b_x_a, c, d, glm::cross(d, c)))
      return false;
    crossing(j);
    return true;
  };
  std::uint32_t v = s0;
  std::uint32_t came_by = std::numeric_limits<std::uint32_t>::max();
  bool lost = false;
  for (std::size_t step = 0; v != s1; ++step) {
    bool moved = false;
    if (step <= eb.size()) {
      for (const auto& ve : b.vertexEdges(v)) {
        if (ve.edge == came_by || !edgePair(ve.edge))
          continue;
        came_by = ve.edge;
        v = ve.other;
        moved = true;
        break;
      }
    }
    if (!moved) {
      lost = true;  // a degenerate crossing (arc through a vertex of the map)
      break;
    }
  }
  if (lost) {
    // every edge of B. Most fail the test's first half (both ends of B's arc on one side of
    // this arc's great circle), and that half reads only each face's side, so each face's is
    // computed once rather than once per edge: the same products, the same crossings
    // (isMinkowskiFace). Parallel prisms (the gears' teeth, a resting cap) lose most walks:
    // their arcs run through vertices of the map and along its arcs
    const auto fb = b.faces();
    std::array<double, kSideCap> side;
    if (fb.size() > side.size()) {
      for (std::uint32_t j = 0; j < eb.size(); ++j)
        edgePair(j);
      return false;
    }
    for (std::uint32_t k = 0; k < fb.size(); ++k)
      side[k] = glm::dot(neg_normal(k), b_x_a);
    for (std::uint32_t j = 0; j < eb.size(); ++j) {
      const double cba = side[eb[j].face[0]];
      const double dba = side[eb[j].face[1]];
      if (!(cba * dba < 0.0))
        continue;
      const Vec3 c = neg_normal(eb[j].face[0]);
      const Vec3 d = neg_normal(eb[j].face[1]);
      const Vec3 d_x_c = glm::cross(d, c);
      const double adc = glm::dot(na, d_x_c);
      const double bdc = glm::dot(nb, d_x_c);
      if (adc * bdc < 0.0 && cba * bdc > 0.0)
        crossing(j);
    }
  }
  return regular && !lost;
}

// Arcs that only meet at an end (a face normal of A equal to one of -B: parallel faces, e.g.
// the edges of two opposed caps) pass the crossing test by rounding; such a "face" has no
// area and lies in that face's plane, the face passes' answer less a rounding error, and its
// edges' closest points are no witnesses of it. True when an edge-pair answer's axis lies within
// 1e-12 rad of one of its arcs' ends: it gives way to the faces' answer.
template <class NegNormal>
bool atArcEnd(const Polytope& a,
              const Polytope& b,
              const DepthResult& best,
              NegNormal&& neg_normal) {
  const auto fa = a.faces();
  const auto ea = a.edges();
  const auto eb = b.edges();
  const Vec3 ends[4] = {fa[ea[best.ia].face[0]].normal, fa[ea[best.ia].face[1]].normal,
                        neg_normal(eb[best.ib].face[0]), neg_normal(eb[best.ib].face[1])};
  for (const Vec3& end : ends) {
    const Vec3 off = glm::cross(best.normal, end);
    if (glm::dot(off, off) < 1e-24)
      return true;
  }
  return false;
}

// A lower bound of the depths an irregular arc (edgeArc false) can give: the support gap along
// a great-circle arc on which the pair overlaps is concave between the points where B's support
// changes, so its least value is at an end (a face of A: the caller's), at a crossing (offered:
// arc_min), or at a face point of -B on the arc; a crossing the walk missed by rounding lies at
// one of these. `depth_b(k)`: face k of B's depth (or a lower bound of it). The faces of -B
// within 1e-8 rad of the arc are taken (more is only lower: still a bound).
template <class NegNormal, class DepthB>
double irregularArcMin(const Polytope& a,
                       const Polytope& b,
                       std::uint32_t i,
                       double arc_min,
                       NegNormal&& neg_normal,
                       DepthB&& depth_b) {
  const auto& e = a.edges()[i];
  const Vec3& na = a.faces()[e.face[0]].normal;
  const Vec3& nb = a.faces()[e.face[1]].normal;
  const Vec3 pole = glm::normalize(glm::cross(na, nb));  // the arc runs na -> nb about it
  double m = arc_min;
  for (std::uint32_t k = 0; k < b.faces().size(); ++k) {
    const Vec3 c = neg_normal(k);
    if (std::abs(glm::dot(c, pole)) <= 1e-8 && glm::dot(glm::cross(na, c), pole) >= -1e-8 &&
        glm::dot(glm::cross(c, nb), pole) >= -1e-8)
      m = std::min(m, depth_b(k));
  }
  return m;
}

// Edge pairs whose Gauss-map arcs cross, for every edge of A (edgeArc); `rec`, when given,
// receives each edge's least crossing depth (-infinity when the arc has no such bound).
void edgePairs(const Polytope& a,
               const Polytope& b,
               const Transform& X_AB,
               const std::vector<std::uint32_t>& support_of_face,
               const std::vector<Vec3>& neg_normal_b,
               DepthSearch& s,
               DepthRecord* rec) {
  const auto ea = a.edges();
  const DepthSearch face_best = s;
  auto neg_normal = [&](std::uint32_t k) { return neg_normal_b[k]; };
  for (std::uint32_t i = 0; i < ea.size(); ++i) {
    double arc_min = 0.0;
    const bool bounded = edgeArc(
        a, b, X_AB, i, support_of_face[ea[i].face[0]], support_of_face[ea[i].face[1]], neg_normal,
        [&](double d, const Vec3& axis, std::uint32_t j) {
          s.consider(d, axis, DepthFeature::kEdgeEdge, i, j, 0);
        },
        arc_min);
    if (rec != nullptr) {
      rec->edge_min[i] =
          bounded ? arc_min : irregularArcMin(a, b, i, arc_min, neg_normal, [&](std::uint32_t k) {
            return rec->value_b[k];
          });
    }
  }
  if (s.best.kind == DepthFeature::kEdgeEdge && atArcEnd(a, b, s.best, neg_normal)) {
    s = face_best;
  }
}

// The witness points of `best` from the touching features of A and of B moved out of A by its
// depth along its normal (plus `margin`): B then touches A (the plane of best's feature supports
// A - B, and the point depth * normal lies within a grid step of A - B), and the closest points
// of the two are witnesses whatever feature of A - B holds them. False when the walk does not
// end separated or touching (then the caller keeps its own witness).
bool touchingWitnesses(const Polytope& a,
                       const Polytope& b,
                       const Transform& X_AB,
                       double margin,
                       DepthResult& best) {
  Transform X_out = X_AB;
  const Vec3 out = best.normal * (best.depth + margin);
  X_out.t += out;
  FeatureCache fc;
  const ClosestResult c = closestFeatures(a, b, X_out, fc);
  if (c.end != WalkEnd::kConverged || c.status == ContactStatus::kPenetrating)
    return false;
  best.point_a = c.point_a;
  best.point_b = c.point_b - out;
  return true;
}

// The witness points of the answer and the support hints it leaves in the cache. The answer is
// the tie grid's pick, whose depth may exceed the least by up to a grid step; next to nearly
// parallel faces (a face of A - B a sliver between them) such a pick's own feature need not hold
// the origin's projection, and its own witness can lie far off (an edge pair's closest points
// clamped at a segment's end, thousandths of the size from alignment). Then the witnesses come
// from the touching features (touchingWitnesses), which do not depend on which tied candidate
// was picked.
void witnesses(const Polytope& a,
               const Polytope& b,
               const Transform& X_AB,
               const Transform& X_BA,
               double tie_tol,
               DepthSearch& s,
               DepthCache& cache) {
  DepthResult& best = s.best;
  bool held = true;
  switch (best.kind) {
    case DepthFeature::kFaceA:
      best.point_b = faceWitness(a, best.ia, b, X_AB, s.best_support, tie_tol, held);
      best.point_a = best.point_b + best.normal * best.depth;
      cache.support_b = best.support_b = s.best_support;
      best.support_a = a.faceEdges(best.ia)[0].vertex;
      break;
    case DepthFeature::kFaceB:
      best.point_a = X_AB.apply(faceWitness(b, best.ib, a, X_BA, s.best_support, tie_tol, held));
      best.point_b = best.point_a - best.normal * best.depth;
      cache.support_a = best.support_a = s.best_support;
      best.support_b = b.faceEdges(best.ib)[0].vertex;
      break;
    case DepthFeature::kEdgeEdge: {
      const auto& e1 = a.edges()[best.ia];
      const auto& e2 = b.edges()[best.ib];
      const auto seg = detail::closestSegments(a.vertices()[e1.tail].p, a.vertices()[e1.head].p,
                                               X_AB.apply(b.vertices()[e2.tail].p),
                                               X_AB.apply(b.vertices()[e2.head].p));
      best.point_a = seg.c1;
      best.point_b = seg.c2;
      best.support_a = e1.tail;
      best.support_b = e2.tail;
      // the lines' closest points differ by depth * normal; clamped to the segments they do
      // only when the edge pair's face of A - B holds the origin's projection
      held = glm::length(seg.c1 - seg.c2 - best.normal * best.depth) <= tie_tol;
      break;
    }
    case DepthFeature::kNone:
      break;
  }
  if (!held)
    touchingWitnesses(a, b, X_AB, 4.0 * s.step, best);
}

}  // namespace

void DepthScratch::reserve(std::size_t faces) {
  if (support_of_face.size() < faces)
    support_of_face.resize(faces);
  if (neg_normal_b.size() < faces)
    neg_normal_b.resize(faces);
}

DepthScratch& DepthScratch::forThisThread() {
  thread_local DepthScratch scratch;
  return scratch;
}

namespace {

// The exact method; `rec`, when given, receives every candidate's depth (DepthRecord).
DepthResult exactSolve(const Polytope& a,
                       const Polytope& b,
                       const Transform& X_AB,
                       DepthCache& cache,
                       DepthScratch& scratch,
                       DepthRecord* rec) {
  const Transform X_BA = X_AB.inverse();
  DepthSearch s(kTieStep * depthScale(a, b, X_AB));
  std::uint32_t hint_a = cache.support_a < a.vertices().size() ? cache.support_a : 0;
  std::uint32_t hint_b = cache.support_b < b.vertices().size() ? cache.support_b : 0;
  // support heights within this count as tied (parallel features), as the closest-feature
  // walk's plane tolerance
  const double tie_tol = 1e-12 * std::max(a.radius(), b.radius());

  // per face of A, B's support vertex against its normal; -(normals of B's faces) in A's frame
  // (the caller's scratch holds them: it grows only if it was not sized for these polytopes)
  std::vector<std::uint32_t>& support_of_face = scratch.support_of_face;
  std::vector<Vec3>& neg_normal_b = scratch.neg_normal_b;
  if (support_of_face.size() < a.faces().size())
    support_of_face.resize(a.faces().size());
  if (neg_normal_b.size() < b.faces().size())
    neg_normal_b.resize(b.faces().size());

  facesOfA(a, b, X_AB, X_BA, hint_b, support_of_face, s, rec);
  if (s.best.depth >= 0.0)
    facesOfB(a, b, X_AB, hint_a, neg_normal_b, s, rec);
  if (s.best.depth >= 0.0)
    edgePairs(a, b, X_AB, support_of_face, neg_normal_b, s, rec);
  witnesses(a, b, X_AB, X_BA, tie_tol, s, cache);
  cache.kind = s.best.kind;
  cache.ia = s.best.ia;
  cache.ib = s.best.ib;
  return s.best;
}

}  // namespace

DepthResult penetrationDepthExact(const Polytope& a,
                                  const Polytope& b,
                                  const Transform& X_AB,
                                  DepthCache& cache,
                                  DepthScratch& scratch) {
  return exactSolve(a, b, X_AB, cache, scratch, nullptr);
}

namespace {

// Room for faces_a faces and edges_a edges of A and faces_b faces of B (grows only).
void reserveTracker(DepthTracker& t,
                    std::size_t faces_a,
                    std::size_t edges_a,
                    std::size_t faces_b) {
  const std::size_t n = faces_b + edges_a;
  t.heap.reserve(n);
  t.popped.reserve(n);
  auto grow = [](auto& v, std::size_t size) {
    if (v.size() < size)
      v.resize(size);
  };
  grow(t.value_a, faces_a);
  grow(t.value_b, faces_b);
  grow(t.support_b, faces_b);
  grow(t.edge_min, edges_a);
  grow(t.face_support_a, faces_a);
  grow(t.stamp_a, faces_a);
  grow(t.stamp_b, faces_b);
  grow(t.neg_normal_b, faces_b);
}

}  // namespace

void DepthTracker::reserve(const Polytope& pa, const Polytope& pb) {
  reserveTracker(*this, pa.faces().size(), pa.edges().size(), pb.faces().size());
}

void DepthTracker::reserve(std::size_t faces, std::size_t edges) {
  reserveTracker(*this, faces, edges, faces);
}

std::size_t DepthTracker::bytesFor(std::size_t faces, std::size_t edges) {
  // as reserveTracker(faces, edges, faces)
  return 2 * (faces + edges) * sizeof(Entry) + (2 * faces + edges) * sizeof(double) +
         2 * faces * sizeof(std::uint32_t) + 2 * faces * sizeof(std::uint64_t) +
         faces * sizeof(Vec3);
}

std::size_t DepthTracker::reservedBytes() const {
  return (heap.capacity() + popped.capacity()) * sizeof(Entry) +
         (value_a.capacity() + value_b.capacity() + edge_min.capacity()) * sizeof(double) +
         (support_b.capacity() + face_support_a.capacity()) * sizeof(std::uint32_t) +
         (stamp_a.capacity() + stamp_b.capacity()) * sizeof(std::uint64_t) +
         neg_normal_b.capacity() * sizeof(Vec3);
}

namespace {

constexpr std::uint32_t kIndexMask = (std::uint32_t{1} << 30) - 1;

bool keyAfter(const DepthTracker::Entry& x, const DepthTracker::Entry& y) {
  return x.key > y.key;  // std::*_heap with this: a min-heap on key
}

// A bound on how much the support gap along any direction fixed in A's frame, or in B's, can
// change between the relative poses X0 and X1 (docs/narrow-phase.md, "Coherent exact depth"):
// B's centroid moves in A's frame, A's in B's, and each polytope's points turn about its
// centroid by at most |R1 - R0| (spectral norm, = Frobenius / sqrt 2 for rotations) times its
// radius.
double poseDrift(const Polytope& a, const Polytope& b, const Transform& X0, const Transform& X1) {
  const geom::Mat3 dR = X1.R - X0.R;
  double f2 = 0.0;
  for (int c = 0; c < 3; ++c)
    f2 += glm::dot(dR[c], dR[c]);
  const double rho = std::sqrt(0.5 * f2) * (1.0 + 1e-6) + 1e-15;
  const Vec3& ca = a.centroid();
  const Vec3& cb = b.centroid();
  const double move_b = glm::length(X1.apply(cb) - X0.apply(cb));
  const double move_a =
      glm::length(glm::transpose(X1.R) * (ca - X1.t) - glm::transpose(X0.R) * (ca - X0.t));
  return std::max(move_b + b.radius() * rho, move_a + a.radius() * rho) * (1.0 + 1e-9);
}

// The best candidate of a coherent query (the full method's tie grid) and the least depth of
// the evaluated candidates that lie within the guard of a cell's edge.
struct CoherentBest {
  DepthSearch s;
  double edge_min = std::numeric_limits<double>::infinity();
  // the least depth and its feature, and the least depth of any other feature
  double min1 = std::numeric_limits<double>::infinity();
  double min2 = std::numeric_limits<double>::infinity();
  DepthFeature kind1 = DepthFeature::kNone;
  std::uint32_t ia1 = 0, ib1 = 0;
  explicit CoherentBest(double tie_step) : s(tie_step) {}
  // (inlined into the edge walks: the common case, a candidate above the best's tie band and
  // above the second least depth, changes nothing and returns at once)
  void offer(double d,
             const Vec3& n,
             DepthFeature kind,
             std::uint32_t ia,
             std::uint32_t ib,
             std::uint32_t support) {
    if (d > s.above && d >= min2)
      return;
    record(d, n, kind, ia, ib, support);
  }
  [[gnu::noinline]] void record(double d,
                                const Vec3& n,
                                DepthFeature kind,
                                std::uint32_t ia,
                                std::uint32_t ib,
                                std::uint32_t support) {
    s.consider(d, n, kind, ia, ib, support);
    if (kind == kind1 && ia == ia1 && ib == ib1) {
      // the same feature again (an edge pair met twice by a lost walk's sweep)
    } else if (d < min1) {
      min2 = min1;
      min1 = d, kind1 = kind, ia1 = ia, ib1 = ib;
    } else {
      min2 = std::min(min2, d);
    }
    const double x = d / s.step;
    const double f = x - std::floor(x);
    if (!(f >= kTieGuard && f <= 1.0 - kTieGuard))
      edge_min = std::min(edge_min, d);
  }
  // Whether the full method, computing each candidate's depth to within the guard of this
  // query's value, puts them in the same cells: no evaluated candidate below the winner's
  // next cell plus the guard lies near a cell's edge (an unevaluated one lies beyond the
  // certificate's margin, many cells up).
  bool cellsCertain() const { return !(edge_min / s.step < s.best_cell + 1.0 + kTieGuard); }
  // Whether the answer is the least depth by `margin` (many cells): then no cell matters.
  bool unique(double margin) const {
    const DepthResult& r = s.best;
    return r.kind == kind1 && r.ia == ia1 && r.ib == ib1 && min2 > min1 + margin;
  }
};

// The certificate: evaluate the entries whose lower bound does not exceed the best depth found
// (plus the rounding margin), nearest first; true, with `out`, when every other bound exceeds
// the best and the best is unique by the margin.
bool coherentTry(const Polytope& a,
                 const Polytope& b,
                 const Transform& X_AB,
                 DepthTracker& t,
                 DepthCache& cache,
                 DepthResult& out) {
  t.drift += poseDrift(a, b, t.last, X_AB);
  if (!(t.drift <= t.limit))
    return false;
  const double mu = 1e-10 * depthScale(a, b, X_AB);
  const Transform X_BA = X_AB.inverse();
  const auto fa = a.faces();
  const auto fb = b.faces();
  const auto ea = a.edges();
  const std::uint64_t tick = ++t.tick;
  // B's face normals in A's frame and A's face depths, each computed once per query
  auto neg_normal = [&](std::uint32_t k) {
    if (t.stamp_b[k] != tick) {
      t.stamp_b[k] = tick;
      t.neg_normal_b[k] = -X_AB.rotate(fb[k].normal);
    }
    return t.neg_normal_b[k];
  };
  CoherentBest best(kTieStep * depthScale(a, b, X_AB));
  auto faceA = [&](std::uint32_t i) {
    if (t.stamp_a[i] == tick)
      return t.value_a[i];
    t.stamp_a[i] = tick;
    const Vec3& n = fa[i].normal;
    std::uint32_t& hint = t.face_support_a[i];
    hint = b.support(X_BA.rotate(-n), hint);
    const double d = fa[i].offset - glm::dot(n, X_AB.apply(b.vertices()[hint].p));
    best.offer(d, n, DepthFeature::kFaceA, i, 0, hint);
    t.value_a[i] = d;
    return d;
  };
  const std::size_t budget = t.heap.size() / 4 + 8;
  t.popped.clear();
  bool ok = true;
  while (!t.heap.empty() && t.heap.front().key - t.drift <= best.s.best.depth + mu) {
    if (t.popped.size() >= budget) {
      ok = false;
      break;
    }
    std::pop_heap(t.heap.begin(), t.heap.end(), keyAfter);
    DepthTracker::Entry e = t.heap.back();
    t.heap.pop_back();
    const std::uint32_t idx = e.code & kIndexMask;
    double value = 0.0;
    switch (e.code >> 30) {
      case DepthTracker::kCodeFaceB: {
        const Vec3 m = -neg_normal(idx);
        e.hint = a.support(-m, e.hint);
        value = fb[idx].offset + glm::dot(m, X_AB.t) - glm::dot(m, a.vertices()[e.hint].p);
        best.offer(value, -m, DepthFeature::kFaceB, 0, idx, e.hint);
        break;
      }
      default: {
        // an edge of A: both ends (faces of A) and every crossing on its arc
        const double d0 = faceA(ea[idx].face[0]);
        const double d1 = faceA(ea[idx].face[1]);
        double arc_min = 0.0;
        const bool bounded = edgeArc(
            a, b, X_AB, idx, t.face_support_a[ea[idx].face[0]], t.face_support_a[ea[idx].face[1]],
            neg_normal,
            [&](double d, const Vec3& axis, std::uint32_t j) {
              best.offer(d, axis, DepthFeature::kEdgeEdge, idx, j, 0);
            },
            arc_min);
        if (!bounded) {
          arc_min = irregularArcMin(a, b, idx, arc_min, neg_normal, [&](std::uint32_t k) {
            const Vec3 m = -neg_normal(k);
            const std::uint32_t v = a.support(-m, t.support_b[k]);
            return fb[k].offset + glm::dot(m, X_AB.t) - glm::dot(m, a.vertices()[v].p);
          });
        }
        value = std::min({d0, d1, arc_min});
        break;
      }
    }
    e.key = value + t.drift;
    t.popped.push_back(e);
  }
  for (const DepthTracker::Entry& e : t.popped) {
    t.heap.push_back(e);
    std::push_heap(t.heap.begin(), t.heap.end(), keyAfter);
  }
  const DepthResult& r = best.s.best;
  // the answer is unique by the margin, or (ties) every candidate within the margin of the best
  // was evaluated and the tie grid's cells are certain: the full method picks the same feature
  ok = ok && r.kind != DepthFeature::kNone && r.depth > mu &&
       (best.unique(mu) || best.cellsCertain()) &&
       !(r.kind == DepthFeature::kEdgeEdge && atArcEnd(a, b, r, neg_normal));
  if (!ok)
    return false;
  const double tie_tol = 1e-12 * std::max(a.radius(), b.radius());
  witnesses(a, b, X_AB, X_BA, tie_tol, best.s, cache);
  cache.kind = r.kind;
  cache.ia = r.ia;
  cache.ib = r.ib;
  cache.normal = r.normal;
  t.last = X_AB;
  t.stats.evaluated += t.popped.size();
  out = r;
  return true;
}

// The full solve, recording every candidate, and the tracked state rebuilt from it.
DepthResult rebuild(const Polytope& a,
                    const Polytope& b,
                    const Transform& X_AB,
                    DepthTracker& t,
                    DepthCache& cache,
                    DepthScratch& scratch) {
  DepthRecord rec{t.value_a.data(), t.value_b.data(), t.support_b.data(), t.edge_min.data()};
  const DepthResult r = exactSolve(a, b, X_AB, cache, scratch, &rec);
  cache.normal = r.normal;
  const double mu = 1e-10 * depthScale(a, b, X_AB);
  // a lower bound on the depths needs the pair overlapping (every support gap positive), and
  // the record is whole only then (the exact method stops at a separating face of A)
  t.valid = r.kind != DepthFeature::kNone && r.depth > mu;
  if (!t.valid)
    return r;
  const auto fa = a.faces();
  const auto fb = b.faces();
  const auto ea = a.edges();
  t.heap.clear();
  // the faces of A need no entries: each is an end of its edges' arcs, whose keys bound it
  for (std::uint32_t i = 0; i < fa.size(); ++i) {
    t.face_support_a[i] = scratch.support_of_face[i];
    t.stamp_a[i] = 0;
  }
  std::fill(t.stamp_b.begin(), t.stamp_b.end(), 0);
  t.tick = 0;
  for (std::uint32_t j = 0; j < fb.size(); ++j)
    t.heap.push_back({t.value_b[j], (DepthTracker::kCodeFaceB << 30) | j, t.support_b[j]});
  for (std::uint32_t i = 0; i < ea.size(); ++i) {
    const auto& f = ea[i].face;
    t.heap.push_back({std::min({t.value_a[f[0]], t.value_a[f[1]], t.edge_min[i]}),
                      (DepthTracker::kCodeEdgeA << 30) | i, 0});
  }
  std::make_heap(t.heap.begin(), t.heap.end(), keyAfter);
  t.a = &a;
  t.b = &b;
  t.last = X_AB;
  t.answer = r;
  t.drift = 0.0;
  // keys are depth + drift: a drift of many sizes would round away the margin
  t.limit = 64.0 * (a.radius() + b.radius());
  return r;
}

}  // namespace

bool DepthTracker::fits(const Polytope& pa, const Polytope& pb) const {
  const std::size_t fa = pa.faces().size();
  const std::size_t fb = pb.faces().size();
  const std::size_t ea = pa.edges().size();
  return heap.capacity() >= fb + ea && popped.capacity() >= fb + ea && value_a.size() >= fa &&
         value_b.size() >= fb && support_b.size() >= fb && edge_min.size() >= ea &&
         face_support_a.size() >= fa && stamp_a.size() >= fa && stamp_b.size() >= fb &&
         neg_normal_b.size() >= fb && ea <= kIndexMask && fb <= kIndexMask;
}

DepthResult penetrationDepthCoherent(const Polytope& a,
                                     const Polytope& b,
                                     const Transform& X_AB,
                                     DepthTracker& tracker,
                                     DepthCache& cache,
                                     DepthScratch& scratch) {
  DepthTracker& t = tracker;
  ++t.stats.queries;
  const bool fits = t.fits(a, b);
  if (t.valid && fits && t.a == &a && t.b == &b) {
    if (geom::sameBits(X_AB.R, t.last.R) && geom::sameBits(X_AB.t, t.last.t)) {
      // the pose of the last answer, bit for bit: that answer again (every method here is a
      // function of the polytopes and the pose). A pair at rest whose answer lies at the tie
      // grid's guard band failed its certificate at every tick (the top pair of each of
      // Tick/stack100's stacks, answered in full each tick)
      ++t.stats.certified;
      ++t.stats.repeated;
      cache.kind = t.answer.kind;
      cache.ia = t.answer.ia;
      cache.ib = t.answer.ib;
      cache.normal = t.answer.normal;
      return t.answer;
    }
    DepthResult r;
    if (coherentTry(a, b, X_AB, t, cache, r)) {
      ++t.stats.certified;
      t.answer = r;
      return r;
    }
    ++t.stats.fallbacks;
  } else {
    ++t.stats.cold;
  }
  if (!fits) {
    t.valid = false;
    DepthResult r = penetrationDepthExact(a, b, X_AB, cache, scratch);
    cache.normal = r.normal;
    return r;
  }
  return rebuild(a, b, X_AB, t, cache, scratch);
}

DepthResult penetrationDepth(const Polytope& a,
                             const Polytope& b,
                             const Transform& X_AB,
                             DepthCache& cache,
                             DepthScratch& scratch) {
  DepthResult r;
  // small hulls: the separating axes are cheaper than the expanding polytope
  const bool small = a.edges().size() * b.edges().size() <= 4096;
  if (!small && penetrationDepthEpa(a, b, X_AB, cache, r))
    return r;
  r = penetrationDepthExact(a, b, X_AB, cache, scratch);
  cache.normal = r.normal;
  return r;
}

double depthAlong(const Polytope& a,
                  const Polytope& b,
                  const Transform& X_AB,
                  const Vec3& dir,
                  std::uint32_t& hint_a,
                  std::uint32_t& hint_b) {
  hint_a = a.support(dir, hint_a);
  const Vec3 dir_b = glm::transpose(X_AB.R) * (-dir);
  hint_b = b.support(dir_b, hint_b);
  return glm::dot(dir, a.vertices()[hint_a].p) - glm::dot(dir, X_AB.apply(b.vertices()[hint_b].p));
}

}  // namespace hapticd::collision
