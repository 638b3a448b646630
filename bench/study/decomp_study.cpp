// The decomposition part of the accuracy study (part decomposition/crescent): a non-convex model
// touched through the convex pieces of its decomposition (core/decomp) at several concavities,
// against the exact distance to the model's own triangle mesh.
//
// The model: a crescent, a ring sector of 270 degrees (outer radius 30 mm, inner 20 mm, 20 mm
// thick, 32 segments) whose inner wall is concave. The probe: a sphere of 4 mm radius whose centre
// runs along the inner and the outer wall (from 1 mm deep to 0.5 mm apart, up and down the
// thickness), 200 configurations each. Every answer becomes the same force as in the pair part:
// the predictive penalty F = k_s (delta - d) n when the gap d < delta (k_s = 0.6 N/mm, delta = 0.1
// mm), n pushing the probe out. A sphere's contact force passes through its centre: no torque.
//
// - Truth: the signed distance from the sphere's centre to the triangle mesh, brute force over
//   its triangles (closest point on each, Ericson 2005 §5.1.5), inside by the winding number
//   (the sum of the triangles' solid angles, Van Oosterom & Strackee 1983), less the radius.
// - Decomposition at concavity c: the same sphere against the union of the pieces, each piece
//   exactly (outside: the closest point on its triangles; inside: the nearest face plane), the
//   piece with the smallest distance answering (the deepest, when inside several). Its time per
//   configuration is what the narrow phase pays for it: the tracked query (collision::queryPair,
//   a 128-point hull of the sphere) against every piece whose bounding sphere is within reach.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <vector>

#include "bench/study/study.h"
#include "core/collision/pair_query.h"
#include "core/decomp/decompose.h"
#include "core/geometry/polytope.h"
#include "core/geometry/sphere_points.h"

namespace hapticd::study {
namespace {

using geom::Vec3;

constexpr double kStiffness = 600.0;  // N/m
constexpr double kDelta = 1e-4;       // m
constexpr double kProbeRadius = 0.004;
constexpr double kOuter = 0.030, kInner = 0.020, kHalfThick = 0.010;
constexpr double kHalfAngle = 0.75 * std::numbers::pi;  // 270 degrees in all
constexpr int kSegments = 32;

// The crescent, closed, triangles counter-clockwise seen from outside.
decomp::TriangleMesh crescent() {
  decomp::TriangleMesh m;
  for (int i = 0; i <= kSegments; ++i) {
    const double a = -kHalfAngle + 2.0 * kHalfAngle * i / kSegments;
    const double c = std::cos(a), s = std::sin(a);
    m.positions.push_back({kOuter * c, kOuter * s, -kHalfThick});  // 4i: outer bottom
    m.positions.push_back({kOuter * c, kOuter * s, kHalfThick});   // 4i+1: outer top
    m.positions.push_back({kInner * c, kInner * s, -kHalfThick});  // 4i+2: inner bottom
    m.positions.push_back({kInner * c, kInner * s, kHalfThick});   // 4i+3: inner top
  }
  const auto v = [](int i, int k) { return static_cast<std::uint32_t>(4 * i + k); };
  for (int i = 0; i < kSegments; ++i) {
    const int j = i + 1;
    m.triangles.push_back({v(i, 0), v(j, 0), v(j, 1)});  // outer wall
    m.triangles.push_back({v(i, 0), v(j, 1), v(i, 1)});
    m.triangles.push_back({v(i, 2), v(j, 3), v(j, 2)});  // inner wall
    m.triangles.push_back({v(i, 2), v(i, 3), v(j, 3)});
    m.triangles.push_back({v(i, 1), v(j, 1), v(j, 3)});  // top
    m.triangles.push_back({v(i, 1), v(j, 3), v(i, 3)});
    m.triangles.push_back({v(i, 0), v(j, 2), v(j, 0)});  // bottom
    m.triangles.push_back({v(i, 0), v(i, 2), v(j, 2)});
  }
  const int n = kSegments;
  m.triangles.push_back({v(0, 0), v(0, 1), v(0, 3)});  // the end at the first angle
  m.triangles.push_back({v(0, 0), v(0, 3), v(0, 2)});
  m.triangles.push_back({v(n, 0), v(n, 3), v(n, 1)});  // the end at the last angle
  m.triangles.push_back({v(n, 0), v(n, 2), v(n, 3)});
  return m;
}

// Closest point to p on the triangle abc (Ericson, Real-Time Collision Detection, §5.1.5).
Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0)
    return a;
  const Vec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3)
    return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
    return a + d1 / (d1 - d3) * ab;
  const Vec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6)
    return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
    return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// The solid angle of the triangle abc seen from p, signed by its winding (Van Oosterom and
// Strackee 1983).
double solidAngle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 A = a - p, B = b - p, C = c - p;
  const double la = glm::length(A), lb = glm::length(B), lc = glm::length(C);
  const double num = glm::dot(A, glm::cross(B, C));
  const double den = la * lb * lc + glm::dot(A, B) * lc + glm::dot(B, C) * la + glm::dot(C, A) * lb;
  return 2.0 * std::atan2(num, den);
}

// A signed distance of the probe's centre to a surface (< 0 inside) and the unit direction that
// pushes the probe out.
struct Answer {
  double d = std::numeric_limits<double>::infinity();
  Vec3 n{0.0};
};

Answer meshAnswer(const decomp::TriangleMesh& m, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity(), winding = 0.0;
  Vec3 q_best{0.0};
  for (const auto& t : m.triangles) {
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    const Vec3 q = closestOnTriangle(p, a, b, c);
    const double d = glm::length(p - q);
    if (d < best) {
      best = d;
      q_best = q;
    }
    winding += solidAngle(p, a, b, c);
  }
  const bool inside = std::abs(winding) > 2.0 * std::numbers::pi;  // |w| > 1/2 of 4 pi
  Answer out;
  out.d = inside ? -best : best;
  out.n = best > 0.0 ? (inside ? q_best - p : p - q_best) / best : Vec3{0.0};
  return out;
}

// One convex piece, its faces oriented outward.
struct Piece {
  decomp::ConvexPiece mesh;
  std::vector<Vec3> normals;  // per triangle, outward
  Vec3 centre{0.0};
  double radius = 0.0;
  std::shared_ptr<const geom::Polytope> hull;
};

Piece makePiece(decomp::ConvexPiece mesh) {
  Piece p;
  for (const Vec3& v : mesh.vertices)
    p.centre += v / static_cast<double>(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices)
    p.radius = std::max(p.radius, glm::length(v - p.centre));
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    Vec3 n = glm::cross(b - a, c - a);
    const double l = glm::length(n);
    n = l > 0.0 ? n / l : Vec3{0.0};
    if (glm::dot(n, p.centre - a) > 0.0)
      n = -n;
    p.normals.push_back(n);
  }
  auto hull = geom::Polytope::fromPoints(mesh.vertices);
  if (hull.ok())
    p.hull = std::make_shared<const geom::Polytope>(std::move(hull).value());
  p.mesh = std::move(mesh);
  return p;
}

Answer pieceAnswer(const Piece& piece, const Vec3& p) {
  const auto& m = piece.mesh;
  double deepest = -std::numeric_limits<double>::infinity();
  Vec3 n_deepest{0.0};
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    const double s = glm::dot(piece.normals[i], p - m.vertices[m.triangles[i][0]]);
    if (s > deepest) {
      deepest = s;
      n_deepest = piece.normals[i];
    }
  }
  Answer out;
  if (deepest <= 0.0) {  // inside: the nearest face plane
    out.d = deepest;
    out.n = n_deepest;
    return out;
  }
  double best = std::numeric_limits<double>::infinity();
  Vec3 q_best{0.0};
  for (const auto& t : m.triangles) {
    const Vec3 q = closestOnTriangle(p, m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]);
    const double d = glm::length(p - q);
    if (d < best) {
      best = d;
      q_best = q;
    }
  }
  out.d = best;
  out.n = best > 0.0 ? (p - q_best) / best : n_deepest;
  return out;
}

Vec3 penaltyForce(const Answer& a) {
  const double gap = a.d - kProbeRadius;
  return gap < kDelta ? kStiffness * (kDelta - gap) * a.n : Vec3{0.0};
}

// The probe's centres: along the inner wall and along the outer wall.
std::vector<Vec3> probePath(int per_wall) {
  std::vector<Vec3> out;
  for (const bool inner : {true, false}) {
    for (int i = 0; i < per_wall; ++i) {
      const double u = (i + 0.5) / per_wall;
      const double a = -0.95 * kHalfAngle + 1.9 * kHalfAngle * u;
      // from 1 mm deep to 0.5 mm apart, three times along the wall
      const double gap = -0.00025 + 0.00075 * std::sin(6.0 * std::numbers::pi * u);
      const double r = inner ? kInner - kProbeRadius - gap : kOuter + kProbeRadius + gap;
      const double z = 0.5 * kHalfThick * std::sin(4.0 * std::numbers::pi * u);
      out.push_back({r * std::cos(a), r * std::sin(a), z});
    }
  }
  return out;
}

}  // namespace

void runDecomposition(const Options& options, std::vector<Row>& rows) {
  const std::string part = "decomposition/crescent";
  const decomp::TriangleMesh mesh = crescent();
  const auto path = probePath(options.quick ? 60 : 200);
  std::vector<Vec3> truth;
  std::vector<bool> truth_contact;
  Row exact{part, "exact mesh", "brute force (the truth)", {}, {}, {}, 0, 0, 0, 0, {}, {}};
  const double overhead = timerOverheadNs();
  for (const Vec3& p : path) {
    const auto t0 = std::chrono::steady_clock::now();
    const Vec3 f = penaltyForce(meshAnswer(mesh, p));
    const auto t1 = std::chrono::steady_clock::now();
    truth.push_back(f);
    truth_contact.push_back(glm::dot(f, f) > 0.0);
    exact.add(0.0, 0.0,
              std::max(0.0, std::chrono::duration<double, std::nano>(t1 - t0).count() - overhead),
              truth_contact.back(), truth_contact.back());
  }
  rows.push_back(std::move(exact));
  auto probe = geom::Polytope::fromPoints(geom::spiralSpherePoints(kProbeRadius, 128));
  if (!probe.ok()) {
    std::fprintf(stderr, "study: %s: probe hull: %s\n", part.c_str(),
                 probe.error().message.c_str());
    return;
  }
  const std::vector<double> concavities = options.quick
                                              ? std::vector<double>{0.04, 0.01}
                                              : std::vector<double>{0.08, 0.04, 0.02, 0.01, 0.005};
  for (const double c : concavities) {
    decomp::DecompOptions o;
    o.concavity = c;
    auto result = decomp::decompose(mesh, o);
    if (!result.ok()) {
      std::fprintf(stderr, "study: %s: concavity %g: %s\n", part.c_str(), c,
                   result.error().message.c_str());
      continue;
    }
    std::vector<Piece> pieces;
    for (auto& p : result.value().pieces)
      pieces.push_back(makePiece(std::move(p)));
    char setting[96];
    std::snprintf(setting, sizeof setting, "concavity=%g%s", c, c == 0.01 ? " (default)" : "");
    Row row{part, "decomposition", setting, {}, {}, {}, 0, 0, 0, 0, {}, {}};
    std::size_t narrow_contacts = 0;  // the timed queries' answers, used (and printed)
    for (std::size_t k = 0; k < path.size(); ++k) {
      const Vec3& p = path[k];
      Answer best;
      for (const Piece& piece : pieces) {
        const Answer a = pieceAnswer(piece, p);
        if (a.d < best.d)
          best = a;
      }
      const Vec3 f = penaltyForce(best);
      // the narrow phase's cost: the tracked query against every piece within reach
      const geom::Transform X_AB = geom::Pose{-p, geom::Quat{1.0, 0.0, 0.0, 0.0}}.toTransform();
      const auto t0 = std::chrono::steady_clock::now();
      double nearest = std::numeric_limits<double>::infinity();
      for (const Piece& piece : pieces) {
        if (!piece.hull || glm::length(piece.centre - p) > piece.radius + kProbeRadius + kDelta)
          continue;
        collision::PairCache cache;
        nearest = std::min(nearest,
                           collision::queryPair(probe.value(), *piece.hull, X_AB, cache).distance);
      }
      const auto t1 = std::chrono::steady_clock::now();
      const double ns =
          std::max(0.0, std::chrono::duration<double, std::nano>(t1 - t0).count() - overhead);
      narrow_contacts += nearest < kDelta ? 1 : 0;
      row.add(glm::length(f - truth[k]), 0.0, ns, truth_contact[k], glm::dot(f, f) > 0.0);
    }
    std::fprintf(stderr,
                 "study: %s concavity %g: %zu pieces (reached %.3g of the diagonal); the narrow "
                 "phase within delta at %zu of %zu configurations\n",
                 part.c_str(), c, pieces.size(), result.value().report.concavity, narrow_contacts,
                 path.size());
    rows.push_back(std::move(row));
  }
}

}  // namespace hapticd::study
