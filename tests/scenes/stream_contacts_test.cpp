// The pose streams against their scenes: the held body, put at each row's target pose, is tested
// with the project's pair queries against the other bodies as the scene places them at the start,
// so each stream is shown to touch, push and penetrate what it is meant to, when it is meant to
// (docs/demo-scenes.md). The bodies are not moved here: this checks the script, not a simulation.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/collision/pair_query.h"
#include "core/geometry/polytope.h"
#include "scenes/demo_scenes.h"
#include "scenes/pose_streams.h"
#include "tests/scenes/glb_reader.h"

namespace hapticd::scenes {
namespace {

using namespace testing;  // NOLINT(google-build-using-namespace)

struct Target {
  std::string body;     // root node name of the body the primitive belongs to
  geom::Polytope hull;  // in the scene frame
  Vec3 lo, hi;          // its bounding box
};

struct Row {
  double t;
  geom::Pose X_WP;
  unsigned buttons;
};

std::vector<Row> rows(std::string_view scene) {
  std::istringstream in(makePoseStream(scene));
  std::string line;
  std::getline(in, line);
  std::vector<Row> out;
  while (std::getline(in, line)) {
    double v[9];
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3],
                    &v[4], &v[5], &v[6], &v[7], &v[8]) != 9)
      continue;
    out.push_back({v[0], geom::Pose::fromXyzw({v[1], v[2], v[3]}, v[4], v[5], v[6], v[7]),
                   static_cast<unsigned>(v[8])});
  }
  return out;
}

/// The scene, split into the held body's hull (in its own frame) and every other primitive's
/// hull in the scene frame, from the written mesh of each collider node.
class SceneHulls {
 public:
  explicit SceneHulls(std::string_view name) {
    std::vector<std::string> problems;
    glb_ = *splitGlb(makeDemoScene(name), problems);
    const std::vector<int> parent = parents(glb_);
    const Json& nodes = glb_.json["nodes"];
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const Json* body = physicsOf(nodes[i]);
      if (body == nullptr || !body->contains("collider"))
        continue;
      int root = static_cast<int>(i);
      while (parent[static_cast<std::size_t>(root)] >= 0)
        root = parent[static_cast<std::size_t>(root)];
      const Json& root_node = nodes[static_cast<std::size_t>(root)];
      const bool probe =
          root_node.contains("extras") && root_node["extras"]["haptic"].value("probe", false);
      const Mesh mesh = readMesh(glb_, nodes[i]["mesh"].get<int>());
      std::vector<geom::Vec3> pts;
      if (probe) {
        // the probe's collider is its own root node: its frame is the held body's frame
        EXPECT_EQ(root, static_cast<int>(i));
        pts = mesh.positions;
        probe_ = std::make_unique<geom::Polytope>(geom::Polytope::fromPoints(pts).value());
        continue;
      }
      const Rigid X = worldTransform(glb_, static_cast<int>(i));
      Vec3 lo{1e300}, hi{-1e300};
      for (const Vec3& p : mesh.positions) {
        pts.push_back(X.apply(p));
        lo = glm::min(lo, pts.back());
        hi = glm::max(hi, pts.back());
      }
      targets_.push_back(
          {root_node.value("name", ""), geom::Polytope::fromPoints(pts).value(), lo, hi});
    }
    caches_.resize(targets_.size());
  }

  /// Smallest signed distance (negative: minus the penetration depth) from the held body at
  /// X_WP to each body, by name; bodies farther than `reach` in bounding boxes are skipped.
  std::map<std::string, double> distances(const geom::Pose& X_WP, double reach) {
    std::map<std::string, double> out;
    const geom::Transform X = X_WP.toTransform();
    Vec3 plo{1e300}, phi{-1e300};
    for (const auto& v : probe_->vertices()) {
      const Vec3 p = X.apply(v.p);
      plo = glm::min(plo, p);
      phi = glm::max(phi, p);
    }
    for (std::size_t k = 0; k < targets_.size(); ++k) {
      const Target& t = targets_[k];
      if (glm::any(glm::greaterThan(t.lo - phi, Vec3{reach})) ||
          glm::any(glm::greaterThan(plo - t.hi, Vec3{reach})))
        continue;
      const double d = collision::queryPair(t.hull, *probe_, X, caches_[k]).distance;
      auto [it, fresh] = out.emplace(t.body, d);
      if (!fresh)
        it->second = std::min(it->second, d);
    }
    return out;
  }

 private:
  Glb glb_;
  std::unique_ptr<geom::Polytope> probe_;
  std::vector<Target> targets_;
  std::vector<collision::PairCache> caches_;
};

double get(const std::map<std::string, double>& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? 1e300 : it->second;
}

/// Per body: the smallest distance over the rows with t in [t0, t1].
std::map<std::string, double> closest(SceneHulls& hulls,
                                      const std::vector<Row>& r,
                                      double t0,
                                      double t1,
                                      double reach) {
  std::map<std::string, double> out;
  for (const Row& row : r) {
    if (row.t < t0 || row.t > t1)
      continue;
    for (const auto& [body, d] : hulls.distances(row.X_WP, reach)) {
      auto [it, fresh] = out.emplace(body, d);
      if (!fresh)
        it->second = std::min(it->second, d);
    }
  }
  return out;
}

TEST(StreamContacts, PegTouchesWhileWobblingJamsAndPressesTheFloor) {
  SceneHulls hulls("peg_in_hole");
  const std::vector<Row> r = rows("peg_in_hole");
  const double approach = get(closest(hulls, r, 0.0, 2.9, 0.1), "Hole");
  const double wobble = get(closest(hulls, r, 3.0, 6.0, 0.1), "Hole");
  const double jam = get(closest(hulls, r, 7.5, 8.5, 0.1), "Hole");
  const double push = get(closest(hulls, r, 10.0, 11.0, 0.1), "Hole");
  const double end = get(closest(hulls, r, 14.0, 15.0, 0.1), "Hole");
  std::printf(
      "peg vs hole: approach %.3f mm, wobble %.3f mm, jam %.3f mm, push %.3f mm, end "
      "%.3f mm (negative: into the hole's parts)\n",
      approach * 1e3, wobble * 1e3, jam * 1e3, push * 1e3, end * 1e3);
  EXPECT_GT(approach, 0.001);  // clear of the hole while approaching
  EXPECT_LT(wobble, 0.0);      // the wobble reaches the walls
  EXPECT_GT(wobble, -0.001);   // ...lightly
  EXPECT_LT(jam, -0.0005);     // jammed: the tilted target is well into two walls
  EXPECT_NEAR(push, -0.002, 1e-5 * peg::kPegSide_m);  // 2 mm into the floor, straight
  EXPECT_GT(end, 0.01);
}

TEST(StreamContacts, GearRodSitsInTheGapThenPushesATeethEachWay) {
  SceneHulls hulls("gears");
  const std::vector<Row> r = rows("gears");
  const auto in_gap = closest(hulls, r, 3.0, 4.0, 0.2);
  const auto clockwise = closest(hulls, r, 6.5, 7.5, 0.2);
  const auto back = closest(hulls, r, 12.5, 13.5, 0.2);
  const auto all = closest(hulls, r, 0.0, 16.0, 0.2);
  std::printf(
      "rod vs gear A: in the gap %.3f mm, end of the clockwise push %.3f mm, end of the "
      "push back %.3f mm; closest to gear B ever %.3f mm\n",
      get(in_gap, "GearA") * 1e3, get(clockwise, "GearA") * 1e3, get(back, "GearA") * 1e3,
      get(all, "GearB") * 1e3);
  EXPECT_GT(get(in_gap, "GearA"), 0.0);  // between two teeth, touching neither
  // were gear A held still, the targets would be deep in a tooth: the stream turns the gear
  EXPECT_LT(get(clockwise, "GearA"), -0.002);
  EXPECT_LT(get(back, "GearA"), -0.002);
  EXPECT_GT(get(all, "GearB"), 0.0);  // the rod only ever touches gear A
}

TEST(StreamContacts, StickReachesEachObjectInTurnAndNeverTheFloor) {
  SceneHulls hulls("dynamic");
  const std::vector<Row> r = rows("dynamic");
  const auto all = closest(hulls, r, 0.0, 19.5, 0.05);
  const double push = get(closest(hulls, r, 2.5, 4.5, 0.05), "Cube0");
  const double strike = get(closest(hulls, r, 7.5, 7.8, 0.05), "Sphere3");
  // on its way to the strike it passes high over Sphere3 (its end 45 mm over its top) and comes
  // down beside it: nothing touches Sphere3 before the strike
  const double before_strike = get(closest(hulls, r, 4.5, 7.5, 0.05), "Sphere3");
  const double press = get(closest(hulls, r, 11.5, 12.5, 0.05), "Ellipsoid1");
  double grab = 1e300;
  for (const Row& row : r)
    if (row.buttons & 1u)
      grab = std::min(grab, get(hulls.distances(row.X_WP, 0.05), "Cube2"));
  std::printf(
      "stick: into Cube0 %.1f mm (push), Sphere3 %.1f mm (strike; before it never nearer than "
      "%.1f mm), Ellipsoid1 %.1f mm (press); Cube2 at the grab %.3f mm; floor never nearer than "
      "%.1f mm\n",
      -push * 1e3, -strike * 1e3, before_strike * 1e3, -press * 1e3, grab * 1e3,
      get(all, "Floor") * 1e3);
  EXPECT_LT(push, -0.01);
  EXPECT_LT(strike, -0.01);
  EXPECT_LT(press, -0.001);
  EXPECT_GT(before_strike, 0.01);
  // the grab starts on the cube's top as it rests on the floor: 1 mm (kDropGap_m) into it where
  // it starts
  EXPECT_NEAR(grab, -dynamic::kDropGap_m, 1e-5);
  EXPECT_GT(get(all, "Floor"), 0.0);
}

TEST(StreamContacts, SweeperRidesOnThePillarTopsAndHitsTheBlocks) {
  SceneHulls hulls("stress");
  const std::vector<Row> r = rows("stress");
  std::size_t touching_rows = 0, rows_near_pillars = 0;
  double deepest = 0.0;
  std::set<std::string> blocks_hit;
  for (const Row& row : r) {
    const auto d = hulls.distances(row.X_WP, 0.01);
    const double field = get(d, "Field");
    if (field < 1e300)
      ++rows_near_pillars;
    if (field <= 0.0)
      ++touching_rows;
    deepest = std::min(deepest, field);
    for (const auto& [body, dist] : d)
      if (body.rfind("Block", 0) == 0 && dist < 0.0)
        blocks_hit.insert(body);
  }
  std::printf(
      "sweeper: %zu of %zu rows into pillar tops (deepest %.3f mm), %zu near pillars; "
      "%zu blocks hit\n",
      touching_rows, r.size(), -deepest * 1e3, rows_near_pillars, blocks_hit.size());
  EXPECT_GT(touching_rows, r.size() / 4);
  EXPECT_LT(deepest, -0.0005);
  EXPECT_GT(deepest, -0.0015);        // it rides on the tops, never ploughs through a pillar
  EXPECT_EQ(blocks_hit.size(), 16u);  // every block: four on each of four passes
}

}  // namespace
}  // namespace hapticd::scenes
