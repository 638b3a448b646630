#include "core/collision/closest_features.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/collision/segment.h"

namespace hapticd::collision {
namespace {

using detail::closestOnSegment;
using detail::closestSegments;

constexpr std::uint32_t kNoIndex = std::numeric_limits<std::uint32_t>::max();
// edgesConfirmed()'s margin in units of the walk's plane tolerance (1e-9 of the pair's size)
constexpr double kConfirmMargin = 1e3;

// One ordered view of the pair: feature 1 on p1, feature 2 on p2.
struct View {
  const Polytope* p1;
  const Polytope* p2;
  const Transform* T12;  // p2's frame -> p1's frame
  const Transform* T21;  // p1's frame -> p2's frame
  bool* ambiguous;       // set by a step whose derivative test was within the tolerance
};

enum class Act : std::uint8_t { kDone, kSet1, kSet2, kPenetration };
struct Outcome {
  Act act = Act::kDone;
  Feature f;
};
Outcome set1(Feature f) {
  return {Act::kSet1, f};
}
Outcome set2(Feature f) {
  return {Act::kSet2, f};
}
constexpr Outcome kDone{Act::kDone, {}};
constexpr Outcome kPenetrating{Act::kPenetration, {}};

struct Tol {
  double len;    // lengths: plane violations, distance derivatives
  double angle;  // dimensionless: cosines of directions
};

// Result of clipping a segment p(l) = t + l (h - t), l in [0, 1], against planes.
struct Clip {
  double lo = 0.0, hi = 1.0;
  Feature nlo, nhi;  // the features beyond the planes that clipped at lo and hi
  bool excluded = false;
  bool simple = false;  // excluded by one plane alone (both ends outside it)
};

// Clips against the plane (x - p)·n >= 0 (inside) whose other side belongs to `neighbour`.
inline void clipPlane(Clip& c,
                      const Vec3& t,
                      const Vec3& h,
                      const Vec3& p,
                      const Vec3& n,
                      Feature neighbour,
                      double eps) {
  if (c.excluded)
    return;
  const double st = glm::dot(t - p, n);
  const double sh = glm::dot(h - p, n);
  if (st < -eps && sh < -eps) {
    c.excluded = true;
    c.simple = true;
    c.nlo = c.nhi = neighbour;
    return;
  }
  if (st < -eps) {
    const double l = std::clamp(st / (st - sh), 0.0, 1.0);
    if (l > c.lo)
      c.lo = l, c.nlo = neighbour;
  } else if (sh < -eps) {
    const double l = std::clamp(st / (st - sh), 0.0, 1.0);
    if (l < c.hi)
      c.hi = l, c.nhi = neighbour;
  }
  if (c.lo > c.hi)
    c.excluded = true;
}

// Derivative of half the squared distance from the moving point x(l) (unit direction u) to
// feature `n` of polytope `p` (all in p's frame): a length; > 0 when the distance grows with l.
double distanceDerivative(const Polytope& p, Feature n, const Vec3& x, const Vec3& u) {
  switch (n.type) {
    case FeatureType::kVertex:
      return glm::dot(u, x - p.vertices()[n.index].p);
    case FeatureType::kEdge: {
      const auto& e = p.edges()[n.index];
      const Vec3& t = p.vertices()[e.tail].p;
      const Vec3 q = t + e.dir * std::clamp(glm::dot(x - t, e.dir), 0.0, e.length);
      return glm::dot(u, x - q);
    }
    case FeatureType::kFace: {
      const auto& f = p.faces()[n.index];
      return (glm::dot(f.normal, x) - f.offset) * glm::dot(u, f.normal);
    }
    case FeatureType::kNone:
      break;
  }
  return 0.0;
}

// After clipping segment [t, h] (in p's frame) against VR(X) of p: Mirtich's derivative test.
// Returns the neighbour to move X to, or kNone. The derivative is that of half the squared
// distance, D * dD/dl: a slope below eps / D goes unseen, and `ambiguous` says one was that small.
Feature derivativeUpdate(const Polytope& p,
                         const Clip& c,
                         const Vec3& t,
                         const Vec3& h,
                         double eps,
                         bool& ambiguous) {
  if (!c.nlo.valid() && !c.nhi.valid())
    return {};  // not clipped: no neighbour to test (most warm steps end here)
  const Vec3 u = h - t;
  const double ulen = glm::length(u);
  if (ulen <= 0.0)
    return {};
  const Vec3 un = u / ulen;
  if (c.nlo.valid()) {
    const double d = distanceDerivative(p, c.nlo, t + u * c.lo, un);
    if (d > eps)
      return c.nlo;
    ambiguous = ambiguous || d >= -eps;
  }
  if (c.nhi.valid()) {
    const double d = distanceDerivative(p, c.nhi, t + u * c.hi, un);
    if (d < -eps)
      return c.nhi;
    ambiguous = ambiguous || d <= eps;
  }
  return {};
}

// Closest points of two segments, well conditioned also when they are nearly parallel (where
// closestSegments' line solution is not: its parameters carry errors of 1e-16 / sin^2 of the
// angle). In segment 1's frame, a point of segment 2 whose foot on line 1 falls inside segment 1
// is at the distance of its offset from line 1, and the offsets are linear along segment 2 and
// computed without cancellation; a point whose foot falls outside is nearer an end of segment 1,
// against which segment 2 is also tried. s, t are set; dist2 is the squared offset.
detail::SegmentPair closestSegmentsExact(const Vec3& p1,
                                         const Vec3& q1,
                                         const Vec3& p2,
                                         const Vec3& q2) {
  detail::SegmentPair best;
  best.dist2 = std::numeric_limits<double>::infinity();
  const Vec3 d1 = q1 - p1, d2 = q2 - p2;
  const double l1 = glm::length(d1);
  auto consider = [&](double s, double t, const Vec3& c1, const Vec3& c2, double dist2) {
    if (dist2 < best.dist2)
      best.s = s, best.t = t, best.c1 = c1, best.c2 = c2, best.dist2 = dist2;
  };
  for (const double s : {0.0, 1.0}) {
    const Vec3 x = s == 0.0 ? p1 : q1;
    const double t = closestOnSegment(x, p2, q2);
    const Vec3 c = p2 + d2 * t;
    consider(s, t, x, c, glm::dot(x - c, x - c));
  }
  if (l1 > 0.0) {
    const Vec3 u = d1 / l1;
    const double a0 = glm::dot(p2 - p1, u), a1 = glm::dot(q2 - p1, u);
    const Vec3 e0 = (p2 - p1) - u * a0, e1 = (q2 - p1) - u * a1;
    // the part of segment 2 whose feet lie on segment 1
    double lo = 0.0, hi = 1.0;
    if (a1 != a0) {
      const double ta = -a0 / (a1 - a0), tb = (l1 - a0) / (a1 - a0);
      lo = std::max(lo, std::min(ta, tb));
      hi = std::min(hi, std::max(ta, tb));
    } else if (a0 < 0.0 || a0 > l1) {
      lo = 2.0;  // none
    }
    if (lo <= hi) {
      const Vec3 de = e1 - e0;
      const double dd = glm::dot(de, de);
      const double t = std::clamp(dd > 0.0 ? -glm::dot(e0, de) / dd : lo, lo, hi);
      const Vec3 e = e0 + de * t;
      const double a = std::clamp(a0 + (a1 - a0) * t, 0.0, l1);
      consider(a / l1, t, p1 + u * a, p2 + d2 * t, glm::dot(e, e));
    }
  }
  return best;
}

// A vertex-edge pair where the walk stopped on a derivative within the tolerance: nearly
// parallel edges at a small gap D, whose distance falls along them at a slope below eps / D, so
// the walk may hold the far end's vertex (measured: 30% of a 1e-6 s gap). An edge of the vertex
// nearer to the other edge by more than `margin` is returned (kNoIndex when there is none);
// distances are compared directly, so each such move strictly lowers the distance.
std::uint32_t nearerEdgeOfVertex(const Polytope& pv,
                                 std::uint32_t v,
                                 const Transform& X_v,
                                 const Polytope& pe,
                                 std::uint32_t e,
                                 const Transform& X_e,
                                 double margin) {
  const auto& edge = pe.edges()[e];
  const Vec3 t = X_e.apply(pe.vertices()[edge.tail].p), h = X_e.apply(pe.vertices()[edge.head].p);
  const Vec3 x = X_v.apply(pv.vertices()[v].p);
  const Vec3 c = t + (h - t) * closestOnSegment(x, t, h);
  double best = glm::dot(x - c, x - c);
  const double d0 = std::sqrt(best);
  std::uint32_t out = kNoIndex;
  for (const auto& ve : pv.vertexEdges(v)) {
    const double d2 = closestSegmentsExact(x, X_v.apply(pv.vertices()[ve.other].p), t, h).dist2;
    if (d2 < best && std::sqrt(d2) < d0 - margin)
      best = d2, out = ve.edge;
  }
  return out;
}

// Distance from segment [t, h] (p's frame) to face f of p over the part of the segment inside
// the face's side planes (infinity when there is none; 0 when that part crosses the plane).
double segmentFaceDistance(const Polytope& p, std::uint32_t f, const Vec3& t, const Vec3& h) {
  double lo = 0.0, hi = 1.0;
  for (const auto& fe : p.faceEdges(f)) {
    const Vec3& v = p.vertices()[fe.vertex].p;
    const double st = glm::dot(t - v, fe.side), sh = glm::dot(h - v, fe.side);
    if (st < 0.0 && sh < 0.0)
      return std::numeric_limits<double>::infinity();
    if (st < 0.0) {
      lo = std::max(lo, st / (st - sh));
    } else if (sh < 0.0) {
      hi = std::min(hi, st / (st - sh));
    }
  }
  if (lo > hi)
    return std::numeric_limits<double>::infinity();
  const auto& face = p.faces()[f];
  const double dl = glm::dot(face.normal, t + (h - t) * lo) - face.offset;
  const double dh = glm::dot(face.normal, t + (h - t) * hi) - face.offset;
  if ((dl > 0.0) != (dh > 0.0))
    return 0.0;
  return std::min(std::abs(dl), std::abs(dh));
}

// An edge-edge pair where the walk stopped on a derivative within the tolerance: nearly parallel
// faces at a small gap, over which the distance falls at a slope below eps / D. A face of either
// edge nearer to the other edge by more than `margin` gives the next state (false: none). A's
// frame; X_AB places B.
bool nearerFaceOfEdges(const Polytope& a,
                       std::uint32_t ea,
                       const Polytope& b,
                       std::uint32_t eb,
                       const Transform& X_AB,
                       const Transform& X_BA,
                       double margin,
                       Feature& fa,
                       Feature& fb) {
  const auto& e1 = a.edges()[ea];
  const auto& e2 = b.edges()[eb];
  const Vec3 t1 = a.vertices()[e1.tail].p, h1 = a.vertices()[e1.head].p;
  const Vec3 t2 = b.vertices()[e2.tail].p, h2 = b.vertices()[e2.head].p;
  const double d0 =
      std::sqrt(closestSegmentsExact(t1, h1, X_AB.apply(t2), X_AB.apply(h2)).dist2) - margin;
  double best = d0;
  bool found = false;
  for (const std::uint32_t f : e2.face) {  // a face of B against A's edge, in B's frame
    const double d = segmentFaceDistance(b, f, X_BA.apply(t1), X_BA.apply(h1));
    if (d < best)
      best = d, fa = Feature::edge(ea), fb = Feature::face(f), found = true;
  }
  for (const std::uint32_t f : e1.face) {  // a face of A against B's edge
    const double d = segmentFaceDistance(a, f, X_AB.apply(t2), X_AB.apply(h2));
    if (d < best)
      best = d, fa = Feature::face(f), fb = Feature::edge(eb), found = true;
  }
  return found;
}

// The boundary edge of face f (of p) closest to segment [t, h] (p's frame).
std::uint32_t closestBoundaryEdge(const Polytope& p,
                                  std::uint32_t f,
                                  const Vec3& t,
                                  const Vec3& h) {
  double best = std::numeric_limits<double>::infinity();
  std::uint32_t best_edge = kNoIndex;
  for (const auto& fe : p.faceEdges(f)) {
    const auto& e = p.edges()[fe.edge];
    const double d2 = closestSegments(t, h, p.vertices()[e.tail].p, p.vertices()[e.head].p).dist2;
    if (d2 < best)
      best = d2, best_edge = fe.edge;
  }
  return best_edge;
}

// The edge of vertex v (of p) whose Voronoi plane x (p's frame) violates most, or kNoIndex.
std::uint32_t mostViolatedEdge(const Polytope& p, std::uint32_t v, const Vec3& x, double tol) {
  const Vec3& pv = p.vertices()[v].p;
  double worst = tol;
  std::uint32_t edge = kNoIndex;
  for (const auto& ve : p.vertexEdges(v)) {
    const double s = glm::dot(x - pv, ve.out);
    if (s > worst)
      worst = s, edge = ve.edge;
  }
  return edge;
}

Outcome stepVV(const View& w, std::uint32_t v1, std::uint32_t v2, const Tol& tol) {
  const Vec3& p1 = w.p1->vertices()[v1].p;
  const Vec3& p2 = w.p2->vertices()[v2].p;
  if (const auto e = mostViolatedEdge(*w.p1, v1, w.T12->apply(p2), tol.len); e != kNoIndex) {
    return set1(Feature::edge(e));
  }
  if (const auto e = mostViolatedEdge(*w.p2, v2, w.T21->apply(p1), tol.len); e != kNoIndex) {
    return set2(Feature::edge(e));
  }
  return kDone;
}

// Vertex v of p1 against edge e of p2.
Outcome stepVE(const View& w, std::uint32_t v, std::uint32_t ei, const Tol& tol) {
  const auto& e = w.p2->edges()[ei];
  const Vec3& t = w.p2->vertices()[e.tail].p;
  const Vec3& h = w.p2->vertices()[e.head].p;
  const Vec3 x = w.T21->apply(w.p1->vertices()[v].p);
  // x against VR(e): vertex planes first, then face planes
  if (glm::dot(x - t, e.dir) < -tol.len)
    return set2(Feature::vertex(e.tail));
  if (glm::dot(h - x, e.dir) < -tol.len)
    return set2(Feature::vertex(e.head));
  const double s0 = glm::dot(x - t, e.fe_normal[0]);
  const double s1 = glm::dot(x - t, e.fe_normal[1]);
  if (s0 < -tol.len || s1 < -tol.len)
    return set2(Feature::face(s0 < s1 ? e.face[0] : e.face[1]));
  // clip e against VR(v) in p1's frame
  const Vec3& pv = w.p1->vertices()[v].p;
  const Vec3 t1 = w.T12->apply(t), h1 = w.T12->apply(h);
  Clip c;
  for (const auto& ve : w.p1->vertexEdges(v)) {
    clipPlane(c, t1, h1, pv, -ve.out, Feature::edge(ve.edge), tol.len);
  }
  if (c.excluded && c.simple)
    return set1(c.nlo);
  const Feature n = derivativeUpdate(*w.p1, c, t1, h1, tol.len, *w.ambiguous);
  if (n.valid())
    return set1(n);
  if (c.excluded)
    return set1(c.nlo);
  return kDone;
}

// Vertex v of p1 against face f of p2.
Outcome stepVF(const View& w, std::uint32_t v, std::uint32_t fi, const Tol& tol) {
  const auto& f = w.p2->faces()[fi];
  const Vec3 x = w.T21->apply(w.p1->vertices()[v].p);
  double worst = -tol.len;
  bool outside = false;
  for (const auto& fe : w.p2->faceEdges(fi)) {
    const double s = glm::dot(x - w.p2->vertices()[fe.vertex].p, fe.side);
    if (s < worst)
      worst = s, outside = true;
  }
  if (outside)
    return set2(Feature::edge(closestBoundaryEdge(*w.p2, fi, x, x)));

  const double D = glm::dot(f.normal, x) - f.offset;
  // the edge of v that descends most steeply toward (D > 0) or away from (D < 0) the plane (the
  // face's normal turned into p1's frame once, not each edge into p2's)
  const Vec3 n1 = w.T12->rotate(f.normal);
  double steepest = 0.0;
  std::uint32_t edge = kNoIndex;
  for (const auto& ve : w.p1->vertexEdges(v)) {
    const double c = glm::dot(ve.out, n1);
    if (c < steepest)
      steepest = c, edge = ve.edge;
  }
  if (D > tol.len) {
    if (edge != kNoIndex && steepest < -tol.angle)
      return set1(Feature::edge(edge));
    return kDone;
  }
  if (D >= -tol.len) {
    // on the plane: an edge of v going below it pierces the face
    if (edge != kNoIndex && steepest < -tol.angle)
      return kPenetrating;
    return kDone;
  }
  // below the face plane: a local minimum unless some face of p2 has v above it
  double best = -std::numeric_limits<double>::infinity();
  std::uint32_t best_face = kNoIndex;
  const auto faces = w.p2->faces();
  for (std::uint32_t k = 0; k < faces.size(); ++k) {
    const double d = glm::dot(faces[k].normal, x) - faces[k].offset;
    if (d > best)
      best = d, best_face = k;
  }
  if (best < -tol.len)
    return kPenetrating;
  if (best_face == fi)
    return kPenetrating;  // cannot happen (D < -tol); guards a cycle
  return set2(Feature::face(best_face));
}

// Edge e1 of p1 against the Voronoi region of edge e2 of p2 (one direction of the E-E test).
Outcome clipEdgeAgainstEdge(const View& w, std::uint32_t e1i, std::uint32_t e2i, const Tol& tol) {
  const auto& e1 = w.p1->edges()[e1i];
  const auto& e2 = w.p2->edges()[e2i];
  const Vec3 t1 = w.T21->apply(w.p1->vertices()[e1.tail].p);
  const Vec3 h1 = w.T21->apply(w.p1->vertices()[e1.head].p);
  const Vec3& t2 = w.p2->vertices()[e2.tail].p;
  const Vec3& h2 = w.p2->vertices()[e2.head].p;
  Clip c;
  clipPlane(c, t1, h1, t2, e2.dir, Feature::vertex(e2.tail), tol.len);
  clipPlane(c, t1, h1, h2, -e2.dir, Feature::vertex(e2.head), tol.len);
  if (c.excluded && c.simple)
    return set2(c.nlo);
  if (const Feature n = derivativeUpdate(*w.p2, c, t1, h1, tol.len, *w.ambiguous); n.valid()) {
    return set2(n);
  }
  clipPlane(c, t1, h1, t2, e2.fe_normal[0], Feature::face(e2.face[0]), tol.len);
  clipPlane(c, t1, h1, t2, e2.fe_normal[1], Feature::face(e2.face[1]), tol.len);
  if (c.excluded && c.simple)
    return set2(c.nlo);
  if (const Feature n = derivativeUpdate(*w.p2, c, t1, h1, tol.len, *w.ambiguous); n.valid()) {
    return set2(n);
  }
  if (c.excluded) {
    // Excluded by both face planes with no derivative verdict: e1 passes through the apex of
    // e2's wedge, i.e. the edges meet (distance within the plane tolerance). No neighbour is
    // nearer, and moving e2 to a face would keep the distance while raising the dimension: the
    // edge-face step then hands the face back to e2, a cycle. The pair is final (touching).
    if (closestSegments(t1, h1, t2, h2).dist2 <= 4.0 * tol.len * tol.len)
      return kDone;
    return set2(c.nlo);
  }
  return kDone;
}

Outcome stepEE(const View& w, std::uint32_t e1, std::uint32_t e2, const Tol& tol) {
  if (const Outcome o = clipEdgeAgainstEdge(w, e1, e2, tol); o.act != Act::kDone)
    return o;
  const View r{w.p2, w.p1, w.T21, w.T12, w.ambiguous};
  const Outcome o = clipEdgeAgainstEdge(r, e2, e1, tol);
  if (o.act == Act::kSet2)
    return set1(o.f);
  return o;
}

// Edge e of p1 against face f of p2. Never a final state.
Outcome stepEF(const View& w, std::uint32_t ei, std::uint32_t fi, const Tol& tol) {
  const auto& e = w.p1->edges()[ei];
  const auto& f = w.p2->faces()[fi];
  const Vec3 t = w.T21->apply(w.p1->vertices()[e.tail].p);
  const Vec3 h = w.T21->apply(w.p1->vertices()[e.head].p);
  Clip c;
  for (const auto& fe : w.p2->faceEdges(fi)) {
    clipPlane(c, t, h, w.p2->vertices()[fe.vertex].p, fe.side, Feature::edge(fe.edge), tol.len);
  }
  if (c.excluded)
    return set2(Feature::edge(closestBoundaryEdge(*w.p2, fi, t, h)));
  const Vec3 u = h - t;
  const double dl = glm::dot(f.normal, t + u * c.lo) - f.offset;
  const double du = glm::dot(f.normal, t + u * c.hi) - f.offset;
  if ((dl > tol.len && du < -tol.len) || (dl < -tol.len && du > tol.len))
    return kPenetrating;
  const double un = glm::dot(glm::normalize(u), f.normal);
  auto sgn = [&](double d) { return d > tol.len ? 1.0 : (d < -tol.len ? -1.0 : 0.0); };
  if (sgn(dl) * un >= 0.0) {
    return c.nlo.valid() ? set2(c.nlo) : set1(Feature::vertex(e.tail));
  }
  if (sgn(du) * un <= 0.0) {
    return c.nhi.valid() ? set2(c.nhi) : set1(Feature::vertex(e.head));
  }
  return kDone;
}

// The closest points of an edge pair, as closestPoints() computes them (A's frame). No default
// values: it lives on the walk's every query and is read only once set (zeroing it, and the
// results below, cost a tenth of a near-contact pair query: PairQuery/NearContact).
struct EdgePair {
  double s, t;   // parameters on ea and eb
  Vec3 c1, c2;   // the closest points
  double dist2;  // squared distance
  Vec3 n;        // ea.dir x eb.dir
  double len;    // |n|
  void set(const detail::SegmentPair& p) {
    s = p.s, t = p.t, c1 = p.c1, c2 = p.c2, dist2 = p.dist2;
  }
};

// The witnesses of the final feature pair (A's frame); set by closestPoints().
struct Witness {
  Vec3 point_a, point_b, normal;
  double distance;
};

void edgePair(const Polytope& a,
              std::uint32_t ea_i,
              const Polytope& b,
              std::uint32_t eb_i,
              const Transform& T_ab,
              EdgePair& out) {
  const auto& ea = a.edges()[ea_i];
  const auto& eb = b.edges()[eb_i];
  out.n = glm::cross(ea.dir, T_ab.rotate(eb.dir));
  out.len = glm::length(out.n);
  const Vec3& ta = a.vertices()[ea.tail].p;
  const Vec3& ha = a.vertices()[ea.head].p;
  const Vec3 tb = T_ab.apply(b.vertices()[eb.tail].p), hb = T_ab.apply(b.vertices()[eb.head].p);
  // (edges within 1e-3 rad of parallel: closestSegments' line solution is ill-conditioned)
  out.set(out.len > 1e-3 ? closestSegments(ta, ha, tb, hb) : closestSegmentsExact(ta, ha, tb, hb));
}

// V-Clip's termination condition checked on the closest points themselves (Mirtich 1998,
// Theorem 2): when the point of edge ea closest to edge eb lies in VR(eb) and the point of eb
// closest to ea lies in VR(ea), they are the polytopes' closest points (x2 in VR(ea) puts B's
// point outside A with A's nearest point x1, and the other way round: the slab between them
// separates). The walk's step would end there too, after clipping each edge against the other's
// region and two derivative tests (a square root and a division each): a warm edge-edge pair,
// half of the near-contact path, is confirmed by eight plane tests instead. Each test must hold
// by `margin` and the edges must cross at more than 1e-3 rad with both points inside their
// edges; anything closer to a region's boundary, or a gap within the margin, goes through the
// walk's step as before. A's frame; `out` holds the points for closestPoints().
bool edgesConfirmed(const Polytope& a,
                    std::uint32_t ea_i,
                    const Polytope& b,
                    std::uint32_t eb_i,
                    const Transform& X_AB,
                    const Transform& X_BA,
                    double margin,
                    EdgePair& out) {
  const auto& ea = a.edges()[ea_i];
  const auto& eb = b.edges()[eb_i];
  out.n = glm::cross(ea.dir, X_AB.rotate(eb.dir));
  out.len = glm::length(out.n);
  if (!(out.len > 1e-3))
    return false;
  out.set(closestSegments(a.vertices()[ea.tail].p, a.vertices()[ea.head].p,
                          X_AB.apply(b.vertices()[eb.tail].p),
                          X_AB.apply(b.vertices()[eb.head].p)));
  const EdgePair& s = out;
  if (!(s.s > 0.0 && s.s < 1.0 && s.t > 0.0 && s.t < 1.0) || !(s.dist2 > margin * margin))
    return false;
  auto inRegion = [margin](const Polytope& p, std::uint32_t ei, const Vec3& x) {
    const auto& e = p.edges()[ei];
    const Vec3 r = x - p.vertices()[e.tail].p;
    const double along = glm::dot(r, e.dir);
    return along > margin && e.length - along > margin && glm::dot(r, e.fe_normal[0]) > margin &&
           glm::dot(r, e.fe_normal[1]) > margin;
  };
  return inRegion(a, ea_i, s.c2) && inRegion(b, eb_i, X_BA.apply(s.c1));
}

Outcome dispatch(const View& w, Feature f1, Feature f2, const Tol& tol) {
  using FT = FeatureType;
  switch (f1.type) {
    case FT::kVertex:
      if (f2.type == FT::kVertex)
        return stepVV(w, f1.index, f2.index, tol);
      if (f2.type == FT::kEdge)
        return stepVE(w, f1.index, f2.index, tol);
      return stepVF(w, f1.index, f2.index, tol);
    case FT::kEdge:
      if (f2.type == FT::kEdge)
        return stepEE(w, f1.index, f2.index, tol);
      return stepEF(w, f1.index, f2.index, tol);
    default:
      // face-face is never reached by the walk; a stale cache may hold it: restart at a vertex
      return set1(Feature::vertex(w.p1->faceEdges(f1.index)[0].vertex));
  }
}

bool validFeature(const Polytope& p, Feature f) {
  switch (f.type) {
    case FeatureType::kVertex:
      return f.index < p.vertices().size();
    case FeatureType::kEdge:
      return f.index < p.edges().size();
    case FeatureType::kFace:
      return f.index < p.faces().size();
    case FeatureType::kNone:
      break;
  }
  return false;
}

// Closest points of the final feature pair, in A's frame.
void closestPoints(const Polytope& a,
                   const Polytope& b,
                   const Transform& T_ab,
                   Feature fa,
                   Feature fb,
                   const EdgePair* known,
                   Witness& r) {
  using FT = FeatureType;
  r.normal = Vec3{0.0};
  auto vertA = [&](std::uint32_t i) { return a.vertices()[i].p; };
  auto vertB = [&](std::uint32_t i) { return T_ab.apply(b.vertices()[i].p); };
  auto centreLine = [&] { return T_ab.apply(b.centroid()) - a.centroid(); };
  if (fa.type == FT::kVertex && fb.type == FT::kVertex) {
    r.point_a = vertA(fa.index);
    r.point_b = vertB(fb.index);
  } else if (fa.type == FT::kVertex && fb.type == FT::kEdge) {
    const auto& e = b.edges()[fb.index];
    r.point_a = vertA(fa.index);
    const Vec3 t = vertB(e.tail), h = vertB(e.head);
    r.point_b = t + (h - t) * closestOnSegment(r.point_a, t, h);
  } else if (fa.type == FT::kEdge && fb.type == FT::kVertex) {
    const auto& e = a.edges()[fa.index];
    r.point_b = vertB(fb.index);
    const Vec3 t = vertA(e.tail), h = vertA(e.head);
    r.point_a = t + (h - t) * closestOnSegment(r.point_b, t, h);
  } else if (fa.type == FT::kEdge && fb.type == FT::kEdge) {
    EdgePair computed;  // NOLINT(cppcoreguidelines-pro-type-member-init): set before it is read
    if (known == nullptr)
      edgePair(a, fa.index, b, fb.index, T_ab, computed);
    const EdgePair& ep = known != nullptr ? *known : computed;
    const EdgePair& s = ep;
    const Vec3& n = ep.n;
    const double len = ep.len;
    r.point_a = s.c1;
    r.point_b = s.c2;
    const bool interior = s.s > 0.0 && s.s < 1.0 && s.t > 0.0 && s.t < 1.0;
    if (len > 1e-6 && (interior || s.dist2 == 0.0)) {
      // the normal of non-parallel edges meeting inside both is their common perpendicular, away
      // from A (when the closest points are at an end, it is the witnesses' direction)
      r.normal = n / len;
      const double side = glm::dot(r.normal, r.point_b - r.point_a);
      if (side < 0.0 || (side == 0.0 && glm::dot(r.normal, centreLine()) < 0.0)) {
        r.normal = -r.normal;
      }
    }
  } else if (fa.type == FT::kVertex && fb.type == FT::kFace) {
    const auto& f = b.faces()[fb.index];
    const Vec3 n = T_ab.rotate(f.normal);
    r.point_a = vertA(fa.index);
    const Vec3 on = vertB(b.faceEdges(fb.index)[0].vertex);
    r.point_b = r.point_a - n * glm::dot(r.point_a - on, n);
    r.normal = -n;
  } else if (fa.type == FT::kFace && fb.type == FT::kVertex) {
    const auto& f = a.faces()[fa.index];
    r.point_b = vertB(fb.index);
    r.point_a = r.point_b - f.normal * (glm::dot(f.normal, r.point_b) - f.offset);
    r.normal = f.normal;
  }
  const Vec3 d = r.point_b - r.point_a;
  r.distance = glm::length(d);
  if (r.normal == Vec3{0.0}) {
    r.normal = r.distance > 0.0 ? d / r.distance : glm::normalize(centreLine());
  }
}

}  // namespace

ClosestResult closestFeatures(const Polytope& a,
                              const Polytope& b,
                              const Transform& X_AB,
                              FeatureCache& cache,
                              const QueryOptions& options) {
  const Transform X_BA = X_AB.inverse();
  const double scale = std::max(a.radius(), b.radius());
  const Tol tol{1e-12 * scale, 1e-12};
  Feature fa = cache.a, fb = cache.b;
  if (!validFeature(a, fa) || !validFeature(b, fb)) {
    // cold start: the directional lookup table, along the line between the centres
    const Vec3 cb_a = X_AB.apply(b.centroid());
    Vec3 d = cb_a - a.centroid();
    if (glm::dot(d, d) <= 0.0)
      d = Vec3{1.0, 0.0, 0.0};
    fa = Feature::vertex(a.lookup(d));
    fb = Feature::vertex(b.lookup(X_BA.rotate(-d)));
  }
  // the cap, 4 * (features of A + features of B) + 64, is only worked out if 64 steps are not
  // enough
  std::uint32_t cap = options.max_iterations != 0 ? options.max_iterations : 64;
  const bool default_cap = options.max_iterations == 0;
  bool ambiguous = false;
  const View ab{&a, &b, &X_AB, &X_BA, &ambiguous};
  const View ba{&b, &a, &X_BA, &X_AB, &ambiguous};
  const Transform I{};
  Outcome o;
  // an edge pair's closest points, when edgesConfirmed() ended the walk
  EdgePair known;  // NOLINT(cppcoreguidelines-pro-type-member-init): set before it is read
  bool confirmed = false;
  std::uint32_t it = 0;
  int nudges = 0;
  for (;; ++it) {
    if (it == cap) {
      if (!default_cap || cap > 64)
        break;
      cap = static_cast<std::uint32_t>(4 * (a.vertices().size() + a.edges().size() +
                                            a.faces().size() + b.vertices().size() +
                                            b.edges().size() + b.faces().size()) +
                                       64);
      if (it == cap)
        break;
    }
    const bool swap = static_cast<int>(fa.type) > static_cast<int>(fb.type);
    if (fa.type == FeatureType::kEdge && fb.type == FeatureType::kEdge &&
        edgesConfirmed(a, fa.index, b, fb.index, X_AB, X_BA, kConfirmMargin * tol.len, known)) {
      confirmed = true;
      o = kDone;
      break;
    }
    ambiguous = false;
    o = swap ? dispatch(ba, fb, fa, tol) : dispatch(ab, fa, fb, tol);
    if (o.act == Act::kDone && ambiguous && nudges < 4) {
      // a vertex-edge or edge-edge end on a derivative within the tolerance: compare the
      // distances themselves (each such move lowers the distance by more than 1e-14 s)
      std::uint32_t e = kNoIndex;
      if (fa.type == FeatureType::kVertex && fb.type == FeatureType::kEdge) {
        e = nearerEdgeOfVertex(a, fa.index, I, b, fb.index, X_AB, 1e-2 * tol.len);
        if (e != kNoIndex)
          fa = Feature::edge(e);
      } else if (fa.type == FeatureType::kEdge && fb.type == FeatureType::kVertex) {
        e = nearerEdgeOfVertex(b, fb.index, X_AB, a, fa.index, I, 1e-2 * tol.len);
        if (e != kNoIndex)
          fb = Feature::edge(e);
      }
      if (e != kNoIndex) {
        ++nudges;
        continue;
      }
      if (fa.type == FeatureType::kEdge && fb.type == FeatureType::kEdge &&
          nearerFaceOfEdges(a, fa.index, b, fb.index, X_AB, X_BA, 1e-2 * tol.len, fa, fb)) {
        ++nudges;
        continue;
      }
    }
    if (o.act == Act::kDone || o.act == Act::kPenetration)
      break;
    const bool first = o.act == Act::kSet1;
    if (first != swap) {
      fa = o.f;
    } else {
      fb = o.f;
    }
  }
  cache.a = fa;
  cache.b = fb;
  if (it == cap || o.act == Act::kPenetration) {
    ClosestResult r;
    r.iterations = it;
    r.fa = fa;
    r.fb = fb;
    r.end = it == cap ? WalkEnd::kIterationCap : WalkEnd::kPenetration;
    r.status = it == cap ? ContactStatus::kSeparated : ContactStatus::kPenetrating;
    return r;
  }
  Witness w;  // NOLINT(cppcoreguidelines-pro-type-member-init): closestPoints() sets it
  closestPoints(a, b, X_AB, fa, fb, confirmed ? &known : nullptr, w);
  // every field written once (a ClosestResult built with its defaults was zeroed first)
  return ClosestResult{.status = w.distance <= options.touch_tolerance * scale
                                     ? ContactStatus::kTouching
                                     : ContactStatus::kSeparated,
                       .end = WalkEnd::kConverged,
                       .distance = w.distance,
                       .point_a = w.point_a,
                       .point_b = w.point_b,
                       .normal = w.normal,
                       .fa = fa,
                       .fb = fb,
                       .iterations = it};
}

}  // namespace hapticd::collision
