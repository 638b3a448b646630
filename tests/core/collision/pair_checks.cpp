#include "tests/core/collision/pair_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "tests/core/geometry_helpers.h"

// The brute-force checks run inside the Debug (-O0) test binaries; optimising them changes no
// result (no -ffast-math).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("O2")
#endif

namespace hapticd::collision::checks {

Polytope hullOf(std::span<const Vec3> points) {
  auto r = Polytope::fromPoints(points);
  if (!r.ok())
    throw std::runtime_error("test shape refused: " + r.error().message);
  return std::move(r).value();
}

std::vector<Vec3> box(double x, double y, double z) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i)
    p.push_back(Vec3{i & 1 ? x : -x, i & 2 ? y : -y, i & 4 ? z : -z});
  return p;
}

std::vector<Vec3> scaled(std::vector<Vec3> points, double s) {
  for (auto& v : points)
    v *= s;
  return points;
}

double pairSize(const Polytope& a, const Polytope& b) {
  return std::max(a.radius(), b.radius());
}

double angle(const Vec3& u, const Vec3& v) {
  return std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v));
}

double outside(const Polytope& q, const Transform& X, const Vec3& p) {
  const Vec3 x = X.inverse().apply(p);
  double worst = -std::numeric_limits<double>::infinity();
  for (const auto& f : q.faces())
    worst = std::max(worst, glm::dot(f.normal, x) - f.offset);
  return worst;
}

using testing::segmentDistance;

double distanceToFeature(const Polytope& q, const Transform& X, Feature f, const Vec3& p) {
  const Vec3 x = X.inverse().apply(p);
  switch (f.type) {
    case FeatureType::kVertex:
      return f.index < q.vertices().size() ? glm::length(x - q.vertices()[f.index].p)
                                           : std::numeric_limits<double>::infinity();
    case FeatureType::kEdge: {
      if (f.index >= q.edges().size())
        return std::numeric_limits<double>::infinity();
      const auto& e = q.edges()[f.index];
      return segmentDistance(x, q.vertices()[e.tail].p, q.vertices()[e.head].p);
    }
    case FeatureType::kFace: {
      if (f.index >= q.faces().size())
        return std::numeric_limits<double>::infinity();
      const auto fe = q.faceEdges(f.index);
      // Newell normal of the loop, then inside test against each boundary edge
      Vec3 n{0.0}, c{0.0};
      for (std::size_t k = 0; k < fe.size(); ++k) {
        const Vec3& a = q.vertices()[fe[k].vertex].p;
        n += glm::cross(a, q.vertices()[fe[(k + 1) % fe.size()].vertex].p);
        c += a / static_cast<double>(fe.size());
      }
      n = glm::normalize(n);
      bool inside = true;
      for (std::size_t k = 0; k < fe.size() && inside; ++k) {
        const Vec3& a = q.vertices()[fe[k].vertex].p;
        const Vec3& b = q.vertices()[fe[(k + 1) % fe.size()].vertex].p;
        inside = glm::dot(glm::cross(b - a, x - a), n) >= 0.0;
      }
      if (inside)
        return std::abs(glm::dot(n, x - c));
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < fe.size(); ++k) {
        best = std::min(best, segmentDistance(x, q.vertices()[fe[k].vertex].p,
                                              q.vertices()[fe[(k + 1) % fe.size()].vertex].p));
      }
      return best;
    }
    case FeatureType::kNone:
      break;
  }
  return std::numeric_limits<double>::infinity();
}

AxisMargin axisMargin(const Polytope& a, const Polytope& b, const Transform& X_AB) {
  using Real = long double;
  struct R3 {
    Real x, y, z;
  };
  auto dot = [](const R3& u, const R3& v) { return u.x * v.x + u.y * v.y + u.z * v.z; };
  auto cross = [](const R3& u, const R3& v) {
    return R3{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
  };
  std::vector<R3> va, vb;
  for (const auto& v : a.vertices())
    va.push_back({v.p.x, v.p.y, v.p.z});
  for (const auto& v : b.vertices()) {
    const Vec3& p = v.p;
    R3 q{X_AB.t.x, X_AB.t.y, X_AB.t.z};
    for (int c = 0; c < 3; ++c) {
      const Real pc = c == 0 ? p.x : c == 1 ? p.y : p.z;
      q.x += static_cast<Real>(X_AB.R[c][0]) * pc;
      q.y += static_cast<Real>(X_AB.R[c][1]) * pc;
      q.z += static_cast<Real>(X_AB.R[c][2]) * pc;
    }
    vb.push_back(q);
  }
  // candidate axes: face normals (from the loops) and edge-pair cross products
  std::vector<R3> axes;
  auto faceNormals = [&](const Polytope& p, const std::vector<R3>& v) {
    for (std::uint32_t f = 0; f < p.faces().size(); ++f) {
      const auto fe = p.faceEdges(f);
      R3 n{0, 0, 0};
      for (std::size_t k = 0; k < fe.size(); ++k) {
        const R3 c = cross(v[fe[k].vertex], v[fe[(k + 1) % fe.size()].vertex]);
        n = {n.x + c.x, n.y + c.y, n.z + c.z};
      }
      axes.push_back(n);
    }
  };
  faceNormals(a, va);
  faceNormals(b, vb);
  for (const auto& ea : a.edges()) {
    const R3 da{va[ea.head].x - va[ea.tail].x, va[ea.head].y - va[ea.tail].y,
                va[ea.head].z - va[ea.tail].z};
    for (const auto& eb : b.edges()) {
      const R3 db{vb[eb.head].x - vb[eb.tail].x, vb[eb.head].y - vb[eb.tail].y,
                  vb[eb.head].z - vb[eb.tail].z};
      const R3 c = cross(da, db);
      if (dot(c, c) > 1e-24L * dot(da, da) * dot(db, db))
        axes.push_back(c);
    }
  }
  struct Cand {
    Real depth;
    R3 u;
  };
  std::vector<Cand> cands;
  cands.reserve(2 * axes.size());
  for (R3 u : axes) {
    const Real len = std::sqrt(dot(u, u));
    if (!(len > 0))
      continue;
    u = {u.x / len, u.y / len, u.z / len};
    // (plain pointers and comparisons: the library templates are not inlined in the -O0 build)
    Real loA = std::numeric_limits<Real>::infinity(), hiA = -loA, loB = loA, hiB = -loA;
    const R3* pa = va.data();
    for (std::size_t i = 0, n = va.size(); i < n; ++i) {
      const Real d = u.x * pa[i].x + u.y * pa[i].y + u.z * pa[i].z;
      if (d < loA)
        loA = d;
      if (d > hiA)
        hiA = d;
    }
    const R3* pb = vb.data();
    for (std::size_t i = 0, n = vb.size(); i < n; ++i) {
      const Real d = u.x * pb[i].x + u.y * pb[i].y + u.z * pb[i].z;
      if (d < loB)
        loB = d;
      if (d > hiB)
        hiB = d;
    }
    cands.push_back({hiA - loB, u});
    cands.push_back({hiB - loA, R3{-u.x, -u.y, -u.z}});
  }
  AxisMargin out;
  if (cands.empty())
    return out;
  const Cand* best = &cands[0];
  for (const Cand& c : cands) {
    if (c.depth < best->depth)
      best = &c;
  }
  const Real cos_tol = std::cos(static_cast<Real>(kAngleTol));
  Real second = std::numeric_limits<Real>::infinity();
  for (const Cand& c : cands) {
    if (c.depth < second && dot(c.u, best->u) < cos_tol)
      second = c.depth;
  }
  out.best = static_cast<double>(best->depth);
  out.axis = Vec3{static_cast<double>(best->u.x), static_cast<double>(best->u.y),
                  static_cast<double>(best->u.z)};
  out.second = static_cast<double>(second);
  return out;
}

ContactStatus statusOf(double signed_distance, double size) {
  const double touch = QueryOptions{}.touch_tolerance * size;
  if (signed_distance > touch)
    return ContactStatus::kSeparated;
  if (signed_distance < -touch)
    return ContactStatus::kPenetrating;
  return ContactStatus::kTouching;
}

bool statusAcceptable(ContactStatus status, double ref_signed_distance, double size) {
  const double band = kStatusBand * size;
  return status == statusOf(ref_signed_distance, size) ||
         status == statusOf(ref_signed_distance - band, size) ||
         status == statusOf(ref_signed_distance + band, size);
}

const char* name(ContactStatus s) {
  switch (s) {
    case ContactStatus::kSeparated:
      return "separated";
    case ContactStatus::kTouching:
      return "touching";
    case ContactStatus::kPenetrating:
      return "penetrating";
  }
  return "?";
}

void Figures::countStatus(ContactStatus s) {
  switch (s) {
    case ContactStatus::kSeparated:
      ++separated;
      break;
    case ContactStatus::kTouching:
      ++touching;
      break;
    case ContactStatus::kPenetrating:
      ++penetrating;
      break;
  }
}

void Figures::print(const std::string& what) const {
  std::printf(
      "[figures] %s: %zu pairs (%zu separated, %zu touching, %zu penetrating); max errors, "
      "relative to size: distance %.3g, witnesses %.3g, deepest contact %.3g; max normal error "
      "%.3g rad over %zu normals (%zu not unique, not compared); max walk iterations %u; "
      "overlapping pairs the walk handed to the depth as touching %zu; "
      "manifold sizes 1:%zu 2:%zu 3:%zu 4:%zu\n",
      what.c_str(), pairs, separated, touching, penetrating, max_dist_err, max_witness_err,
      max_manifold_err, max_normal_err, normals_checked, normals_skipped, max_iterations,
      walk_handoffs, manifold_sizes[1], manifold_sizes[2], manifold_sizes[3], manifold_sizes[4]);
  std::fflush(stdout);
}

namespace {

std::string vec(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g]", v.x, v.y, v.z);
  return buf;
}

}  // namespace

bool Failures::add(const std::string& label, const std::string& message) {
  if (message.empty())
    return false;
  std::string kind = "other";
  if (message.size() > 1 && message[0] == '[') {
    const auto end = message.find(']');
    if (end != std::string::npos)
      kind = message.substr(1, end - 1);
  }
  ++total_;
  ++count_[kind];
  auto& ex = examples_[kind];
  if (ex.size() < 2)
    ex.push_back(label + ": " + message);
  auto& names = labels_[kind];
  if (names.size() < 60)
    names.push_back(label);
  return true;
}

std::string Failures::summary() const {
  std::ostringstream s;
  s << total_ << " failed checks\n";
  for (const auto& [kind, n] : count_) {
    s << "  " << n << " x [" << kind << "]:";
    for (const auto& l : labels_.at(kind))
      s << " {" << l << "}";
    s << (n > labels_.at(kind).size() ? " ...\n" : "\n");
  }
  for (const auto& [kind, ex] : examples_) {
    for (const auto& e : ex)
      s << "--- first cases of [" << kind << "]:\n" << e << "\n";
  }
  return s.str();
}

std::string describe(const Polytope& a, const Polytope& b, const Transform& X_AB) {
  std::ostringstream s;
  auto verts = [&](const char* what, const Polytope& p) {
    s << what << ": " << p.vertices().size() << " vertices, " << p.faces().size()
      << " faces, radius " << p.radius();
    if (p.vertices().size() <= 24) {
      s << ", vertices {";
      for (const auto& v : p.vertices())
        s << vec(v.p) << " ";
      s << "}";
    }
    s << "\n";
  };
  verts("A", a);
  verts("B", b);
  s << "X_AB: R columns " << vec(X_AB.R[0]) << " " << vec(X_AB.R[1]) << " " << vec(X_AB.R[2])
    << ", t " << vec(X_AB.t) << "\n";
  return s.str();
}

Transform randomTransform(std::mt19937_64& rng, double spread) {
  std::normal_distribution<double> g(0.0, 1.0);
  return geom::Pose{Vec3{g(rng), g(rng), g(rng)} * spread, reference::randomRotation(rng)}
      .toTransform();
}

namespace {

// starts a failure's message: its first line is "[check: kind, the status the reference implies]
// details", so that Failures counts the failures by kind
std::ostringstream& failLine(std::ostringstream& err,
                             const char* check,
                             const char* kind,
                             const PairCase& in) {
  err << "[" << check << ": " << kind << ", "
      << name(statusOf(in.ref.signed_distance, pairSize(in.a, in.b))) << "] ";
  return err;
}

}  // namespace

std::string checkPairResult(const PairCase& in, const PairResult& r, Figures& fig) {
  // named references, not a structured binding: clang 14 cannot capture bindings in lambdas
  const Polytope& a = in.a;
  const Polytope& b = in.b;
  const Transform& X_AB = in.X_AB;
  const reference::RefAnswer& ref = in.ref;
  const double size = pairSize(a, b);
  const double tol = kDistTol * size;
  std::ostringstream err;
  auto fail = [&](const char* kind) -> std::ostringstream& {
    return failLine(err, "queryPair", kind, in);
  };
  auto report = [&] {
    std::ostringstream s;
    s << err.str() << "\n  got: status " << name(r.status) << ", distance " << r.distance
      << ", normal " << vec(r.normal) << ", point_a " << vec(r.point_a) << ", point_b "
      << vec(r.point_b) << ", features " << r.fa.name() << " " << r.fb.name() << ", "
      << int{r.manifold.count} << " contacts\n  reference: signed distance " << ref.signed_distance
      << ", normal " << vec(ref.normal) << "\n"
      << describe(a, b, X_AB);
    return s.str();
  };

  ++fig.pairs;
  // no NaN anywhere
  if (!std::isfinite(r.distance) || !finite(r.normal) || !finite(r.point_a) || !finite(r.point_b)) {
    fail("non-finite field") << "a non-finite field";
    return report();
  }
  if (std::abs(glm::length(r.normal) - 1.0) > 1e-12) {
    fail("normal not unit") << "normal not unit (length " << glm::length(r.normal) << ")";
    return report();
  }
  // status: as the reference says, and as our own distance says
  if (!statusAcceptable(r.status, ref.signed_distance, size)) {
    fail("status") << "status " << name(r.status) << ", reference implies "
                   << name(statusOf(ref.signed_distance, size));
    return report();
  }
  if (r.status != statusOf(r.distance, size)) {
    fail("status vs own distance")
        << "status " << name(r.status) << " disagrees with its own distance";
    return report();
  }
  fig.countStatus(r.status);
  // signed distance
  const double dist_err = std::abs(r.distance - ref.signed_distance);
  fig.max_dist_err = std::max(fig.max_dist_err, dist_err / size);
  if (dist_err > tol) {
    fail("signed distance") << "signed distance off by " << dist_err / size << " of the size";
    return report();
  }
  // witnesses: point_b - point_a == distance * normal, each point on its own hull's surface
  const double w_align = glm::length(r.point_b - r.point_a - r.normal * r.distance);
  const double w_a = std::abs(outside(a, Transform{}, r.point_a));
  const double w_b = std::abs(outside(b, X_AB, r.point_b));
  fig.max_witness_err = std::max({fig.max_witness_err, w_align / size, w_a / size, w_b / size});
  if (w_align > tol) {
    fail("witness alignment") << "|point_b - point_a - distance * normal| = " << w_align / size
                              << " of the size";
    return report();
  }
  if (w_a > tol || w_b > tol) {
    fail("witness off its hull") << "witness off its hull's surface: point_a by " << w_a / size
                                 << ", point_b by " << w_b / size << " of the size";
    return report();
  }
  // features: valid, and holding their witness points (separated and touching)
  if (r.status != ContactStatus::kPenetrating) {
    const double fa = distanceToFeature(a, Transform{}, r.fa, r.point_a);
    const double fb = distanceToFeature(b, X_AB, r.fb, r.point_b);
    if (!(fa <= tol) || !(fb <= tol)) {
      fail("witness off its feature") << "witness not on its feature: point_a " << fa / size
                                      << ", point_b " << fb / size << " of the size away";
      return report();
    }
  }
  // normal: the depth along it is the answer (a minimal translation, or the gap along the
  // closest direction); compared with the reference's when that is unique
  // (not for separated pairs: there the normal comes from the witnesses, and an error within the
  // angle tolerance moves the support along an extended contact by more than the distance
  // tolerance; the separated normal is compared with the reference's, which is unique)
  const double along = r.status == ContactStatus::kSeparated
                           ? -r.distance
                           : reference::bruteDepthAlong(a, b, X_AB, r.normal);
  if (std::abs(along + r.distance) > tol) {
    fail("depth along the normal")
        << "depth along the normal " << along << " != -distance " << -r.distance;
    return report();
  }
  bool compare = r.status == ContactStatus::kSeparated;
  Vec3 ref_normal = ref.normal;
  if (!compare) {
    const AxisMargin m = axisMargin(a, b, X_AB);
    compare = m.unique(size);
    ref_normal = m.axis;
  }
  if (compare) {
    const double e = angle(r.normal, ref_normal);
    // a separated normal joins the witnesses, which the walk places within the Voronoi plane
    // tolerance of their exact spots: kPlaneTol of the size across a gap of `distance`
    const double normal_tol = r.status == ContactStatus::kSeparated
                                  ? kAngleTol + kPlaneTol * size / r.distance
                                  : kAngleTol;
    ++fig.normals_checked;
    fig.max_normal_err = std::max(fig.max_normal_err, e);
    if (e > normal_tol) {
      fail("normal") << "normal off by " << e << " rad, more than " << normal_tol << " (reference "
                     << vec(ref_normal) << ")";
      return report();
    }
  } else {
    ++fig.normals_skipped;
  }
  // manifold: 1..kMaxPoints points, finite, unit normals, each depth no deeper than the pair,
  // the deepest equal to the pair's depth, each point between the two surfaces
  const Manifold& m = r.manifold;
  if (m.count < 1 || m.count > Manifold::kMaxPoints) {
    fail("manifold size") << "manifold has " << int{m.count} << " points";
    return report();
  }
  ++fig.manifold_sizes[m.count];
  double deepest = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < m.count; ++i) {
    const ContactPoint& p = m.points[i];
    if (!finite(p.point) || !finite(p.normal) || !std::isfinite(p.depth) ||
        std::abs(glm::length(p.normal) - 1.0) > 1e-9) {
      fail("contact not finite") << "contact " << i << " not finite or normal not unit";
      return report();
    }
    if (p.depth > -r.distance + tol) {
      fail("contact deeper than the pair")
          << "contact " << i << " depth " << p.depth << " deeper than the pair " << -r.distance;
      return report();
    }
    const double half = std::abs(p.depth) * 0.5 + tol;
    if (outside(a, Transform{}, p.point) > half || outside(b, X_AB, p.point) > half) {
      fail("contact not between the surfaces")
          << "contact " << i << " " << vec(p.point) << " not between the surfaces (outside A by "
          << outside(a, Transform{}, p.point) << ", outside B by " << outside(b, X_AB, p.point)
          << ", depth " << p.depth << ")";
      return report();
    }
    deepest = std::max(deepest, p.depth);
  }
  fig.max_manifold_err = std::max(fig.max_manifold_err, std::abs(deepest + r.distance) / size);
  if (std::abs(deepest + r.distance) > tol) {
    fail("deepest contact") << "deepest contact " << deepest << " != -distance " << -r.distance;
    return report();
  }
  return {};
}

std::string checkClosest(const PairCase& in, const ClosestResult& c, Figures& fig) {
  // named references, not a structured binding: clang 14 cannot capture bindings in lambdas
  const Polytope& a = in.a;
  const Polytope& b = in.b;
  const Transform& X_AB = in.X_AB;
  const reference::RefAnswer& ref = in.ref;
  const double size = pairSize(a, b);
  const double tol = kDistTol * size;
  std::ostringstream err;
  auto report = [&] {
    std::ostringstream s;
    s << err.str() << "\n  got: end " << static_cast<int>(c.end)
      << " (0 converged, 1 penetration, 2 iteration cap), status " << name(c.status)
      << ", distance " << c.distance << ", features " << c.fa.name() << " " << c.fb.name() << ", "
      << c.iterations << " iterations\n  reference: signed distance " << ref.signed_distance << "\n"
      << describe(a, b, X_AB);
    return s.str();
  };
  auto fail = [&](const char* kind) -> std::ostringstream& {
    return failLine(err, "closestFeatures", kind, in);
  };
  fig.max_iterations = std::max(fig.max_iterations, c.iterations);
  if (c.end == WalkEnd::kIterationCap) {
    fail("iteration cap") << "the walk hit its iteration cap";
    return report();
  }
  const ContactStatus expect = statusOf(ref.signed_distance, size);
  if (expect == ContactStatus::kPenetrating &&
      statusAcceptable(ContactStatus::kPenetrating, ref.signed_distance, size) &&
      !statusAcceptable(ContactStatus::kTouching, ref.signed_distance, size)) {
    // penetration, or the documented hand-off: a walk ending within the touch tolerance is
    // settled by the exact depth (docs/narrow-phase.md); never "separated"
    const bool handoff = c.end == WalkEnd::kConverged && c.status == ContactStatus::kTouching &&
                         c.distance <= QueryOptions{}.touch_tolerance * size;
    if (handoff)
      ++fig.walk_handoffs;
    if (!handoff && (c.end != WalkEnd::kPenetration || c.status != ContactStatus::kPenetrating)) {
      fail("penetration missed") << "overlapping pair (reference depth " << -ref.signed_distance
                                 << ") not reported as penetration";
      return report();
    }
    return {};
  }
  if (expect == ContactStatus::kSeparated &&
      !statusAcceptable(ContactStatus::kTouching, ref.signed_distance, size)) {
    if (c.end != WalkEnd::kConverged || c.status != ContactStatus::kSeparated) {
      fail("separation missed") << "separated pair not converged as separated";
      return report();
    }
  }
  if (c.end != WalkEnd::kConverged)
    return {};  // touching: the walk may see either side
  if (!std::isfinite(c.distance) || !finite(c.point_a) || !finite(c.point_b) || !finite(c.normal)) {
    fail("non-finite field") << "a non-finite field";
    return report();
  }
  if (ref.signed_distance >= 0.0) {
    fig.max_dist_err =
        std::max(fig.max_dist_err, std::abs(c.distance - ref.signed_distance) / size);
  }
  fig.max_witness_err = std::max(fig.max_witness_err,
                                 std::abs(glm::length(c.point_b - c.point_a) - c.distance) / size);
  if (c.distance > 1e-6 * size) {
    fig.max_normal_err = std::max(fig.max_normal_err, angle(c.normal, ref.normal));
  }
  if (ref.signed_distance >= 0.0 && std::abs(c.distance - ref.signed_distance) > tol) {
    fail("distance") << "distance off by " << std::abs(c.distance - ref.signed_distance) / size
                     << " of the size";
    return report();
  }
  if (std::abs(glm::length(c.point_b - c.point_a) - c.distance) > tol) {
    fail("witness distance") << "|point_b - point_a| != distance";
    return report();
  }
  const double fa = distanceToFeature(a, Transform{}, c.fa, c.point_a);
  const double fb = distanceToFeature(b, X_AB, c.fb, c.point_b);
  if (!(fa <= tol) || !(fb <= tol)) {
    fail("witness off its feature") << "witness not on its feature: point_a " << fa / size
                                    << ", point_b " << fb / size << " of the size away";
    return report();
  }
  if (c.distance > 1e-6 * size && angle(c.normal, ref.normal) > kAngleTol) {
    fail("normal") << "normal off by " << angle(c.normal, ref.normal) << " rad";
    return report();
  }
  return {};
}

std::string checkPair(const Polytope& a, const Polytope& b, const Transform& X_AB, Figures& fig) {
  const reference::RefAnswer ref = reference::bruteForce(a, b, X_AB);
  FeatureCache fc;
  const ClosestResult c = closestFeatures(a, b, X_AB, fc);
  std::string s = checkClosest({a, b, X_AB, ref}, c, fig);
  if (!s.empty())
    return s;
  PairCache cache;
  const PairResult r = queryPair(a, b, X_AB, cache);
  return checkPairResult({a, b, X_AB, ref}, r, fig);
}

}  // namespace hapticd::collision::checks
