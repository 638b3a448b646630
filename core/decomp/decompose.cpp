#include "core/decomp/decompose.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <numbers>
#include <optional>
#include <thread>

#include "core/decomp/bvh.h"
#include "core/decomp/cut.h"
#include "core/decomp/measure.h"
#include "core/decomp/quickhull.h"
#include "core/decomp/repair.h"
#include "core/decomp/sha256.h"
#include "core/decomp/union_integrals.h"
#include "core/geometry/polytope.h"

namespace hapticd::decomp {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Fixed tuning of the search (relative to the concavity bound c or the diagonal).
constexpr std::size_t kSamplePoints = 2500;      // hull points a candidate cut is scored with
constexpr std::size_t kSearchEvaluations = 500;  // distance queries per scored hull
constexpr std::size_t kLeafEvaluations = 40000;  // per piece's own measure
constexpr std::size_t kSearchHullVertices = 256;
constexpr double kHullTolerance = 0.1;     // of c: points this close to a hull are dropped
constexpr double kSearchTolerance = 0.1;   // of c: branch-and-bound slack when scoring cuts
constexpr double kSearchResolution = 0.5;  // of c: smallest triangle radius when scoring cuts
constexpr double kLeafTolerance = 0.05;    // of c: slack of a piece's own measure
constexpr double kLeafResolution = 0.1;    // of c: and its resolution (docs/decomposition.md)
constexpr double kFloor = 0.25;            // of c: excess below this is not resolved further
constexpr double kStuck = 0.85;  // a best cut above this share of the part's concavity: look ahead
constexpr double kTie = 0.05;    // of c: search scores this close are equal
constexpr std::size_t kMergeRounds = 8;  // merge passes at the piece cap before giving up
constexpr double kFocusRadius = 1.5;     // of the part's concavity (+ c): the worst pocket's reach

struct Context {
  RepairedMesh mesh;
  std::unique_ptr<TriangleBvh> bvh;
  ModelView view;
  double c_abs = 0.0;
  double eps = 0.0;  // points this close to a plane are on it
  std::size_t max_piece_vertices = 256;
  unsigned threads = 1;
};

struct Part {
  Polygons polys;            // the model's surface inside the cell
  Cell cell;                 // the convex cell (empty after a merge)
  std::vector<Vec3> inside;  // cell vertices inside the model
  std::vector<Vec3> points;  // hull input: polygon vertices and `inside`, sorted, unique
  std::vector<Vec3> sample;  // at most kSamplePoints of them, for scoring cuts
  HullMesh hull;
  ExcessBound excess;
  double concavity = 0.0;  // max(excess.lower, coverage), absolute
  bool final = false;      // cannot or need not be cut further
};

// runs fn(i) for i in [0, n) on `threads` threads; thread t takes i = t, t + T, ... (fixed split)
template <class Fn>
void parallelFor(std::size_t n, unsigned threads, const Fn& fn) {
  const unsigned t_count = static_cast<unsigned>(std::min<std::size_t>(threads, n));
  if (t_count <= 1) {
    for (std::size_t i = 0; i < n; ++i)
      fn(i);
    return;
  }
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < t_count; ++t)
    pool.emplace_back([&, t] {
      for (std::size_t i = t; i < n; i += t_count)
        fn(i);
    });
  for (std::size_t i = 0; i < n; i += t_count)
    fn(i);
  for (std::thread& th : pool)
    th.join();
}

// a fixed pseudo-random permutation key of an index (splitmix64's finaliser)
std::uint64_t mixIndex(std::uint64_t i) {
  std::uint64_t h = i + 0x9E3779B97F4A7C15ull;
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
  return h ^ (h >> 31);
}

// a deterministic pseudo-random subset of at most k points (by index, so the same at any scale),
// plus the extremes along 13 directions
std::vector<Vec3> subsample(const std::vector<Vec3>& pts, std::size_t k) {
  if (pts.size() <= k)
    return pts;
  static constexpr double kDirs[13][3] = {{1, 0, 0},  {0, 1, 0},  {0, 0, 1}, {1, 1, 0},  {1, -1, 0},
                                          {1, 0, 1},  {1, 0, -1}, {0, 1, 1}, {0, 1, -1}, {1, 1, 1},
                                          {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}};
  std::vector<std::uint32_t> keep;
  for (const auto& d : kDirs) {
    const Vec3 dir{d[0], d[1], d[2]};
    std::uint32_t lo = 0, hi = 0;
    for (std::uint32_t i = 0; i < pts.size(); ++i) {
      if (glm::dot(pts[i], dir) < glm::dot(pts[lo], dir))
        lo = i;
      if (glm::dot(pts[i], dir) > glm::dot(pts[hi], dir))
        hi = i;
    }
    keep.push_back(lo);
    keep.push_back(hi);
  }
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(pts.size());
  for (std::uint32_t i = 0; i < pts.size(); ++i)
    keyed[i] = {mixIndex(i), i};
  std::nth_element(keyed.begin(), keyed.begin() + static_cast<std::ptrdiff_t>(k), keyed.end());
  for (std::size_t i = 0; i < k; ++i)
    keep.push_back(keyed[i].second);
  std::sort(keep.begin(), keep.end());
  keep.erase(std::unique(keep.begin(), keep.end()), keep.end());
  std::vector<Vec3> out;
  out.reserve(keep.size());
  for (std::uint32_t i : keep)
    out.push_back(pts[i]);
  return out;
}

// points that span a plane or a line get copies pushed off it, so that the hull has volume
std::vector<Vec3> thicken(const std::vector<Vec3>& pts, double eps) {
  std::vector<Vec3> out = pts;
  if (pts.empty())
    return out;
  Vec3 lo = pts[0], hi = pts[0];
  for (const Vec3& p : pts)
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  Vec3 n{0.0};
  // the normal of the plane through the first point and the two that span most
  std::size_t i1 = 0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (glm::length(pts[i] - pts[0]) > glm::length(pts[i1] - pts[0]))
      i1 = i;
  double best = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Vec3 c = glm::cross(pts[i1] - pts[0], pts[i] - pts[0]);
    if (glm::length(c) > best)
      best = glm::length(c), n = c;
  }
  std::vector<Vec3> dirs;
  if (best > 0.0) {
    dirs.push_back(glm::normalize(n));
  } else {
    const Vec3 axis =
        glm::length(pts[i1] - pts[0]) > 0.0 ? glm::normalize(pts[i1] - pts[0]) : Vec3{1, 0, 0};
    const Vec3 helper = std::abs(axis.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    dirs.push_back(glm::normalize(glm::cross(axis, helper)));
    dirs.push_back(glm::cross(axis, dirs[0]));
    if (glm::length(pts[i1] - pts[0]) == 0.0)
      dirs.push_back(axis);
  }
  for (const Vec3& d : dirs)
    for (const Vec3& p : pts)
      out.push_back(p + d * eps), out.push_back(p - d * eps);
  return out;
}

// the hull, or for points thinner than the tolerance the exact hull, or for flat points the hull
// of a slab 2e-6 of the diagonal thick
HullMesh hullOf(const Context& ctx, const std::vector<Vec3>& pts, double tol, std::size_t max_v) {
  HullMesh h = quickHull(pts, tol, max_v);
  if (h.valid() || pts.empty())
    return h;
  h = quickHull(pts, 0.0, max_v);
  if (h.valid())
    return h;
  return quickHull(thicken(pts, 1e-6 * ctx.mesh.diagonal), 0.0, max_v);
}

// the measure's options: tolerance and resolution as fractions of the bound
ExcessOptions excessOptions(const Context& ctx,
                            double tolerance,
                            double resolution,
                            std::size_t evaluations,
                            double bound) {
  ExcessOptions o;
  o.tolerance = tolerance * ctx.c_abs;
  o.resolution = resolution * ctx.c_abs;
  o.floor = kFloor * ctx.c_abs;
  o.max_evaluations = evaluations;
  o.stop_above = bound;
  return o;
}

// the hull of the part's points, its measure and its concavity (the boundary excess and the
// hull's own coverage); infinite when the excess passes `bound`
void measurePart(const Context& ctx, Part& part, double bound) {
  sortUnique(part.points);
  const double tol = kHullTolerance * ctx.c_abs;
  part.hull = hullOf(ctx, part.points, tol, ctx.max_piece_vertices);
  const ExcessOptions o =
      excessOptions(ctx, kLeafTolerance, kLeafResolution, kLeafEvaluations, bound);
  part.excess = hullExcess(ctx.view, part.hull, o);
  part.concavity =
      part.excess.aborted ? kInf : std::max({part.excess.lower, part.hull.max_outside, tol});
}

// a new part: measured, and sampled for scoring its cuts
void finishPart(const Context& ctx, Part& part) {
  measurePart(ctx, part, kInf);
  part.sample = subsample(part.points, kSamplePoints);
}

// the inside vertices of the new face of `cell` on `plane`
std::vector<Vec3> insideSection(const Context& ctx, const Cell& cell, const Plane& plane) {
  std::vector<Vec3> out;
  for (const Vec3& v : cellSection(cell, plane))
    if (ctx.bvh->inside(v))
      out.push_back(v);
  return out;
}

// the hull input of each side of `plane`: the part's sample strictly off the plane, the section of
// its surface and of its cell inside the model, and the polygons lying in the plane (by facing);
// false when a side would be empty
bool sidePoints(const Context& ctx,
                const Part& part,
                const Plane& plane,
                std::array<std::vector<Vec3>, 2>& side) {
  const double eps = ctx.eps;
  for (const Vec3& p : part.sample) {
    const double s = plane.signedDistance(p);
    if (s < -eps)
      side[0].push_back(p);
    if (s > eps)
      side[1].push_back(p);
  }
  std::vector<Vec3> section;
  std::array<std::vector<Vec3>, 2> on;
  sectionPoints(part.polys, plane, eps, section, on[0], on[1]);
  sortUnique(section);
  if (section.size() > kSamplePoints / 2)
    section = subsample(section, kSamplePoints / 2);
  for (std::size_t k = 0; k < 2; ++k) {
    sortUnique(on[k]);
    if (on[k].size() > kSamplePoints / 2)
      on[k] = subsample(on[k], kSamplePoints / 2);
    side[k].insert(side[k].end(), on[k].begin(), on[k].end());
  }
  if (side[0].empty() || side[1].empty())
    return false;
  if (side[0].size() + section.size() < 4 || side[1].size() + section.size() < 4)
    return false;
  for (const Vec3& v : insideSection(ctx, part.cell, plane))
    section.push_back(v);
  for (const Vec3& v : part.inside) {
    const double s = plane.signedDistance(v);
    if (s <= eps)
      side[0].push_back(v);
    if (s >= -eps)
      side[1].push_back(v);
  }
  for (auto& pts : side)
    pts.insert(pts.end(), section.begin(), section.end());
  return true;
}

// How good a cut (or a cross of two) is for the part being cut, smaller is better: the largest
// excess of the new hulls, then the sum of their excesses; for a cross, the largest excess near the
// part's worst point (does it open the worst pocket?).
struct Score {
  double cost = kInf;
  double sum = kInf;
  double local = kInf;
  bool valid = false;
};

// the search's measure of one new hull: near the focus (kind 0) or anywhere (kind 1); infinite when
// above `bound`
double searchExcess(const Context& ctx,
                    const HullMesh& hull,
                    const Part& part,
                    int kind,
                    double bound) {
  if (!hull.valid())
    return 0.0;  // no points (hullOf gives a flat half the slab its piece would be)
  ExcessOptions o =
      excessOptions(ctx, kSearchTolerance, kSearchResolution, kSearchEvaluations, bound);
  if (kind == 0) {
    o.focus = part.excess.worst_q;
    o.focus_radius = kFocusRadius * part.concavity + ctx.c_abs;
  }
  const ExcessBound e = hullExcess(ctx.view, hull, o);
  if (e.aborted)
    return kInf;
  return e.upper;
}

// The new hulls of a cut (two) or of a cross (up to four), from the search's sample.
struct Trial {
  std::vector<HullMesh> hulls;
  bool valid = false;
};

// (a half's hull as its piece's would be, by hullOf: a flat half, an open sheet closed into a shell
// of no volume, has no hull at the search's tolerance, and scored as "no excess" every cut of a
// flat part tied at 0, so the first candidate was taken whatever it did)
Trial cutTrial(const Context& ctx, const Part& part, const Plane& plane) {
  Trial t;
  std::array<std::vector<Vec3>, 2> side;
  if (!sidePoints(ctx, part, plane, side))
    return t;
  for (const auto& pts : side)
    t.hulls.push_back(hullOf(ctx, pts, kHullTolerance * ctx.c_abs, kSearchHullVertices));
  t.valid = true;
  return t;
}

bool splitGeometry(const Context& ctx,
                   const Part& part,
                   const Plane& plane,
                   Part& below,
                   Part& above);

// a cross: the part cut by `a`, then each half that `b` crosses cut by `b`
Trial crossTrial(const Context& ctx, const Part& part, const Plane& a, const Plane& b) {
  Trial t;
  Part half[2];
  if (!splitGeometry(ctx, part, a, half[0], half[1]))
    return t;
  int split = 0;
  for (const Part& h : half) {
    std::array<std::vector<Vec3>, 2> side;
    if (sidePoints(ctx, h, b, side)) {
      ++split;
      for (const auto& pts : side)
        t.hulls.push_back(hullOf(ctx, pts, kHullTolerance * ctx.c_abs, kSearchHullVertices));
    } else {
      t.hulls.push_back(hullOf(ctx, h.sample, kHullTolerance * ctx.c_abs, kSearchHullVertices));
    }
  }
  t.valid = split > 0;
  return t;
}

// scores trials on all threads by their excess near the part's worst point (local) or anywhere
// (cost, sum); a trial worse than the best so far is dropped early, which is deterministic (a
// dropped trial cannot be chosen)
void scorePass(const Context& ctx,
               const Part& part,
               const std::vector<Trial>& trials,
               const std::vector<std::size_t>& which,
               int kind,
               double slack,
               std::vector<Score>& scores) {
  std::atomic<double> bound{kInf};
  parallelFor(which.size(), ctx.threads, [&](std::size_t k) {
    const std::size_t i = which[k];
    double cost = 0.0, sum = 0.0;
    for (const HullMesh& h : trials[i].hulls) {
      const double e =
          searchExcess(ctx, h, part, kind, bound.load(std::memory_order_relaxed) + slack);
      if (e == kInf)
        return;
      cost = std::max(cost, e);
      sum += e;
    }
    Score& s = scores[i];
    if (kind == 0) {
      s.local = cost;
    } else {
      s.cost = cost;
      s.sum = sum;
    }
    double seen = bound.load(std::memory_order_relaxed);
    while (cost < seen && !bound.compare_exchange_weak(seen, cost)) {
    }
  });
}

// the trials' scores: the excess near the part's worst point of every trial, then, with `global`,
// the excess anywhere of those within kTie x c of the best there (the others are not valid: a cut
// must open the worst pocket as well as any)
std::vector<Score> scoreTrials(const Context& ctx,
                               const Part& part,
                               const std::vector<Trial>& trials,
                               bool global) {
  std::vector<Score> scores(trials.size());
  const double tie = kTie * ctx.c_abs;
  std::vector<std::size_t> which;
  for (std::size_t i = 0; i < trials.size(); ++i)
    if (trials[i].valid)
      which.push_back(i);
  scorePass(ctx, part, trials, which, 0, tie, scores);
  double best = kInf;
  for (const Score& s : scores)
    best = std::min(best, s.local);
  std::vector<std::size_t> tied;
  for (std::size_t i : which)
    if (scores[i].local <= best + tie)
      tied.push_back(i);
  if (global)
    scorePass(ctx, part, trials, tied, 1, 0.0, scores);
  for (std::size_t i : tied)
    scores[i].valid = !global || scores[i].cost < kInf;
  return scores;
}

bool better(const Score& a, const Score& b) {
  if (!a.valid || !b.valid)
    return a.valid && !b.valid;
  if (a.cost != b.cost || a.sum != b.sum)
    return a.cost < b.cost || (a.cost == b.cost && a.sum < b.sum);
  return a.local < b.local;
}

// the best of the scored trials (lowest index among equals); scores.size() when none is valid
std::size_t bestOf(const std::vector<Score>& scores) {
  std::size_t best = scores.size();
  for (std::size_t i = 0; i < scores.size(); ++i)
    if (scores[i].valid && (best == scores.size() || better(scores[i], scores[best])))
      best = i;
  return best;
}

// candidate planes: the axis planes through the deepest point of the worst pocket and through the
// surface point nearest it, the part's mid-planes, six planes containing the direction of the
// pocket's depth, and two planes across it
std::vector<Plane> candidates(const Part& part) {
  std::vector<Plane> out;
  Vec3 lo = part.points.front(), hi = lo;
  for (const Vec3& p : part.points)
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  const Vec3 p0 = part.excess.worst_p;
  const Vec3 q0 = part.excess.worst_q;
  Vec3 v = q0 - p0;
  const double depth = glm::length(v);
  v = depth > 0.0 ? v / depth : Vec3{0.0, 0.0, 1.0};
  for (int a = 0; a < 3; ++a) {
    Vec3 n{0.0};
    n[a] = 1.0;
    out.push_back({n, glm::dot(n, q0)});
    out.push_back({n, glm::dot(n, p0)});
    out.push_back({n, 0.5 * (lo[a] + hi[a])});
  }
  const Vec3 helper = std::abs(v.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 a = glm::normalize(glm::cross(v, helper));
  const Vec3 b = glm::cross(v, a);
  for (int k = 0; k < 6; ++k) {
    const double t = k * std::numbers::pi / 6.0;
    const Vec3 n = a * std::cos(t) + b * std::sin(t);
    out.push_back({n, glm::dot(n, p0)});
  }
  for (double t : {0.33, 0.67})
    out.push_back({v, glm::dot(v, p0) + t * depth});
  return out;
}

/// What to do with the worst part: one plane, or a cross (the second plane then cuts both halves).
struct CutPlan {
  Plane first;
  std::optional<Plane> second;
};

std::vector<Trial> trialsOf(const Context& ctx,
                            const Part& part,
                            const std::vector<Plane>& planes) {
  std::vector<Trial> trials(planes.size());
  parallelFor(planes.size(), ctx.threads,
              [&](std::size_t i) { trials[i] = cutTrial(ctx, part, planes[i]); });
  return trials;
}

// the best cut: the candidates; when none opens the worst pocket, the crosses of two planes through
// its deepest point (a bore or a ring opens only to two cuts through its axis: a two-step look
// ahead in the sense of CoACD's tree search, §5); then two rounds of shifting and tilting the
// winner
std::optional<CutPlan> chooseCut(const Context& ctx, const Part& part) {
  const std::vector<Plane> first = candidates(part);
  const std::vector<Score> scores = scoreTrials(ctx, part, trialsOf(ctx, part, first), true);
  const std::size_t index = bestOf(scores);
  if (index == scores.size())
    return std::nullopt;
  Plane best = first[index];
  Score score = scores[index];
  if (score.local > kStuck * part.concavity) {
    // the three axis planes through the deepest point, pairwise
    std::vector<std::pair<Plane, Plane>> pairs;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j)
          pairs.push_back(
              {first[3 * static_cast<std::size_t>(i)], first[3 * static_cast<std::size_t>(j)]});
    std::vector<Trial> trials(pairs.size());
    parallelFor(pairs.size(), ctx.threads, [&](std::size_t i) {
      trials[i] = crossTrial(ctx, part, pairs[i].first, pairs[i].second);
    });
    const std::vector<Score> cross = scoreTrials(ctx, part, trials, false);
    const std::size_t c = bestOf(cross);
    if (c < cross.size() && cross[c].local <= kStuck * part.concavity)
      return CutPlan{pairs[c].first, pairs[c].second};
  }
  Vec3 lo = part.points.front(), hi = lo;
  for (const Vec3& p : part.points)
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  double shift = 0.05 * glm::length(hi - lo), tilt = 0.15;
  for (int round = 0; round < 2; ++round, shift *= 0.5, tilt *= 0.5) {
    const Vec3 helper = std::abs(best.n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 a = glm::normalize(glm::cross(best.n, helper));
    const Vec3 b = glm::cross(best.n, a);
    const Vec3 centre = best.n * best.d;  // a point of the plane
    std::vector<Plane> near{best, {best.n, best.d + shift}, {best.n, best.d - shift}};
    for (const Vec3& axis : {a, b, -a, -b}) {
      const Vec3 n = glm::normalize(best.n + axis * std::tan(tilt));
      near.push_back({n, glm::dot(n, centre)});
    }
    const std::vector<Score> s = scoreTrials(ctx, part, trialsOf(ctx, part, near), true);
    const std::size_t k = bestOf(s);
    if (k < s.size() && better(s[k], score)) {
      best = near[k];
      score = s[k];
    }
  }
  return CutPlan{best, std::nullopt};
}

// `part` cut by `plane` into its two halves (surface, cell, inside points, hull input and sample),
// not yet measured; false when a half is empty
bool splitGeometry(const Context& ctx,
                   const Part& part,
                   const Plane& plane,
                   Part& below,
                   Part& above) {
  splitPolygons(part.polys, plane, ctx.eps, below.polys, above.polys);
  std::vector<Vec3> section;
  splitCell(part.cell, plane, below.cell, above.cell, section);
  for (const Vec3& v : section)
    if (ctx.bvh->inside(v))
      below.inside.push_back(v), above.inside.push_back(v);
  for (const Vec3& v : part.inside) {
    const double s = plane.signedDistance(v);
    if (s <= ctx.eps)
      below.inside.push_back(v);
    if (s >= -ctx.eps)
      above.inside.push_back(v);
  }
  for (Part* child : {&below, &above}) {
    if (child->polys.size() == 0)
      return false;
    child->points = child->polys.pts;
    child->points.insert(child->points.end(), child->inside.begin(), child->inside.end());
    sortUnique(child->points);
    child->sample = subsample(child->points, kSamplePoints);
  }
  return true;
}

// the two halves of `part` by `plane`, measured; false when one half is empty
bool splitPart(const Context& ctx, const Part& part, const Plane& plane, Part& below, Part& above) {
  if (!splitGeometry(ctx, part, plane, below, above))
    return false;
  measurePart(ctx, below, kInf);
  measurePart(ctx, above, kInf);
  return true;
}

bool boxesTouch(const HullPlanes& a, const HullPlanes& b, double slack) {
  return !(glm::any(glm::lessThan(a.hi + slack, b.lo)) ||
           glm::any(glm::lessThan(b.hi + slack, a.lo)));
}

// the hull of two parts together, measured; its concavity is infinite when above the bound
Part mergedPart(const Context& ctx, const Part& a, const Part& b, double bound) {
  Part m;
  m.points = a.points;
  m.points.insert(m.points.end(), b.points.begin(), b.points.end());
  measurePart(ctx, m, bound);
  m.final = true;
  return m;
}

struct Run {
  const Context& ctx;
  const DecompOptions& options;
  const ProgressFn& progress;
  Clock::time_point start;
  std::vector<Part> leaves;
  std::vector<std::uint64_t> ids;  // per leaf, for the merge cost cache
  std::uint64_t next_id = 0;
  DecompReport report;

  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start).count(); }
  bool outOfTime() const { return options.time_limit_s > 0.0 && elapsed() > options.time_limit_s; }
  double worst() const {
    double w = 0.0;
    for (const Part& p : leaves)
      w = std::max(w, p.concavity);
    return w;
  }
  void tell(const char* stage) const {
    if (progress)
      progress({leaves.size(), worst() / ctx.mesh.diagonal, elapsed(), stage});
  }
  void add(Part&& p) {
    leaves.push_back(std::move(p));
    ids.push_back(next_id++);
  }
  void cutAll();
  /// merges while the merged hull stays within the bound; returns the merges made
  std::size_t mergeAll();
  struct MergeCost {
    std::uint64_t a, b;
    double concavity;
  };
  std::vector<MergeCost> merge_cache;
};

// cuts the worst part until every part is within the bound, or a limit
void Run::cutAll() {
  std::size_t merge_rounds = 0;
  while (true) {
    std::size_t w = leaves.size();
    for (std::size_t i = 0; i < leaves.size(); ++i)
      if (!leaves[i].final && leaves[i].concavity > ctx.c_abs &&
          (w == leaves.size() || leaves[i].concavity > leaves[w].concavity))
        w = i;
    if (w == leaves.size())
      return;
    if (leaves.size() >= options.max_pieces) {
      // at the cap: merge what the bound allows and go on cutting
      if (options.merge && merge_rounds < kMergeRounds && mergeAll() > 0) {
        ++merge_rounds;
        continue;
      }
      report.max_pieces_hit = true;
      return;
    }
    if (outOfTime()) {
      report.time_limit_hit = true;
      return;
    }
    const std::optional<CutPlan> plan = chooseCut(ctx, leaves[w]);
    Part below, above;
    if (!plan || !splitPart(ctx, leaves[w], plan->first, below, above)) {
      leaves[w].final = true;
      continue;
    }
    leaves.erase(leaves.begin() + static_cast<std::ptrdiff_t>(w));
    ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(w));
    for (Part* half : {&below, &above}) {
      Part a, b;
      if (plan->second && leaves.size() + 2 + (half == &below ? 1u : 0u) <= options.max_pieces &&
          splitPart(ctx, *half, *plan->second, a, b)) {
        add(std::move(a));
        add(std::move(b));
        ++report.cuts;
      } else {
        add(std::move(*half));
      }
    }
    ++report.cuts;
    tell("cut");
  }
}

// merges the cheapest touching pair while the merged hull stays within the bound
std::size_t Run::mergeAll() {
  using Cost = MergeCost;
  std::vector<Cost>& cache = merge_cache;
  std::size_t merged_count = 0;
  while (leaves.size() > 1) {
    if (outOfTime()) {
      report.time_limit_hit = true;
      return merged_count;
    }
    std::vector<HullPlanes> boxes;
    for (const Part& p : leaves)
      boxes.push_back(HullPlanes::of(p.hull));
    std::vector<std::pair<std::size_t, std::size_t>> todo;
    for (std::size_t i = 0; i < leaves.size(); ++i)
      for (std::size_t j = i + 1; j < leaves.size(); ++j) {
        if (leaves[i].concavity > ctx.c_abs || leaves[j].concavity > ctx.c_abs ||
            !boxesTouch(boxes[i], boxes[j], kHullTolerance * ctx.c_abs))
          continue;
        const bool known = std::any_of(cache.begin(), cache.end(), [&](const Cost& c) {
          return c.a == ids[i] && c.b == ids[j];
        });
        if (!known)
          todo.push_back({i, j});
      }
    std::vector<double> costs(todo.size());
    parallelFor(todo.size(), ctx.threads, [&](std::size_t k) {
      costs[k] =
          mergedPart(ctx, leaves[todo[k].first], leaves[todo[k].second], ctx.c_abs).concavity;
    });
    for (std::size_t k = 0; k < todo.size(); ++k)
      cache.push_back({ids[todo[k].first], ids[todo[k].second], costs[k]});
    // the cheapest pair of current leaves within the bound
    std::size_t bi = 0, bj = 0;
    double best = kInf;
    for (std::size_t i = 0; i < leaves.size(); ++i)
      for (std::size_t j = i + 1; j < leaves.size(); ++j)
        for (const Cost& c : cache)
          if (c.a == ids[i] && c.b == ids[j] && c.concavity <= ctx.c_abs && c.concavity < best)
            best = c.concavity, bi = i, bj = j;
    if (best == kInf)
      return merged_count;
    Part merged = mergedPart(ctx, leaves[bi], leaves[bj], kInf);
    leaves.erase(leaves.begin() + static_cast<std::ptrdiff_t>(bj));
    ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(bj));
    leaves.erase(leaves.begin() + static_cast<std::ptrdiff_t>(bi));
    ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(bi));
    add(std::move(merged));
    ++report.merges;
    ++merged_count;
    tell("merge");
  }
  return merged_count;
}

// the global measure of decompose.h over the final hulls (boundary points inside another piece
// are not on the union's boundary); absolute
std::pair<double, double> unionExcess(const Context& ctx,
                                      std::span<const HullMesh> hulls,
                                      double tolerance,
                                      double resolution,
                                      double floor) {
  std::vector<HullPlanes> planes;
  for (const HullMesh& h : hulls)
    planes.push_back(HullPlanes::of(h));
  std::vector<ExcessBound> excess(hulls.size());
  parallelFor(hulls.size(), ctx.threads, [&](std::size_t i) {
    std::vector<HullPlanes> others;
    for (std::size_t j = 0; j < hulls.size(); ++j)
      if (j != i && boxesTouch(planes[i], planes[j], 0.0))
        others.push_back(planes[j]);
    ExcessOptions o;
    o.tolerance = tolerance;
    o.resolution = resolution;
    o.floor = floor;
    o.max_evaluations = kLeafEvaluations;
    o.others = others;
    excess[i] = hullExcess(ctx.view, hulls[i], o);
  });
  std::pair<double, double> worst{0.0, 0.0};
  for (const ExcessBound& e : excess)
    worst = {std::max(worst.first, e.lower), std::max(worst.second, e.upper)};
  return worst;  // (sampled, bound)
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

Result<Context> prepare(const TriangleMesh& mesh,
                        const DecompOptions& options,
                        RepairCounts& counts,
                        std::vector<std::string>& warnings) {
  if (!(options.concavity > 0.0 && options.concavity < 1.0))
    return Error{"concavity must be in (0, 1) (a fraction of the bounding-box diagonal), got " +
                 std::to_string(options.concavity)};
  if (options.max_pieces < 1)
    return Error{"max_pieces must be at least 1"};
  if (options.threads > 16)
    return Error{"threads must be 0 (automatic) to 16"};
  if (options.max_piece_vertices < 8)
    return Error{"max_piece_vertices must be at least 8"};
  RepairLimits limits;
  limits.max_triangles = options.max_triangles;
  limits.decimate_to = std::min(options.decimate_to, options.max_triangles);
  limits.refuse_triangles = options.refuse_triangles;
  Result<RepairedMesh> repaired = repairMesh(mesh, limits, counts);
  if (!repaired)
    return repaired.error();
  Context ctx;
  ctx.mesh = std::move(repaired).value();
  if (counts.decimated_from > 0)
    warnings.push_back("the mesh has " + std::to_string(counts.decimated_from) +
                       " triangles, above the limit of " + std::to_string(options.max_triangles) +
                       ": decimated by vertex clustering to " +
                       std::to_string(ctx.mesh.triangles.size()) + " (cell " +
                       fixed(ctx.mesh.decimation_cell / ctx.mesh.diagonal, 5) +
                       " of the diagonal; concavity is measured against the decimated mesh)");
  ctx.bvh = std::make_unique<TriangleBvh>(ctx.mesh.positions, ctx.mesh.triangles);
  // crossing triangles: parts that touch or overlap, where the closest feature's side is not the
  // solid's (docs/decomposition.md: overlapping parts are one solid by the winding number)
  if (counts.self_intersections > 0)
    ctx.bvh->useWindingNumberOnly();
  ctx.view.bvh = ctx.bvh.get();
  ctx.c_abs = options.concavity * ctx.mesh.diagonal;
  // on a plane within 1e-9 of the diagonal, or within the rounding of float32 inputs (STL, glTF)
  double extent = 0.0;
  for (int a = 0; a < 3; ++a)
    extent = std::max({extent, std::abs(ctx.mesh.lo[a]), std::abs(ctx.mesh.hi[a])});
  ctx.eps = std::max(1e-9 * ctx.mesh.diagonal, 2.5e-7 * extent);
  ctx.max_piece_vertices = options.max_piece_vertices;
  const unsigned hw = std::max(1u, std::min(2u, std::thread::hardware_concurrency()));
  ctx.threads = options.threads == 0 ? hw : options.threads;
  return ctx;
}

// the parts' hulls as pieces (each checked by the loader's own hull code) and the final measure
void finish(Run& run, DecompResult& result) {
  const Context& ctx = run.ctx;
  std::vector<HullMesh> hulls;
  double coverage = 0.0;
  for (Part& p : run.leaves) {
    if (!geom::Polytope::fromPoints(p.hull.vertices).ok())
      p.hull = quickHull(thicken(p.points, 1e-5 * ctx.mesh.diagonal), 0.0, ctx.max_piece_vertices);
    if (!p.hull.valid())
      continue;
    coverage = std::max({coverage, p.hull.max_outside, kHullTolerance * ctx.c_abs});
    hulls.push_back(p.hull);
    result.pieces.push_back({p.hull.vertices, p.hull.triangles});
  }
  DecompReport& r = run.report;
  r.pieces = result.pieces.size();
  const auto [boundary, bound] =
      unionExcess(ctx, hulls, kLeafTolerance * ctx.c_abs, kLeafResolution * ctx.c_abs, 0.0);
  r.concavity = std::max(boundary, coverage) / ctx.mesh.diagonal;
  r.concavity_bound = std::max(bound, coverage) / ctx.mesh.diagonal;
  // the union's volume (merged pieces overlap their neighbours): what a body of them weighs
  std::vector<Cell> cells;
  cells.reserve(result.pieces.size());
  for (const ConvexPiece& piece : result.pieces)
    cells.push_back(pieceCell(piece));
  const UnionIntegrals weighed = unionIntegrals(cells);
  r.union_volume = weighed.integrals.volume;
  if (!weighed.exact)
    r.warnings.push_back("the pieces overlap too much to weigh their union (the work passed " +
                         std::to_string(kUnionWorkBudget) +
                         " plane tests): the union's volume is their summed volume");
  // (a model with next to no volume, a flat part or a soup of triangles closed by the hole
  // filling into flat shells, has no meaningful ratio: left 0, said as such)
  const double d3 = ctx.mesh.diagonal * ctx.mesh.diagonal * ctx.mesh.diagonal;
  if (ctx.mesh.closed && ctx.mesh.volume > 1e-9 * d3) {
    double v = 0.0;
    for (const HullMesh& h : hulls)
      v += meshVolume(h.vertices, h.triangles);
    r.volume_ratio = v / ctx.mesh.volume;
    r.union_ratio = r.union_volume / ctx.mesh.volume;
  }
  if (r.time_limit_hit)
    r.warnings.push_back("time limit of " + fixed(run.options.time_limit_s, 1) +
                         " s reached: the best result so far is returned");
  // the target missed: which limit, or none, and what is left (a warning that names its cause)
  if (r.concavity > r.concavity_target && !r.time_limit_hit) {
    std::size_t over = 0;
    for (const Part& p : run.leaves)
      over += p.concavity > ctx.c_abs ? 1 : 0;
    const std::string reached = "target concavity " + fixed(r.concavity_target, 4) +
                                " not reached (" + fixed(r.concavity, 4) + ")";
    if (r.max_pieces_hit) {
      r.warnings.push_back("max_pieces (" + std::to_string(run.options.max_pieces) +
                           ") reached before the target concavity: " + reached + "; " +
                           std::to_string(kMergeRounds) +
                           " rounds of merging made no room for the cuts left, " +
                           std::to_string(r.pieces) + " pieces after the last merge, " +
                           std::to_string(over) + " of them above the target");
    } else if (over > 0) {
      r.warnings.push_back(reached + ": " + std::to_string(over) +
                           (over == 1 ? " part" : " parts") +
                           " could not be cut further (no plane lowers the concavity)");
    } else {
      r.warnings.push_back(reached +
                           ": every part is within it by its own estimate, the union's "
                           "measure is not (where two parts meet)");
    }
  }
}

}  // namespace

Result<DecompResult> decompose(const TriangleMesh& mesh,
                               const DecompOptions& options,
                               const ProgressFn& progress) {
  const Clock::time_point start = Clock::now();
  DecompReport report;
  Result<Context> prepared = prepare(mesh, options, report.repairs, report.warnings);
  if (!prepared)
    return prepared.error();
  const Context& ctx = prepared.value();
  Run run{ctx, options, progress, start, {}, {}, 0, std::move(report), {}};
  run.report.concavity_target = options.concavity;
  run.report.diagonal = ctx.mesh.diagonal;
  run.report.closed = ctx.mesh.closed;
  {
    Part root;
    for (const Triangle& t : ctx.mesh.triangles)
      root.polys.add(
          {ctx.mesh.positions[t[0]], ctx.mesh.positions[t[1]], ctx.mesh.positions[t[2]]});
    const Vec3 margin{0.01 * ctx.mesh.diagonal};
    root.cell = boxCell(ctx.mesh.lo - margin, ctx.mesh.hi + margin);
    root.points = ctx.mesh.positions;
    finishPart(ctx, root);
    run.add(std::move(root));
  }
  run.tell("cut");
  run.cutAll();
  if (options.merge && !run.report.time_limit_hit)
    run.mergeAll();
  DecompResult result;
  finish(run, result);
  run.report.seconds = run.elapsed();
  result.report = std::move(run.report);
  run.tell("finish");
  return result;
}

Result<double> measureConcavity(const TriangleMesh& mesh,
                                std::span<const ConvexPiece> pieces,
                                double tolerance) {
  DecompOptions options;
  options.concavity = std::clamp(tolerance, 1e-6, 0.5);
  RepairCounts counts;
  std::vector<std::string> warnings;
  Result<Context> prepared = prepare(mesh, options, counts, warnings);
  if (!prepared)
    return prepared.error();
  const Context& ctx = prepared.value();
  std::vector<HullMesh> hulls;
  std::vector<HullPlanes> planes;
  for (const ConvexPiece& p : pieces) {
    HullMesh h = quickHull(p.vertices, 0.0, std::numeric_limits<std::size_t>::max());
    if (!h.valid())
      continue;  // a flat piece covers no volume; its points count in coverage below
    planes.push_back(HullPlanes::of(h));
    hulls.push_back(std::move(h));
  }
  if (hulls.empty())
    return Error{"no piece has volume"};
  const double abs_tol = tolerance * ctx.mesh.diagonal;
  const double boundary = unionExcess(ctx, hulls, abs_tol, abs_tol, 0.0).first;
  const double coverage =
      surfaceCoverage(ctx.mesh.positions, ctx.mesh.triangles, hulls, planes, abs_tol);
  return std::max(boundary, coverage) / ctx.mesh.diagonal;
}

std::string contentHash(const TriangleMesh& mesh, const DecompOptions& options) {
  Sha256 h;
  auto putU64 = [&](std::uint64_t x) {
    std::array<std::uint8_t, 8> b{};
    for (std::size_t i = 0; i < 8; ++i)
      b[i] = static_cast<std::uint8_t>(x >> (8 * i));
    h.update(b);
  };
  auto putF64 = [&](double x) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &x, sizeof bits);
    putU64(bits);
  };
  static constexpr char kTag[] = "hapticd-decomp algorithm 6";
  h.update(kTag, sizeof kTag - 1);
  putU64(mesh.positions.size());
  for (const Vec3& p : mesh.positions)
    putF64(p.x), putF64(p.y), putF64(p.z);
  putU64(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t) {
      const std::array<std::uint8_t, 4> b{
          static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8),
          static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 24)};
      h.update(b);
    }
  putF64(options.concavity);
  putU64(options.max_pieces);
  putU64(options.max_triangles);
  putU64(options.decimate_to);
  putU64(options.refuse_triangles);
  putU64(options.max_piece_vertices);
  putU64(options.merge ? 1 : 0);
  return h.hexDigest();
}

std::string describe(const DecompReport& r) {
  std::string s = std::to_string(r.pieces) + " pieces, concavity " + fixed(r.concavity, 4) +
                  " of the diagonal (target " + fixed(r.concavity_target, 4) + ", diagonal " +
                  fixed(r.diagonal, 6) + ")";
  s += !r.closed              ? ", open model (no volume ratio)"
       : r.volume_ratio > 0.0 ? ", volume of the pieces " + fixed(r.volume_ratio, 3) +
                                    " x the model's (their union " + fixed(r.union_ratio, 3) + ")"
                              : ", flat model (no volume to compare)";
  s += ", " + fixed(r.seconds, 2) + " s, " + std::to_string(r.cuts) + " cuts, " +
       std::to_string(r.merges) + " merges\n";
  const RepairCounts& c = r.repairs;
  s += "input " + std::to_string(c.input_vertices) + " vertices, " +
       std::to_string(c.input_triangles) + " triangles, " + std::to_string(c.components) +
       " parts (" + std::to_string(c.open_components) + " open)\n";
  const std::pair<const char*, std::size_t> items[] = {
      {"non-finite vertices", c.non_finite_vertices},
      {"triangles with bad indices", c.bad_index_triangles},
      {"duplicate vertices welded", c.duplicate_vertices},
      {"unreferenced vertices dropped", c.unreferenced_vertices},
      {"degenerate triangles dropped", c.degenerate_triangles},
      {"duplicate triangles dropped", c.duplicate_triangles},
      {"boundary edges", c.boundary_edges},
      {"holes filled", c.holes_filled},
      {"non-manifold edges", c.non_manifold_edges},
      {"triangles re-wound", c.flipped_triangles},
      {"parts wound inside out (turned)", c.inverted_components},
      {"crossing triangle pairs (self-intersections)", c.self_intersections}};
  std::string repairs;
  for (const auto& [what, n] : items)
    if (n > 0)
      repairs += (repairs.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  if (c.self_intersections_capped)
    repairs += " (counting stopped at its budget)";
  s += "repairs: " + (repairs.empty() ? std::string("none needed") : repairs) + "\n";
  for (const std::string& w : r.warnings)
    s += "warning: " + w + "\n";
  return s;
}

}  // namespace hapticd::decomp
