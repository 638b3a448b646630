// Polytope construction: refused input (never a crash), near-duplicate merging relative to size,
// polygon faces, Euler's formula, every adjacency list and Voronoi plane, the lookup table and the
// support climb against brute force.
#include "core/geometry/polytope.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>

#include "tests/reference/reference.h"

namespace hapticd::geom {
namespace {

std::vector<Vec3> cube(double h = 1.0) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i)
    p.push_back(Vec3{i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
  return p;
}

Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Vec3 v{0.0};
  while (glm::length(v) < 1e-6)
    v = Vec3{g(rng), g(rng), g(rng)};
  return glm::normalize(v);
}

TEST(Polytope, CubeHasSixQuadFaces) {
  const auto r = Polytope::fromPoints(cube());
  ASSERT_TRUE(r.ok()) << r.error().message;
  const Polytope& p = r.value();
  EXPECT_EQ(p.vertices().size(), 8u);
  EXPECT_EQ(p.edges().size(), 12u);
  ASSERT_EQ(p.faces().size(), 6u);
  for (std::uint32_t f = 0; f < 6; ++f)
    EXPECT_EQ(p.faceEdges(f).size(), 4u);
  EXPECT_NEAR(p.radius(), std::sqrt(3.0), 1e-12);
  // every face normal is an axis
  for (const auto& f : p.faces()) {
    EXPECT_NEAR(std::max({std::abs(f.normal.x), std::abs(f.normal.y), std::abs(f.normal.z)}), 1.0,
                1e-15);
    EXPECT_NEAR(f.offset, 1.0, 1e-15);
  }
}

// Coplanar hull triangles merged into polygons, whatever the orientation and extra coplanar points.
TEST(Polytope, CoplanarTrianglesMergeIntoPolygons) {
  std::mt19937_64 rng(2);
  for (int rep = 0; rep < 20; ++rep) {
    const Quat q = reference::randomRotation(rng);
    std::vector<Vec3> pts = cube(0.5);
    // points on the faces and edges: coplanar with the faces, never vertices
    for (int i = 0; i < 30; ++i) {
      Vec3 v{0.0};
      const int axis = i % 3;
      for (int k = 0; k < 3; ++k)
        v[k] = (static_cast<double>((i * 7 + k * 3) % 11) / 10.0 - 0.5);
      v[axis] = (i % 2 ? 0.5 : -0.5);
      pts.push_back(v);
    }
    pts.push_back({0.5, 0.5, 0.0});  // on an edge
    for (auto& v : pts)
      v = q * v;
    const auto r = Polytope::fromPoints(pts);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r.value().vertices().size(), 8u) << "rep " << rep;
    ASSERT_EQ(r.value().faces().size(), 6u) << "rep " << rep;
    for (std::uint32_t f = 0; f < 6; ++f)
      EXPECT_EQ(r.value().faceEdges(f).size(), 4u);
  }
  // prism over a 12-gon: two 12-gon caps, 12 quads
  std::vector<Vec3> prism;
  for (int k = 0; k < 12; ++k) {
    const double t = k * 2.0 * std::numbers::pi / 12.0;
    prism.push_back({std::cos(t), std::sin(t), -0.3});
    prism.push_back({std::cos(t), std::sin(t), 0.3});
  }
  const auto r = Polytope::fromPoints(prism);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r.value().faces().size(), 14u);
  std::size_t caps = 0, quads = 0;
  for (std::uint32_t f = 0; f < 14; ++f) {
    const auto n = r.value().faceEdges(f).size();
    caps += n == 12;
    quads += n == 4;
  }
  EXPECT_EQ(caps, 2u);
  EXPECT_EQ(quads, 12u);
  // octahedron: 8 triangles
  const std::vector<Vec3> octa = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  const auto o = Polytope::fromPoints(octa);
  ASSERT_TRUE(o.ok());
  EXPECT_EQ(o.value().faces().size(), 8u);
  EXPECT_EQ(o.value().edges().size(), 12u);
}

TEST(Polytope, RefusesBadInputWithClearErrors) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* what;
    std::vector<Vec3> points;
    const char* expect;
  };
  std::vector<Case> cases = {
      {"no points", {}, "at least 4"},
      {"one point", {{0, 0, 0}}, "at least 4"},
      {"three points", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, "at least 4"},
      {"NaN", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, nan}}, "not finite"},
      {"NaN in x", {{nan, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, "not finite"},
      {"Inf", {{0, 0, 0}, {1, 0, 0}, {inf, 1, 0}, {0, 0, 1}}, "not finite"},
      {"-Inf", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -inf}}, "not finite"},
      {"coplanar", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.2, 0}}, "coplanar"},
      {"collinear", {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}, "collinear"},
      {"coincident", {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, "coincide"},
      {"duplicates of a triangle", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1e-13, 0, 0}}, "at least 4"},
      {"huge", {{0, 0, 0}, {1e300, 0, 0}, {0, 1e300, 0}, {0, 0, 1e300}}, "too large"},
      {"tiny", {{0, 0, 0}, {1e-300, 0, 0}, {0, 1e-300, 0}, {0, 0, 1e-300}}, "too small"},
  };
  // many points on a tilted plane, with noise far below the size
  {
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Vec3 n = randomUnit(rng);
    const Vec3 e1 = glm::normalize(glm::cross(n, Vec3{0.3, 0.5, 0.7}));
    const Vec3 e2 = glm::cross(n, e1);
    Case plane{"1000 coplanar points, tilted", {}, "coplanar"};
    Case line{"1000 collinear points, tilted", {}, "collinear"};
    for (int i = 0; i < 1000; ++i) {
      plane.points.push_back(Vec3{5, -3, 2} + e1 * u(rng) + e2 * u(rng) + n * (1e-15 * u(rng)));
      line.points.push_back(Vec3{5, -3, 2} + e1 * (3.0 * u(rng)) + e2 * (1e-15 * u(rng)));
    }
    cases.push_back(plane);
    cases.push_back(line);
  }
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
  // exactly at the limit is accepted
  small.max_vertices = 8;
  EXPECT_TRUE(Polytope::fromPoints(cube(), small).ok());
  small.max_vertices = 7;
  EXPECT_FALSE(Polytope::fromPoints(cube(), small).ok());
  HullOptions few_inputs;
  few_inputs.max_input_points = 5;
  const auto too_many = Polytope::fromPoints(cube(), few_inputs);
  ASSERT_FALSE(too_many.ok());
  EXPECT_NE(too_many.error().message.find("too many points"), std::string::npos);
}

// Random, mostly degenerate inputs: always a hull or an Error, never a crash.
TEST(Polytope, GarbageNeverCrashes) {
  std::mt19937_64 rng(99);
  std::uniform_int_distribution<int> pick(0, 9);
  const double specials[] = {0.0,
                             1.0,
                             -1.0,
                             1e-300,
                             1e300,
                             1e-12,
                             0.5,
                             1.0 + 1e-15,
                             std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity()};
  std::size_t ok = 0, refused = 0;
  for (int rep = 0; rep < 3000; ++rep) {
    std::vector<Vec3> pts(static_cast<std::size_t>(rep % 9));
    for (auto& v : pts) {
      v = Vec3{specials[pick(rng) % (rep % 3 == 0 ? 10 : 8)], specials[pick(rng) % 8],
               specials[pick(rng) % 8]};
    }
    const auto r = Polytope::fromPoints(pts);
    if (r.ok()) {
      ++ok;
      const auto& p = r.value();
      EXPECT_EQ(p.vertices().size() + p.faces().size(), p.edges().size() + 2);
    } else {
      ++refused;
      EXPECT_FALSE(r.error().message.empty());
    }
  }
  std::printf("[figures] garbage input: %zu hulls, %zu refused\n", ok, refused);
}

// Near-duplicates closer than 1e-9 of the bounding-box diagonal merge; 1e-6 apart stay distinct,
// at every unit scale.
TEST(Polytope, MergesNearDuplicatesRelativeToSize) {
  for (const double scale : {1e-3, 1.0, 1e3}) {
    auto pts = cube(scale);
    const std::size_t n = pts.size();
    for (std::size_t i = 0; i < n; ++i)
      pts.push_back(pts[i] + Vec3{1e-12, -1e-12, 1e-12} * scale);
    const auto r = Polytope::fromPoints(pts);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r.value().vertices().size(), 8u) << "scale " << scale;
    EXPECT_EQ(r.value().faces().size(), 6u) << "scale " << scale;

    // points on a sphere of radius `scale`, each with a twin displaced tangentially: both are
    // extreme points of the set, so both are vertices unless merged
    const auto sphere = reference::ellipsoidPoints(100, scale, scale, scale, 17);
    for (const double offset : {1e-12, 1e-6}) {
      std::vector<Vec3> twins = sphere;
      for (const Vec3& p : sphere) {
        const Vec3 t = glm::normalize(glm::cross(p, Vec3{0.3, -0.7, 0.2}));
        twins.push_back(p + t * (offset * scale));
      }
      const auto h = Polytope::fromPoints(twins);
      ASSERT_TRUE(h.ok()) << h.error().message;
      EXPECT_EQ(h.value().vertices().size(), offset < 1e-9 ? 100u : 200u)
          << "scale " << scale << " offset " << offset;
    }
  }
}

// Every structural invariant the walk relies on.
void checkStructure(const Polytope& p, const std::vector<Vec3>& input, const std::string& label) {
  SCOPED_TRACE(label);
  const auto V = p.vertices().size(), E = p.edges().size(), F = p.faces().size();
  ASSERT_GE(V, 4u);
  ASSERT_EQ(V + F, E + 2) << "Euler";
  const double tol = 1e-9 * p.radius();
  // vertices are input points; input points are inside the hull
  for (const auto& v : p.vertices()) {
    EXPECT_TRUE(std::find(input.begin(), input.end(), v.p) != input.end()) << "vertex not an input";
  }
  for (const Vec3& x : input) {
    double worst = -1e300;
    for (const auto& f : p.faces())
      worst = std::max(worst, glm::dot(f.normal, x) - f.offset);
    ASSERT_LE(worst, tol) << "input point outside the hull";
  }
  // centroid, radius
  Vec3 c{0.0};
  for (const auto& v : p.vertices())
    c += v.p / static_cast<double>(V);
  EXPECT_LE(glm::length(c - p.centroid()), 1e-12 * p.radius());
  double radius = 0.0;
  for (const auto& v : p.vertices())
    radius = std::max(radius, glm::length(v.p - c));
  EXPECT_NEAR(p.radius(), radius, 1e-12 * radius);
  // edges
  for (std::uint32_t e = 0; e < E; ++e) {
    const auto& edge = p.edges()[e];
    ASSERT_LT(edge.tail, V);
    ASSERT_LT(edge.head, V);
    ASSERT_NE(edge.tail, edge.head);
    ASSERT_LT(edge.face[0], F);
    ASSERT_LT(edge.face[1], F);
    ASSERT_NE(edge.face[0], edge.face[1]);
    const Vec3 d = p.vertices()[edge.head].p - p.vertices()[edge.tail].p;
    EXPECT_NEAR(edge.length, glm::length(d), 1e-12 * p.radius());
    EXPECT_LE(glm::length(edge.dir - d / glm::length(d)), 1e-12);
    // face[0] runs tail -> head, face[1] head -> tail
    for (int side = 0; side < 2; ++side) {
      const auto fe = p.faceEdges(edge.face[static_cast<std::size_t>(side)]);
      bool found = false;
      for (std::size_t k = 0; k < fe.size(); ++k) {
        const std::uint32_t v0 = fe[k].vertex, v1 = fe[(k + 1) % fe.size()].vertex;
        if (fe[k].edge == e) {
          found = true;
          EXPECT_EQ(v0, side == 0 ? edge.tail : edge.head);
          EXPECT_EQ(v1, side == 0 ? edge.head : edge.tail);
        }
      }
      EXPECT_TRUE(found) << "edge " << e << " missing from its face " << side;
      // the Voronoi plane against face[side]: through the edge, perpendicular to the face, and
      // the face's inside on its negative side
      const auto& face = p.faces()[edge.face[static_cast<std::size_t>(side)]];
      const Vec3& m = edge.fe_normal[static_cast<std::size_t>(side)];
      EXPECT_NEAR(glm::length(m), 1.0, 1e-12);
      EXPECT_NEAR(glm::dot(m, edge.dir), 0.0, 1e-9);
      EXPECT_NEAR(glm::dot(m, face.normal), 0.0, 1e-9);
      Vec3 fc{0.0};
      for (const auto& x : fe)
        fc += p.vertices()[x.vertex].p / static_cast<double>(fe.size());
      EXPECT_LT(glm::dot(fc - p.vertices()[edge.tail].p, m), 0.0) << "face inside VR(edge)";
    }
  }
  // vertex -> incident edges: each edge twice overall, out directions, degree >= 3
  std::size_t incidences = 0;
  for (std::uint32_t v = 0; v < V; ++v) {
    EXPECT_GE(p.vertexEdges(v).size(), 3u);
    for (const auto& ve : p.vertexEdges(v)) {
      ASSERT_LT(ve.edge, E);
      const auto& e = p.edges()[ve.edge];
      ASSERT_TRUE((e.tail == v && e.head == ve.other) || (e.head == v && e.tail == ve.other));
      const Vec3 d = glm::normalize(p.vertices()[ve.other].p - p.vertices()[v].p);
      EXPECT_LE(glm::length(d - ve.out), 1e-12);
      ++incidences;
    }
  }
  EXPECT_EQ(incidences, 2 * E);
  // faces: planar convex CCW polygons with outward normals; every edge in exactly two faces
  std::vector<int> seen_edge(E, 0);
  for (std::uint32_t f = 0; f < F; ++f) {
    const auto& face = p.faces()[f];
    EXPECT_NEAR(glm::length(face.normal), 1.0, 1e-12);
    const auto fe = p.faceEdges(f);
    ASSERT_GE(fe.size(), 3u);
    Vec3 centroid{0.0}, newell{0.0};
    for (std::size_t k = 0; k < fe.size(); ++k) {
      centroid += p.vertices()[fe[k].vertex].p / static_cast<double>(fe.size());
      newell +=
          glm::cross(p.vertices()[fe[k].vertex].p, p.vertices()[fe[(k + 1) % fe.size()].vertex].p);
    }
    EXPECT_GT(glm::dot(newell, face.normal), 0.0) << "counter-clockwise seen from outside";
    EXPECT_LE(glm::length(glm::normalize(newell) - face.normal), 1e-9) << "normal of the loop";
    for (std::size_t k = 0; k < fe.size(); ++k) {
      const Vec3& v0 = p.vertices()[fe[k].vertex].p;
      const Vec3& v1 = p.vertices()[fe[(k + 1) % fe.size()].vertex].p;
      const Vec3& v2 = p.vertices()[fe[(k + 2) % fe.size()].vertex].p;
      EXPECT_NEAR(glm::dot(face.normal, v0), face.offset, tol) << "planar face";
      EXPECT_GE(glm::dot(glm::cross(v1 - v0, v2 - v1), face.normal), -tol * tol) << "convex, CCW";
      const auto& e = p.edges()[fe[k].edge];
      EXPECT_TRUE((e.tail == fe[k].vertex && e.head == fe[(k + 1) % fe.size()].vertex) ||
                  (e.head == fe[k].vertex && e.tail == fe[(k + 1) % fe.size()].vertex));
      // side planes contain the edge, stand on the face and face its inside
      EXPECT_NEAR(glm::length(fe[k].side), 1.0, 1e-12);
      EXPECT_NEAR(glm::dot(fe[k].side, face.normal), 0.0, 1e-9);
      EXPECT_NEAR(glm::dot(fe[k].side, v1 - v0), 0.0, 1e-9 * p.radius());
      EXPECT_GT(glm::dot(centroid - v0, fe[k].side), 0.0);
      EXPECT_TRUE(e.face[0] == f || e.face[1] == f);
      ++seen_edge[fe[k].edge];
    }
    // outward: every vertex below or on the face plane
    for (const auto& v : p.vertices())
      EXPECT_LE(glm::dot(face.normal, v.p) - face.offset, tol);
  }
  for (std::size_t e = 0; e < E; ++e)
    EXPECT_EQ(seen_edge[e], 2) << "edge in two faces";
  // face order visits every face once
  std::vector<int> in_order(F, 0);
  for (const auto f : p.faceOrder())
    ++in_order[f];
  for (std::size_t f = 0; f < F; ++f)
    EXPECT_EQ(in_order[f], 1);
}

TEST(Polytope, StructureOfRandomHulls) {
  std::mt19937_64 rng(11);
  std::size_t hulls = 0, refused = 0, max_v = 0;
  for (std::size_t n : {4u, 5u, 6u, 8u, 12u, 20u, 50u, 100u, 500u, 2000u}) {
    for (int rep = 0; rep < (n <= 100 ? 30 : 6); ++rep) {
      const auto pts = reference::randomPointSet(rng, n, 0.05);
      const auto r = Polytope::fromPoints(pts);
      if (!r.ok()) {
        // only a flat random set may be refused, and with a reason
        ++refused;
        EXPECT_NE(r.error().message.find("coplanar"), std::string::npos) << r.error().message;
        continue;
      }
      ++hulls;
      max_v = std::max(max_v, r.value().vertices().size());
      checkStructure(r.value(), pts, "n=" + std::to_string(n) + " rep " + std::to_string(rep));
      if (HasFatalFailure())
        return;
    }
  }
  std::printf("[figures] structure: %zu random hulls checked (up to %zu vertices), %zu refused\n",
              hulls, max_v, refused);
  EXPECT_LE(refused, hulls / 20);
}

// The lookup table gives a vertex; support() climbs from any hint to the brute-force maximum.
TEST(Polytope, SupportAndLookupTable) {
  std::mt19937_64 rng(5);
  EXPECT_LE(Polytope::kLookupBytes, 1024u);
  std::size_t queries = 0;
  double worst_lookup = 0.0;
  for (int shape = 0; shape < 60; ++shape) {
    const std::size_t n = shape < 20 ? 512 : 4 + static_cast<std::size_t>(shape) * 7;
    const auto pts = shape < 20 ? reference::ellipsoidPoints(n, 0.025, 0.018, 0.012, rng())
                                : reference::randomPointSet(rng, n, 0.05);
    const auto r = Polytope::fromPoints(pts);
    if (!r.ok())
      continue;
    const Polytope& p = r.value();
    std::vector<Vec3> dirs;
    for (int i = 0; i < 200; ++i)
      dirs.push_back(randomUnit(rng));
    // axis directions: ties on boxes and prisms
    for (int k = 0; k < 3; ++k) {
      Vec3 d{0.0};
      d[k] = 1.0;
      dirs.push_back(d);
      dirs.push_back(-d);
    }
    for (const Vec3& dir : dirs) {
      double best = -std::numeric_limits<double>::infinity();
      for (const auto& v : p.vertices())
        best = std::max(best, glm::dot(v.p, dir));
      const std::uint32_t start = p.lookup(dir);
      ASSERT_LT(start, p.vertices().size());
      EXPECT_EQ(p.lookup(dir * 1e-3), start) << "lookup of an unnormalised direction";
      EXPECT_EQ(p.lookup(dir * 1e3), start);
      worst_lookup =
          std::max(worst_lookup, (best - glm::dot(p.vertices()[start].p, dir)) / p.radius());
      EXPECT_GT(glm::dot(p.vertices()[start].p, dir), best - 0.5 * p.radius());
      for (const std::uint32_t hint :
           {start, 0u, static_cast<std::uint32_t>(p.vertices().size() - 1),
            static_cast<std::uint32_t>(rng() % p.vertices().size())}) {
        const std::uint32_t s = p.support(dir, hint);
        ASSERT_LT(s, p.vertices().size());
        ASSERT_EQ(glm::dot(p.vertices()[s].p, dir), best) << "shape " << shape << " hint " << hint;
        ++queries;
      }
    }
  }
  std::printf(
      "[figures] support: %zu climbs equal to brute force; lookup vertex at most %.3g of "
      "the radius below the extreme\n",
      queries, worst_lookup);
}

}  // namespace
}  // namespace hapticd::geom
