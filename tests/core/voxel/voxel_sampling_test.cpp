// Voxel sampling (McNeely et al. 1999): the signed distance it voxelises, the map, the point
// shell and the tangent-plane force, against closed forms on boxes.
#include "core/voxel/voxel_sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "tests/core/alloc_counter.h"

namespace hapticd::voxel {
namespace {

Polytope box(const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> pts;
  for (int i = 0; i < 8; ++i) {
    pts.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  }
  auto r = Polytope::fromPoints(pts);
  EXPECT_TRUE(r.ok());
  return std::move(r).value();
}

TEST(VoxelSampling, SignedDistanceToABoxIsExact) {
  const Polytope b = box(Vec3(-1.0), Vec3(1.0));
  const PlacedShape s{&b, Transform{}};
  const std::span<const PlacedShape> shapes(&s, 1);
  // inside: minus the depth below the nearest face
  auto d = signedDistance(shapes, Vec3(0.25, 0.5, 0.0));
  EXPECT_DOUBLE_EQ(d.distance, -0.5);
  EXPECT_DOUBLE_EQ(d.normal_W.y, 1.0);
  // outside a face, an edge, a vertex
  d = signedDistance(shapes, Vec3(0.0, 3.0, 0.5));
  EXPECT_DOUBLE_EQ(d.distance, 2.0);
  EXPECT_DOUBLE_EQ(d.normal_W.y, 1.0);
  d = signedDistance(shapes, Vec3(4.0, 5.0, 0.0));
  EXPECT_NEAR(d.distance, 5.0, 1e-15);
  EXPECT_NEAR(d.normal_W.x, 0.6, 1e-15);
  EXPECT_NEAR(d.normal_W.y, 0.8, 1e-15);
  d = signedDistance(shapes, Vec3(2.0, 2.0, 2.0));
  EXPECT_NEAR(d.distance, std::sqrt(3.0), 1e-15);
}

TEST(VoxelSampling, UnionIsTheSmallestSignedDistance) {
  // two boxes sharing the face x = 0: near the seam the CSG union is shallow (documented)
  const Polytope a = box(Vec3(-2.0, -1.0, -1.0), Vec3(0.0, 1.0, 1.0));
  const Polytope b = box(Vec3(0.0, -1.0, -1.0), Vec3(2.0, 1.0, 1.0));
  const PlacedShape s[2] = {{&a, Transform{}}, {&b, Transform{}}};
  EXPECT_NEAR(signedDistance(s, Vec3(0.01, 0.0, 0.0)).distance, -0.01, 1e-15);
  EXPECT_NEAR(signedDistance(s, Vec3(3.0, 0.0, 0.0)).distance, 1.0, 1e-15);
}

TEST(VoxelSampling, SeamsBetweenTouchingShapesAreNotSurfaces) {
  // a wall standing on a floor: inside, along the seam, voxels are interior; on the top surface
  // next to the seam the normal is the exposed surface's
  const Polytope floor = box(Vec3(-20.0, -10.0, -20.0), Vec3(20.0, 0.0, 20.0));
  const Polytope wall = box(Vec3(-2.0, 0.0, -20.0), Vec3(2.0, 20.0, 20.0));
  const PlacedShape s[2] = {{&floor, Transform{}}, {&wall, Transform{}}};
  auto map = VoxelMap::build(s, 0.5);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map.value().lookup(Vec3(0.1, 0.1, 0.3)), VoxelMap::Cell::kInterior);
  EXPECT_EQ(map.value().lookup(Vec3(0.1, -0.1, 0.3)), VoxelMap::Cell::kInterior);
  Vec3 n{0.0};
  ASSERT_EQ(map.value().lookup(Vec3(8.0, -0.1, 0.3), nullptr, &n), VoxelMap::Cell::kSurface);
  EXPECT_EQ(n, Vec3(0.0, 1.0, 0.0));
  ASSERT_EQ(map.value().lookup(Vec3(8.0, 0.1, 0.3), nullptr, &n), VoxelMap::Cell::kSurface);
  EXPECT_EQ(n, Vec3(0.0, 1.0, 0.0));
  ASSERT_EQ(map.value().lookup(Vec3(2.1, 8.0, 0.3), nullptr, &n), VoxelMap::Cell::kSurface);
  EXPECT_EQ(n, Vec3(1.0, 0.0, 0.0));
}

// A floor whose top is y = 0 (size in scene units), voxelised at h.
Result<VoxelMap> floorMap(const Polytope& floor, double h) {
  const PlacedShape s{&floor, Transform{}};
  return VoxelMap::build(std::span<const PlacedShape>(&s, 1), h);
}

TEST(VoxelSampling, MapClassifiesFreeSurfaceAndInterior) {
  const Polytope floor = box(Vec3(-50.0, -10.0, -50.0), Vec3(50.0, 0.0, 50.0));
  auto map = floorMap(floor, 1.0);
  ASSERT_TRUE(map.ok()) << map.error().message;
  Vec3 c{0.0}, n{0.0};
  EXPECT_EQ(map.value().lookup(Vec3(0.3, -0.2, 0.4), &c, &n), VoxelMap::Cell::kSurface);
  EXPECT_EQ(n, Vec3(0.0, 1.0, 0.0));
  // the voxel's centre is within half a voxel diagonal of the surface
  EXPECT_LE(std::abs(c.y), 0.5 * std::sqrt(3.0));
  EXPECT_EQ(map.value().lookup(Vec3(0.0, -5.0, 0.0)), VoxelMap::Cell::kInterior);
  EXPECT_EQ(map.value().lookup(Vec3(0.0, 5.0, 0.0)), VoxelMap::Cell::kFree);
  EXPECT_EQ(map.value().lookup(Vec3(0.0, 500.0, 0.0)), VoxelMap::Cell::kFree);  // off the grid
  EXPECT_GT(map.value().surfaceVoxelCount(), 0u);
}

TEST(VoxelSampling, BadArgumentsAreRefusedWithTheirReason) {
  const Polytope floor = box(Vec3(-1.0), Vec3(1.0));
  const PlacedShape s{&floor, Transform{}};
  const std::span<const PlacedShape> one(&s, 1);
  auto r = VoxelMap::build({}, 1.0);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("no shape"), std::string::npos);
  r = VoxelMap::build(one, 0.0);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("positive"), std::string::npos);
  r = VoxelMap::build(one, std::nan(""));
  ASSERT_FALSE(r.ok());
  r = VoxelMap::build(one, 1e-4, 1000);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("exceed the limit"), std::string::npos);
  auto shell = makePointShell(one, -1.0);
  ASSERT_FALSE(shell.ok());
  shell = makePointShell(one, 1e-4, 100);
  ASSERT_FALSE(shell.ok());
  EXPECT_NE(shell.error().message.find("more than 100 points"), std::string::npos);
}

TEST(VoxelSampling, PointShellCoversTheSurfaceOnlyWithInwardNormals) {
  // an L of two boxes: the shared face is not sampled
  const Polytope a = box(Vec3(0.0), Vec3(2.0, 1.0, 1.0));
  const Polytope b = box(Vec3(0.0, 1.0, 0.0), Vec3(1.0, 2.0, 1.0));
  const PlacedShape s[2] = {{&a, Transform{}}, {&b, Transform{}}};
  auto shell = makePointShell(s, 0.1);
  ASSERT_TRUE(shell.ok()) << shell.error().message;
  const auto& sh = shell.value();
  ASSERT_GT(sh.p_B.size(), 100u);
  for (std::size_t i = 0; i < sh.p_B.size(); ++i) {
    const auto d = signedDistance(s, sh.p_B[i]);
    EXPECT_NEAR(d.distance, 0.0, 1e-12) << "point " << i << " is not on the surface";
    EXPECT_NEAR(glm::length(sh.inward_B[i]), 1.0, 1e-12);
    // a step along the inward normal goes inside the body
    EXPECT_LT(signedDistance(s, sh.p_B[i] + sh.inward_B[i] * 1e-3).distance, 0.0);
  }
}

// A cube of side 20 resting on the floor, its bottom at y = -depth. McNeely's force is k Σ dᵢ nᵢ
// over the shell points below their voxel's tangent plane, which passes through the voxel centre,
// not the surface: each dᵢ is within half a voxel diagonal of the true depth, the force is
// straight up and there is no torque about the centre. A depth can also give no force at all
// (a point above its voxel's centre, or past the surface layer in an interior voxel): counted.
struct CubeOnFloor {
  double max_error = 0.0;  // of the mean point depth, in voxels
  int depths = 0, misses = 0;
};

CubeOnFloor cubeOnFloor(double unit, double h) {
  CubeOnFloor out;
  const Polytope floor = box(Vec3(-50.0, -10.0, -50.0) * unit, Vec3(50.0, 0.0, 50.0) * unit);
  auto map = floorMap(floor, h * unit);
  EXPECT_TRUE(map.ok()) << map.error().message;
  // the cube's bottom face as a point shell (side points would be shallower than the cube)
  PointShell shell;
  for (int a = 0; a < 20; ++a) {
    for (int b = 0; b < 20; ++b) {
      shell.p_B.push_back(Vec3(-9.5 + a, -10.0, -9.5 + b) * unit);
      shell.inward_B.push_back(Vec3(0.0, 1.0, 0.0));
    }
  }
  const double bound = 0.5 * std::sqrt(3.0) * h * unit;
  for (int i = 0; i < 40; ++i) {
    // 0.0123 to 1.96 voxels, never on a voxel boundary
    const double depth = (0.05 * i + 0.0123) * h * unit;
    Transform X_WB;
    X_WB.t = Vec3(0.0, 10.0 * unit - depth, 0.0);
    const double k = 1.0;
    const VoxelForce f = force(map.value(), shell, X_WB, X_WB.t, k);
    ++out.depths;
    if (f.points_in_contact == 0) {
      ++out.misses;
      continue;
    }
    EXPECT_EQ(f.force_W.x, 0.0);
    EXPECT_EQ(f.force_W.z, 0.0);
    EXPECT_GT(f.force_W.y, 0.0);
    const double mean = f.force_W.y / (k * f.points_in_contact);
    EXPECT_LE(std::abs(mean - depth), bound) << "depth " << depth;
    EXPECT_LE(f.max_depth, depth + bound);
    EXPECT_LE(glm::length(f.torque_W), 1e-9 * f.force_W.y * 10.0 * unit);
    out.max_error = std::max(out.max_error, std::abs(mean - depth) / (h * unit));
  }
  return out;
}

TEST(VoxelSampling, CubeOnFloorForceWithinTheVoxelBound) {
  for (const double h : {2.0, 1.0, 0.5, 0.25}) {
    const CubeOnFloor r = cubeOnFloor(1.0, h);
    std::printf(
        "voxel %.2f: max mean-depth error %.3f voxels (bound 0.866), %d of %d depths "
        "felt nothing\n",
        h, r.max_error, r.misses, r.depths);
    EXPECT_LT(r.misses, r.depths);  // not vacuous
    EXPECT_GT(r.misses, 0);         // the method's known blind spots show
  }
}

TEST(VoxelSampling, TheSameSceneInMillimetresMetresAndKilometres) {
  const CubeOnFloor mm = cubeOnFloor(1.0, 1.0), m = cubeOnFloor(1e-3, 1.0),
                    km = cubeOnFloor(1e3, 1.0);
  EXPECT_NEAR(m.max_error, mm.max_error, 1e-9);
  EXPECT_NEAR(km.max_error, mm.max_error, 1e-9);
  EXPECT_EQ(m.misses, mm.misses);
  EXPECT_EQ(km.misses, mm.misses);
}

// A floor from y = -floor_depth to its top at y = 0 voxelised at 1, and a cube of side 20 at the
// origin sampled as a point shell at spacing 1.
struct CubeOverFloor {
  Result<VoxelMap> map;
  Result<PointShell> shell;
};

CubeOverFloor cubeOverFloor(double floor_depth) {
  const Polytope floor = box(Vec3(-50.0, -floor_depth, -50.0), Vec3(50.0, 0.0, 50.0));
  const Polytope cube = box(Vec3(-10.0), Vec3(10.0));
  const PlacedShape c{&cube, Transform{}};
  return {floorMap(floor, 1.0), makePointShell(std::span<const PlacedShape>(&c, 1), 1.0)};
}

TEST(VoxelSampling, DeepPenetrationReachesInteriorVoxelsWhichGiveNoForce) {
  // where the method breaks: pushed deeper than the surface layer, points feel nothing
  const CubeOverFloor set = cubeOverFloor(30.0);
  ASSERT_TRUE(set.map.ok());
  ASSERT_TRUE(set.shell.ok());
  Transform X_WB;
  X_WB.t = Vec3(0.0, 10.0 - 8.0, 0.0);
  const VoxelForce f = force(set.map.value(), set.shell.value(), X_WB, X_WB.t, 1.0);
  EXPECT_GT(f.points_interior, 400u);  // the whole bottom face (20 x 20) and more
  EXPECT_LT(f.max_depth, 1.0);         // only the side points near the surface push
}

TEST(VoxelSampling, ForceAllocatesNothing) {
  const CubeOverFloor set = cubeOverFloor(10.0);
  ASSERT_TRUE(set.map.ok());
  ASSERT_TRUE(set.shell.ok());
  Transform X_WB;
  const std::uint64_t before = testing_alloc::count();
  double sum = 0.0;
  for (int i = 0; i < 100; ++i) {
    X_WB.t = Vec3(0.0, 10.0 - 0.01 * i, 0.0);
    sum += force(set.map.value(), set.shell.value(), X_WB, X_WB.t, 1.0).force_W.y;
  }
  EXPECT_EQ(testing_alloc::count(), before);
  EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace hapticd::voxel
