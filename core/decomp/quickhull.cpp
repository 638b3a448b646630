#include "core/decomp/quickhull.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapticd::decomp {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

struct Face {
  std::array<std::uint32_t, 3> v{};   // point indices, counter-clockwise from outside
  std::array<std::uint32_t, 3> nb{};  // nb[e]: the face across edge v[e] -> v[e+1]
  Vec3 n{0.0};
  double offset = 0.0;
  std::vector<std::uint32_t> outside;  // points above this face by more than the tolerance
  std::uint32_t far = kNone;
  double far_d = 0.0;
  bool alive = true;
};

struct HorizonEdge {
  std::uint32_t a, b;        // the edge, as the visible face ran it
  std::uint32_t face, edge;  // the hidden face across it and the edge's index there
};

class Builder {
 public:
  Builder(std::span<const Vec3> p, double tol, double eps) : p_(p), tol_(tol), eps_(eps) {}

  bool init();
  void run(std::size_t max_vertices);
  HullMesh output() const;

 private:
  double dist(const Face& f, std::uint32_t i) const { return glm::dot(f.n, p_[i]) - f.offset; }
  std::uint32_t addFace(std::uint32_t a, std::uint32_t b, std::uint32_t c);
  void assign(std::uint32_t point, std::span<const std::uint32_t> faces);
  bool horizon(std::uint32_t start, std::uint32_t apex);
  void addPoint(std::uint32_t face);

  std::span<const Vec3> p_;
  double tol_;  // outside sets: points within it of the hull are dropped
  // visibility: a face the apex is above by more than rounding's is replaced, however little,
  // so that every edge stays convex (with `tol_` here, a face the apex lay just above stayed,
  // the new faces folded over it by up to `tol_`, and later horizons over those folds turned
  // whole faces inside out: pieces whose triangles were not their hull)
  double eps_;
  std::vector<Face> faces_;
  // faces that may have outside points, farthest point first (ties: lower face index)
  std::vector<std::pair<double, std::uint32_t>> pending_;
  void push(std::uint32_t f) {
    if (faces_[f].outside.empty())
      return;
    pending_.push_back({faces_[f].far_d, f});
    std::push_heap(pending_.begin(), pending_.end(), farther);
  }
  static bool farther(const std::pair<double, std::uint32_t>& a,
                      const std::pair<double, std::uint32_t>& b) {
    return a.first != b.first ? a.first < b.first : a.second > b.second;
  }
  std::vector<std::uint32_t> visible_;
  std::vector<HorizonEdge> horizon_;
  std::vector<std::uint32_t> mark_;  // per face: the pass that saw it visible
  std::uint32_t pass_ = 0;
  std::vector<std::uint32_t> by_a_;  // per point: new face starting there (this pass)
  std::vector<std::uint32_t> by_a_pass_;
  std::size_t vertex_count_ = 0;
  double max_outside_ = 0.0;
};

std::uint32_t Builder::addFace(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  Face f;
  f.v = {a, b, c};
  f.nb = {kNone, kNone, kNone};
  const Vec3 n = glm::cross(p_[b] - p_[a], p_[c] - p_[a]);
  const double len = glm::length(n);
  f.n = len > 0.0 ? n / len : Vec3{0.0};
  f.offset = glm::dot(f.n, p_[a]);
  faces_.push_back(std::move(f));
  mark_.push_back(0);
  return static_cast<std::uint32_t>(faces_.size() - 1);
}

// puts `point` on the first of `faces` it lies above (by more than the tolerance), or drops it
void Builder::assign(std::uint32_t point, std::span<const std::uint32_t> faces) {
  for (std::uint32_t fi : faces) {
    Face& f = faces_[fi];
    const double d = dist(f, point);
    if (d > tol_) {
      f.outside.push_back(point);
      if (d > f.far_d)
        f.far_d = d, f.far = point;
      return;
    }
  }
}

bool Builder::init() {
  const std::size_t n = p_.size();
  if (n < 4)
    return false;
  // extreme points along the axes; the farthest pair of them starts the simplex
  std::array<std::uint32_t, 6> ext{};
  for (std::uint32_t i = 0; i < n; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      const auto axis = static_cast<glm::length_t>(a);
      if (p_[i][axis] < p_[ext[2 * a]][axis])
        ext[2 * a] = i;
      if (p_[i][axis] > p_[ext[2 * a + 1]][axis])
        ext[2 * a + 1] = i;
    }
  }
  std::uint32_t i0 = 0, i1 = 0;
  double best = -1.0;
  for (std::size_t a = 0; a < 6; ++a)
    for (std::size_t b = a + 1; b < 6; ++b) {
      const double d = glm::length(p_[ext[a]] - p_[ext[b]]);
      if (d > best)
        best = d, i0 = ext[a], i1 = ext[b];
    }
  if (best <= tol_)
    return false;
  const Vec3 axis = (p_[i1] - p_[i0]) / best;
  std::uint32_t i2 = 0;
  best = -1.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec3 r = p_[i] - p_[i0];
    const double d = glm::length(r - axis * glm::dot(r, axis));
    if (d > best)
      best = d, i2 = i;
  }
  if (best <= tol_)
    return false;
  const Vec3 nrm = glm::normalize(glm::cross(p_[i1] - p_[i0], p_[i2] - p_[i0]));
  std::uint32_t i3 = 0;
  best = -1.0;
  double side = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double d = glm::dot(p_[i] - p_[i0], nrm);
    if (std::abs(d) > best)
      best = std::abs(d), i3 = i, side = d;
  }
  if (best <= tol_)
    return false;
  if (side > 0.0)
    std::swap(i1, i2);  // i3 behind the face (i0, i1, i2)
  const std::uint32_t f0 = addFace(i0, i1, i2);
  const std::uint32_t f1 = addFace(i0, i3, i1);
  const std::uint32_t f2 = addFace(i1, i3, i2);
  const std::uint32_t f3 = addFace(i2, i3, i0);
  // adjacency of the tetrahedron: the face holding the reversed edge
  for (std::uint32_t f : {f0, f1, f2, f3})
    for (std::uint32_t e = 0; e < 3; ++e) {
      const std::uint32_t a = faces_[f].v[e], b = faces_[f].v[(e + 1) % 3];
      for (std::uint32_t g : {f0, f1, f2, f3})
        for (std::uint32_t k = 0; k < 3; ++k)
          if (faces_[g].v[k] == b && faces_[g].v[(k + 1) % 3] == a)
            faces_[f].nb[e] = g;
    }
  vertex_count_ = 4;
  const std::array<std::uint32_t, 4> all{f0, f1, f2, f3};
  for (std::uint32_t i = 0; i < n; ++i)
    if (i != i0 && i != i1 && i != i2 && i != i3)
      assign(i, all);
  for (std::uint32_t f : all)
    push(f);
  by_a_.assign(n, kNone);
  by_a_pass_.assign(n, 0);
  return true;
}

// the faces visible from `apex` (connected to `start`) and the horizon loop around them
bool Builder::horizon(std::uint32_t start, std::uint32_t apex) {
  ++pass_;
  visible_.clear();
  horizon_.clear();
  struct Frame {
    std::uint32_t face, first, k;
  };
  std::vector<Frame> stack{{start, 0, 0}};
  mark_[start] = pass_;
  visible_.push_back(start);
  while (!stack.empty()) {
    Frame& fr = stack.back();
    const std::uint32_t count = fr.face == start ? 3u : 2u;
    if (fr.k == count) {
      stack.pop_back();
      continue;
    }
    const std::uint32_t e = (fr.first + fr.k) % 3;
    ++fr.k;
    const Face& f = faces_[fr.face];
    const std::uint32_t g = f.nb[e];
    if (g == kNone)
      return false;
    if (mark_[g] == pass_)
      continue;
    if (dist(faces_[g], apex) > eps_) {
      mark_[g] = pass_;
      visible_.push_back(g);
      std::uint32_t back = 0;
      while (back < 3 && faces_[g].nb[back] != fr.face)
        ++back;
      if (back == 3)
        return false;
      stack.push_back({g, (back + 1) % 3, 0});  // `fr` is not used after this
    } else {
      std::uint32_t back = 0;
      while (back < 3 && faces_[g].nb[back] != fr.face)
        ++back;
      if (back == 3)
        return false;
      horizon_.push_back({f.v[e], f.v[(e + 1) % 3], g, back});
    }
  }
  // a simple loop: every vertex starts exactly one horizon edge
  for (const HorizonEdge& h : horizon_) {
    if (by_a_pass_[h.a] == pass_)
      return false;
    by_a_pass_[h.a] = pass_;
  }
  return horizon_.size() >= 3;
}

void Builder::addPoint(std::uint32_t fi) {
  const std::uint32_t apex = faces_[fi].far;
  if (!horizon(fi, apex)) {
    // not a clean horizon (a near-degenerate configuration): drop the point, remember how far
    Face& f = faces_[fi];
    max_outside_ = std::max(max_outside_, f.far_d);
    f.outside.erase(std::find(f.outside.begin(), f.outside.end(), apex));
    f.far = kNone;
    f.far_d = 0.0;
    for (std::uint32_t q : f.outside) {
      const double d = dist(f, q);
      if (d > f.far_d)
        f.far_d = d, f.far = q;
    }
    push(fi);
    return;
  }
  std::vector<std::uint32_t> made;
  made.reserve(horizon_.size());
  for (const HorizonEdge& h : horizon_) {
    const std::uint32_t nf = addFace(h.a, h.b, apex);
    made.push_back(nf);
    faces_[nf].nb[0] = h.face;
    faces_[h.face].nb[h.edge] = nf;
    by_a_[h.a] = nf;
  }
  for (std::uint32_t nf : made) {
    Face& f = faces_[nf];
    f.nb[1] = by_a_[f.v[1]];  // edge b -> apex: the new face starting at b
  }
  for (std::uint32_t nf : made) {
    const std::uint32_t next = faces_[nf].nb[1];
    faces_[next].nb[2] = nf;  // its edge apex -> a borders us
  }
  for (std::uint32_t vf : visible_) {
    Face& f = faces_[vf];
    f.alive = false;
    for (std::uint32_t q : f.outside)
      if (q != apex)
        assign(q, made);
    f.outside.clear();
    f.outside.shrink_to_fit();
  }
  ++vertex_count_;
  for (std::uint32_t nf : made)
    push(nf);
}

void Builder::run(std::size_t max_vertices) {
  while (!pending_.empty()) {
    std::pop_heap(pending_.begin(), pending_.end(), farther);
    const std::uint32_t fi = pending_.back().second;
    pending_.pop_back();
    if (!faces_[fi].alive || faces_[fi].outside.empty())
      continue;
    if (vertex_count_ >= max_vertices) {
      max_outside_ = std::max(max_outside_, faces_[fi].far_d);
      continue;
    }
    addPoint(fi);
  }
}

HullMesh Builder::output() const {
  HullMesh h;
  std::vector<std::uint32_t> remap(p_.size(), kNone);
  for (const Face& f : faces_) {
    if (!f.alive)
      continue;
    Triangle t{};
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& r = remap[f.v[static_cast<std::size_t>(k)]];
      if (r == kNone) {
        r = static_cast<std::uint32_t>(h.vertices.size());
        h.vertices.push_back(p_[f.v[static_cast<std::size_t>(k)]]);
      }
      t[static_cast<std::size_t>(k)] = r;
    }
    h.triangles.push_back(t);
  }
  h.max_outside = max_outside_;
  return h;
}

}  // namespace

HullMesh quickHull(std::span<const Vec3> points, double tolerance, std::size_t max_vertices) {
  if (points.size() < 4)
    return {};
  Vec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};
  for (const Vec3& p : points)
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  const double scale = glm::length(hi - lo);
  if (!(scale > 0.0) || !std::isfinite(scale))
    return {};
  Builder b(points, std::max(tolerance, 1e-12 * scale), 1e-12 * scale);
  if (!b.init())
    return {};
  b.run(std::max<std::size_t>(max_vertices, 4));
  return b.output();
}

double meshVolume(std::span<const Vec3> vertices, std::span<const Triangle> triangles) {
  if (vertices.empty())
    return 0.0;
  const Vec3 o = vertices[0];
  double six_v = 0.0;
  for (const Triangle& t : triangles) {
    const Vec3 a = vertices[t[0]] - o, b = vertices[t[1]] - o, c = vertices[t[2]] - o;
    six_v += glm::dot(a, glm::cross(b, c));
  }
  return six_v / 6.0;
}

}  // namespace hapticd::decomp
