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
constexpr std::size_t kLookahead = 3;  // candidates looked two steps ahead

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

// the hull of the part's points, its measure and its concavity (the boundary excess and the
// hull's own coverage); infinite when the excess passes `bound`
void measurePart(const Context& ctx, Part& part, double bound) {
  sortUnique(part.points);
  const double tol = kHullTolerance * ctx.c_abs;
  part.hull = hullOf(ctx, part.points, tol, ctx.max_piece_vertices);
  ExcessOptions o;
  o.tolerance = kLeafTolerance * ctx.c_abs;
  o.resolution = kLeafResolution * ctx.c_abs;
  o.floor = kFloor * ctx.c_abs;
  o.max_evaluations = kLeafEvaluations;
  o.stop_above = bound;
  part.excess = hullExcess(ctx.view, part.hull, o);
  part.concavity =
      part.excess.aborted ? kInf : std::max({part.excess.lower, part.hull.max_outside, tol});
}

// a new part: measured, and sampled for scoring its cuts
void finishPart(const Context& ctx, Part& part) {
  measurePart(ctx, part, kInf);
  part.sample = subsample(part.points, kSamplePoints);
}

struct Score {
  double cost = kInf;  // max of the two halves' excess
  double sum = kInf;
  bool valid = false;
};

// the inside vertices of the new face of `cell` on `plane`
std::vector<Vec3> insideSection(const Context& ctx, const Cell& cell, const Plane& plane) {
  std::vector<Vec3> out;
  for (const Vec3& v : cellSection(cell, plane))
    if (ctx.bvh->inside(v))
      out.push_back(v);
  return out;
}

Score scoreCut(const Context& ctx,
               const Part& part,
               const Plane& plane,
               std::atomic<double>& bound) {
  // strictly off the plane from the sample; on it from the polygons (which side a vertex on the
  // plane belongs to depends on its polygon)
  const double eps = ctx.eps;
  std::vector<Vec3> side[2];
  for (const Vec3& p : part.sample) {
    const double s = plane.signedDistance(p);
    if (s < -eps)
      side[0].push_back(p);
    if (s > eps)
      side[1].push_back(p);
  }
  std::vector<Vec3> section;
  std::vector<Vec3> on[2];
  sectionPoints(part.polys, plane, eps, section, on[0], on[1]);
  sortUnique(section);
  if (section.size() > kSamplePoints / 2)
    section = subsample(section, kSamplePoints / 2);
  for (int k = 0; k < 2; ++k) {
    sortUnique(on[k]);
    if (on[k].size() > kSamplePoints / 2)
      on[k] = subsample(on[k], kSamplePoints / 2);
    side[k].insert(side[k].end(), on[k].begin(), on[k].end());
  }
  if (side[0].size() + section.size() < 4 || side[1].size() + section.size() < 4)
    return {};
  if (side[0].empty() || side[1].empty())
    return {};
  for (const Vec3& v : insideSection(ctx, part.cell, plane))
    section.push_back(v);
  for (const Vec3& v : part.inside) {
    const double s = plane.signedDistance(v);
    if (s <= eps)
      side[0].push_back(v);
    if (s >= -eps)
      side[1].push_back(v);
  }
  Score score;
  score.cost = 0.0;
  score.sum = 0.0;
  for (auto& pts : side) {
    pts.insert(pts.end(), section.begin(), section.end());
    const HullMesh hull = quickHull(pts, kHullTolerance * ctx.c_abs, kSearchHullVertices);
    if (!hull.valid())
      continue;  // flat (an open sheet): no excess
    ExcessOptions o;
    o.tolerance = kSearchTolerance * ctx.c_abs;
    o.resolution = kSearchResolution * ctx.c_abs;
    o.floor = kFloor * ctx.c_abs;
    o.max_evaluations = kSearchEvaluations;
    o.stop_above = bound.load(std::memory_order_relaxed);
    const ExcessBound e = hullExcess(ctx.view, hull, o);
    if (e.aborted)
      return {};
    score.cost = std::max(score.cost, e.upper);
    score.sum += e.upper;
  }
  score.valid = true;
  double seen = bound.load(std::memory_order_relaxed);
  while (score.cost < seen && !bound.compare_exchange_weak(seen, score.cost)) {
  }
  return score;
}

// candidate planes: through the deepest point of the worst pocket, and across the part's box
std::vector<Plane> candidates(const Part& part) {
  std::vector<Plane> out;
  Vec3 lo = part.points.front(), hi = lo;
  for (const Vec3& p : part.points)
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  const Vec3 p0 = part.excess.worst_p;
  Vec3 v = part.excess.worst_q - part.excess.worst_p;
  const double depth = glm::length(v);
  v = depth > 0.0 ? v / depth : Vec3{0.0, 0.0, 1.0};
  for (int a = 0; a < 3; ++a) {
    Vec3 n{0.0};
    n[a] = 1.0;
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

// scores `planes` on all threads (a candidate worse than `incumbent` is dropped early)
std::vector<Score> scoreAll(const Context& ctx,
                            const Part& part,
                            const std::vector<Plane>& planes,
                            double incumbent) {
  std::vector<Score> scores(planes.size());
  std::atomic<double> bound{incumbent};
  parallelFor(planes.size(), ctx.threads,
              [&](std::size_t i) { scores[i] = scoreCut(ctx, part, planes[i], bound); });
  return scores;
}

bool better(const Score& a, const Score& b) {
  return a.cost < b.cost || (a.cost == b.cost && a.sum < b.sum);
}

// the valid candidates, best first by (cost, sum, index)
std::vector<std::size_t> ranked(const std::vector<Score>& scores) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < scores.size(); ++i)
    if (scores[i].valid)
      order.push_back(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return better(scores[a], scores[b]); });
  return order;
}

bool splitPart(const Context& ctx, const Part& part, const Plane& plane, Part& below, Part& above);

// two steps ahead (a depth-2 tree search, CoACD §5): the worst of the cut's better half and the
// best single cut of its worse half
double lookahead(const Context& ctx, const Part& part, const Plane& plane) {
  Part below, above;
  if (!splitPart(ctx, part, plane, below, above))
    return kInf;
  const Part& worse = below.concavity >= above.concavity ? below : above;
  const Part& other = below.concavity >= above.concavity ? above : below;
  if (worse.concavity <= ctx.c_abs)
    return other.concavity;
  const std::vector<Score> next = scoreAll(ctx, worse, candidates(worse), kInf);
  const std::vector<std::size_t> order = ranked(next);
  const double step =
      order.empty() ? worse.concavity : std::min(worse.concavity, next[order[0]].cost);
  return std::max(other.concavity, step);
}

// the best cut: the candidates (with a look two steps ahead when no single cut makes progress),
// then two rounds of shifting and tilting the winner
std::optional<Plane> chooseCut(const Context& ctx, const Part& part) {
  const std::vector<Plane> first = candidates(part);
  const std::vector<Score> scores = scoreAll(ctx, part, first, kInf);
  const std::vector<std::size_t> order = ranked(scores);
  if (order.empty())
    return std::nullopt;
  std::size_t index = order[0];
  if (scores[index].cost > kStuck * part.concavity) {
    double best_value = kInf;
    for (std::size_t k = 0; k < std::min<std::size_t>(kLookahead, order.size()); ++k) {
      const double value = lookahead(ctx, part, first[order[k]]);
      if (value < best_value)
        best_value = value, index = order[k];
    }
    return first[index];
  }
  Plane best = first[index];
  Score score = scores[index];
  Vec3 lo = part.points.front(), hi = lo;
  for (const Vec3& p : part.points)
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  double shift = 0.05 * glm::length(hi - lo), tilt = 0.15;
  for (int round = 0; round < 2; ++round, shift *= 0.5, tilt *= 0.5) {
    const Vec3 helper = std::abs(best.n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 a = glm::normalize(glm::cross(best.n, helper));
    const Vec3 b = glm::cross(best.n, a);
    const Vec3 centre = best.n * best.d;  // a point of the plane
    std::vector<Plane> near{{best.n, best.d + shift}, {best.n, best.d - shift}};
    for (const Vec3& axis : {a, b, -a, -b}) {
      const Vec3 n = glm::normalize(best.n + axis * std::tan(tilt));
      near.push_back({n, glm::dot(n, centre)});
    }
    const std::vector<Score> s = scoreAll(ctx, part, near, score.cost);
    const std::vector<std::size_t> o = ranked(s);
    if (!o.empty() && better(s[o[0]], score)) {
      best = near[o[0]];
      score = s[o[0]];
    }
  }
  return best;
}

// the two halves of `part` by `plane`, exactly; false when one half is empty
bool splitPart(const Context& ctx, const Part& part, const Plane& plane, Part& below, Part& above) {
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
    finishPart(ctx, *child);
  }
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
  void mergeAll();
};

// cuts the worst part until every part is within the bound, or a limit
void Run::cutAll() {
  while (true) {
    std::size_t w = leaves.size();
    for (std::size_t i = 0; i < leaves.size(); ++i)
      if (!leaves[i].final && leaves[i].concavity > ctx.c_abs &&
          (w == leaves.size() || leaves[i].concavity > leaves[w].concavity))
        w = i;
    if (w == leaves.size())
      return;
    if (leaves.size() >= options.max_pieces) {
      report.max_pieces_hit = true;
      return;
    }
    if (outOfTime()) {
      report.time_limit_hit = true;
      return;
    }
    const std::optional<Plane> plane = chooseCut(ctx, leaves[w]);
    Part below, above;
    if (!plane || !splitPart(ctx, leaves[w], *plane, below, above)) {
      leaves[w].final = true;
      continue;
    }
    leaves.erase(leaves.begin() + static_cast<std::ptrdiff_t>(w));
    ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(w));
    add(std::move(below));
    add(std::move(above));
    ++report.cuts;
    tell("cut");
  }
}

// merges the cheapest touching pair while the merged hull stays within the bound
void Run::mergeAll() {
  struct Cost {
    std::uint64_t a, b;
    double concavity;
  };
  std::vector<Cost> cache;
  while (leaves.size() > 1) {
    if (outOfTime()) {
      report.time_limit_hit = true;
      return;
    }
    std::vector<HullPlanes> boxes;
    for (const Part& p : leaves)
      boxes.push_back(HullPlanes::of(p.hull));
    std::vector<std::pair<std::size_t, std::size_t>> todo;
    for (std::size_t i = 0; i < leaves.size(); ++i)
      for (std::size_t j = i + 1; j < leaves.size(); ++j) {
        if (!boxesTouch(boxes[i], boxes[j], kHullTolerance * ctx.c_abs))
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
      return;
    Part merged = mergedPart(ctx, leaves[bi], leaves[bj], kInf);
    leaves.erase(leaves.begin() + static_cast<std::ptrdiff_t>(bj));
    ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(bj));
    leaves.erase(leaves.begin() + static_cast<std::ptrdiff_t>(bi));
    ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(bi));
    add(std::move(merged));
    ++report.merges;
    tell("merge");
  }
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
  if (ctx.mesh.closed && ctx.mesh.volume > 0.0) {
    double v = 0.0;
    for (const HullMesh& h : hulls)
      v += meshVolume(h.vertices, h.triangles);
    r.volume_ratio = v / ctx.mesh.volume;
  }
  if (r.time_limit_hit)
    r.warnings.push_back("time limit of " + fixed(run.options.time_limit_s, 1) +
                         " s reached: the best result so far is returned");
  if (r.max_pieces_hit && r.concavity > r.concavity_target)
    r.warnings.push_back("max_pieces (" + std::to_string(run.options.max_pieces) +
                         ") reached before the target concavity");
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
  Run run{ctx, options, progress, start, {}, {}, 0, std::move(report)};
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
  static constexpr char kTag[] = "hapticd-decomp algorithm 1";
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
  s += r.closed ? ", volume of the pieces " + fixed(r.volume_ratio, 3) + " x the model's"
                : ", open model (no volume ratio)";
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
