// Polytope construction: hulls, adjacency, Voronoi planes, lookup table, refused input.
#include "core/geometry/polytope.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "tests/reference/reference.h"

namespace hapticd::geom {
namespace {

std::vector<Vec3> cube(double h = 1.0) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) p.push_back(Vec3{i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
  return p;
}

TEST(Polytope, CubeHasSixQuadFaces) {
  const auto r = Polytope::fromPoints(cube());
  ASSERT_TRUE(r.ok()) << r.error().message;
  const Polytope& p = r.value();
  EXPECT_EQ(p.vertices().size(), 8u);
  EXPECT_EQ(p.edges().size(), 12u);
  ASSERT_EQ(p.faces().size(), 6u);
  for (std::uint32_t f = 0; f < 6; ++f) EXPECT_EQ(p.faceEdges(f).size(), 4u);
  EXPECT_NEAR(p.radius(), std::sqrt(3.0), 1e-12);
}

TEST(Polytope, RefusesBadInputWithClearErrors) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* what;
    std::vector<Vec3> points;
    const char* expect;
  };
  const std::vector<Case> cases = {
      {"three points", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, "at least 4"},
      {"NaN", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, nan}}, "not finite"},
      {"Inf", {{0, 0, 0}, {1, 0, 0}, {inf, 1, 0}, {0, 0, 1}}, "not finite"},
      {"coplanar", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.2, 0}}, "coplanar"},
      {"collinear", {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}, "collinear"},
      {"coincident", {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, "coincide"},
      {"duplicates of a triangle", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1e-13, 0, 0}}, "at least 4"},
      {"huge", {{0, 0, 0}, {1e300, 0, 0}, {0, 1e300, 0}, {0, 0, 1e300}}, "too large"},
      {"tiny", {{0, 0, 0}, {1e-300, 0, 0}, {0, 1e-300, 0}, {0, 0, 1e-300}}, "too small"},
  };
  for (const Case& c : cases) {
    const auto r = Polytope::fromPoints(c.points);
    ASSERT_FALSE(r.ok()) << c.what;
    EXPECT_NE(r.error().message.find(c.expect), std::string::npos)
        << c.what << ": " << r.error().message;
  }
  HullOptions small;
  small.max_vertices = 10;
  const auto many = Polytope::fromPoints(reference::ellipsoidPoints(50, 1, 1, 1, 3), small);
  ASSERT_FALSE(many.ok());
  EXPECT_NE(many.error().message.find("limit 10"), std::string::npos) << many.error().message;
  HullOptions few_inputs;
  few_inputs.max_input_points = 5;
  EXPECT_FALSE(Polytope::fromPoints(cube(), few_inputs).ok());
}

TEST(Polytope, MergesNearDuplicatesRelativeToSize) {
  for (const double scale : {1e-3, 1.0, 1e3}) {
    auto pts = cube(scale);
    const std::size_t n = pts.size();
    for (std::size_t i = 0; i < n; ++i) pts.push_back(pts[i] + Vec3{1e-12, -1e-12, 1e-12} * scale);
    const auto r = Polytope::fromPoints(pts);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r.value().vertices().size(), 8u) << "scale " << scale;
    EXPECT_EQ(r.value().faces().size(), 6u) << "scale " << scale;
  }
}

// Every structural invariant the walk relies on.
void checkStructure(const Polytope& p) {
  const auto V = p.vertices().size(), E = p.edges().size(), F = p.faces().size();
  ASSERT_EQ(V + F, E + 2) << "Euler";
  const double tol = 1e-9 * p.radius();
  std::size_t incidences = 0;
  for (std::uint32_t v = 0; v < V; ++v) {
    for (const auto& ve : p.vertexEdges(v)) {
      const auto& e = p.edges()[ve.edge];
      ASSERT_TRUE((e.tail == v && e.head == ve.other) || (e.head == v && e.tail == ve.other));
      const Vec3 d = glm::normalize(p.vertices()[ve.other].p - p.vertices()[v].p);
      EXPECT_NEAR(glm::length(d - ve.out), 0.0, 1e-12);
      ++incidences;
    }
  }
  EXPECT_EQ(incidences, 2 * E);
  std::vector<int> seen_edge(E, 0);
  for (std::uint32_t f = 0; f < F; ++f) {
    const auto& face = p.faces()[f];
    EXPECT_NEAR(glm::length(face.normal), 1.0, 1e-12);
    const auto fe = p.faceEdges(f);
    Vec3 centroid{0.0}, area{0.0};
    for (std::size_t k = 0; k < fe.size(); ++k) {
      centroid += p.vertices()[fe[k].vertex].p / static_cast<double>(fe.size());
      area += glm::cross(p.vertices()[fe[k].vertex].p, p.vertices()[fe[(k + 1) % fe.size()].vertex].p);
    }
    EXPECT_GT(glm::dot(area, face.normal), 0.0) << "counter-clockwise seen from outside";
    for (std::size_t k = 0; k < fe.size(); ++k) {
      const Vec3& v0 = p.vertices()[fe[k].vertex].p;
      const Vec3& v1 = p.vertices()[fe[(k + 1) % fe.size()].vertex].p;
      EXPECT_NEAR(glm::dot(face.normal, v0), face.offset, tol) << "planar face";
      // side planes contain the edge, stand on the face and face its inside
      EXPECT_NEAR(glm::dot(fe[k].side, face.normal), 0.0, 1e-9);
      EXPECT_NEAR(glm::dot(fe[k].side, v1 - v0), 0.0, 1e-9 * p.radius());
      EXPECT_GT(glm::dot(centroid - v0, fe[k].side), 0.0);
      const auto& e = p.edges()[fe[k].edge];
      EXPECT_TRUE(e.face[0] == f || e.face[1] == f);
      ++seen_edge[fe[k].edge];
    }
    // every vertex below or on the face plane (convexity)
    for (const auto& v : p.vertices()) EXPECT_LE(glm::dot(face.normal, v.p) - face.offset, tol);
  }
  for (std::size_t e = 0; e < E; ++e) EXPECT_EQ(seen_edge[e], 2) << "edge in two faces";
  // face order visits every face once
  std::vector<int> in_order(F, 0);
  for (const auto f : p.faceOrder()) ++in_order[f];
  for (std::size_t f = 0; f < F; ++f) EXPECT_EQ(in_order[f], 1);
}

TEST(Polytope, StructureOfRandomHulls) {
  std::mt19937_64 rng(11);
  for (std::size_t n : {4u, 5u, 8u, 20u, 100u, 500u, 2000u}) {
    for (int rep = 0; rep < 5; ++rep) {
      const auto pts = reference::randomPointSet(rng, n, 0.05);
      const auto r = Polytope::fromPoints(pts);
      ASSERT_TRUE(r.ok()) << r.error().message;
      checkStructure(r.value());
    }
  }
}

TEST(Polytope, SupportAndLookupTable) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  const auto r = Polytope::fromPoints(reference::ellipsoidPoints(512, 0.025, 0.018, 0.012, 1));
  ASSERT_TRUE(r.ok());
  const Polytope& p = r.value();
  EXPECT_LE(Polytope::kLookupBytes, 1024u);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 dir = glm::normalize(Vec3{g(rng), g(rng), g(rng)});
    double best = -1e300;
    for (const auto& v : p.vertices()) best = std::max(best, glm::dot(v.p, dir));
    const std::uint32_t start = p.lookup(dir);
    ASSERT_LT(start, p.vertices().size());
    // the table's vertex is already near the extreme
    EXPECT_GT(glm::dot(p.vertices()[start].p, dir), best - 0.5 * p.radius());
    EXPECT_DOUBLE_EQ(glm::dot(p.vertices()[p.support(dir, start)].p, dir), best);
    EXPECT_DOUBLE_EQ(glm::dot(p.vertices()[p.support(dir, 0)].p, dir), best);
  }
}

}  // namespace
}  // namespace hapticd::geom
