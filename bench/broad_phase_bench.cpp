// hapticbench, broad phase: BroadPhase/AllMoving/<N> and BroadPhase/OneMoving/<N>, ours and the
// peers' (Bullet btAxisSweep3, bt32BitAxisSweep3, btDbvtBroadphase; FCL DynamicAABBTree and SaP
// managers) on the same boxes and motion. One iteration is one frame: every moving box gets its
// new extent, then the library updates its pair set. The motion itself (a few adds per box) is
// inside the timed loop for every library alike.
#include <benchmark/benchmark.h>
#include <btBulletCollisionCommon.h>
#include <fcl/broadphase/broadphase_SaP.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>

#include <cmath>
#include <memory>
#include <random>

#include "core/collision/broad_phase.h"
#include "core/collision/collision_world.h"

namespace hapticd::bench {
namespace {

using collision::Aabb;
using geom::Vec3;

// N boxes, half-extents uniform in [0.5, 1.5]^3, centres uniform in a cube of side cbrt(70 N), each
// moving by a random unit direction times U[0.01, 0.05] per frame, reflected at the walls.
struct Boxes {
  double side = 0.0;
  std::vector<Vec3> c, h, v;
  Boxes(std::size_t n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> g(0.0, 1.0);
    side = std::cbrt(70.0 * static_cast<double>(n));
    for (std::size_t i = 0; i < n; ++i) {
      c.push_back(Vec3{u(rng), u(rng), u(rng)} * side);
      h.push_back(Vec3{0.5 + u(rng), 0.5 + u(rng), 0.5 + u(rng)});
      v.push_back(glm::normalize(Vec3{g(rng), g(rng), g(rng)}) * (0.01 + 0.04 * u(rng)));
    }
  }
  void step(std::size_t i) {
    c[i] += v[i];
    for (int k = 0; k < 3; ++k) {
      if (c[i][k] < 0.0 || c[i][k] > side)
        v[i][k] = -v[i][k];
    }
  }
  Aabb box(std::size_t i) const { return {c[i] - h[i], c[i] + h[i]}; }
};

void iterationsFor(benchmark::internal::Benchmark* b, std::size_t n) {
  if (n >= 100000) {
    b->Iterations(5);
  } else if (n >= 10000) {
    b->Iterations(40);
  }
  b->Unit(benchmark::kMicrosecond);
}

// ---------------------------------------------------------------- ours
// grid: whether commits that move most boxes may recompute the pairs on the grid (the default)
void oursAllMoving(benchmark::State& state, std::size_t n, bool grid) {
  Boxes boxes(n, 1);
  collision::SweepAndPrune sap;
  sap.reserve(n, 8 * n);
  if (!grid)
    sap.setGridMinBoxes(static_cast<std::size_t>(-1));
  std::vector<std::uint32_t> handles(n);
  for (std::size_t i = 0; i < n; ++i) {
    collision::BoxFilter f;
    f.body = static_cast<std::uint32_t>(i);
    handles[i] = sap.add(boxes.box(i), f);
  }
  sap.commit();
  sap.takeEvents();
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      boxes.step(i);
      sap.update(handles[i], boxes.box(i));
    }
    sap.commit();
    benchmark::DoNotOptimize(sap.takeEvents().size());
  }
  state.counters["pairs"] = static_cast<double>(sap.pairs().size());
}

// one body of 20 boxes in a row moving among N static boxes
void oursOneMoving(benchmark::State& state, std::size_t n) {
  Boxes boxes(n, 2);
  collision::SweepAndPrune sap;
  sap.reserve(n + 20, 8 * n);
  for (std::size_t i = 0; i < n; ++i) {
    collision::BoxFilter f;
    f.body = static_cast<std::uint32_t>(i);
    f.is_static = true;
    sap.add(boxes.box(i), f);
  }
  std::vector<std::uint32_t> mine;
  Vec3 origin{boxes.side * 0.3, boxes.side * 0.5, boxes.side * 0.5};
  auto member = [&](std::size_t k) {
    const Vec3 c = origin + Vec3{1.1 * static_cast<double>(k), 0.0, 0.0};
    return Aabb{c - 0.5, c + 0.5};
  };
  for (std::size_t k = 0; k < 20; ++k) {
    collision::BoxFilter f;
    f.body = static_cast<std::uint32_t>(n);
    mine.push_back(sap.add(member(k), f));
  }
  sap.commit();
  sap.takeEvents();
  double t = 0.0;
  for (auto _ : state) {
    t += 1.0;
    origin = Vec3{boxes.side * (0.3 + 0.2 * std::sin(t * 1e-3)),
                  boxes.side * 0.5 + 3.0 * std::sin(t * 7e-3), boxes.side * 0.5};
    for (std::size_t k = 0; k < 20; ++k)
      sap.update(mine[k], member(k));
    sap.commit();
    benchmark::DoNotOptimize(sap.takeEvents().size());
  }
  state.counters["pairs"] = static_cast<double>(sap.pairs().size());
}

// the same through the whole collision step: a 20-cube body among N static cube bodies.
// state.range(0): 1 = the world's default (a body of 8 pieces or more is one box with a tree of
// its pieces), 0 = a box per piece (WorldOptions::piece_tree_min = 0, as before issue 16)
void oursOneMovingWorld(benchmark::State& state, std::size_t n) {
  Boxes boxes(n, 2);
  std::vector<Vec3> pts;
  for (int i = 0; i < 8; ++i)
    pts.push_back(Vec3{i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5});
  auto cube = std::make_shared<const geom::Polytope>(geom::Polytope::fromPoints(pts).value());
  collision::WorldOptions options;
  if (state.range(0) == 0)
    options.piece_tree_min = 0;
  collision::CollisionWorld world(options);
  world.reserve(n + 20, 8 * n);
  for (std::size_t i = 0; i < n; ++i) {
    collision::BodyDesc d;
    d.kind = collision::BodyKind::kStatic;
    d.primitives.push_back({cube, geom::Transform{}});
    world.addBody(d, geom::Pose{boxes.c[i], geom::Quat{1, 0, 0, 0}});
  }
  collision::BodyDesc probe;
  probe.kind = collision::BodyKind::kProbe;
  for (int k = 0; k < 20; ++k) {
    geom::Transform X;
    X.t = Vec3{1.1 * k, 0.0, 0.0};
    probe.primitives.push_back({cube, X});
  }
  // a corridor with no static box in it, so that the narrow phase has nothing to do
  const std::uint32_t id =
      world.addBody(probe, geom::Pose{Vec3{-100.0, 0.0, 0.0}, geom::Quat{1, 0, 0, 0}});
  world.step();
  double t = 0.0;
  for (auto _ : state) {
    t += 1.0;
    world.setPose(id,
                  geom::Pose{Vec3{-100.0 + 3.0 * std::sin(t * 1e-3), 0.1 * std::sin(t * 7e-3), 0.0},
                             geom::Quat{1, 0, 0, 0}});
    benchmark::DoNotOptimize(world.step());
  }
}

// Many pieces of one body moving together (issue 16, issue 18 item 3): a body of `pieces` cubes
// of 0.2 (a 10-wide grid, 0.25 apart) sweeps and turns slowly through N static unit cubes of
// the box field; every box pair it meets goes to the narrow phase (the same pairs either way).
// state.range(0): 1 = a tree of its pieces under one box, 0 = a box per piece.
void oursManyPiecesWorld(benchmark::State& state, std::size_t n, std::size_t pieces) {
  Boxes boxes(n, 3);
  auto cubeOf = [](double h) {
    std::vector<Vec3> pts;
    for (int i = 0; i < 8; ++i)
      pts.push_back(Vec3{i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
    return std::make_shared<const geom::Polytope>(geom::Polytope::fromPoints(pts).value());
  };
  const auto unit = cubeOf(0.5), small = cubeOf(0.1);
  collision::WorldOptions options;
  options.box_margin = 0.01;
  if (state.range(0) == 0)
    options.piece_tree_min = 0;
  collision::CollisionWorld world(options);
  world.reserve(n + pieces, 8 * n);
  for (std::size_t i = 0; i < n; ++i) {
    collision::BodyDesc d;
    d.kind = collision::BodyKind::kStatic;
    d.primitives.push_back({unit, geom::Transform{}});
    world.addBody(d, geom::Pose{boxes.c[i], geom::Quat{1, 0, 0, 0}});
  }
  collision::BodyDesc body;
  body.kind = collision::BodyKind::kKinematic;
  for (std::size_t k = 0; k < pieces; ++k) {
    geom::Transform X;
    X.t = Vec3{0.25 * static_cast<double>(k % 10), 0.0, 0.25 * static_cast<double>(k / 10)};
    body.primitives.push_back({small, X});
  }
  const Vec3 centre{boxes.side * 0.5};
  auto poseAt = [&](double t) {
    return geom::Pose{centre + Vec3{0.3 * boxes.side * std::sin(t * 1e-3),
                                    0.2 * boxes.side * std::sin(t * 1.3e-3), 0.0},
                      glm::angleAxis(t * 2e-3, glm::normalize(Vec3{1.0, 2.0, 3.0}))};
  };
  const std::uint32_t id = world.addBody(body, poseAt(0.0));
  world.step();
  double t = 0.0, pairs = 0.0;
  for (auto _ : state) {
    t += 1.0;
    world.setPose(id, poseAt(t));
    pairs += world.step().pairs_overlapping;
  }
  state.counters["pairs"] = pairs / static_cast<double>(state.iterations());
}

// ---------------------------------------------------------------- Bullet
enum class BulletKind { kAxisSweep3, k32BitAxisSweep3, kDbvt };

void bulletAllMoving(benchmark::State& state, std::size_t n, BulletKind kind) {
  Boxes boxes(n, 1);
  const btVector3 lo(-2, -2, -2), hi(boxes.side + 2, boxes.side + 2, boxes.side + 2);
  std::unique_ptr<btBroadphaseInterface> bp;
  switch (kind) {
    case BulletKind::kAxisSweep3:
      bp = std::make_unique<btAxisSweep3>(lo, hi, static_cast<unsigned short>(n + 2));
      break;
    case BulletKind::k32BitAxisSweep3:
      bp = std::make_unique<bt32BitAxisSweep3>(lo, hi, static_cast<unsigned int>(n + 2));
      break;
    case BulletKind::kDbvt:
      bp = std::make_unique<btDbvtBroadphase>();
      break;
  }
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  auto bt = [](const Vec3& p) { return btVector3(p.x, p.y, p.z); };
  std::vector<btBroadphaseProxy*> proxies(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Aabb b = boxes.box(i);
    proxies[i] =
        bp->createProxy(bt(b.lo), bt(b.hi), 0, reinterpret_cast<void*>(i + 1), 1, -1, &dispatcher);
  }
  bp->calculateOverlappingPairs(&dispatcher);
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      boxes.step(i);
      const Aabb b = boxes.box(i);
      bp->setAabb(proxies[i], bt(b.lo), bt(b.hi), &dispatcher);
    }
    bp->calculateOverlappingPairs(&dispatcher);
  }
  state.counters["pairs"] = bp->getOverlappingPairCache()->getNumOverlappingPairs();
}

// ---------------------------------------------------------------- FCL
template <class Manager>
void fclAllMoving(benchmark::State& state, std::size_t n) {
  Boxes boxes(n, 1);
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<fcl::CollisionObjectd*> raw;
  for (std::size_t i = 0; i < n; ++i) {
    auto geom = std::make_shared<fcl::Boxd>(2 * boxes.h[i].x, 2 * boxes.h[i].y, 2 * boxes.h[i].z);
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(geom));
    objects.back()->setTranslation(fcl::Vector3d(boxes.c[i].x, boxes.c[i].y, boxes.c[i].z));
    objects.back()->computeAABB();
    raw.push_back(objects.back().get());
  }
  Manager manager;
  manager.registerObjects(raw);
  manager.setup();
  std::size_t pairs = 0;
  auto count = [](fcl::CollisionObjectd*, fcl::CollisionObjectd*, void* data) {
    ++*static_cast<std::size_t*>(data);
    return false;
  };
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      boxes.step(i);
      objects[i]->setTranslation(fcl::Vector3d(boxes.c[i].x, boxes.c[i].y, boxes.c[i].z));
      objects[i]->computeAABB();
    }
    manager.update();
    pairs = 0;
    manager.collide(&pairs, count);
  }
  state.counters["pairs"] = static_cast<double>(pairs);
}

void registerAll() {
  for (const std::size_t n : {100u, 1000u, 10000u, 100000u}) {
    const std::string name = "BroadPhase/AllMoving/" + std::to_string(n);
    iterationsFor(benchmark::RegisterBenchmark(name.c_str(), oursAllMoving, n, true), n);
    iterationsFor(
        benchmark::RegisterBenchmark(("BroadPhase/AllMovingSweep/" + std::to_string(n)).c_str(),
                                     oursAllMoving, n, false),
        n);
    if (n < 65535) {  // btAxisSweep3 has 16-bit handles
      iterationsFor(benchmark::RegisterBenchmark(("Peer/Bullet-btAxisSweep3/" + name).c_str(),
                                                 bulletAllMoving, n, BulletKind::kAxisSweep3),
                    n);
    }
    iterationsFor(benchmark::RegisterBenchmark(("Peer/Bullet-bt32BitAxisSweep3/" + name).c_str(),
                                               bulletAllMoving, n, BulletKind::k32BitAxisSweep3),
                  n);
    iterationsFor(benchmark::RegisterBenchmark(("Peer/Bullet-btDbvtBroadphase/" + name).c_str(),
                                               bulletAllMoving, n, BulletKind::kDbvt),
                  n);
    iterationsFor(
        benchmark::RegisterBenchmark(("Peer/FCL-DynamicAABBTree/" + name).c_str(),
                                     fclAllMoving<fcl::DynamicAABBTreeCollisionManagerd>, n),
        n);
    if (n <= 10000) {  // FCL's SaP manager is quadratic in places: 100 000 takes minutes
      iterationsFor(benchmark::RegisterBenchmark(("Peer/FCL-SaP/" + name).c_str(),
                                                 fclAllMoving<fcl::SaPCollisionManagerd>, n),
                    n);
    }
  }
  for (const std::size_t n : {1000u, 10000u}) {
    benchmark::RegisterBenchmark(("BroadPhase/OneMoving/" + std::to_string(n)).c_str(),
                                 oursOneMoving, n)
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::RegisterBenchmark("BroadPhase/OneMovingWorld/10000", oursOneMovingWorld, 10000)
      ->ArgName("piece_tree")
      ->Arg(1)
      ->Arg(0)
      ->Unit(benchmark::kMicrosecond);
  for (const std::size_t pieces : {100u, 500u}) {
    benchmark::RegisterBenchmark(
        ("BroadPhase/ManyPiecesWorld/10000/" + std::to_string(pieces)).c_str(), oursManyPiecesWorld,
        10000, pieces)
        ->ArgName("piece_tree")
        ->Arg(1)
        ->Arg(0)
        ->Iterations(4000)  // the same poses both ways: the same pairs
        ->Unit(benchmark::kMicrosecond);
  }
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace hapticd::bench
