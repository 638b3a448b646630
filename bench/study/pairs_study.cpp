// The pair part of the accuracy study: two convex hulls near contact on coherent paths, every
// method's signed distance, normal and contact point turned into the same penalty force and
// torque, against a ground truth.
//
// The force model, for every method alike: F = k_s (δ − d) n on B at the contact point p when
// d < δ (d the signed distance, n from A toward B), T = (p − c_B) × F about B's centroid; k_s =
// 600 N/m (§5.1), δ = 0.1 mm (v_c Δt for 0.1 m/s at 1 kHz). The voxel method makes its own force
// (McNeely's Σ k dᵢ nᵢ), its one stiffness fitted by least squares on separate calibration paths.
//
// The ground truth is our exact query with a cold cache and the separating-axis depth
// (penetrationDepthExact, not the EPA the tracked query uses), its signed distance checked at
// every configuration against the brute-force reference of tests/reference/.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "bench/peers.h"
#include "bench/study/study.h"
#include "core/collision/pair_query.h"
#include "core/voxel/voxel_sampling.h"
#include "tests/reference/reference.h"

namespace hapticd::study {
namespace {

using collision::PairCache;
using geom::Polytope;
using geom::Pose;
using geom::Quat;
using geom::Transform;
using geom::Vec3;

constexpr double kStiffness = 600.0;  // N/m
constexpr double kDelta = 1e-4;       // m

struct Answer {
  bool ok = false;
  double distance = 0.0;
  Vec3 normal{0.0}, point{0.0};
};

struct Wrench {
  Vec3 f{0.0}, t{0.0};
  bool contact() const { return glm::dot(f, f) > 0.0; }
};

Wrench penalty(const Answer& a, const Vec3& c_B) {
  Wrench w;
  if (!a.ok || !(a.distance < kDelta))
    return w;
  w.f = a.normal * (kStiffness * (kDelta - a.distance));
  w.t = glm::cross(a.point - c_B, w.f);
  return w;
}

Answer fromPair(const collision::PairResult& r) {
  return {true, r.distance, r.normal, 0.5 * (r.point_a + r.point_b)};
}

Polytope ellipsoidHull(std::size_t n, std::uint64_t seed) {
  auto pts = reference::ellipsoidPoints(n, 0.025, 0.018, 0.012, seed);
  const Vec3 c = Polytope::fromPoints(pts).value().centroid();
  for (Vec3& p : pts)
    p -= c;
  return Polytope::fromPoints(pts).value();
}

// The ground truth: cold closest features, the separating-axis depth when they overlap.
Answer truthAnswer(const Polytope& a, const Polytope& b, const Transform& X_AB) {
  collision::FeatureCache fc;
  const auto c = collision::closestFeatures(a, b, X_AB, fc);
  if (c.status != collision::ContactStatus::kPenetrating) {
    return {true, c.distance, c.normal, 0.5 * (c.point_a + c.point_b)};
  }
  collision::DepthCache dc;
  const auto d = collision::penetrationDepthExact(a, b, X_AB, dc);
  return {true, -d.depth, d.normal, 0.5 * (d.point_a + d.point_b)};
}

// A path of B near A: its centre swings 1.5 mm in and out about a start at signed distance
// `target` along u while drifting sideways 0.02 mm and turning 0.1 degree per step.
std::vector<Transform> path(const Polytope& a, const Polytope& b, std::mt19937_64& rng, int steps) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  const Vec3 u = glm::normalize(Vec3{g(rng), g(rng), g(rng)});
  Vec3 w = glm::cross(u, Vec3{g(rng), g(rng), g(rng)});
  w = glm::normalize(w);
  const Vec3 axis = glm::normalize(Vec3{g(rng), g(rng), g(rng)});
  const Quat q0 = reference::randomRotation(rng);
  const double target = -1.5e-3 + 2.0e-3 * uni(rng);  // -1.5 mm .. +0.5 mm
  // the centre distance giving `target` at the start, by bisection on the truth
  double lo = 0.0, hi = 0.2;
  for (int i = 0; i < 60; ++i) {
    const double r = 0.5 * (lo + hi);
    const Transform X = Pose{u * r, q0}.toTransform();
    (truthAnswer(a, b, X).distance < target ? lo : hi) = r;
  }
  const double r0 = 0.5 * (lo + hi);
  const double phase = 2.0 * M_PI * uni(rng);
  std::vector<Transform> out;
  for (int k = 0; k < steps; ++k) {
    const double s = 1.5e-3 * std::sin(phase + 2.0 * M_PI * k / steps);
    const Quat q = glm::angleAxis(k * 0.1 * M_PI / 180.0, axis) * q0;
    out.push_back(Pose{u * (r0 + s) + w * (0.02e-3 * k), q}.toTransform());
  }
  return out;
}

double nowNs() {
  return static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                 std::chrono::steady_clock::now().time_since_epoch())
                                 .count());
}

void score(Row& row, const Wrench& truth, const Wrench& got, bool answered, double ns) {
  row.add(glm::length(got.f - truth.f), glm::length(got.t - truth.t), ns, truth.contact(),
          got.contact());
  if (!answered)
    ++row.no_answer;
}

struct Voxel {
  double h = 0.0;
  voxel::VoxelMap map;
  voxel::PointShell shell;
  double k = 0.0;  // fitted stiffness per point
};

}  // namespace

void runPairs(const Options& options, std::vector<Row>& rows) {
  const int paths = options.quick ? 6 : 30;
  const int steps = options.quick ? 40 : 100;
  const double overhead = timerOverheadNs();
  std::vector<double> voxel_sizes = {2e-3, 1e-3, 0.5e-3};
  if (!options.quick)
    voxel_sizes.push_back(0.25e-3);
  for (const std::size_t n : {std::size_t{8}, std::size_t{32}, std::size_t{128}}) {
    const std::string part = "pairs/" + std::to_string(n);
    std::fprintf(stderr, "study: %s: %d paths of %d steps\n", part.c_str(), paths, steps);
    const Polytope a = ellipsoidHull(n, 1), b = ellipsoidHull(n, 2);
    const double size = std::max(a.radius(), b.radius());
    std::mt19937_64 rng(options.seed + n);
    std::vector<std::vector<Transform>> all;
    for (int i = 0; i < paths; ++i)
      all.push_back(path(a, b, rng, steps));
    std::mt19937_64 cal_rng(options.seed + 1000 + n);
    std::vector<std::vector<Transform>> calibration;
    for (int i = 0; i < std::max(2, paths / 5); ++i)
      calibration.push_back(path(a, b, cal_rng, steps));

    // the truth, checked against brute force
    std::vector<std::vector<Wrench>> truth(all.size());
    std::uint64_t truth_mismatch = 0;
    // the long-double brute force costs about 0.2 s a configuration at 128 points: there, every
    // 10th configuration is checked
    const std::size_t check_every = n >= 128 ? 10 : 1;
    std::uint64_t checked = 0;
    for (std::size_t i = 0; i < all.size(); ++i) {
      for (std::size_t k = 0; k < all[i].size(); ++k) {
        const Transform& X = all[i][k];
        const Answer t = truthAnswer(a, b, X);
        if ((i * all[i].size() + k) % check_every == 0) {
          const auto ref = reference::bruteForce(a, b, X);
          if (std::abs(ref.signed_distance - t.distance) > 1e-9 * size)
            ++truth_mismatch;
          ++checked;
        }
        truth[i].push_back(penalty(t, X.t));
      }
    }
    std::fprintf(stderr,
                 "study: %s: the truth checked against brute force at %llu configurations\n",
                 part.c_str(), static_cast<unsigned long long>(checked));
    if (truth_mismatch != 0) {
      std::fprintf(stderr, "study: %s: the truth differs from brute force at %llu configurations\n",
                   part.c_str(), static_cast<unsigned long long>(truth_mismatch));
    }

    // ours, warm-started along each path (what the servo loop does) and cold
    for (const bool warm : {true, false}) {
      Row row{
          part, warm ? "hapticd-exact-warm" : "hapticd-exact-cold", "", {}, {}, {}, 0, 0, 0, 0, {},
          {}};
      for (std::size_t i = 0; i < all.size(); ++i) {
        PairCache cache;
        for (std::size_t k = 0; k < all[i].size(); ++k) {
          if (!warm)
            cache = PairCache{};
          const double t0 = nowNs();
          const auto r = collision::queryPair(a, b, all[i][k], cache);
          const double ns = nowNs() - t0 - overhead;
          score(row, truth[i][k], penalty(fromPair(r), all[i][k].t), true, ns);
        }
      }
      rows.push_back(std::move(row));
    }

    // ours, the depth along the direction of motion instead of the minimal one (§4.1)
    {
      Row row{part, "hapticd-depth-along-motion", "", {}, {}, {}, 0, 0, 0, 0, {}, {}};
      for (std::size_t i = 0; i < all.size(); ++i) {
        PairCache cache;
        std::uint32_t ha = 0, hb = 0;
        for (std::size_t k = 0; k < all[i].size(); ++k) {
          const Transform& X = all[i][k];
          const double t0 = nowNs();
          collision::FeatureCache& fc = cache.features;
          const auto c = collision::closestFeatures(a, b, X, fc);
          Answer ans{true, c.distance, c.normal, 0.5 * (c.point_a + c.point_b)};
          if (c.status == collision::ContactStatus::kPenetrating) {
            // the depth along the line of B's motion over the last step, in the sense that
            // frees B sooner (back the way it came, or on the way it goes)
            const Vec3 motion = k > 0 ? X.t - all[i][k - 1].t : -X.t;
            const Vec3 m = glm::length(motion) > 0.0 ? glm::normalize(motion) : Vec3{1, 0, 0};
            std::uint32_t ha2 = ha, hb2 = hb;
            const double back = collision::depthAlong(a, b, X, -m, ha, hb);
            const double ahead = collision::depthAlong(a, b, X, m, ha2, hb2);
            const bool fwd = ahead < back;
            const Vec3 dir = fwd ? m : -m;
            const std::uint32_t sa = fwd ? ha2 : ha, sb = fwd ? hb2 : hb;
            const Vec3 pa = a.vertices()[sa].p, pb = X.apply(b.vertices()[sb].p);
            ans = {true, -std::min(back, ahead), dir, 0.5 * (pa + pb)};
          }
          const double ns = nowNs() - t0 - overhead;
          score(row, truth[i][k], penalty(ans, X.t), true, ns);
        }
      }
      rows.push_back(std::move(row));
    }

    // the peers: each answers what it can (distance methods apart, depth methods overlapping);
    // a pair is answered by the library's distance and depth method together where it has both
    struct PeerSet {
      std::string name;
      std::vector<std::string> methods;
    };
    const std::vector<PeerSet> peers = {
        {"libccd-GJK-EPA", {"libccd-GJK-EPA"}},
        {"libccd-MPR", {"libccd-MPR"}},
        {"FCL-libccd", {"FCL-GJK-libccd", "FCL-GJK-EPA-libccd"}},
        {"Bullet-btGjkPairDetector", {"Bullet-btGjkPairDetector"}},
        {"Bullet-btGjkEpaSolver2",
         {"Bullet-btGjkEpaSolver2", "Bullet-btGjkEpaSolver2-Penetration"}},
    };
    for (const auto& set : peers) {
      std::vector<std::unique_ptr<bench::PeerMethod>> methods;
      for (const auto& m : set.methods)
        methods.push_back(bench::makePeer(m, a, b));
      Row row{part, set.name, "", {}, {}, {}, 0, 0, 0, 0, {}, {}};
      for (std::size_t i = 0; i < all.size(); ++i) {
        for (std::size_t k = 0; k < all[i].size(); ++k) {
          const Transform& X = all[i][k];
          const double t0 = nowNs();
          bench::PeerAnswer p;
          for (auto& m : methods) {
            p = m->answer(X);
            if (p.ok)
              break;
          }
          const double ns = nowNs() - t0 - overhead;
          const bool finite = std::isfinite(p.distance) && std::isfinite(p.normal.x) &&
                              std::isfinite(p.normal.y) && std::isfinite(p.normal.z);
          const Answer ans{p.ok && finite, p.distance, p.normal, p.point};
          // libccd answers only overlapping pairs: apart, "no answer" means no force, which is
          // right when the gap exceeds δ
          score(row, truth[i][k], penalty(ans, X.t), ans.ok, ns);
        }
      }
      rows.push_back(std::move(row));
    }

    // voxel sampling at several resolutions, A voxelised, B a point shell
    for (const double h : voxel_sizes) {
      Voxel v;
      v.h = h;
      const voxel::PlacedShape pa{&a, Transform{}};
      auto map = voxel::VoxelMap::build(std::span<const voxel::PlacedShape>(&pa, 1), h);
      const voxel::PlacedShape pb{&b, Transform{}};
      auto shell = voxel::makePointShell(std::span<const voxel::PlacedShape>(&pb, 1), h);
      if (!map.ok() || !shell.ok()) {
        std::fprintf(stderr, "study: voxel h=%g: %s\n", h,
                     (!map.ok() ? map.error() : shell.error()).message.c_str());
        continue;
      }
      v.map = std::move(map).value();
      v.shell = std::move(shell).value();
      // the stiffness per point that best fits the truth's forces on the calibration paths
      double num = 0.0, den = 0.0;
      for (const auto& p : calibration) {
        for (const Transform& X : p) {
          const auto unit = voxel::force(v.map, v.shell, X, X.t, 1.0);
          const Wrench t = penalty(truthAnswer(a, b, X), X.t);
          num += glm::dot(unit.force_W, t.f);
          den += glm::dot(unit.force_W, unit.force_W);
        }
      }
      v.k = den > 0.0 ? num / den : 0.0;
      char setting[64];
      std::snprintf(setting, sizeof setting, "h=%gmm", h * 1e3);
      Row row{part, "voxel-McNeely", setting, {}, {}, {}, 0, 0, 0, 0, {}, {}};
      for (std::size_t i = 0; i < all.size(); ++i) {
        for (std::size_t k = 0; k < all[i].size(); ++k) {
          const Transform& X = all[i][k];
          const double t0 = nowNs();
          const auto f = voxel::force(v.map, v.shell, X, X.t, v.k);
          const double ns = nowNs() - t0 - overhead;
          score(row, truth[i][k], Wrench{f.force_W, f.torque_W}, true, ns);
        }
      }
      std::fprintf(
          stderr, "study: %s: voxel h=%g mm: %llu voxels, %zu shell points, k=%.3g N/m per point\n",
          part.c_str(), h * 1e3, static_cast<unsigned long long>(v.map.voxelCount()),
          v.shell.p_B.size(), v.k);
      rows.push_back(std::move(row));
    }
  }
}

}  // namespace hapticd::study
