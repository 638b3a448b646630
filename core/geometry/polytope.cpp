#include "core/geometry/polytope.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <utility>

#include "core/geometry/rotation.h"

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace hapticd::geom {

std::string Feature::name() const {
  switch (type) {
    case FeatureType::kVertex:
      return "V" + std::to_string(index);
    case FeatureType::kEdge:
      return "E" + std::to_string(index);
    case FeatureType::kFace:
      return "F" + std::to_string(index);
    case FeatureType::kNone:
      break;
  }
  return "-";
}

namespace {

// Octahedral map of the unit sphere to [-1, 1]^2 (continuous, nearly uniform cells).
std::pair<double, double> octEncode(const Vec3& d) {
  const double s = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
  double u = d.x / s;
  double v = d.y / s;
  if (d.z < 0.0) {
    const double u0 = u;
    u = (1.0 - std::abs(v)) * (u0 >= 0.0 ? 1.0 : -1.0);
    v = (1.0 - std::abs(u0)) * (v >= 0.0 ? 1.0 : -1.0);
  }
  return {u, v};
}

Vec3 octDecode(double u, double v) {
  Vec3 d{u, v, 1.0 - std::abs(u) - std::abs(v)};
  if (d.z < 0.0) {
    const double x = d.x;
    d.x = (1.0 - std::abs(d.y)) * (x >= 0.0 ? 1.0 : -1.0);
    d.y = (1.0 - std::abs(x)) * (d.y >= 0.0 ? 1.0 : -1.0);
  }
  return glm::normalize(d);
}

constexpr int kLookupSide = 16;

std::size_t lookupCell(const Vec3& dir) {
  const auto [u, v] = octEncode(dir);
  auto cell = [](double c) {
    const int i = static_cast<int>(std::floor((c + 1.0) * 0.5 * kLookupSide));
    return static_cast<std::size_t>(std::clamp(i, 0, kLookupSide - 1));
  };
  return cell(u) * kLookupSide + cell(v);
}

// Merges points closer than `tol` (greedy, in x-sorted order). Returns the kept points.
std::vector<Vec3> mergeNearDuplicates(std::span<const Vec3> points, double tol) {
  std::vector<std::size_t> order(points.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t i, std::size_t j) { return points[i].x < points[j].x; });
  std::vector<Vec3> kept;
  kept.reserve(points.size());
  std::vector<std::size_t> kept_sorted;  // indices into kept, in x order (kept is built in x order)
  const double tol2 = tol * tol;
  std::size_t window_start = 0;
  for (std::size_t idx : order) {
    const Vec3& p = points[idx];
    while (window_start < kept.size() && kept[window_start].x < p.x - tol)
      ++window_start;
    bool duplicate = false;
    for (std::size_t k = window_start; k < kept.size(); ++k) {
      const Vec3 d = kept[k] - p;
      if (glm::dot(d, d) <= tol2) {
        duplicate = true;
        break;
      }
    }
    if (!duplicate)
      kept.push_back(p);
  }
  return kept;
}

// RAII owner of one Qhull run.
class QhullRun {
 public:
  QhullRun() {
    err_ = open_memstream(&err_text_, &err_size_);
    qh_zero(&qh_, err_);
  }
  ~QhullRun() {
    qh_freeqhull(&qh_, !qh_ALL);
    int curlong = 0, totlong = 0;
    qh_memfreeshort(&qh_, &curlong, &totlong);
    if (err_ != nullptr)
      std::fclose(err_);
    std::free(err_text_);
  }
  QhullRun(const QhullRun&) = delete;
  QhullRun& operator=(const QhullRun&) = delete;

  int run(std::vector<double>& coords) {
    char flags[] = "qhull Qx C-0";
    return qh_new_qhull(&qh_, 3, static_cast<int>(coords.size() / 3), coords.data(), False, flags,
                        nullptr, err_);
  }
  std::string errorText() {
    if (err_ != nullptr)
      std::fflush(err_);
    std::string s = err_text_ != nullptr ? std::string(err_text_, err_size_) : std::string();
    const auto nl = s.find('\n');
    return nl == std::string::npos ? s : s.substr(0, nl);
  }
  qhT* qh() { return &qh_; }

 private:
  qhT qh_{};
  FILE* err_ = nullptr;
  char* err_text_ = nullptr;
  std::size_t err_size_ = 0;
};

// The points checked (count, finite, size), near-duplicates merged, and the volume checked
// relative to the size (qhull's "flat simplex" errors are cryptic).
Result<std::vector<Vec3>> hullInput(std::span<const Vec3> points, const HullOptions& options) {
  if (points.size() > options.max_input_points) {
    return Error{"too many points: " + std::to_string(points.size()) + " (limit " +
                 std::to_string(options.max_input_points) + ")"};
  }
  if (points.size() < 4) {
    return Error{"a convex hull needs at least 4 non-coplanar points, got " +
                 std::to_string(points.size())};
  }
  Vec3 lo{std::numeric_limits<double>::max()};
  Vec3 hi{-std::numeric_limits<double>::max()};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    if (!finite(p)) {
      return Error{"point " + std::to_string(i) + " is not finite (NaN or Inf)"};
    }
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const double diagonal = glm::length(hi - lo);
  if (!std::isfinite(diagonal) || diagonal > 1e150) {
    return Error{"coordinates too large (the bounding box spans more than 1e150)"};
  }
  if (!(diagonal > 0.0)) {
    return Error{hi == lo ? "all points coincide (the hull has no volume)"
                          : "coordinates too small (the bounding box's size underflows)"};
  }
  if (diagonal < 1e-150)
    return Error{"coordinates too small (the bounding box spans less than 1e-150)"};
  std::vector<Vec3> merged = mergeNearDuplicates(points, options.merge_tolerance * diagonal);
  if (merged.size() < 4) {
    return Error{"a convex hull needs at least 4 distinct non-coplanar points, got " +
                 std::to_string(merged.size()) + " after merging near-duplicates"};
  }

  {
    std::size_t i0 = 0, i1 = 0;
    double best = -1.0;
    for (std::size_t i = 0; i < merged.size(); ++i) {
      const double d = glm::length(merged[i] - merged[0]);
      if (d > best)
        best = d, i1 = i;
    }
    const Vec3 axis = glm::normalize(merged[i1] - merged[i0]);
    std::size_t i2 = 0;
    best = -1.0;
    for (std::size_t i = 0; i < merged.size(); ++i) {
      const Vec3 r = merged[i] - merged[i0];
      const double d = glm::length(r - axis * glm::dot(r, axis));
      if (d > best)
        best = d, i2 = i;
    }
    if (best <= 1e-12 * diagonal)
      return Error{"all points are collinear (the hull has no volume)"};
    const Vec3 n = glm::normalize(glm::cross(merged[i1] - merged[i0], merged[i2] - merged[i0]));
    best = 0.0;
    for (const Vec3& p : merged)
      best = std::max(best, std::abs(glm::dot(p - merged[i0], n)));
    if (best <= 1e-12 * diagonal)
      return Error{"all points are coplanar (the hull has no volume)"};
  }
  return merged;
}

}  // namespace

Result<Polytope> Polytope::fromPoints(std::span<const Vec3> points, const HullOptions& options) {
  auto merged = hullInput(points, options);
  if (!merged.ok())
    return merged.error();
  Polytope poly;
  std::vector<std::vector<std::uint32_t>> loops;
  std::vector<Vec3> normals;
  if (auto ok = poly.takeHull(merged.value(), &loops, &normals); !ok.ok())
    return ok.error();
  if (poly.vertices_.size() > options.max_vertices) {
    return Error{"hull has " + std::to_string(poly.vertices_.size()) + " vertices (limit " +
                 std::to_string(options.max_vertices) + ")"};
  }
  if (poly.vertices_.size() > std::numeric_limits<std::uint16_t>::max()) {
    return Error{"hull has more than 65535 vertices"};
  }
  if (auto ok = poly.buildFacesAndEdges(loops, normals); !ok.ok())
    return ok.error();
  poly.buildVertexEdges();
  if (auto ok = poly.buildFaceOrder(); !ok.ok())
    return ok.error();
  poly.buildLookup();
  return poly;
}

// The hull's vertices (in the order qhull's facets meet them) and each facet's vertex loop,
// counter-clockwise seen from outside, with its unit normal.
Result<bool> Polytope::takeHull(const std::vector<Vec3>& merged,
                                std::vector<std::vector<std::uint32_t>>* loops,
                                std::vector<Vec3>* normals) {
  std::vector<double> coords;
  coords.reserve(merged.size() * 3);
  for (const Vec3& p : merged)
    coords.insert(coords.end(), {p.x, p.y, p.z});

  QhullRun q;
  if (const int code = q.run(coords); code != 0) {
    return Error{"qhull failed (code " + std::to_string(code) + "): " + q.errorText()};
  }
  qhT* qh = q.qh();

  std::vector<std::int64_t> vertex_of_point(merged.size(), -1);

  facetT* facet = nullptr;
  FORALLfacets {
    if (facet->upperdelaunay || !facet->normal)
      continue;
    setT* fverts = qh_facet3vertex(qh, facet);
    std::vector<std::uint32_t> loop;
    vertexT* vertex = nullptr;
    vertexT** vertexp = nullptr;
    FOREACHvertex_(fverts) {
      const int pid = qh_pointid(qh, vertex->point);
      if (pid < 0 || static_cast<std::size_t>(pid) >= merged.size())
        continue;
      auto& slot = vertex_of_point[static_cast<std::size_t>(pid)];
      if (slot < 0) {
        slot = static_cast<std::int64_t>(vertices_.size());
        vertices_.push_back(Vertex{merged[static_cast<std::size_t>(pid)], 0, 0});
      }
      loop.push_back(static_cast<std::uint32_t>(slot));
    }
    qh_settempfree(qh, &fverts);
    if (loop.size() < 3)
      return Error{"qhull returned a degenerate facet"};
    // orient counter-clockwise seen from outside (Newell normal along qhull's outward normal)
    Vec3 newell{0.0};
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const Vec3& p = vertices_[loop[k]].p;
      const Vec3& r = vertices_[loop[(k + 1) % loop.size()]].p;
      newell +=
          Vec3{(p.y - r.y) * (p.z + r.z), (p.z - r.z) * (p.x + r.x), (p.x - r.x) * (p.y + r.y)};
    }
    const Vec3 qn{facet->normal[0], facet->normal[1], facet->normal[2]};
    if (glm::dot(newell, qn) < 0.0) {
      std::reverse(loop.begin(), loop.end());
      newell = -newell;
    }
    const double len = glm::length(newell);
    normals->push_back(len > 0.0 ? newell / len : qn);
    loops->push_back(std::move(loop));
  }
  return true;
}

// Faces, edges (each once in each direction) and the Voronoi planes from the face loops; the
// hull must be a closed 2-manifold of Euler characteristic 2.
Result<bool> Polytope::buildFacesAndEdges(const std::vector<std::vector<std::uint32_t>>& loops,
                                          const std::vector<Vec3>& normals) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> edge_of;
  faces_.reserve(loops.size());
  for (std::size_t f = 0; f < loops.size(); ++f) {
    const auto& loop = loops[f];
    Face face;
    face.normal = normals[f];
    double offset = 0.0;
    for (std::uint32_t v : loop)
      offset += glm::dot(face.normal, vertices_[v].p);
    face.offset = offset / static_cast<double>(loop.size());
    face.first = static_cast<std::uint32_t>(face_edges_.size());
    face.count = static_cast<std::uint32_t>(loop.size());
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const std::uint32_t v0 = loop[k];
      const std::uint32_t v1 = loop[(k + 1) % loop.size()];
      const auto key = std::minmax(v0, v1);
      auto it = edge_of.find(key);
      std::uint32_t e = 0;
      if (it == edge_of.end()) {
        e = static_cast<std::uint32_t>(edges_.size());
        Edge edge;
        edge.tail = v0;
        edge.head = v1;
        edge.face = {static_cast<std::uint32_t>(f), std::numeric_limits<std::uint32_t>::max()};
        edges_.push_back(edge);
        edge_of.emplace(key, e);
      } else {
        e = it->second;
        Edge& edge = edges_[e];
        if (edge.tail != v1 || edge.head != v0 ||
            edge.face[1] != std::numeric_limits<std::uint32_t>::max()) {
          return Error{"hull is not a closed 2-manifold (edge used twice in one direction)"};
        }
        edge.face[1] = static_cast<std::uint32_t>(f);
      }
      const Vec3 d = vertices_[v1].p - vertices_[v0].p;
      face_edges_.push_back(FaceEdge{e, v0, glm::normalize(glm::cross(face.normal, d))});
    }
    faces_.push_back(face);
  }
  for (Edge& edge : edges_) {
    if (edge.face[1] == std::numeric_limits<std::uint32_t>::max()) {
      return Error{"hull is not closed (an edge has one face)"};
    }
    const Vec3 d = vertices_[edge.head].p - vertices_[edge.tail].p;
    edge.length = glm::length(d);
    edge.dir = d / edge.length;
    edge.fe_normal[0] = glm::normalize(glm::cross(edge.dir, faces_[edge.face[0]].normal));
    edge.fe_normal[1] = glm::normalize(glm::cross(faces_[edge.face[1]].normal, edge.dir));
  }
  const std::size_t nv = vertices_.size(), ne = edges_.size(), nf = faces_.size();
  if (nv + nf != ne + 2)
    return Error{"hull fails Euler's formula V - E + F = 2"};
  return true;
}

// vertex -> incident edges
void Polytope::buildVertexEdges() {
  const std::size_t nv = vertices_.size(), ne = edges_.size();
  std::vector<std::uint32_t> degree(nv, 0);
  for (const Edge& edge : edges_)
    ++degree[edge.tail], ++degree[edge.head];
  std::uint32_t first = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    vertices_[v].first = first;
    first += degree[v];
  }
  vertex_edges_.resize(first);
  for (std::size_t e = 0; e < ne; ++e) {
    const Edge& edge = edges_[e];
    auto add = [&](std::uint32_t v, std::uint32_t other, const Vec3& out) {
      Vertex& vert = vertices_[v];
      vertex_edges_[vert.first + vert.count++] =
          VertexEdge{static_cast<std::uint32_t>(e), other, out};
    };
    add(edge.tail, edge.head, edge.dir);
    add(edge.head, edge.tail, -edge.dir);
  }
}

// depth-first face order: consecutive faces are mostly adjacent
Result<bool> Polytope::buildFaceOrder() {
  const std::size_t nf = faces_.size();
  {
    std::vector<bool> seen(nf, false);
    std::vector<std::uint32_t> stack{0};
    face_order_.reserve(nf);
    while (!stack.empty()) {
      const std::uint32_t f = stack.back();
      stack.pop_back();
      if (seen[f])
        continue;
      seen[f] = true;
      face_order_.push_back(f);
      for (const FaceEdge& fe : faceEdges(f)) {
        const Edge& edge = edges_[fe.edge];
        const std::uint32_t g = edge.face[0] == f ? edge.face[1] : edge.face[0];
        if (!seen[g])
          stack.push_back(g);
      }
    }
    if (face_order_.size() != nf)
      return Error{"hull faces are not connected"};
  }
  return true;
}

// centroid, radius, and the directional lookup table: the extreme vertex for each cell's
// central direction
void Polytope::buildLookup() {
  const std::size_t nv = vertices_.size();
  Vec3 centroid{0.0};
  for (const Vertex& v : vertices_)
    centroid += v.p;
  centroid_ = centroid / static_cast<double>(nv);
  for (const Vertex& v : vertices_) {
    radius_ = std::max(radius_, glm::length(v.p - centroid_));
  }

  for (int i = 0; i < kLookupSide; ++i) {
    for (int j = 0; j < kLookupSide; ++j) {
      const double u = (i + 0.5) / kLookupSide * 2.0 - 1.0;
      const double v = (j + 0.5) / kLookupSide * 2.0 - 1.0;
      const Vec3 dir = octDecode(u, v);
      std::uint32_t best = 0;
      double best_dot = -std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < nv; ++k) {
        const double d = glm::dot(vertices_[k].p - centroid_, dir);
        if (d > best_dot)
          best_dot = d, best = static_cast<std::uint32_t>(k);
      }
      lookup_[static_cast<std::size_t>(i) * kLookupSide + static_cast<std::size_t>(j)] =
          static_cast<std::uint16_t>(best);
    }
  }
}

std::uint32_t Polytope::support(const Vec3& dir, std::uint32_t hint) const {
  std::uint32_t v = hint < vertices_.size() ? hint : 0;
  double best = glm::dot(vertices_[v].p, dir);
  // hill climbing on the vertex graph; a vertex with no better neighbour is a global maximum
  // on a convex polytope. The bound only guards against NaN directions.
  for (std::size_t step = 0; step <= vertices_.size(); ++step) {
    std::uint32_t next = v;
    for (const VertexEdge& ve : vertexEdges(v)) {
      const double d = glm::dot(vertices_[ve.other].p, dir);
      if (d > best)
        best = d, next = ve.other;
    }
    if (next == v)
      break;
    v = next;
  }
  return v;
}

std::uint32_t Polytope::lookup(const Vec3& dir) const {
  return lookup_[lookupCell(dir)];
}

}  // namespace hapticd::geom
