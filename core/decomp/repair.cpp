#include "core/decomp/repair.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "core/decomp/bvh.h"
#include "core/decomp/quickhull.h"

namespace hapticd::decomp {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    std::uint64_t h = static_cast<std::uint64_t>(k.x) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint64_t>(k.y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= static_cast<std::uint64_t>(k.z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return static_cast<std::size_t>(h);
  }
};

CellKey cellOf(const Vec3& p, const Vec3& origin, double cell) {
  const Vec3 q = (p - origin) / cell;
  return {static_cast<std::int64_t>(std::floor(q.x)), static_cast<std::int64_t>(std::floor(q.y)),
          static_cast<std::int64_t>(std::floor(q.z))};
}

// welds vertices within `tol` of an earlier one (grid of cell tol, the 27 neighbouring cells);
// returns the representative of each vertex (kNone for non-finite ones)
std::vector<std::uint32_t> weld(const std::vector<Vec3>& p,
                                const std::vector<bool>& finite,
                                const Vec3& origin,
                                double tol,
                                std::size_t* merged) {
  std::vector<std::uint32_t> rep(p.size(), kNone);
  std::unordered_map<CellKey, std::vector<std::uint32_t>, CellHash> grid;
  grid.reserve(p.size());
  *merged = 0;
  for (std::uint32_t i = 0; i < p.size(); ++i) {
    if (!finite[i])
      continue;
    const CellKey k = cellOf(p[i], origin, tol);
    std::uint32_t found = kNone;
    for (std::int64_t dx = -1; dx <= 1 && found == kNone; ++dx)
      for (std::int64_t dy = -1; dy <= 1 && found == kNone; ++dy)
        for (std::int64_t dz = -1; dz <= 1 && found == kNone; ++dz) {
          const auto it = grid.find({k.x + dx, k.y + dy, k.z + dz});
          if (it == grid.end())
            continue;
          for (std::uint32_t j : it->second)
            if (glm::length(p[j] - p[i]) <= tol) {
              found = j;
              break;
            }
        }
    if (found != kNone) {
      rep[i] = found;
      ++*merged;
    } else {
      rep[i] = i;
      grid[k].push_back(i);
    }
  }
  return rep;
}

// vertex clustering: every vertex moves to the mean of its grid cell
std::vector<std::uint32_t> cluster(const std::vector<Vec3>& p,
                                   std::vector<Vec3>& means,
                                   const std::vector<std::uint32_t>& rep,
                                   const Vec3& origin,
                                   double cell) {
  std::unordered_map<CellKey, std::uint32_t, CellHash> ids;
  std::vector<std::uint32_t> out(p.size(), kNone);
  std::vector<double> count;
  means.clear();
  for (std::uint32_t i = 0; i < p.size(); ++i) {
    if (rep[i] != i)
      continue;
    const auto [it, fresh] =
        ids.try_emplace(cellOf(p[i], origin, cell), static_cast<std::uint32_t>(means.size()));
    if (fresh)
      means.push_back(Vec3{0.0}), count.push_back(0.0);
    means[it->second] += p[i];
    count[it->second] += 1.0;
    out[i] = it->second;
  }
  for (std::size_t k = 0; k < means.size(); ++k)
    means[k] /= count[k];
  for (std::uint32_t i = 0; i < p.size(); ++i)
    if (rep[i] != kNone && rep[i] != i)
      out[i] = out[rep[i]];
  return out;
}

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
}

// drops degenerate and duplicate triangles; returns the kept ones
std::vector<Triangle> cleanTriangles(const std::vector<Triangle>& in,
                                     const std::vector<Vec3>& p,
                                     double area_eps,
                                     RepairCounts& counts) {
  std::vector<Triangle> out;
  out.reserve(in.size());
  std::vector<std::array<std::uint32_t, 3>> sorted;
  sorted.reserve(in.size());
  for (const Triangle& t : in) {
    const bool repeated = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    if (repeated || glm::length(glm::cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]])) <= area_eps) {
      ++counts.degenerate_triangles;
      continue;
    }
    out.push_back(t);
  }
  // duplicates: the same three vertices in any order; the first one stays
  std::vector<std::uint32_t> order(out.size());
  std::iota(order.begin(), order.end(), 0u);
  auto key = [&](std::uint32_t i) {
    std::array<std::uint32_t, 3> k = out[i];
    std::sort(k.begin(), k.end());
    return k;
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
    const auto ki = key(i), kj = key(j);
    return ki != kj ? ki < kj : i < j;
  });
  std::vector<bool> keep(out.size(), true);
  for (std::size_t k = 1; k < order.size(); ++k)
    if (key(order[k]) == key(order[k - 1]))
      keep[order[k]] = false, ++counts.duplicate_triangles;
  std::vector<Triangle> kept;
  kept.reserve(out.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    if (keep[i])
      kept.push_back(out[i]);
  return kept;
}

struct EdgeUse {
  std::uint64_t key;
  std::uint32_t tri;
  bool forward;  // the triangle runs min -> max
};

std::vector<EdgeUse> edgeUses(const std::vector<Triangle>& tris) {
  std::vector<EdgeUse> uses;
  uses.reserve(tris.size() * 3);
  for (std::uint32_t t = 0; t < tris.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = tris[t][static_cast<std::size_t>(e)];
      const std::uint32_t b = tris[t][static_cast<std::size_t>((e + 1) % 3)];
      uses.push_back({edgeKey(a, b), t, a < b});
    }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.tri < y.tri;
  });
  return uses;
}

// consistent winding breadth first over manifold edges, then each component outward; returns the
// component of every triangle
std::vector<std::uint32_t> orient(std::vector<Triangle>& tris,
                                  const std::vector<Vec3>& p,
                                  RepairCounts& counts) {
  const std::vector<EdgeUse> uses = edgeUses(tris);
  // neighbours over manifold edges, and components over any shared edge
  std::vector<std::vector<std::pair<std::uint32_t, bool>>> nb(tris.size());  // (other, same dir)
  std::vector<std::uint32_t> parent(tris.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x)
      x = parent[x] = parent[parent[x]];
    return x;
  };
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key)
      ++j;
    const std::size_t n = j - i;
    if (n == 1)
      ++counts.boundary_edges;
    if (n >= 3)
      ++counts.non_manifold_edges;
    if (n == 2) {
      const bool same = uses[i].forward == uses[i + 1].forward;
      nb[uses[i].tri].push_back({uses[i + 1].tri, same});
      nb[uses[i + 1].tri].push_back({uses[i].tri, same});
    }
    const std::uint32_t first = uses[i].tri;
    std::for_each(uses.begin() + static_cast<std::ptrdiff_t>(i) + 1,
                  uses.begin() + static_cast<std::ptrdiff_t>(j), [&](const EdgeUse& u) {
                    const std::uint32_t a = find(first), b = find(u.tri);
                    if (a != b)
                      parent[std::max(a, b)] = std::min(a, b);
                  });
    i = j;
  }
  std::vector<std::uint32_t> comp(tris.size(), kNone);
  std::vector<std::uint32_t> comp_id(tris.size(), kNone);
  std::uint32_t components = 0;
  for (std::uint32_t t = 0; t < tris.size(); ++t) {
    const std::uint32_t r = find(t);
    if (comp_id[r] == kNone)
      comp_id[r] = components++;
    comp[t] = comp_id[r];
  }
  counts.components = components;
  // breadth first from each component's first triangle
  std::vector<std::int8_t> flip(tris.size(), -1);
  std::deque<std::uint32_t> queue;
  for (std::uint32_t s = 0; s < tris.size(); ++s) {
    if (flip[s] >= 0)
      continue;
    flip[s] = 0;
    queue.push_back(s);
    while (!queue.empty()) {
      const std::uint32_t t = queue.front();
      queue.pop_front();
      for (const auto& [o, same] : nb[t]) {
        if (flip[o] >= 0)
          continue;
        flip[o] = static_cast<std::int8_t>(same ? 1 - flip[t] : flip[t]);
        queue.push_back(o);
      }
    }
  }
  std::vector<Triangle> original = tris;
  for (std::uint32_t t = 0; t < tris.size(); ++t)
    if (flip[t] == 1)
      std::swap(tris[t][1], tris[t][2]);
  // each component outward: positive signed volume about its own centroid
  std::vector<Vec3> centre(components, Vec3{0.0});
  std::vector<double> weight(components, 0.0);
  std::vector<bool> open(components, false);
  for (std::uint32_t t = 0; t < tris.size(); ++t) {
    centre[comp[t]] += p[tris[t][0]] + p[tris[t][1]] + p[tris[t][2]];
    weight[comp[t]] += 3.0;
  }
  for (std::uint32_t c = 0; c < components; ++c)
    centre[c] /= weight[c];
  std::vector<double> volume(components, 0.0);
  for (std::uint32_t t = 0; t < tris.size(); ++t) {
    const Vec3& o = centre[comp[t]];
    volume[comp[t]] +=
        glm::dot(p[tris[t][0]] - o, glm::cross(p[tris[t][1]] - o, p[tris[t][2]] - o));
  }
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key)
      ++j;
    if (j - i != 2)
      open[comp[uses[i].tri]] = true;
    i = j;
  }
  for (std::uint32_t c = 0; c < components; ++c) {
    if (volume[c] < 0.0)
      ++counts.inverted_components;
    if (open[c])
      ++counts.open_components;
  }
  for (std::uint32_t t = 0; t < tris.size(); ++t) {
    if (volume[comp[t]] < 0.0)
      std::swap(tris[t][1], tris[t][2]);
    if (tris[t] != original[t])
      ++counts.flipped_triangles;
  }
  return comp;
}

// closes every boundary loop with a fan about its centroid (the scan's missing patch, as a
// winding number would fill it); returns the boundary edges left open (loops it could not follow)
std::size_t fillHoles(std::vector<Triangle>& tris, std::vector<Vec3>& p, RepairCounts& counts) {
  const std::vector<EdgeUse> uses = edgeUses(tris);
  // boundary edges as their triangle runs them: from -> to
  std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key)
      ++j;
    if (j - i == 1) {
      const auto lo = static_cast<std::uint32_t>(uses[i].key >> 32);
      const auto hi = static_cast<std::uint32_t>(uses[i].key & 0xffffffffu);
      boundary.push_back(uses[i].forward ? std::make_pair(lo, hi) : std::make_pair(hi, lo));
    }
    i = j;
  }
  std::sort(boundary.begin(), boundary.end());
  std::vector<bool> used(boundary.size(), false);
  std::size_t left_open = 0;
  for (std::size_t s = 0; s < boundary.size(); ++s) {
    if (used[s])
      continue;
    std::vector<std::uint32_t> loop{boundary[s].first};
    std::vector<std::size_t> edges{s};
    used[s] = true;
    std::uint32_t at = boundary[s].second;
    bool closed = false;
    while (loop.size() <= boundary.size()) {
      if (at == loop.front()) {
        closed = true;
        break;
      }
      // the first unused boundary edge leaving `at`
      auto it = std::lower_bound(boundary.begin(), boundary.end(), std::make_pair(at, 0u));
      while (it != boundary.end() && it->first == at &&
             used[static_cast<std::size_t>(it - boundary.begin())])
        ++it;
      if (it == boundary.end() || it->first != at)
        break;
      const auto k = static_cast<std::size_t>(it - boundary.begin());
      used[k] = true;
      edges.push_back(k);
      loop.push_back(at);
      at = it->second;
    }
    if (!closed || loop.size() < 3) {
      left_open += edges.size();
      continue;
    }
    Vec3 centre{0.0};
    for (std::uint32_t v : loop)
      centre += p[v];
    centre /= static_cast<double>(loop.size());
    const auto c = static_cast<std::uint32_t>(p.size());
    p.push_back(centre);
    for (std::size_t i = 0; i < loop.size(); ++i)
      tris.push_back({loop[(i + 1) % loop.size()], loop[i], c});
    ++counts.holes_filled;
  }
  return left_open;
}

}  // namespace

Result<RepairedMesh> repairMesh(const TriangleMesh& mesh,
                                const RepairLimits& limits,
                                RepairCounts& counts) {
  counts = {};
  counts.input_vertices = mesh.positions.size();
  counts.input_triangles = mesh.triangles.size();
  if (mesh.triangles.size() > limits.refuse_triangles)
    return Error{"the mesh has " + std::to_string(mesh.triangles.size()) +
                 " triangles, above the limit of " + std::to_string(limits.refuse_triangles) +
                 " (decimate it first)"};
  const std::vector<Vec3>& p = mesh.positions;
  std::vector<bool> finite(p.size());
  Vec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};
  for (std::size_t i = 0; i < p.size(); ++i) {
    finite[i] = std::isfinite(p[i].x) && std::isfinite(p[i].y) && std::isfinite(p[i].z) &&
                std::abs(p[i].x) < 1e150 && std::abs(p[i].y) < 1e150 && std::abs(p[i].z) < 1e150;
    if (!finite[i]) {
      ++counts.non_finite_vertices;
      continue;
    }
    lo = glm::min(lo, p[i]);
    hi = glm::max(hi, p[i]);
  }
  const double diag = glm::length(hi - lo);
  if (!(diag > 0.0) || !std::isfinite(diag))
    return Error{"the mesh has no extent (no finite vertices apart)"};
  std::size_t merged = 0;
  std::vector<std::uint32_t> rep = weld(p, finite, lo, 1e-9 * diag, &merged);
  counts.duplicate_vertices = merged;
  // triangles with usable indices, on representatives
  std::vector<Triangle> tris;
  tris.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    if (t[0] >= p.size() || t[1] >= p.size() || t[2] >= p.size()) {
      ++counts.bad_index_triangles;
      continue;
    }
    if (!finite[t[0]] || !finite[t[1]] || !finite[t[2]])
      continue;  // counted by vertex
    tris.push_back({rep[t[0]], rep[t[1]], rep[t[2]]});
  }
  RepairedMesh out;
  std::vector<Vec3> pos = p;
  if (tris.size() > limits.max_triangles) {
    // vertex clustering: about two triangles per occupied cell of a surface
    double area = 0.0;
    for (const Triangle& t : tris)
      area += 0.5 * glm::length(glm::cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]));
    double cell =
        std::sqrt(2.0 * area / static_cast<double>(std::max<std::size_t>(limits.decimate_to, 1)));
    counts.decimated_from = tris.size();
    std::vector<Triangle> dec;
    for (int attempt = 0; attempt < 12; ++attempt, cell *= 1.3) {
      std::vector<Vec3> means;
      const std::vector<std::uint32_t> to = cluster(p, means, rep, lo, cell);
      dec.clear();
      for (const Triangle& t : tris)
        if (to[t[0]] != to[t[1]] && to[t[1]] != to[t[2]] && to[t[0]] != to[t[2]])
          dec.push_back({to[t[0]], to[t[1]], to[t[2]]});
      pos = std::move(means);
      if (dec.size() <= limits.max_triangles)
        break;
    }
    tris = std::move(dec);
    out.decimation_cell = cell;
  }
  std::vector<Triangle> kept = cleanTriangles(tris, pos, 1e-14 * diag * diag, counts);
  if (out.decimation_cell > 0.0)
    counts.degenerate_triangles = 0;  // clustering makes them on purpose
  if (kept.empty())
    return Error{"no usable triangle (all degenerate, non-finite or out of range)"};
  // compact: referenced vertices only, in first-use order
  std::vector<std::uint32_t> remap(pos.size(), kNone);
  for (Triangle& t : kept)
    for (std::uint32_t& v : t) {
      if (remap[v] == kNone) {
        remap[v] = static_cast<std::uint32_t>(out.positions.size());
        out.positions.push_back(pos[v]);
      }
      v = remap[v];
    }
  const std::size_t representatives =
      out.decimation_cell > 0.0
          ? pos.size()
          : static_cast<std::size_t>(std::count_if(
                rep.begin(), rep.end(), [i = 0u](std::uint32_t r) mutable { return r == i++; }));
  counts.unreferenced_vertices = representatives - out.positions.size();
  orient(kept, out.positions, counts);
  const std::size_t open_edges = fillHoles(kept, out.positions, counts);
  out.triangles = std::move(kept);
  out.lo = Vec3{std::numeric_limits<double>::max()};
  out.hi = Vec3{-std::numeric_limits<double>::max()};
  for (const Vec3& v : out.positions)
    out.lo = glm::min(out.lo, v), out.hi = glm::max(out.hi, v);
  out.diagonal = glm::length(out.hi - out.lo);
  out.closed = open_edges == 0 && counts.non_manifold_edges == 0;
  if (out.closed)
    out.volume = meshVolume(out.positions, out.triangles);
  const TriangleBvh bvh(out.positions, out.triangles);
  counts.self_intersections =
      bvh.countCrossingPairs(limits.max_crossing_pairs_tested, &counts.self_intersections_capped);
  return out;
}

}  // namespace hapticd::decomp
