#include "tests/core/decomp/checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include "core/geometry/polytope.h"
#include "tests/core/geometry_helpers.h"

namespace hapticd::decomp::checks {
namespace {

using testing::segmentDistance;

struct Face {
  std::vector<std::array<Vec3, 3>> tris;  // the face's fan
  Vec3 n;
  double offset;
  double area;
};

struct Hull {
  std::vector<Face> faces;
  double depth(const Vec3& q) const {
    double d = std::numeric_limits<double>::infinity();
    for (const Face& f : faces)
      d = std::min(d, f.offset - glm::dot(f.n, q));
    return d;
  }
  double distance(const Vec3& q) const {
    if (depth(q) >= 0.0)
      return 0.0;
    double best = std::numeric_limits<double>::infinity();
    for (const Face& f : faces)
      for (const auto& t : f.tris)
        best = std::min(best, pointTriangleDistance(q, t[0], t[1], t[2]));
    return best;
  }
};

std::optional<Hull> hullOf(const ConvexPiece& piece) {
  auto poly = geom::Polytope::fromPoints(piece.vertices);
  if (!poly.ok())
    return std::nullopt;
  const geom::Polytope& P = poly.value();
  Hull h;
  for (std::uint32_t f = 0; f < P.faces().size(); ++f) {
    Face face{{}, P.faces()[f].normal, P.faces()[f].offset, 0.0};
    const auto fe = P.faceEdges(f);
    const Vec3 a = P.vertices()[fe[0].vertex].p;
    for (std::size_t k = 1; k + 1 < fe.size(); ++k) {
      const Vec3 b = P.vertices()[fe[k].vertex].p, c = P.vertices()[fe[k + 1].vertex].p;
      face.tris.push_back({a, b, c});
      face.area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    h.faces.push_back(std::move(face));
  }
  return h;
}

Vec3 samplePoint(std::mt19937_64& rng, const Vec3& a, const Vec3& b, const Vec3& c) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double s = u(rng), t = u(rng);
  if (s + t > 1.0)
    s = 1.0 - s, t = 1.0 - t;
  return a + (b - a) * s + (c - a) * t;
}

double surfaceDistance(const TriangleMesh& mesh, const Vec3& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.positions[t[0]];
    const Vec3& b = mesh.positions[t[1]];
    const Vec3& c = mesh.positions[t[2]];
    if (!std::isfinite(a.x + a.y + a.z + b.x + b.y + b.z + c.x + c.y + c.z))
      continue;
    best = std::min(best, pointTriangleDistance(q, a, b, c));
  }
  return best;
}

}  // namespace

double pointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = glm::cross(b - a, c - a);
  const double len = glm::length(n);
  if (len > 0.0) {
    const Vec3 u = n / len;
    const Vec3 proj = p - u * glm::dot(p - a, u);
    const bool in = glm::dot(glm::cross(b - a, proj - a), n) >= 0.0 &&
                    glm::dot(glm::cross(c - b, proj - b), n) >= 0.0 &&
                    glm::dot(glm::cross(a - c, proj - c), n) >= 0.0;
    if (in)
      return std::abs(glm::dot(p - a, u));
  }
  return std::min({segmentDistance(p, a, b), segmentDistance(p, b, c), segmentDistance(p, c, a)});
}

double windingNumber(const TriangleMesh& mesh, const Vec3& p) {
  double omega = 0.0;
  for (const Triangle& t : mesh.triangles) {
    if (t[0] >= mesh.positions.size() || t[1] >= mesh.positions.size() ||
        t[2] >= mesh.positions.size())
      continue;
    const Vec3 a = mesh.positions[t[0]] - p, b = mesh.positions[t[1]] - p,
               c = mesh.positions[t[2]] - p;
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = glm::dot(a, glm::cross(b, c));
    const double den =
        la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
    if (std::isfinite(num) && std::isfinite(den))
      omega += 2.0 * std::atan2(num, den);
  }
  return omega / (4.0 * std::numbers::pi);
}

double diagonal(const TriangleMesh& mesh) {
  Vec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};
  for (const Vec3& p : mesh.positions)
    if (std::isfinite(p.x + p.y + p.z))
      lo = glm::min(lo, p), hi = glm::max(hi, p);
  return glm::length(hi - lo);
}

UnionCheck checkUnion(const TriangleMesh& mesh,
                      std::span<const ConvexPiece> pieces,
                      std::size_t surface_samples,
                      std::size_t boundary_samples_per_piece,
                      std::uint64_t seed) {
  UnionCheck out;
  std::mt19937_64 rng(seed);
  std::vector<Hull> hulls;
  for (const ConvexPiece& p : pieces) {
    auto h = hullOf(p);
    if (!h) {
      out.hulls_valid = false;
      continue;
    }
    hulls.push_back(std::move(*h));
  }
  // surface samples, area-weighted
  std::vector<double> cumulative;
  double total = 0.0;
  for (const Triangle& t : mesh.triangles) {
    double a = 0.0;
    if (t[0] < mesh.positions.size() && t[1] < mesh.positions.size() &&
        t[2] < mesh.positions.size()) {
      a = 0.5 * glm::length(glm::cross(mesh.positions[t[1]] - mesh.positions[t[0]],
                                       mesh.positions[t[2]] - mesh.positions[t[0]]));
      if (!std::isfinite(a))
        a = 0.0;
    }
    total += a;
    cumulative.push_back(total);
  }
  std::uniform_real_distribution<double> pick(0.0, total);
  for (std::size_t k = 0; k < surface_samples && total > 0.0; ++k) {
    const auto it = std::lower_bound(cumulative.begin(), cumulative.end(), pick(rng));
    const Triangle& t = mesh.triangles[static_cast<std::size_t>(it - cumulative.begin())];
    const Vec3 q =
        samplePoint(rng, mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]);
    double best = std::numeric_limits<double>::infinity();
    for (const Hull& h : hulls)
      best = std::min(best, h.distance(q));
    out.surface_to_union = std::max(out.surface_to_union, best);
    ++out.surface_samples;
  }
  // boundary samples of each piece, not inside another piece, not inside the model
  const double eps = 1e-9 * diagonal(mesh);
  for (std::size_t i = 0; i < hulls.size(); ++i) {
    double area = 0.0;
    for (const Face& f : hulls[i].faces)
      area += f.area;
    std::uniform_real_distribution<double> pa(0.0, area);
    for (std::size_t k = 0; k < boundary_samples_per_piece; ++k) {
      double x = pa(rng);
      const Face* face = &hulls[i].faces.back();
      for (const Face& f : hulls[i].faces) {
        if (x <= f.area) {
          face = &f;
          break;
        }
        x -= f.area;
      }
      std::uniform_int_distribution<std::size_t> tri(0, face->tris.size() - 1);
      const auto& t = face->tris[tri(rng)];
      const Vec3 q = samplePoint(rng, t[0], t[1], t[2]);
      bool covered = false;
      for (std::size_t j = 0; j < hulls.size() && !covered; ++j)
        covered = j != i && hulls[j].depth(q) > eps;
      if (covered || windingNumber(mesh, q) >= 0.5)
        continue;
      out.boundary_to_model = std::max(out.boundary_to_model, surfaceDistance(mesh, q));
      ++out.boundary_samples;
    }
  }
  return out;
}

}  // namespace hapticd::decomp::checks
