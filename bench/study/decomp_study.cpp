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
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "bench/study/scene_study.h"
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

// The crescent's pieces at concavity c, and the concavity reached (false, said on stderr: it
// failed).
bool decomposeAt(const decomp::TriangleMesh& mesh,
                 double c,
                 const std::string& part,
                 std::vector<Piece>& pieces,
                 double& reached) {
  decomp::DecompOptions o;
  o.concavity = c;
  auto result = decomp::decompose(mesh, o);
  if (!result.ok()) {
    std::fprintf(stderr, "study: %s: concavity %g: %s\n", part.c_str(), c,
                 result.error().message.c_str());
    return false;
  }
  reached = result.value().report.concavity;
  pieces.clear();
  for (auto& p : result.value().pieces)
    pieces.push_back(makePiece(std::move(p)));
  return true;
}

// The setting text of concavity c.
std::string concavitySetting(double c) {
  char setting[96];
  std::snprintf(setting, sizeof setting, "concavity=%g%s", c, c == 0.01 ? " (default)" : "");
  return setting;
}

// --- the same in the closed loop: the tick on the crescent decomposed at each concavity ---------

// The crescent as a scene: one static body of the pieces (each its hull, in the body's frame,
// which is the mesh's), the hand the configured probe sphere (SimOptions::probe_sphere_radius_m).
std::shared_ptr<const scene::SceneModel> crescentScene(const std::vector<Piece>& pieces,
                                                       const std::string& name) {
  scene::SceneModel s;
  s.name = name;
  scene::Body body;
  body.name = "crescent";
  for (const Piece& p : pieces) {
    if (p.hull)
      body.primitives.push_back(
          scene::Primitive{p.hull, geom::Pose{}, scene::ShapeSource::kCode, -1, -1});
  }
  s.plan.static_primitives = static_cast<std::uint32_t>(body.primitives.size());
  s.bodies.push_back(std::move(body));
  s.length_scale = 2.0 * std::sqrt(2.0 * kOuter * kOuter + kHalfThick * kHalfThick);
  s.plan.contact_forces = true;
  return std::make_shared<const scene::SceneModel>(std::move(s));
}

// The hand's path: from the hollow's centre to the inner (concave) wall, along it from one end to
// the other (from 1 mm into it to 0.5 mm off it, three times, up and down the thickness), and
// back; `seconds` in all (10 s; the quick run 3 s).
std::vector<proto::PoseStreamRow> innerWallStream(double seconds) {
  const auto wall = [](double u) {
    const double a = -0.95 * kHalfAngle + 1.9 * kHalfAngle * u;
    const double gap = -0.00025 + 0.00075 * std::sin(6.0 * std::numbers::pi * u);
    const double r = kInner - kProbeRadius - gap;
    const double z = 0.5 * kHalfThick * std::sin(4.0 * std::numbers::pi * u);
    return Vec3{r * std::cos(a), r * std::sin(a), z};
  };
  std::vector<proto::PoseStreamRow> rows;
  constexpr int kRows = 1000;
  for (int i = 0; i <= kRows; ++i) {
    const double f = static_cast<double>(i) / kRows;  // fraction of the whole path
    Vec3 x{0.0};
    if (f < 0.1) {  // out to the wall's first point
      const double w = 0.5 - 0.5 * std::cos(std::numbers::pi * f / 0.1);
      x = w * wall(0.0);
    } else if (f < 0.9) {
      x = wall((f - 0.1) / 0.8);
    } else {  // back to the centre
      const double w = 0.5 - 0.5 * std::cos(std::numbers::pi * (f - 0.9) / 0.1);
      x = (1.0 - w) * wall(1.0);
    }
    rows.push_back({f * seconds, geom::Pose{x, geom::Quat{1.0, 0.0, 0.0, 0.0}}, 0});
  }
  return rows;
}

// The truth inside the loop: every pair of the probe and a piece answered from the crescent's own
// triangle mesh. The probe's centre c (its frame's origin) is at signed distance d from the mesh,
// its closest point q, n the unit direction from q toward c (out of the mesh); the probe hull's
// extent toward the mesh, h = max over its vertices of dot(-n, v), makes the gap d - h (exact
// where the mesh is flat within the contact, as the sphere's own answer would be against a
// plane). One contact in all: the pair of the piece nearest to q (the deepest when q is inside
// several; the first of equals) answers; every other piece pair answers as far apart.
class MeshTruth final : public LoopQuery {
 public:
  MeshTruth(const decomp::TriangleMesh* mesh, const std::vector<Piece>* pieces)
      : mesh_(mesh), pieces_(pieces) {
    for (std::size_t i = 0; i < pieces->size(); ++i)
      index_[(*pieces)[i].hull.get()] = i;
  }

  void query(const geom::Polytope& a,
             const geom::Polytope& b,
             const geom::Transform& X_AB,
             const geom::Transform* /*X_AB_last*/,
             collision::PairCache& cache,
             collision::PairResult& out) override {
    const auto ia = index_.find(&a), ib = index_.find(&b);
    const bool piece_a = ia != index_.end();
    if (piece_a == (ib != index_.end())) {  // not a probe and a piece: nothing of the mesh's
      farApart(out, cache);
      return;
    }
    const geom::Polytope& probe = piece_a ? b : a;
    const std::size_t piece = piece_a ? ia->second : ib->second;
    // the probe's pose in the mesh's frame (a piece's frame is the body's, the mesh's)
    const geom::Transform X_MP = piece_a ? X_AB : X_AB.inverse();
    const Vec3 c = X_MP.t;
    if (!(c == centre_)) {
      centre_ = c;
      answer_ = meshAnswer(*mesh_, c);
      q_ = c - answer_.d * answer_.n;
      owner_ = 0;
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < pieces_->size(); ++i) {
        const double d = pieceAnswer((*pieces_)[i], q_).d;
        if (d < best)
          best = d, owner_ = i;
      }
    }
    farApart(out, cache);
    if (piece != owner_ || !(answer_.d < std::numeric_limits<double>::infinity()))
      return;
    // the probe's vertex farthest toward the mesh, in the mesh's frame
    const Vec3 toward = glm::transpose(X_MP.R) * -answer_.n;
    double h = -std::numeric_limits<double>::infinity();
    for (const auto& v : probe.vertices())
      h = std::max(h, glm::dot(toward, v.p));
    const double gap = answer_.d - h;
    out.distance = gap;
    out.status =
        gap > 0.0 ? collision::ContactStatus::kSeparated : collision::ContactStatus::kPenetrating;
    cache.penetrating = gap <= 0.0;
    // Both witnesses at q, so the contact row acts at q, on the line through the probe's centre
    // (no torque about it, as for a sphere), and the world reads no separating plane from them:
    // a plane through q would not separate a concave wall, so this pair is never left untested
    // as certainly far (WorldOptions::far_distance). a's frame: the mesh's when a is the piece,
    // else the probe's.
    if (piece_a) {
      out.normal = answer_.n;
      out.point_a = out.point_b = q_;
    } else {
      const geom::Transform X_PM = X_AB;  // the mesh in the probe's frame
      out.normal = X_PM.rotate(-answer_.n);
      out.point_a = out.point_b = X_PM.apply(q_);
    }
  }

 private:
  const decomp::TriangleMesh* mesh_;
  const std::vector<Piece>* pieces_;
  std::map<const geom::Polytope*, std::size_t> index_;
  Vec3 centre_{std::numeric_limits<double>::quiet_NaN()};
  Answer answer_;
  Vec3 q_{0.0};
  std::size_t owner_ = 0;
};

}  // namespace

void runDecompositionLoop(const Options& options, std::vector<Row>& rows) {
  const std::string part = "decomposition/crescent-tick";
  const decomp::TriangleMesh mesh = crescent();
  const std::vector<double> concavities = options.quick
                                              ? std::vector<double>{0.04, 0.01}
                                              : std::vector<double>{0.08, 0.04, 0.02, 0.01, 0.005};
  // each concavity's pieces; the truth runs on the finest's (their pairs hold the mesh within
  // its concavity, so the probe near the mesh is near one of them)
  std::vector<std::vector<Piece>> decompositions;
  std::vector<PlannedRun> runs(1);
  for (const double c : concavities) {
    std::vector<Piece> pieces;
    double reached = 0.0;
    if (!decomposeAt(mesh, c, part, pieces, reached))
      return;
    PlannedRun run;
    run.setting = concavitySetting(c);
    run.model = crescentScene(pieces, "crescent " + run.setting);
    runs.push_back(std::move(run));
    decompositions.push_back(std::move(pieces));
  }
  const std::vector<Piece>& finest = decompositions.back();
  runs[0].setting = "pairs answered from it (the truth)";
  runs[0].model = runs.back().model;
  runs[0].method = {"exact mesh", [&mesh, &finest]() -> std::unique_ptr<LoopQuery> {
                      return std::make_unique<MeshTruth>(&mesh, &finest);
                    }};
  SceneStudyOptions so;
  const double seconds = options.quick ? 3.0 : 10.0;
  const std::vector<proto::PoseStreamRow> stream = innerWallStream(seconds);
  so.progress = [&](const std::string& line) {
    std::fprintf(stderr, "study: %s %s\n", part.c_str(), line.c_str());
  };
  // the scenes' own SimOptions: the probe sphere of the open-loop part's radius
  so.probe_sphere_radius_m = kProbeRadius;
  auto ran = runSweep(part, runs.back().model, stream, so, runs, rows);
  if (!ran.ok())
    std::fprintf(stderr, "study: %s: %s\n", part.c_str(), ran.error().message.c_str());
}

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
    std::vector<Piece> pieces;
    double reached = 0.0;
    if (!decomposeAt(mesh, c, part, pieces, reached))
      continue;
    Row row{part, "decomposition", concavitySetting(c), {}, {}, {}, 0, 0, 0, 0, {}, {}};
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
                 part.c_str(), c, pieces.size(), reached, narrow_contacts, path.size());
    rows.push_back(std::move(row));
  }
}

}  // namespace hapticd::study
