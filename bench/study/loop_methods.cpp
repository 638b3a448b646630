// Methods inside the closed loop (bench/study/loop_methods.h): each answers every pair query of
// the tick in place of collision::queryPair, so that the force the hand would feel is the
// method's, tick after tick, proxy and all.
#include "bench/study/loop_methods.h"

#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "bench/peers.h"
#include "core/collision/pair_query.h"
#include "core/collision/penetration.h"

namespace hapticd::study {
namespace {

using geom::Polytope;
using geom::Transform;
using geom::Vec3;

// The paper's estimate (§4.1, "the penetration depth along the direction of the motion"): the
// tick's own query, and when the pair overlaps, the translation along the line of B's motion
// since the pair's last test (relative to A) that frees it, in the shorter of the two senses,
// instead of the minimal one: the projection of the two hulls on that line, as the pair part's
// `hapticd-depth-along-motion` (bench/study/pairs_study.cpp). One contact point (midway between
// the two support vertices), no face manifold. With no motion to follow (the pair's first test,
// or B not moved relative to A since), the minimal depth.
class AlongMotion final : public LoopQuery {
 public:
  void query(const Polytope& a,
             const Polytope& b,
             const Transform& X_AB,
             const Transform* X_AB_last,
             collision::PairCache& cache,
             collision::PairResult& out) override {
    out = collision::queryPair(a, b, X_AB, cache);
    if (out.status != collision::ContactStatus::kPenetrating || X_AB_last == nullptr)
      return;
    const Vec3 motion = X_AB.t - X_AB_last->t;
    const double length = glm::length(motion);
    if (!(length > 0.0))
      return;
    const Vec3 m = motion / length;
    std::uint32_t ha = 0, hb = 0, ha2 = 0, hb2 = 0;
    const double back = collision::depthAlong(a, b, X_AB, -m, ha, hb);
    const double ahead = collision::depthAlong(a, b, X_AB, m, ha2, hb2);
    const bool forward = ahead < back;
    out.normal = forward ? m : -m;
    out.distance = -std::min(back, ahead);
    out.point_a = a.vertices()[forward ? ha2 : ha].p;
    out.point_b = X_AB.apply(b.vertices()[forward ? hb2 : hb].p);
    out.fa = collision::Feature{};
    out.fb = collision::Feature{};
    out.manifold.count = 0;
    out.manifold.truncated = false;
  }
};

// A peer library's set of methods (a distance method for pairs apart, a depth method for
// overlapping ones, or one that answers both), made per pair of shapes the first time the pair
// is asked: the first of the set that answers, in our conventions (bench/peers.h). Its one
// contact point is the library's (midway between its witnesses), with no face manifold, as the
// library gives it. No answer (a distance method only, on overlapping shapes): as far apart.
class PeerLoop final : public LoopQuery {
 public:
  explicit PeerLoop(std::vector<std::string> methods) : methods_(std::move(methods)) {}

  void query(const Polytope& a,
             const Polytope& b,
             const Transform& X_AB,
             const Transform* /*X_AB_last*/,
             collision::PairCache& cache,
             collision::PairResult& out) override {
    auto& set = peers_[{&a, &b}];
    if (set.empty()) {
      for (const std::string& name : methods_)
        set.push_back(bench::makePeer(name, a, b));
    }
    bench::PeerAnswer p;
    for (auto& method : set) {
      p = method->answer(X_AB);
      if (p.ok && std::isfinite(p.distance) && std::isfinite(p.normal.x) &&
          std::isfinite(p.normal.y) && std::isfinite(p.normal.z)) {
        break;
      }
      p.ok = false;
    }
    farApart(out, cache);
    if (!p.ok) {
      ++unanswered;
      return;
    }
    out.status = p.distance > 0.0 ? collision::ContactStatus::kSeparated
                                  : collision::ContactStatus::kPenetrating;
    out.distance = p.distance;
    out.normal = p.normal;
    // the witnesses either side of the midpoint, the distance apart along the normal
    out.point_a = p.point - 0.5 * p.distance * p.normal;
    out.point_b = p.point + 0.5 * p.distance * p.normal;
    cache.penetrating = p.distance <= 0.0;
  }

 private:
  std::vector<std::string> methods_;
  std::map<std::pair<const Polytope*, const Polytope*>,
           std::vector<std::unique_ptr<bench::PeerMethod>>>
      peers_;
};

}  // namespace

std::vector<LoopMethod> loopMethods() {
  std::vector<LoopMethod> out;
  out.push_back({"hapticd-depth-along-motion", [] { return std::make_unique<AlongMotion>(); }});
  const std::vector<std::pair<std::string, std::vector<std::string>>> peers = {
      {"FCL-libccd", {"FCL-GJK-libccd", "FCL-GJK-EPA-libccd"}},
      {"Bullet-btGjkPairDetector", {"Bullet-btGjkPairDetector"}},
      {"Bullet-btGjkEpaSolver2", {"Bullet-btGjkEpaSolver2", "Bullet-btGjkEpaSolver2-Penetration"}},
  };
  for (const auto& [name, methods] : peers) {
    out.push_back({name, [methods = methods]() -> std::unique_ptr<LoopQuery> {
                     return std::make_unique<PeerLoop>(methods);
                   }});
  }
  return out;
}

}  // namespace hapticd::study
