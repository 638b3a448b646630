// The decomposition's convex hull (core/decomp/quickhull.h) beside Qhull (libqhull_r, Debian's
// libqhull-dev: Barber, Dobkin, Huhdanpaa 1996) on the point sets a decomposition hulls:
//   Hull/ours/<model>/<mode>        quickHull()
//   Peer/Qhull-hull/<model>/<mode>  qh_new_qhull with "Qt" (triangulated output), the triangles
//                                   read out and wound outward, as quickHull returns them
// The point sets: each model's vertices (after the decomposition's repair: welded) split by median
// planes (longest axis first) into the cells of a 5-level tree (1 + 2 + 4 + 8 + 16 = 31 cells, the
// parts a run cuts), each cell's points strided down to at most 2 500 (the search's sample,
// core/decomp/decompose.cpp). Modes: `exact` (no tolerance, no vertex cap: what both compute alike)
// and `search` (quickHull with the search's tolerance, 0.001 of the diagonal, and 256-vertex cap;
// Qhull with the same tolerance as its minimum outside width "W"). Counters: hulls, points and hull
// vertices per iteration; the CPU time per iteration over `hulls` is the time per hull.
#include <benchmark/benchmark.h>
#include <libqhull_r/qhull_ra.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "bench/decomp_meshes.h"
#include "core/decomp/quickhull.h"
#include "core/decomp/repair.h"

namespace {

using hapticd::decomp::HullMesh;
using hapticd::decomp::Vec3;

constexpr std::size_t kSample = 2500;
constexpr int kLevels = 5;
constexpr double kSearchTolerance = 0.001;  // of the diagonal: 0.1 x the default concavity
constexpr std::size_t kSearchVertices = 256;

struct Cells {
  std::vector<std::vector<Vec3>> sets;
  double diagonal = 0.0;
  std::size_t points = 0;
};

void split(std::vector<Vec3> pts, int level, std::vector<std::vector<Vec3>>& out) {
  if (pts.size() < 8)
    return;
  std::vector<Vec3> sample;
  const std::size_t stride = (pts.size() + kSample - 1) / kSample;
  for (std::size_t i = 0; i < pts.size(); i += stride)
    sample.push_back(pts[i]);
  out.push_back(std::move(sample));
  if (level + 1 >= kLevels)
    return;
  Vec3 lo = pts.front(), hi = lo;
  for (const Vec3& p : pts)
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  const Vec3 ext = hi - lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const auto mid = pts.begin() + static_cast<std::ptrdiff_t>(pts.size() / 2);
  std::nth_element(pts.begin(), mid, pts.end(),
                   [axis](const Vec3& a, const Vec3& b) { return a[axis] < b[axis]; });
  std::vector<Vec3> below(pts.begin(), mid), above(mid, pts.end());
  split(std::move(below), level + 1, out);
  split(std::move(above), level + 1, out);
}

const std::map<std::string, Cells>& cells() {
  static const std::map<std::string, Cells> all = [] {
    std::map<std::string, Cells> m;
    for (const auto& [name, raw] : hapticd::bench::decompMeshes()) {
      hapticd::decomp::RepairCounts counts;
      const auto mesh = hapticd::decomp::repairMesh(raw, {}, counts);
      if (!mesh)
        continue;
      Cells c;
      c.diagonal = mesh.value().diagonal;
      split(mesh.value().positions, 0, c.sets);
      for (const auto& s : c.sets)
        c.points += s.size();
      m[name] = std::move(c);
    }
    return m;
  }();
  return all;
}

// Qhull's hull of `pts` as outward triangles; empty on a Qhull error (a flat set)
HullMesh qhullHull(const std::vector<Vec3>& pts, double min_outside, std::vector<double>& coords) {
  coords.clear();
  for (const Vec3& p : pts)
    coords.insert(coords.end(), {p.x, p.y, p.z});
  qhT qh_storage{};
  qhT* qh = &qh_storage;
  qh_zero(qh, stderr);
  std::string flags = "qhull Qt";
  if (min_outside > 0.0)
    flags += " W" + std::to_string(min_outside);
  HullMesh out;
  const int status = qh_new_qhull(qh, 3, static_cast<int>(pts.size()), coords.data(), False,
                                  flags.data(), nullptr, stderr);
  if (status == 0) {
    std::vector<int> index(pts.size(), -1);
    facetT* facet;
    vertexT *vertex, **vertexp;
    FORALLfacets {
      std::array<std::uint32_t, 3> tri{};
      int k = 0;
      FOREACHvertex_(facet->vertices) {
        const int id = qh_pointid(qh, vertex->point);
        if (index[static_cast<std::size_t>(id)] < 0) {
          index[static_cast<std::size_t>(id)] = static_cast<int>(out.vertices.size());
          out.vertices.push_back(pts[static_cast<std::size_t>(id)]);
        }
        if (k < 3)
          tri[static_cast<std::size_t>(k++)] =
              static_cast<std::uint32_t>(index[static_cast<std::size_t>(id)]);
      }
      const Vec3 n{facet->normal[0], facet->normal[1], facet->normal[2]};
      const Vec3 a = out.vertices[tri[0]], b = out.vertices[tri[1]], c = out.vertices[tri[2]];
      if (glm::dot(glm::cross(b - a, c - a), n) < 0.0)
        std::swap(tri[1], tri[2]);
      out.triangles.push_back(tri);
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  return out;
}

void run(benchmark::State& state, const std::string& model, bool search, bool peer) {
  const Cells& c = cells().at(model);
  const double tol = search ? kSearchTolerance * c.diagonal : 0.0;
  const std::size_t cap = search ? kSearchVertices : std::numeric_limits<std::size_t>::max();
  std::vector<double> coords;
  std::size_t vertices = 0;
  for (auto _ : state) {
    vertices = 0;
    for (const auto& s : c.sets) {
      const HullMesh h = peer ? qhullHull(s, tol, coords) : hapticd::decomp::quickHull(s, tol, cap);
      vertices += h.vertices.size();
      benchmark::DoNotOptimize(h.triangles.data());
    }
  }
  const double hulls = static_cast<double>(c.sets.size());
  state.counters["hulls"] = hulls;
  state.counters["points"] = static_cast<double>(c.points);
  state.counters["hull_vertices"] = static_cast<double>(vertices);
}

const bool registered = [] {
  for (const auto& [model, c] : cells())
    for (const bool search : {false, true}) {
      const std::string suffix = model + (search ? "/search" : "/exact");
      for (const bool peer : {false, true})
        benchmark::RegisterBenchmark(
            ((peer ? "Peer/Qhull-hull/" : "Hull/ours/") + suffix).c_str(),
            [model = model, search, peer](benchmark::State& s) { run(s, model, search, peer); })
            ->Unit(benchmark::kMillisecond)
            ->MinTime(0.5);
    }
  return true;
}();

}  // namespace
