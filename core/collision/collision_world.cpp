#include "core/collision/collision_world.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cstddef>
#include <limits>

#include "core/common/slots.h"

namespace hapticd::collision {
namespace {

std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
  if (a > b)
    std::swap(a, b);
  return static_cast<std::uint64_t>(a) << 32 | b;
}

void toWorld(const Transform& X_WA, const PairResult& r, Contact& c) {
  c.status = r.status;
  c.distance = r.distance;
  c.normal = X_WA.rotate(r.normal);
  c.point_a = X_WA.apply(r.point_a);
  c.point_b = X_WA.apply(r.point_b);
  c.feature_a = r.fa;
  c.feature_b = r.fb;
  // the points in use only (those beyond the count are never read)
  c.manifold.count = r.manifold.count;
  c.manifold.truncated = r.manifold.truncated;
  for (std::size_t i = 0; i < c.manifold.count; ++i) {
    c.manifold.points[i].point = X_WA.apply(r.manifold.points[i].point);
    c.manifold.points[i].normal = X_WA.rotate(r.manifold.points[i].normal);
    c.manifold.points[i].depth = r.manifold.points[i].depth;
  }
}

// `from` into `to` but for the manifold's points beyond its count
static_assert(sizeof(Contact) == 360, "copyAnswer copies every field of a Contact: a new one too");
void copyAnswer(const Contact& from, Contact& to) {
  to.body_a = from.body_a;
  to.body_b = from.body_b;
  to.prim_a = from.prim_a;
  to.prim_b = from.prim_b;
  to.status = from.status;
  to.distance = from.distance;
  to.normal = from.normal;
  to.point_a = from.point_a;
  to.point_b = from.point_b;
  to.manifold.count = from.manifold.count;
  to.manifold.truncated = from.manifold.truncated;
  for (std::size_t i = 0; i < from.manifold.count; ++i)
    to.manifold.points[i] = from.manifold.points[i];
  to.feature_a = from.feature_a;
  to.feature_b = from.feature_b;
  to.age = from.age;
  to.answered = from.answered;
}

}  // namespace

CollisionWorld::CollisionWorld(const WorldOptions& options) : options_(options) {}

void CollisionWorld::reserve(std::size_t primitives, std::size_t pairs) {
  reserved_pairs_ = std::max(reserved_pairs_, pairs);
  sap_.reserve(primitives, pairs);
  prims_.reserve(primitives);
  prim_of_box_.reserve(primitives);
  tree_pairs_.reserve(pairs);
  pair_states_.reserve(pairs);
  supports_.reserve(2 * pairs);
  moved_.reserve(primitives);
  posed_.reserve(primitives);
  awake_.reserve(primitives);
  free_pair_states_.reserve(pairs);
  state_of_pair_.reserve(pairs);
  mapped_tree_states_.reserve(pairs);
  order_.reserve(pairs);
  contact_order_.reserve(pairs);
  contacts_.reserve(pairs);
  for (const Body& b : bodies_) {
    if (b.live && !b.tree.empty()) {
      reserveFronts();
      break;
    }
  }
}

void CollisionWorld::reserveFronts() {
  // a front holds the overlapping leaf pairs (at most the close pairs) and about as many node
  // pairs found apart around them; a front that does not fit is not kept (the next descent
  // starts at the roots, as without fronts)
  if (!options_.descent_fronts)
    return;
  const std::size_t need = 2 * reserved_pairs_;
  if (front_.capacity() < need) {
    front_.reserve(need);
    front_next_.reserve(need);
  }
}

Transform CollisionWorld::primitiveTransform(const Prim& p) const {
  const Body& b = bodies_[p.body];
  return b.T_WB * b.desc.primitives[p.index].X_BP;
}

namespace {

// a margin a body's boxes may grow by: a finite number >= 0
bool validMargin(double m) {
  return m >= 0.0 && std::isfinite(m);
}

}  // namespace

// shapes of at most this many vertices get their boxes by one pass over the vertices
constexpr std::size_t kSmallShape = 16;

Aabb CollisionWorld::primitiveBox(Prim& p) {
  const Polytope& shape = *bodies_[p.body].desc.primitives[p.index].shape;
  const Transform X = primitiveTransform(p);
  const double margin = bodies_[p.body].margin;
  Aabb box;
  const auto& vertices = shape.vertices();
  if (vertices.size() <= kSmallShape) {
    // a small piece: one pass over its vertices costs less than six climbs; the extremes are
    // the same values the climbs find
    const Vec3 rows[3] = {{X.R[0][0], X.R[1][0], X.R[2][0]},
                          {X.R[0][1], X.R[1][1], X.R[2][1]},
                          {X.R[0][2], X.R[1][2], X.R[2][2]}};
    Vec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
    for (const auto& v : vertices) {
      for (int k = 0; k < 3; ++k) {
        const double d = glm::dot(rows[k], v.p);
        lo[k] = std::min(lo[k], d);
        hi[k] = std::max(hi[k], d);
      }
    }
    for (int k = 0; k < 3; ++k) {
      box.lo[k] = lo[k] + X.t[k] - margin;
      box.hi[k] = hi[k] + X.t[k] + margin;
    }
    return box;
  }
  for (int k = 0; k < 3; ++k) {
    // world coordinate k of a vertex v is dot(row k of R, v) + t[k]: climb to its extremes
    const Vec3 row{X.R[0][k], X.R[1][k], X.R[2][k]};
    auto& lo_hint = p.hint[2 * static_cast<std::size_t>(k)];
    auto& hi_hint = p.hint[2 * static_cast<std::size_t>(k) + 1];
    lo_hint = shape.support(-row, lo_hint);
    hi_hint = shape.support(row, hi_hint);
    box.lo[k] = glm::dot(row, shape.vertices()[lo_hint].p) + X.t[k] - margin;
    box.hi[k] = glm::dot(row, shape.vertices()[hi_hint].p) + X.t[k] + margin;
  }
  return box;
}

std::uint32_t CollisionWorld::addBody(const BodyDesc& desc, const geom::Pose& X_WB) {
  const std::uint32_t id = takeSlot(bodies_, free_bodies_);
  Body& b = bodies_[id];
  b.desc = desc;
  b.X_WB = X_WB;
  b.T_WB = X_WB.toTransform();
  b.X_stepped = X_WB;
  b.live = true;
  b.radius = 0.0;
  b.base_margin = validMargin(desc.margin) ? desc.margin
                  : desc.kind == BodyKind::kProbe && validMargin(options_.probe_margin)
                      ? options_.probe_margin
                      : options_.box_margin;
  b.margin = b.base_margin;
  b.box_travel = 0.0;
  b.box_r1 = 0.0;
  b.small_pieces = true;
  for (const PrimitiveDesc& pd : desc.primitives) {
    b.small_pieces = b.small_pieces && pd.shape->vertices().size() <= kSmallShape;
    for (const auto& v : pd.shape->vertices()) {
      const Vec3 p = pd.X_BP.apply(v.p);
      b.radius = std::max(b.radius, glm::length(p));
      b.box_r1 = std::max(b.box_r1, std::abs(p.x) + std::abs(p.y) + std::abs(p.z));
    }
  }
  const bool tree =
      options_.piece_tree_min > 0 && desc.primitives.size() >= options_.piece_tree_min;
  std::uint32_t groups = 0, masks = 0;  // a tree body's box: any of its pieces' filters
  for (std::uint32_t i = 0; i < desc.primitives.size(); ++i) {
    const std::uint32_t pi = takeSlot(prims_, free_prims_);
    Prim& p = prims_[pi];
    p.body = id;
    p.index = i;
    p.live = true;
    p.shape = desc.primitives[i].shape.get();
    const Polytope& shape = *desc.primitives[i].shape;
    depth_scratch_.reserve(shape.faces().size());
    if (shape.faces().size() <= WorldOptions::kMaxTrackedFaces) {
      tracker_faces_ = std::max(tracker_faces_, shape.faces().size());
      tracker_edges_ = std::max(tracker_edges_, shape.edges().size());
      ++tracked_prims_;
    }
    for (std::size_t h = 0; h < 6; ++h)
      p.hint[h] = shape.lookup(Vec3{h / 2 == 0, h / 2 == 1, h / 2 == 2} * (h % 2 ? 1.0 : -1.0));
    BoxFilter filter;
    filter.body = id;
    filter.is_static = desc.kind == BodyKind::kStatic;
    filter.group = desc.group & desc.primitives[i].group;
    filter.mask = desc.mask & desc.primitives[i].mask;
    p.group = filter.group;
    p.mask = filter.mask;
    groups |= filter.group;
    masks |= filter.mask;
    bodies_[id].prims.push_back(pi);
    if (tree) {
      p.box = 0xffffffffu;  // in the body's tree, not in the sweep and prune
      continue;
    }
    p.box = sap_.add(primitiveBox(p), filter);
    if (prim_of_box_.size() <= p.box)
      prim_of_box_.resize(p.box + 1);
    prim_of_box_[p.box] = pi;
  }
  if (tree) {
    buildTree(bodies_[id]);
    BoxFilter filter;
    filter.body = id;
    filter.is_static = desc.kind == BodyKind::kStatic;
    filter.group = groups;
    filter.mask = masks;
    refit(id);
    const std::uint32_t h = sap_.add(bodies_[id].tree_W[0].box, filter);
    bodies_[id].box = h;
    if (prim_of_box_.size() <= h)
      prim_of_box_.resize(h + 1);
    prim_of_box_[h] = kBodyBox | id;
  }
  applyEvents(nullptr);
  // room for every body in the per-body lists, so that the servo thread's calls never grow them
  for (auto* list : {&moved_, &posed_, &awake_}) {
    if (list->capacity() < bodies_.size())
      list->reserve(2 * bodies_.size());
  }
  updateAwake(id);
  reserveTrackers();
  return id;
}

std::uint32_t CollisionWorld::trackerPoolSize() const {
  if (options_.depth_trackers != WorldOptions::kAutoTrackers)
    return options_.depth_trackers;
  const std::size_t per =
      std::max<std::size_t>(1, DepthTracker::bytesFor(tracker_faces_, tracker_edges_));
  const std::size_t want =
      std::min<std::size_t>(std::size_t{options_.depth_trackers_per_primitive} * tracked_prims_,
                            options_.depth_tracker_bytes / per);
  return static_cast<std::uint32_t>(
      std::min<std::size_t>(std::max<std::size_t>(want, WorldOptions::kMinAutoTrackers), kNil - 1));
}

void CollisionWorld::reserveTrackers() {
  const std::uint32_t n = trackerPoolSize();
  if (trackers_.size() < n) {
    const auto old = static_cast<std::uint32_t>(trackers_.size());
    trackers_.resize(n);
    tracker_owner_.resize(n, kNil);
    free_trackers_.reserve(n);
    // handed out from the back: the lowest new tracker first
    for (std::uint32_t t = n; t-- > old;)
      free_trackers_.push_back(t);
  }
  for (DepthTracker& t : trackers_)
    t.reserve(tracker_faces_, tracker_edges_);
}

std::size_t CollisionWorld::depthTrackerBytes() const {
  std::size_t bytes = 0;
  for (const DepthTracker& t : trackers_)
    bytes += t.reservedBytes();
  return bytes;
}

void CollisionWorld::buildTree(Body& b) {
  struct Item {
    Vec3 lo, hi, mid;
    double scale = 0.0;
    std::uint32_t prim = 0;
  };
  std::vector<Item> items;
  items.reserve(b.prims.size());
  for (std::uint32_t i = 0; i < b.prims.size(); ++i) {
    const PrimitiveDesc& pd = b.desc.primitives[i];
    Item it;
    it.prim = b.prims[i];
    it.lo = Vec3{std::numeric_limits<double>::infinity()};
    it.hi = -it.lo;
    double vmax = 0.0;
    for (const auto& v : pd.shape->vertices()) {
      const Vec3 w = pd.X_BP.apply(v.p);
      it.lo = glm::min(it.lo, w);
      it.hi = glm::max(it.hi, w);
      for (int k = 0; k < 3; ++k)
        vmax = std::max({vmax, std::abs(v.p[k]), std::abs(w[k])});
    }
    for (int k = 0; k < 3; ++k)
      it.scale = std::max(it.scale, std::abs(pd.X_BP.t[k]));
    it.scale += vmax;
    it.mid = 0.5 * (it.lo + it.hi);
    items.push_back(it);
  }
  b.tree.clear();
  b.tree.reserve(2 * items.size());
  std::size_t depth = 0;
  // top down: each node split at the median of its pieces' centres along its widest spread
  // (ties by piece index, so that the tree depends on the pieces alone)
  auto build = [&](auto&& self, std::size_t begin, std::size_t end,
                   std::size_t level) -> std::uint32_t {
    depth = std::max(depth, level);
    const auto node = static_cast<std::uint32_t>(b.tree.size());
    b.tree.emplace_back();
    Vec3 lo = items[begin].lo, hi = items[begin].hi, mlo = items[begin].mid, mhi = mlo;
    double scale = 0.0;
    for (std::size_t i = begin; i < end; ++i) {
      lo = glm::min(lo, items[i].lo);
      hi = glm::max(hi, items[i].hi);
      mlo = glm::min(mlo, items[i].mid);
      mhi = glm::max(mhi, items[i].mid);
      scale = std::max(scale, items[i].scale);
    }
    TreeNode n;
    n.c = 0.5 * (lo + hi);
    n.e = 0.5 * (hi - lo);
    n.scale = scale;
    if (end - begin == 1) {
      n.prim = items[begin].prim;
      b.tree[node] = n;
      return node;
    }
    const Vec3 spread = mhi - mlo;
    const int axis =
        spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
    const std::size_t mid = begin + (end - begin) / 2;
    std::nth_element(items.begin() + static_cast<std::ptrdiff_t>(begin),
                     items.begin() + static_cast<std::ptrdiff_t>(mid),
                     items.begin() + static_cast<std::ptrdiff_t>(end),
                     [axis](const Item& x, const Item& y) {
                       if (x.mid[axis] != y.mid[axis])
                         return x.mid[axis] < y.mid[axis];
                       return x.prim < y.prim;
                     });
    n.left = self(self, begin, mid, level + 1);
    n.right = self(self, mid, end, level + 1);
    b.tree[node] = n;
    return node;
  };
  build(build, 0, items.size(), 1);
  b.tree_W.assign(b.tree.size(), WorldNode{});
  // a leaf's `left` and `right` (no children) hold its piece's collision filter (Prim::group,
  // Prim::mask): the descent reads no Prim of a static body's piece, whose box is the leaf's
  for (std::size_t i = 0; i < b.tree.size(); ++i) {
    const std::uint32_t prim = b.tree[i].prim;
    b.tree_W[i].left = prim == 0xffffffffu ? b.tree[i].left : prims_[prim].group;
    b.tree_W[i].right = prim == 0xffffffffu ? b.tree[i].right : prims_[prim].mask;
    b.tree_W[i].prim = prim;
  }
  // a leaf box's corners, in the body frame, for Body::box_travel
  for (const TreeNode& n : b.tree) {
    if (n.prim != 0xffffffffu) {
      const Vec3 corner = glm::abs(n.c) + n.e;
      b.box_r1 = std::max(b.box_r1, corner.x + corner.y + corner.z);
    }
  }
  for (std::size_t i = 0; i < b.tree.size(); ++i) {
    if (b.tree[i].prim == 0xffffffffu) {
      b.tree_W[b.tree[i].left].parent = static_cast<std::uint32_t>(i);
      b.tree_W[b.tree[i].right].parent = static_cast<std::uint32_t>(i);
    }
  }
  reserveFronts();
  b.refit_at = 0;
  // the descent's stack holds at most the two trees' depths plus one pairs
  const std::size_t need = 2 * depth + 8;
  if (descent_.capacity() < need)
    descent_.reserve(need);
}

void CollisionWorld::refit(std::uint32_t body) {
  Body& b = bodies_[body];
  if (b.refit_at > b.moved_tick)
    return;
  const bool exact = b.desc.kind == BodyKind::kStatic;  // refitted once: the exact boxes
  const Transform& T = b.T_WB;
  // children come after their parent in the array: backwards, every child before its parent
  for (std::size_t i = b.tree.size(); i-- > 0;) {
    const TreeNode& n = b.tree[i];
    Aabb& box = b.tree_W[i].box;
    if (n.prim == 0xffffffffu) {
      const Aabb& l = b.tree_W[n.left].box;
      const Aabb& r = b.tree_W[n.right].box;
      box.lo = glm::min(l.lo, r.lo);
      box.hi = glm::max(l.hi, r.hi);
      continue;
    }
    if (exact) {
      box = pieceBox(n.prim);
      continue;
    }
    const Vec3 c = T.R * n.c + T.t;
    Vec3 h{0.0};
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k)
        h[k] += std::abs(T.R[j][k]) * n.e[j];
    }
    // the box of the piece's body-frame box turned into the world holds its vertices; the pad
    // covers the rounding of the two ways of computing a vertex's world coordinates (here and
    // in primitiveBox) many times over, and the broad phase's one ulp
    double mag = n.scale;
    for (int k = 0; k < 3; ++k)
      mag = std::max({mag, std::abs(T.t[k]), std::abs(c[k]) + h[k]});
    const double pad = b.margin + 1e-9 * mag;
    box.lo = c - h - pad;
    box.hi = c + h + pad;
  }
  b.refit_at = tick_ + 1;
}

// (inlined: the descent calls it for every pair of overlapping leaves)
[[gnu::always_inline]] inline const Aabb& CollisionWorld::pieceBox(std::uint32_t prim) {
  Prim& p = prims_[prim];
  if (p.box_at > bodies_[p.body].moved_tick)
    return p.box_W;
  p.box_W = primitiveBox(p);
  p.box_at = tick_ + 1;
  return p.box_W;
}

void CollisionWorld::removeBody(std::uint32_t id) {
  if (id >= bodies_.size() || !bodies_[id].live)
    return;
  if (!bodies_[id].tree.empty()) {
    sap_.remove(bodies_[id].box);
    applyEvents(nullptr);
  }
  for (const std::uint32_t pi : bodies_[id].prims) {
    if (bodies_[id].tree.empty()) {
      sap_.remove(prims_[pi].box);
      applyEvents(nullptr);
    }
    prims_[pi].live = false;
    free_prims_.push_back(pi);
  }
  bodies_[id].live = false;
  bodies_[id].prims.clear();
  bodies_[id].tree.clear();
  updateAwake(id);
  if (bodies_[id].posed) {
    posed_.erase(std::find(posed_.begin(), posed_.end(), id));
    bodies_[id].posed = false;
  }
  free_bodies_.push_back(id);
}

void CollisionWorld::setPose(std::uint32_t body, const geom::Pose& X_WB) {
  Body& b = bodies_[body];
  if (b.desc.kind == BodyKind::kStatic)
    return;
  b.X_WB = X_WB;
  b.T_WB = X_WB.toTransform();
  if (!b.moved)
    moved_.push_back(body);
  b.moved = true;
  if (!b.posed)
    posed_.push_back(body);
  b.posed = true;
}

void CollisionWorld::setMargin(std::uint32_t body, double margin) {
  Body& b = bodies_[body];
  if (b.desc.kind == BodyKind::kStatic || !validMargin(margin) || margin == b.margin)
    return;
  // every face of its boxes moves by the change (the descent's bound of their travel)
  b.box_travel += std::abs(margin - b.margin);
  b.margin = margin;
  if (!b.moved)
    moved_.push_back(body);
  b.moved = true;
}

void CollisionWorld::clearPosed() {
  for (const std::uint32_t id : posed_)
    bodies_[id].posed = false;
  posed_.clear();
}

void CollisionWorld::setEnabled(std::uint32_t body, bool enabled) {
  Body& b = bodies_[body];
  if (enabled && !b.enabled) {
    // its pairs' answers are from before it left: as if it moved in the next step
    b.moved_tick = tick_ + 1;
  }
  b.enabled = enabled;
  updateAwake(body);
}

void CollisionWorld::setAsleep(std::uint32_t body, bool asleep) {
  bodies_[body].asleep = asleep;
  updateAwake(body);
}

void CollisionWorld::updateAwake(std::uint32_t id) {
  Body& b = bodies_[id];
  const bool want = b.live && b.enabled && !b.asleep && b.desc.kind != BodyKind::kStatic;
  if (want == (b.awake_at != kNil))
    return;
  if (want) {
    b.awake_at = static_cast<std::uint32_t>(awake_.size());
    awake_.push_back(id);
    return;
  }
  const std::uint32_t at = b.awake_at;
  const std::uint32_t last = awake_.back();
  awake_[at] = last;
  bodies_[last].awake_at = at;
  awake_.pop_back();
  b.awake_at = kNil;
}

void CollisionWorld::linkPair(std::uint32_t si) {
  PairState& s = pair_states_[si];
  const std::uint32_t body[2] = {s.body_a, prims_[s.prim_b].body};
  for (std::size_t k = 0; k < 2; ++k) {
    Body& b = bodies_[body[k]];
    s.prev[k] = kNil;
    s.next[k] = b.pairs_head;
    if (b.pairs_head != kNil) {
      PairState& h = pair_states_[b.pairs_head];
      h.prev[h.body_a == body[k] ? 0 : 1] = si;
    }
    b.pairs_head = si;
  }
}

void CollisionWorld::unlinkPair(std::uint32_t si) {
  PairState& s = pair_states_[si];
  // (not last's ids: a fresh state's are not set; its pieces are live while it is)
  const std::uint32_t body[2] = {s.body_a, prims_[s.prim_b].body};
  for (std::size_t k = 0; k < 2; ++k) {
    const std::uint32_t p = s.prev[k], n = s.next[k];
    if (p != kNil) {
      PairState& ps = pair_states_[p];
      ps.next[ps.body_a == body[k] ? 0 : 1] = n;
    } else {
      bodies_[body[k]].pairs_head = n;
    }
    if (n != kNil) {
      PairState& ns = pair_states_[n];
      ns.prev[ns.body_a == body[k] ? 0 : 1] = p;
    }
    s.prev[k] = s.next[k] = kNil;
  }
}

std::uint32_t CollisionWorld::newPairState(std::uint32_t pa,
                                           std::uint32_t pb,
                                           StepStats* stats,
                                           bool mapped) {
  static_assert(offsetof(PairState, far_travel) + sizeof(double) <= 64,
                "what every step reads of a pair fits its first cache line");
  // a freed slot again, or a new one; either way reset but for its lazy fields (resetLazy, when
  // it is first listed): a state is 13 cache lines, and pairs enter by the dozen where a body's
  // pieces cross another's (75 in a tick on the decomposed stream), most of them to stay far
  std::uint32_t si = 0;
  if (!free_pair_states_.empty()) {
    si = free_pair_states_.back();
    free_pair_states_.pop_back();
  } else {
    si = static_cast<std::uint32_t>(pair_states_.size());
    pair_states_.emplace_back();
  }
  PairState& s = pair_states_[si];
  if (prims_[pa].body > prims_[pb].body)
    std::swap(pa, pb);
  // what the listing's first look at a new pair reads of its pieces (farByBoxes: their
  // transforms in their bodies and their centroids), fetched now, the many pairs' together
  for (const std::uint32_t pi : {pa, pb}) {
    const Prim& p = prims_[pi];
    const auto* desc =
        reinterpret_cast<const char*>(&bodies_[p.body].desc.primitives.data()[p.index]);
    __builtin_prefetch(desc);
    __builtin_prefetch(desc + sizeof(PrimitiveDesc) - 1);
    __builtin_prefetch(&p.shape->centroid());
  }
  static const PairState reset;
  s.prim_a = pa;
  s.prim_b = pb;
  s.body_a = prims_[pa].body;
  s.in_contact = reset.in_contact;
  s.live = true;
  s.from_tree = reset.from_tree;
  s.fresh = true;
  s.visit = reset.visit;
  s.seen = reset.seen;
  s.next = reset.next;
  s.prev = reset.prev;
  s.sep_d = reset.sep_d;
  s.far_travel = reset.far_travel;
  s.last_tested = tick_ - 1;  // never tested: as stale as one tick
  s.sep_rough = reset.sep_rough;
  s.sep_n = reset.sep_n;
  s.X_WA_test = reset.X_WA_test;
  s.X_WB_test = reset.X_WB_test;
  if (mapped)
    state_of_pair_.insert(pairKey(pa, pb), si);
  linkPair(si);
  if (stats != nullptr)
    ++stats->pairs_added;
  return si;
}

void CollisionWorld::resetLazy(PairState& s) const {
  static const PairState reset;
  s.tracker = reset.tracker;
  s.depth_misses = reset.depth_misses;
  s.track_from = reset.track_from;
  s.cache = reset.cache;
  s.last = reset.last;
  s.last.body_a = s.body_a;
  s.last.body_b = prims_[s.prim_b].body;
  s.last.prim_a = prims_[s.prim_a].index;
  s.last.prim_b = prims_[s.prim_b].index;
  s.fresh = false;
}

void CollisionWorld::freePairState(std::uint32_t si, StepStats* stats) {
  PairState& s = pair_states_[si];
  if (!s.fresh)
    releaseTracker(s);  // a pair made again later starts its tracking afresh
  if (!s.from_tree)     // (a tree pair's states are not in the map: see state_of_pair_)
    state_of_pair_.erase(pairKey(s.prim_a, s.prim_b));
  unlinkPair(si);
  s.live = false;
  free_pair_states_.push_back(si);
  if (stats != nullptr)
    ++stats->pairs_removed;
}

void CollisionWorld::applyEvents(StepStats* stats) {
  for (const PairEvent& e : sap_.takeEvents()) {
    const std::uint32_t pa = prim_of_box_[e.pair.lo], pb = prim_of_box_[e.pair.hi];
    if (((pa | pb) & kBodyBox) != 0) {
      // a tree body's box: its piece pairs come from the descent
      if (e.kind == PairEvent::Kind::kAdded)
        tree_pairs_.push_back({e.pair.lo, e.pair.hi, true});
      else
        dropTreePair(e.pair.lo, e.pair.hi, stats);
      continue;
    }
    if (e.kind == PairEvent::Kind::kAdded) {
      newPairState(pa, pb, stats);
    } else {
      const std::uint32_t si = state_of_pair_.find(pairKey(pa, pb));
      if (si != FlatMap::kNone)
        freePairState(si, stats);
    }
  }
}

namespace {

// one side of a tree pair: a tree body (its root node) or one piece with a box of its own
struct Side {
  bool tree = false;
  std::uint32_t body = 0;
  std::uint32_t prim = 0;  // a piece with a box of its own: its prims_ index
};

}  // namespace

bool CollisionWorld::ofTreePair(const PairState& s, std::uint32_t lo, std::uint32_t hi) const {
  auto side = [this](std::uint32_t h) {
    const std::uint32_t t = prim_of_box_[h];
    return (t & kBodyBox) != 0 ? Side{true, t & ~kBodyBox, 0} : Side{false, prims_[t].body, t};
  };
  const Side x = side(lo), y = side(hi);
  auto holds = [this](const Side& of, std::uint32_t prim) {
    return of.tree ? prims_[prim].body == of.body : prim == of.prim;
  };
  return (holds(x, s.prim_a) && holds(y, s.prim_b)) || (holds(x, s.prim_b) && holds(y, s.prim_a));
}

void CollisionWorld::dropTreePair(std::uint32_t lo, std::uint32_t hi, StepStats* stats) {
  for (std::size_t i = 0; i < tree_pairs_.size(); ++i) {
    if (tree_pairs_[i].lo == lo && tree_pairs_[i].hi == hi) {
      tree_pairs_[i] = tree_pairs_.back();
      tree_pairs_.pop_back();
      break;
    }
  }
  for (std::uint32_t si = 0; si < pair_states_.size(); ++si) {
    const PairState& s = pair_states_[si];
    if (s.live && s.from_tree && ofTreePair(s, lo, hi))
      freePairState(si, stats);
  }
}

void CollisionWorld::mapTreeStates(const TreePair& tp) {
  mapped_tree_states_.clear();
  for (std::uint32_t si = 0; si < pair_states_.size(); ++si) {
    const PairState& s = pair_states_[si];
    if (s.live && s.from_tree && ofTreePair(s, tp.lo, tp.hi)) {
      state_of_pair_.insert(pairKey(s.prim_a, s.prim_b), si);
      mapped_tree_states_.push_back(si);
    }
  }
}

void CollisionWorld::descend(TreePair& tp, StepStats* stats) {
  // each side as an array of world nodes: a tree body's own, or a lone piece as one leaf
  WorldNode lone[2];
  const WorldNode* side[2] = {nullptr, nullptr};
  const std::uint32_t handles[2] = {tp.lo, tp.hi};
  // a side whose leaves' boxes are not its pieces' exact boxes (a moving tree body's, refitted
  // from its body-frame boxes): a leaf pair's overlap is decided by the pieces' (pieceBox). A
  // static tree body's leaves hold their pieces' exact boxes (refit, just above: the values
  // pieceBox gives), and a lone piece's is its box in the sweep and prune; neither reads the
  // piece (the static plate's pieces are many and cold in the cache)
  bool loose[2] = {false, false};
  for (int i = 0; i < 2; ++i) {
    const std::uint32_t t = prim_of_box_[handles[i]];
    if ((t & kBodyBox) != 0) {
      refit(t & ~kBodyBox);
      side[i] = bodies_[t & ~kBodyBox].tree_W.data();
      loose[i] = bodies_[t & ~kBodyBox].desc.kind != BodyKind::kStatic;
    } else {
      lone[i].box = sap_.box(handles[i]);
      lone[i].left = prims_[t].group;
      lone[i].right = prims_[t].mask;
      lone[i].prim = t;
      side[i] = &lone[i];
    }
  }
  const WorldNode* const x = side[0];
  const WorldNode* const y = side[1];
  // Entries that cannot have changed (NodePair::until). No face of a box of either side has
  // moved by more than that side's Body::box_travel has grown since the entry was found, so
  // two boxes found apart by a gap g (the largest of the six differences) are still apart, and
  // two found overlapping by o on every axis still overlap, while the two sides' growths sum to
  // less than g or o. The slack covers the rounding of the boxes, of the bound's sum and the
  // loose boxes' pads (which vary by 1e-9 of the motion) many times over.
  // Two leaves are kept so only when neither piece's exact box is climbed to from hints (a
  // moving tree body's large piece, whose box pieceBox must compute at the same steps as before).
  double travel = 0.0, r1 = 0.0;
  bool keep_leaves = true;
  for (int i = 0; i < 2; ++i) {
    const std::uint32_t t = prim_of_box_[handles[i]];
    const Body& body = bodies_[(t & kBodyBox) != 0 ? t & ~kBodyBox : prims_[t].body];
    travel += body.box_travel;
    r1 += body.box_r1;
    keep_leaves = keep_leaves && (!loose[i] || body.small_pieces);
  }
  double mag = 0.0;
  for (const Aabb* root : {&x[0].box, &y[0].box}) {
    const Vec3 m = glm::max(glm::abs(root->lo), glm::abs(root->hi));
    mag = std::max({mag, m.x, m.y, m.z});
  }
  const double slack = 1e-8 * (mag + r1) + 1e-15 * travel;
  // the largest of the six differences: > 0, the two boxes are apart (by it); else they overlap
  // (the least overlap on an axis is its magnitude)
  auto gap = [](const Aabb& A, const Aabb& B) {
    return std::max({A.lo.x - B.hi.x, B.lo.x - A.hi.x, A.lo.y - B.hi.y, B.lo.y - A.hi.y,
                     A.lo.z - B.hi.z, B.lo.z - A.hi.z});
  };
  auto until = [&](double by) { return travel + by - (slack + 1e-8 * std::abs(by)); };
  // The front: the node pairs where this descent stops, depth first, so that the two halves of
  // an opened pair are neighbours once their own halves have folded back into them. Two halves
  // both apart whose opened pair is apart too fold into it, so the front stays as small as the
  // overlap of the trees and does not keep the finest pairs of where the bodies once were. Each
  // front's pairs cover every leaf pair once (an opening splits a pair's leaf pairs in two), so
  // a descent from last step's front finds exactly the overlapping leaf pairs a descent from
  // the roots finds.
  const std::size_t begin = front_next_.size();
  bool keep = options_.descent_fronts;
  auto emit = [&](const NodePair& e) {
    if (!keep)
      return;
    if (front_next_.size() == front_next_.capacity()) {
      keep = false;
      return;
    }
    front_next_.push_back(e);
    while (front_next_.size() >= begin + 2) {
      const NodePair& u = front_next_[front_next_.size() - 2];
      const NodePair& v = front_next_.back();
      if (!u.apart || !v.apart || v.depth == 0 || u.depth != v.depth || u.sides != v.sides)
        break;
      NodePair up = v;
      up.depth = v.depth - 1;
      up.sides = v.sides & ((std::uint64_t{1} << up.depth) - 1);
      if (((v.sides >> up.depth) & 1u) != 0) {
        if (u.a != v.a || u.b == v.b || y[u.b].parent != y[v.b].parent)
          break;
        up.b = y[v.b].parent;
      } else {
        if (u.b != v.b || u.a == v.a || x[u.a].parent != x[v.a].parent)
          break;
        up.a = x[v.a].parent;
      }
      const Aabb& A = x[up.a].box;
      const Aabb& B = y[up.b].box;
      const double g = gap(A, B);
      if (!(g > 0.0))
        break;
      up.until = until(g);
      front_next_.pop_back();
      front_next_.back() = up;
    }
  };
  constexpr std::uint32_t kInner = 0xffffffffu;
  const NodePair roots{};
  const bool from_front = options_.descent_fronts && !tp.fresh && tp.front_size > 0;
  // a descent from the kept front finds every state the tree pair has by its hint (each is a
  // leaf entry of the front: the last descent found exactly those pairs, and the pairs it did
  // not find were dropped in its step), and a fresh tree pair has none; a descent from the roots
  // of a tree pair with states looks them up in the map, where they are put for it
  const bool mapped = !from_front && !tp.fresh;
  if (mapped)
    mapTreeStates(tp);
  std::uint32_t visited = 0, kept = 0;
  const bool keep_entries = from_front && options_.descent_keep;
  const NodePair* const starts = from_front ? front_.data() + tp.front_begin : &roots;
  const std::uint32_t n_starts = from_front ? tp.front_size : 1;
  // a front's overlapping leaf pairs name their states: the first line of the state some
  // entries ahead is fetched while this one is descended (its check below is otherwise a cache
  // miss per pair; a stale or absent index is only a wasted fetch)
  constexpr std::uint32_t kAhead = 8;
  for (std::uint32_t k = 0; k < n_starts; ++k) {
    if (from_front && k + kAhead < n_starts) {
      const std::uint32_t ahead = starts[k + kAhead].state;
      if (ahead < pair_states_.size())
        __builtin_prefetch(&pair_states_[ahead]);
    }
    if (keep_entries && travel < starts[k].until) {
      ++kept;
      // the entry as the descent would find it again, unread: apart, or two leaves found so
      const NodePair& e = starts[k];
      if (!e.apart && e.state != kNil) {
        // its state (a leaf pair's state found by the last descent stays live until the next:
        // resolveTreePairs frees only those a descent did not find)
        assert(e.state < pair_states_.size() && pair_states_[e.state].live &&
               pairKey(pair_states_[e.state].prim_a, pair_states_[e.state].prim_b) ==
                   pairKey(x[e.a].prim, y[e.b].prim));
        pair_states_[e.state].seen = tick_;
      }
      emit(e);
      continue;
    }
    descent_.clear();
    descent_.push_back(starts[k]);
    while (!descent_.empty()) {
      NodePair np = descent_.back();
      descent_.pop_back();
      const WorldNode& na = x[np.a];
      const WorldNode& nb = y[np.b];
      const Aabb& A = na.box;
      const Aabb& B = nb.box;
      ++visited;
      const double g = gap(A, B);
      np.apart = g > 0.0;
      if (np.apart) {
        // a leaf pair that parted: its state is not seen in this descent, so it is freed in this
        // step (resolveTreePairs); the hint would only make a later descent fetch a freed or
        // reused state ahead (kAhead below) while the entry stays apart
        np.state = kNil;
        np.until = until(g);
        emit(np);
        continue;
      }
      const bool la = na.prim != kInner, lb = nb.prim != kInner;
      if (la && lb) {
        // two pieces: the pair the sweep and prune would make of their exact boxes
        const std::uint32_t pa = na.prim, pb = nb.prim;
        const std::uint32_t hint = np.state;
        np.state = kNil;
        // found again while the node boxes overlap (-g) and, for a pair the filter lets
        // through, the pieces' boxes overlap or not as now (their gap, below)
        double by = -g;
        bool exact_overlap = false;
        // (a leaf's left and right: its piece's filter)
        if ((na.left & nb.right) != 0 && (nb.left & na.right) != 0) {
          const Aabb& EA = loose[0] ? pieceBox(pa) : A;
          const Aabb& EB = loose[1] ? pieceBox(pb) : B;
          exact_overlap = SweepAndPrune::overlap(EA, EB);
          by = std::min(by, std::abs(gap(EA, EB)));
        }
        np.until = keep_leaves ? until(by) : -std::numeric_limits<double>::infinity();
        if (exact_overlap) {
          std::uint32_t si = hint;
          if (si >= pair_states_.size() || !pair_states_[si].live ||
              pairKey(pair_states_[si].prim_a, pair_states_[si].prim_b) != pairKey(pa, pb)) {
            si = mapped ? state_of_pair_.find(pairKey(pa, pb)) : FlatMap::kNone;
          }
          if (si == FlatMap::kNone) {
            si = newPairState(pa, pb, stats, mapped);
            pair_states_[si].from_tree = true;
            if (mapped)
              mapped_tree_states_.push_back(si);
          }
          pair_states_[si].seen = tick_;
          np.state = si;
        }
        emit(np);
        continue;
      }
      // open the larger node (a leaf never); the first half is taken (and written) first
      const double size_a = (A.hi.x - A.lo.x) + (A.hi.y - A.lo.y) + (A.hi.z - A.lo.z);
      const double size_b = (B.hi.x - B.lo.x) + (B.hi.y - B.lo.y) + (B.hi.z - B.lo.z);
      const bool open_b = !(lb || (!la && size_a >= size_b));
      if (np.depth >= kMaxFrontDepth) {
        keep = false;  // deeper than a front entry records: the descent goes on, unkept
        np.depth = kMaxFrontDepth;
      }
      np.state = kNil;
      NodePair first = np, second = np;
      first.depth = second.depth = static_cast<std::uint8_t>(np.depth + 1);
      if (np.depth < kMaxFrontDepth && open_b)
        first.sides = second.sides = np.sides | (std::uint64_t{1} << np.depth);
      if (open_b) {
        first.b = nb.left;
        second.b = nb.right;
      } else {
        first.a = na.left;
        second.a = na.right;
      }
      descent_.push_back(second);
      descent_.push_back(first);
    }
  }
  if (mapped) {
    for (const std::uint32_t si : mapped_tree_states_)
      state_of_pair_.erase(pairKey(pair_states_[si].prim_a, pair_states_[si].prim_b));
    mapped_tree_states_.clear();
  }
  if (stats != nullptr) {
    stats->node_pairs_visited += visited;
    stats->node_pairs_kept += kept;
  }
  if (keep) {
    tp.front_begin = static_cast<std::uint32_t>(begin);
    tp.front_size = static_cast<std::uint32_t>(front_next_.size() - begin);
  } else {
    front_next_.resize(begin);
    tp.front_size = 0;
  }
}

void CollisionWorld::resolveTreePairs(StepStats* stats) {
  if (tree_pairs_.empty())
    return;
  auto bodyOf = [this](std::uint32_t h) {
    const std::uint32_t t = prim_of_box_[h];
    return (t & kBodyBox) != 0 ? (t & ~kBodyBox) : prims_[t].body;
  };
  auto due = [&](const TreePair& tp) {
    return tp.fresh || bodies_[bodyOf(tp.lo)].moved_tick == tick_ ||
           bodies_[bodyOf(tp.hi)].moved_tick == tick_;
  };
  if (std::none_of(tree_pairs_.begin(), tree_pairs_.end(), due))
    return;
  // the fronts are written anew, the undescended ones copied
  front_next_.clear();
  for (TreePair& tp : tree_pairs_) {
    if (due(tp)) {
      descend(tp, stats);
      tp.fresh = false;
    } else if (tp.front_size > 0) {
      if (front_next_.size() + tp.front_size <= front_next_.capacity()) {
        const auto from = front_.begin() + tp.front_begin;
        tp.front_begin = static_cast<std::uint32_t>(front_next_.size());
        front_next_.insert(front_next_.end(), from, from + tp.front_size);
      } else {
        tp.front_size = 0;
      }
    }
  }
  front_.swap(front_next_);
  // a piece pair of a descended tree pair that the descent did not find again: its boxes parted
  for (std::uint32_t si = 0; si < pair_states_.size(); ++si) {
    const PairState& s = pair_states_[si];
    if (!s.live || !s.from_tree || s.seen == tick_)
      continue;
    if (bodies_[prims_[s.prim_a].body].moved_tick == tick_ ||
        bodies_[prims_[s.prim_b].body].moved_tick == tick_) {
      freePairState(si, stats);
    }
  }
}

void CollisionWorld::prewarm() {
  sap_.prewarm();
  applyEvents(nullptr);
}

bool CollisionWorld::trackable(const PairState& s) const {
  const Prim& pa = prims_[s.prim_a];
  const Prim& pb = prims_[s.prim_b];
  const Polytope& a = *bodies_[pa.body].desc.primitives[pa.index].shape;
  const Polytope& b = *bodies_[pb.body].desc.primitives[pb.index].shape;
  return a.faces().size() <= tracker_faces_ && b.faces().size() <= tracker_faces_ &&
         a.edges().size() <= tracker_edges_ && b.edges().size() <= tracker_edges_ &&
         DepthTracker::pays(a, b);
}

void CollisionWorld::takeTracker(std::uint32_t si, bool steal) {
  std::uint32_t t = kNil;
  if (!free_trackers_.empty()) {
    t = free_trackers_.back();
    free_trackers_.pop_back();
  } else if (steal && steal_failed_ != tick_ + 1) {
    // the pool is empty: the tracker of the pair tested longest ago, if that is two steps or
    // more (a pair tested every step keeps its own: no two pairs take turns with one tracker)
    std::uint64_t oldest = 0;
    for (std::uint32_t k = 0; k < tracker_owner_.size(); ++k) {
      const std::uint64_t tested = pair_states_[tracker_owner_[k]].last_tested;
      if (tested + 2 <= tick_ && (t == kNil || tested < oldest)) {
        oldest = tested;
        t = k;
      }
    }
    if (t == kNil) {
      steal_failed_ = tick_ + 1;  // none this step: do not look again until the next
      return;
    }
    pair_states_[tracker_owner_[t]].tracker = kNil;
    ++depth_counters_.stolen;
    --depth_counters_.in_use;
  } else {
    return;
  }
  trackers_[t].reset();
  tracker_owner_[t] = si;
  pair_states_[si].tracker = t;
  ++depth_counters_.taken;
  depth_counters_.peak = std::max(depth_counters_.peak, ++depth_counters_.in_use);
}

void CollisionWorld::releaseTracker(PairState& s) {
  if (s.tracker == kNil)
    return;
  trackers_[s.tracker].reset();
  tracker_owner_[s.tracker] = kNil;
  free_trackers_.push_back(s.tracker);
  s.tracker = kNil;
  --depth_counters_.in_use;
}

namespace {

// how far a turn from q0 to q1 moves a point at distance 1 from the axis's origin: the chord
// 2 sin(angle / 2), twice the length of the vector part of q1 q0^-1
double chord(const geom::Quat& q1, const geom::Quat& q0) {
  const geom::Quat d = q1 * glm::conjugate(q0);
  return 2.0 * std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

}  // namespace

double CollisionWorld::farLimit(const PairState& s) const {
  const bool with_static = bodies_[prims_[s.prim_a].body].desc.kind == BodyKind::kStatic ||
                           bodies_[prims_[s.prim_b].body].desc.kind == BodyKind::kStatic;
  return std::max(options_.box_margin, with_static && options_.far_distance_static > 0.0
                                           ? options_.far_distance_static
                                           : options_.far_distance);
}

bool CollisionWorld::far(PairState& s, bool* kept) const {
  if (options_.far_distance <= 0.0 || !(s.sep_d > 0.0))
    return false;
  const Body& a = bodies_[prims_[s.prim_a].body];
  const Body& b = bodies_[prims_[s.prim_b].body];
  // found far by a margin M when the two bodies' travels summed to T: no point of either has
  // moved more than their growth since, so the bound below has lost at most that much (each
  // body's translation along the normal at most its translation's length, each chord term at
  // most the chord of its turn since, by the triangle inequality of chords): while it is under
  // M / 2 the pair is far, as the bound would find it
  const double travel = a.travel + b.travel;
  if (travel < s.far_travel) {
    if (kept != nullptr)
      *kept = true;
    return true;
  }
  // the plane separated the two by sep_d; since, a point of a body has moved by its origin's
  // translation plus at most its turn's chord times the body's radius, so the two are at least
  // sep_d less what moved toward each other along sep_n apart. The pad covers the rounding of
  // the plane many times over.
  const Vec3 moved = (b.X_WB.translation - s.X_WB_test.translation) -
                     (a.X_WB.translation - s.X_WA_test.translation);
  const Vec3 t = glm::abs(s.X_WA_test.translation) + glm::abs(s.X_WB_test.translation);
  const double pad = 1e-9 * (std::max({t.x, t.y, t.z}) + a.radius + b.radius);
  // a body not turned since (a static one: always) moved no point by a chord
  auto turned = [](const geom::Quat& q1, const geom::Quat& q0, double radius) {
    return q1 == q0 ? 0.0 : chord(q1, q0) * radius;
  };
  const double nearest = s.sep_d + glm::dot(s.sep_n, moved) -
                         turned(a.X_WB.rotation, s.X_WA_test.rotation, a.radius) -
                         turned(b.X_WB.rotation, s.X_WB_test.rotation, b.radius) - pad;
  const double margin = nearest - farLimit(s);
  if (!(margin > 0.0) && s.sep_rough) {
    // the boxes' bound of the centroids' plane does not find it far: the plane's exact gap, at
    // the poses it was found at (what farByBoxes would have kept), decides, as it would have
    s.sep_rough = false;
    const double gap = centroidPlaneGap(s);
    s.sep_d = gap > 0.0 ? gap : 0.0;
    s.far_travel = -std::numeric_limits<double>::infinity();
    return far(s, kept);
  }
  s.far_travel = options_.far_by_travel && 0.5 * margin > pad
                     ? travel + 0.5 * margin
                     : -std::numeric_limits<double>::infinity();
  return margin > 0.0;
}

namespace {

// the extreme of a piece along u (world) at X: a small piece's by one pass over its vertices, a
// larger one's by a climb to its support point in its own frame; sign -1: the least
double extremeAlong(const Polytope& shape, const Transform& X, const Vec3& u, double sign) {
  const auto& vertices = shape.vertices();
  if (vertices.size() <= kSmallShape) {
    const Vec3 u_P = sign * (glm::transpose(X.R) * u);
    double most = -std::numeric_limits<double>::infinity();
    for (const auto& v : vertices)
      most = std::max(most, glm::dot(u_P, v.p));
    return sign * most + glm::dot(u, X.t);
  }
  const Vec3 u_P = glm::transpose(X.R) * (sign * u);
  return glm::dot(u, X.apply(vertices[shape.support(u_P, 0)].p));
}

}  // namespace

double CollisionWorld::centroidPlaneGap(const PairState& s) const {
  const Prim& pa = prims_[s.prim_a];
  const Prim& pb = prims_[s.prim_b];
  const PrimitiveDesc& da = bodies_[pa.body].desc.primitives[pa.index];
  const PrimitiveDesc& db = bodies_[pb.body].desc.primitives[pb.index];
  // the pieces' transforms as primitiveTransform gave them then (a body's T_WB is its pose's)
  const Transform X_WA = s.X_WA_test.toTransform() * da.X_BP;
  const Transform X_WB = s.X_WB_test.toTransform() * db.X_BP;
  return extremeAlong(*db.shape, X_WB, s.sep_n, -1.0) - extremeAlong(*da.shape, X_WA, s.sep_n, 1.0);
}

bool CollisionWorld::farByBoxes(PairState& s) {
  if (options_.far_distance <= 0.0)
    return false;
  const Prim& pa = prims_[s.prim_a];
  const Prim& pb = prims_[s.prim_b];
  s.X_WA_test = bodies_[pa.body].X_WB;
  s.X_WB_test = bodies_[pb.body].X_WB;
  // the pieces' boxes (each grown by the margin) hold them: a gap between the boxes on an axis,
  // plus the two margins, is a separating plane's
  const Aabb A = pieceBox(s.prim_a);
  const Aabb B = pieceBox(s.prim_b);
  double best = 0.0;
  Vec3 n{0.0};
  for (int k = 0; k < 3; ++k) {
    const double below = A.lo[k] - B.hi[k], above = B.lo[k] - A.hi[k];
    if (below > best)
      best = below, n = Vec3{0.0}, n[k] = -1.0;
    if (above > best)
      best = above, n = Vec3{0.0}, n[k] = 1.0;
  }
  s.far_travel = -std::numeric_limits<double>::infinity();  // a new plane
  s.sep_rough = false;
  if (best > 0.0) {
    s.sep_n = n;
    s.sep_d = best + bodies_[pa.body].margin + bodies_[pb.body].margin;
    if (far(s))
      return true;
  }
  // else the plane normal to the line from a's centroid to b's, at the two pieces' extreme
  // vertices along it (their support points: exact for convex pieces): pairs that enter the
  // margin diagonally (a plate's pieces crossing the cells of another's at once) are mostly far
  // by it, and a first test, which has no cache to start its walk from, costs several warm ones
  const Polytope& shape_a = *bodies_[pa.body].desc.primitives[pa.index].shape;
  const Polytope& shape_b = *bodies_[pb.body].desc.primitives[pb.index].shape;
  const Transform X_WA = primitiveTransform(pa);
  const Transform X_WB = primitiveTransform(pb);
  const Vec3 d = X_WB.apply(shape_b.centroid()) - X_WA.apply(shape_a.centroid());
  const double len = glm::length(d);
  if (len > 0.0) {
    const Vec3 u = d / len;
    // first a lower bound of the gap from the pieces' world boxes (without their margins; the
    // pad covers the rounding of both ways many times over): a piece's vertices are not read
    // (the static plate's entering pieces are cold in the cache); far() makes the plane exact
    // before it could find the pair near, so the pairs found far are the same
    const double ma = bodies_[pa.body].margin, mb = bodies_[pb.body].margin;
    double top_a = 0.0, bottom_b = 0.0, mag = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double alo = A.lo[k] + ma, ahi = A.hi[k] - ma, blo = B.lo[k] + mb, bhi = B.hi[k] - mb;
      top_a += u[k] * (u[k] >= 0.0 ? ahi : alo);
      bottom_b += u[k] * (u[k] >= 0.0 ? blo : bhi);
      mag = std::max(
          {mag, std::abs(A.lo[k]), std::abs(A.hi[k]), std::abs(B.lo[k]), std::abs(B.hi[k])});
    }
    const double rough = bottom_b - top_a - 1e-9 * (mag + std::max(ma, mb));
    if (options_.far_box_bound && rough > 0.0) {
      s.sep_n = u;
      s.sep_d = rough;
      s.sep_rough = true;
      if (far(s))  // (far() makes it exact when the bound does not find it far)
        return true;
      s.sep_d = 0.0;  // found near by the exact plane (far() made it so), as below
      return false;
    }
    // the plane normal to the line at the pieces' extreme vertices along it
    const double top = extremeAlong(shape_a, X_WA, u, 1.0);
    const double bottom = extremeAlong(shape_b, X_WB, u, -1.0);
    if (bottom - top > 0.0) {
      s.sep_n = u;
      s.sep_d = bottom - top;
      s.far_travel = -std::numeric_limits<double>::infinity();
      if (far(s))
        return true;
    }
  }
  s.sep_d = 0.0;
  return false;
}

void CollisionWorld::test(std::uint32_t si) {
  PairState& s = pair_states_[si];
  if (!s.last.answered)
    ++cold_queries_;
  const Prim& pa = prims_[s.prim_a];
  const Prim& pb = prims_[s.prim_b];
  const Transform X_WA = primitiveTransform(pa);
  const Transform X_WB = primitiveTransform(pb);
  // X_AB = X_WA^-1 X_WB, translations subtracted first (far from the origin stays exact)
  const geom::Mat3 Rt = glm::transpose(X_WA.R);
  const Transform X_AB{Rt * X_WB.R, Rt * (X_WB.t - X_WA.t)};
  // a pair holds a depth tracker while it penetrates: taken at the first test after it was
  // found penetrating (that test's depth is its first: no tracked state to prove it from
  // anyway), from the pool or from a pair not tested for two steps, and given back once apart
  const bool was_penetrating = s.cache.penetrating;
  if (s.tracker == kNil && was_penetrating && tick_ >= s.track_from &&
      options_.query_method == nullptr && trackable(s))
    takeTracker(si, true);
  DepthTracker* const tracker = s.tracker != kNil ? &trackers_[s.tracker] : nullptr;
  DepthTracker::Stats before;
  if (tracker != nullptr)
    before = tracker->stats;
  s.cache.tracker = tracker;
  PairResult& r = result_;
  const Polytope& shape_a = *bodies_[pa.body].desc.primitives[pa.index].shape;
  const Polytope& shape_b = *bodies_[pb.body].desc.primitives[pb.index].shape;
  if (options_.query_method != nullptr) {
    // the pair's pose at its last test, from its bodies' poses then
    Transform last;
    if (s.last.answered) {
      const Transform A =
          s.X_WA_test.toTransform() * bodies_[pa.body].desc.primitives[pa.index].X_BP;
      const Transform B =
          s.X_WB_test.toTransform() * bodies_[pb.body].desc.primitives[pb.index].X_BP;
      const geom::Mat3 At = glm::transpose(A.R);
      last = Transform{At * B.R, At * (B.t - A.t)};
    }
    options_.query_method->query(shape_a, shape_b, X_AB, s.last.answered ? &last : nullptr, s.cache,
                                 r);
  } else {
    queryPair(shape_a, shape_b, X_AB, s.cache, depth_scratch_, options_.query, r);
  }
  s.cache.tracker = nullptr;  // the pool's index is the state (copies of the world keep it)
  if (tracker != nullptr) {
    const std::uint64_t certified = tracker->stats.certified - before.certified;
    const std::uint64_t fallbacks = tracker->stats.fallbacks - before.fallbacks;
    depth_counters_.certified += certified;
    depth_counters_.fallbacks += fallbacks;
    depth_counters_.cold += tracker->stats.cold - before.cold;
    if (certified > 0)
      s.depth_misses = 0;
    bool back_off = false;
    if (fallbacks > 0 && ++s.depth_misses >= 2) {
      // the certificate keeps failing (a tie that lasts): a full solve each step is cheaper
      // without the tracker's attempt and rebuild; try again later
      const std::uint32_t shift = std::min<std::uint32_t>(s.depth_misses - 1, 6);
      s.track_from = tick_ + (std::uint64_t{1} << shift);
      back_off = true;
    }
    if (!s.cache.penetrating || back_off)
      releaseTracker(s);  // apart (or touching): the next depth starts cold in any case
  } else if (r.status == ContactStatus::kPenetrating) {
    // a pair's first penetrating test is cold (it takes a tracker at its next); a later one
    // without a tracker is untracked (pool empty, backed off, or shapes not tracked)
    ++(was_penetrating ? depth_counters_.untracked : depth_counters_.cold);
  }
  toWorld(X_WA, r, s.last);
  s.last.answered = true;
  s.last_tested = tick_;
  // the plane through the closest points, normal to them, separates the two by their distance
  const Vec3 ab = s.last.point_b - s.last.point_a;
  const double d = glm::length(ab);
  s.sep_d = r.status == ContactStatus::kSeparated && d > 0.0 ? d : 0.0;
  s.sep_rough = false;
  s.far_travel = -std::numeric_limits<double>::infinity();  // a new plane
  s.sep_n = s.sep_d > 0.0 ? ab / d : Vec3{0.0};
  s.X_WA_test = bodies_[pa.body].X_WB;
  s.X_WB_test = bodies_[pb.body].X_WB;
  s.in_contact = r.distance <= 0.5 * (bodies_[pa.body].margin + bodies_[pb.body].margin);
}

StepStats CollisionWorld::step() {
  ++tick_;
  StepStats stats;
  // boxes of the bodies that moved
  for (const std::uint32_t bi : moved_) {
    Body& b = bodies_[bi];
    if (!b.live || !b.moved)
      continue;
    b.moved = false;
    b.moved_tick = tick_;
    // the bound of how far its points have moved grows by this step's motion (far())
    b.travel += glm::length(b.X_WB.translation - b.X_stepped.translation) +
                (b.X_WB.rotation == b.X_stepped.rotation
                     ? 0.0
                     : chord(b.X_WB.rotation, b.X_stepped.rotation) * b.radius);
    // a box's face moves by a translation coordinate's change plus, for a point p of the body,
    // sum_j |dR_kj| |p_j| <= max |dR_kj| * box_r1 (the matrices the boxes are computed from:
    // T_WB is X_WB.toTransform(), as X_stepped's was)
    {
      const Transform T0 = b.X_stepped.toTransform();
      const Vec3 dt = glm::abs(b.T_WB.t - T0.t);
      double dr = 0.0;
      for (int j = 0; j < 3; ++j) {
        for (int k = 0; k < 3; ++k)
          dr = std::max(dr, std::abs(b.T_WB.R[j][k] - T0.R[j][k]));
      }
      b.box_travel += std::max({dt.x, dt.y, dt.z}) + dr * b.box_r1;
    }
    b.X_stepped = b.X_WB;
    if (!b.tree.empty()) {
      refit(bi);
      sap_.update(b.box, b.tree_W[0].box);  // one box; its pieces' only where the descent asks
      continue;
    }
    for (const std::uint32_t pi : b.prims)
      sap_.update(prims_[pi].box, primitiveBox(prims_[pi]));
  }
  moved_.clear();
  sap_.commit();
  applyEvents(&stats);
  resolveTreePairs(&stats);

  schedule(&stats);
  return stats;
}

void CollisionWorld::schedule(StepStats* stats) {
  // the asked pairs: those of the awake bodies, each once, grouped by body pair (the states'
  // indices sorted, not the answers, which are large); a pair of two sleeping or static bodies
  // is not looked at, its answer stays in its state
  ++visit_;
  contact_order_.clear();
  std::uint32_t visited = 0;
  for (const std::uint32_t bi : awake_) {
    for (std::uint32_t si = bodies_[bi].pairs_head; si != kNil; si = nextPair(si, bi)) {
      PairState& s = pair_states_[si];
      if (s.visit == visit_)
        continue;
      s.visit = visit_;
      ++visited;
      if (resting(s))
        continue;
      bool kept = false;
      if (far(s, &kept) || ((s.fresh || !s.last.answered) && farByBoxes(s))) {
        ++stats->pairs_far;
        stats->pairs_far_kept += kept ? 1u : 0u;
        stats->pairs_far_box_bound += !kept && s.sep_rough ? 1u : 0u;
        continue;
      }
      if (s.fresh)
        resetLazy(s);
      contact_order_.push_back(si);
    }
  }
  stats->pairs_visited += visited;
  std::sort(contact_order_.begin(), contact_order_.end(), [this](std::uint32_t i, std::uint32_t j) {
    const Contact& x = pair_states_[i].last;
    const Contact& y = pair_states_[j].last;
    if (x.body_a != y.body_a)
      return x.body_a < y.body_a;
    if (x.body_b != y.body_b)
      return x.body_b < y.body_b;
    if (x.prim_a != y.prim_a)
      return x.prim_a < y.prim_a;
    return x.prim_b < y.prim_b;
  });

  // the scheduler (§4.2): overdue pairs first (so that none waits more than ceil(P/B) ticks),
  // then pairs in contact last tick, then the rest by time since their last test
  order_.clear();
  for (const std::uint32_t si : contact_order_) {
    const PairState& s = pair_states_[si];
    // without skip_unmoved_pairs every asked pair is tested once per tick (a relist() in the
    // same tick tests only what it newly asks)
    const bool stale =
        options_.skip_unmoved_pairs ? !unchanged(s) : !s.last.answered || s.last_tested < tick_;
    if (stale)
      order_.push_back(si);
  }
  const auto count = static_cast<std::uint32_t>(order_.size());
  stats->pairs_overlapping = count;
  const std::uint32_t budget =
      options_.budget.max_pairs == 0 ? count : std::min(count, options_.budget.max_pairs);
  const std::uint64_t due = budget == 0 ? 1 : (count + budget - 1) / budget;
  constexpr std::uint64_t kAgeMask = (1ull << 28) - 1;
  const bool ranked = options_.budget.max_microseconds > 0.0 || budget < count;
  for (std::uint64_t& o : order_) {
    if (!ranked) {  // every pair is tested: only the state index is read
      o = 0xffffffffull - o;
      continue;
    }
    const PairState& s = pair_states_[o];
    const std::uint64_t age = std::min<std::uint64_t>(tick_ - s.last_tested, kAgeMask);
    const std::uint64_t cls = (!s.last.answered || age >= due) ? 3 : (s.in_contact ? 2 : 1);
    // larger is more urgent; ties by state index, so that runs are deterministic
    o = cls << 62 | age << 32 | (0xffffffffull - o);
  }
  const bool timed = options_.budget.max_microseconds > 0.0;
  // a time budget may reach any pair: all in order; a count budget needs only its first
  // `budget`; no budget reached: every pair is tested this tick and the order changes no answer
  // (each pair's test reads only its own cache), so it is left in the listing's order
  if (!timed && budget < count) {
    std::nth_element(order_.begin(), order_.begin() + budget, order_.end(), std::greater<>());
    std::sort(order_.begin(), order_.begin() + budget, std::greater<>());
  } else if (timed) {
    std::sort(order_.begin(), order_.end(), std::greater<>());
  }
  const DepthCounters depth_before = depth_counters_;
  const auto start = std::chrono::steady_clock::now();
  std::uint32_t tested = 0;
  for (; tested < budget; ++tested) {
    if (timed && tested > 0 &&
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                .count() >= options_.budget.max_microseconds) {
      break;
    }
    test(static_cast<std::uint32_t>(0xffffffffull - (order_[tested] & 0xffffffffull)));
  }
  stats->pairs_tested = tested;
  stats->pairs_skipped = count - tested;
  stats->depth_certified =
      static_cast<std::uint32_t>(depth_counters_.certified - depth_before.certified);
  stats->depth_fallbacks =
      static_cast<std::uint32_t>(depth_counters_.fallbacks - depth_before.fallbacks);
  stats->depth_cold = static_cast<std::uint32_t>(depth_counters_.cold - depth_before.cold);
  stats->depth_untracked =
      static_cast<std::uint32_t>(depth_counters_.untracked - depth_before.untracked);
  for (std::uint32_t i = tested; i < count; ++i) {
    const PairState& s = pair_states_[0xffffffffull - (order_[i] & 0xffffffffull)];
    const std::uint64_t age = tick_ - s.last_tested;
    stats->worst_staleness =
        std::max(stats->worst_staleness,
                 static_cast<std::uint32_t>(std::min<std::uint64_t>(age, 0xffffffffu)));
  }

  // each answer copied but for its manifold's points beyond the count (never read, as toWorld
  // leaves them): a Contact is 360 bytes, a near pair's answer mostly one point of four
  contacts_.resize(contact_order_.size());
  for (std::size_t i = 0; i < contact_order_.size(); ++i) {
    const PairState& s = pair_states_[contact_order_[i]];
    copyAnswer(s.last, contacts_[i]);
    contacts_[i].age =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(tick_ - s.last_tested, 0xffffffffu));
  }
  levelFlushSeams();
}

double CollisionWorld::supportValue(std::uint32_t body, std::uint32_t prim, const Vec3& dir) const {
  const Polytope& shape = *bodies_[body].desc.primitives[prim].shape;
  const Transform X = bodies_[body].T_WB * bodies_[body].desc.primitives[prim].X_BP;
  const Vec3 local = glm::transpose(X.R) * dir;
  const std::uint32_t v = shape.support(local, shape.lookup(local));
  return glm::dot(dir, X.apply(shape.vertices()[v].p));
}

// A body resting on a face meets, where that face ends, the edge of the next piece: the next
// tile of a floor made of boxes, the next piece of a decomposed surface, flush with the first.
// The pair query answers that contact exactly, by the edge's or the side's normal (the body's
// corner beside the edge, level with it): sliding on, the body struck it as a wall (a 2 cm box
// sliding at 0.5 m/s over 10 cm tiles stopped at the first seam, turning at 18 rad/s; a probe
// sliding over them stuck there). Such a piece lies wholly below the plane of the face the
// body rests on, so it can push the body only along that plane's normal: the contact takes it
// (its gap never nearer than answered). A step, a wall or anything that rises above the plane keeps
// its normal. A body rests on a plane where a contact of its along a face's normal (its own face's
// or the other piece's) is within kRests of its piece's radius (the proxy holds the probe a
// little above what it touches); "below" is within kFlush of it.
namespace {
constexpr double kRests = 0.05;
constexpr double kFlush = 1e-6;
}  // namespace

void CollisionWorld::levelFlushSeams() {
  if (!options_.level_flush_seams)
    return;
  supports_.clear();
  const auto radiusOf = [this](std::uint32_t body, std::uint32_t prim) {
    return bodies_[body].desc.primitives[prim].shape->radius();
  };
  for (std::size_t i = 0; i < contacts_.size(); ++i) {
    const Contact& c = contacts_[i];
    // a contact along a face's normal (of either piece) within kRests of the piece's radius:
    // each piece rests on the plane through the other's witness point, the other piece wholly
    // beyond it (its witness is its extreme point along the normal). Along a face's normal: a
    // face is a closest feature, or the manifold has three points or more (a face parallel to
    // the contact plane was clipped: a box whose corner is exactly at its tile's edge, where
    // the closest features are that edge and the corner, still rests on the tile's face)
    if (!c.answered || supports_.size() + 2 > supports_.capacity() ||
        (c.feature_a.type != geom::FeatureType::kFace &&
         c.feature_b.type != geom::FeatureType::kFace && c.manifold.count < 3))
      continue;
    const double rb = radiusOf(c.body_b, c.prim_b), ra = radiusOf(c.body_a, c.prim_a);
    if (c.distance <= kRests * rb) {
      supports_.push_back(
          {c.body_b, c.prim_b, c.normal, glm::dot(c.normal, c.point_a), rb, c.distance, i});
    }
    if (c.distance <= kRests * ra) {
      supports_.push_back(
          {c.body_a, c.prim_a, -c.normal, glm::dot(-c.normal, c.point_b), ra, c.distance, i});
    }
  }
  if (supports_.empty())
    return;
  // by piece, and each piece's planes once (a floor of many pieces is one plane)
  const auto planeLess = [](const Support& x, const Support& y) {
    if (x.body != y.body || x.prim != y.prim)
      return x.body != y.body ? x.body < y.body : x.prim < y.prim;
    for (int k = 0; k < 3; ++k) {
      if (x.normal[k] != y.normal[k])
        return x.normal[k] < y.normal[k];
    }
    return x.offset < y.offset;
  };
  std::sort(supports_.begin(), supports_.end(), planeLess);
  // (one plane made by several contacts: the nearest gap, and made by more than one)
  std::size_t kept = 1;
  for (std::size_t k = 1; k < supports_.size(); ++k) {
    const Support x = supports_[k];
    Support& last = supports_[kept - 1];
    if (x.body == last.body && x.prim == last.prim &&
        glm::dot(x.normal, last.normal) >= 1.0 - 1e-12 &&
        std::abs(x.offset - last.offset) <= 1e-9 * last.radius) {
      last.gap = std::min(last.gap, x.gap);
      if (x.contact != last.contact)
        last.contact = Support::kSeveral;
    } else {
      supports_[kept++] = x;
    }
  }
  supports_.resize(kept);
  const auto pieceLess = [](const Support& x, std::pair<std::uint32_t, std::uint32_t> piece) {
    return x.body != piece.first ? x.body < piece.first : x.prim < piece.second;
  };
  for (std::size_t i = 0; i < contacts_.size(); ++i) {
    Contact& c = contacts_[i];
    if (!c.answered)
      continue;
    for (const bool y_is_b : {true, false}) {
      const std::uint32_t y_body = y_is_b ? c.body_b : c.body_a;
      const std::uint32_t y_prim = y_is_b ? c.prim_b : c.prim_a;
      const std::uint32_t a_body = y_is_b ? c.body_a : c.body_b;
      const std::uint32_t a_prim = y_is_b ? c.prim_a : c.prim_b;
      // (a contact farther than half the piece's radius is not at a seam it is crossing)
      if (c.distance > 0.5 * radiusOf(y_body, y_prim))
        continue;
      const auto first = std::lower_bound(supports_.begin(), supports_.end(),
                                          std::pair{y_body, y_prim}, pieceLess);
      const Vec3 toward_y = y_is_b ? c.normal : -c.normal;
      // the plane y rests on nearest that a lies wholly below, from another contact: a contact
      // near enough along its own face's normal is a plane y rests on itself (the next tile's
      // side, 0.1 mm ahead of a block the proxy held 1 µm into the tile it slid on, kept its
      // normal against the motion, and the proxy's rows felt it: 0.07 N at each seam)
      const Support* level = nullptr;
      for (auto k = first; k != supports_.end() && k->body == y_body && k->prim == y_prim; ++k) {
        if (k->contact == i)
          continue;
        if (glm::dot(toward_y, k->normal) >= 1.0 - 1e-9) {
          level = nullptr;  // already along a plane it rests on: as answered
          break;
        }
        if ((level == nullptr || k->gap < level->gap) &&
            supportValue(a_body, a_prim, k->normal) <= k->offset + kFlush * k->radius)
          level = &*k;
      }
      if (level == nullptr)
        continue;
      // the plane's normal, from a toward b; each gap the larger of the answer's and that of
      // y's point above the plane (never nearer than the pair is, nor deeper than y rests)
      const Vec3 m = level->normal;
      const Vec3 n = y_is_b ? m : -m;
      const Vec3 y_point = y_is_b ? c.point_b : c.point_a;
      const double gap = std::max(c.distance, glm::dot(m, y_point) - level->offset);
      (y_is_b ? c.point_a : c.point_b) = y_point - m * gap;
      c.distance = gap;
      c.normal = n;
      if (gap < 0.0)
        c.status = ContactStatus::kPenetrating;
      else if (c.status == ContactStatus::kPenetrating)
        c.status = gap > 0.0 ? ContactStatus::kSeparated : ContactStatus::kTouching;
      for (std::size_t k = 0; k < c.manifold.count; ++k) {
        ContactPoint& p = c.manifold.points[k];
        const Vec3 toward = y_is_b ? p.normal : -p.normal;
        const Vec3 yp = p.point - toward * (0.5 * p.depth);  // y's surface point of it
        p.depth = std::min(p.depth, level->offset - glm::dot(m, yp));
        p.normal = n;
        p.point = yp + m * (0.5 * p.depth);
      }
      break;
    }
  }
}

StepStats CollisionWorld::relist() {
  StepStats stats;
  schedule(&stats);
  return stats;
}

namespace {

void writeFeature(StateWriter& w, const Feature& f) {
  w.integer(f.type);
  w.integer(f.index);
}

void writeContact(StateWriter& w, const Contact& c) {
  for (const std::uint32_t v : {c.body_a, c.body_b, c.prim_a, c.prim_b, c.age})
    w.integer(v);
  w.integer(c.status);
  w.f64(c.distance);
  for (const Vec3& v : {c.normal, c.point_a, c.point_b})
    w.glm(v);
  w.integer(c.manifold.count);
  w.flag(c.manifold.truncated);
  for (std::size_t i = 0; i < c.manifold.count; ++i) {
    w.glm(c.manifold.points[i].point);
    w.glm(c.manifold.points[i].normal);
    w.f64(c.manifold.points[i].depth);
  }
  writeFeature(w, c.feature_a);
  writeFeature(w, c.feature_b);
  w.flag(c.answered);
}

void writePairCache(StateWriter& w, const PairCache& c) {
  writeFeature(w, c.features.a);
  writeFeature(w, c.features.b);
  const DepthCache& d = c.depth;
  w.integer(d.kind);
  for (const std::uint32_t v : {d.ia, d.ib, d.support_a, d.support_b})
    w.integer(v);
  w.glm(d.normal);
  w.integer(d.warm_count);
  for (std::size_t i = 0; i < d.warm_count; ++i) {
    w.integer(d.warm_a[i]);
    w.integer(d.warm_b[i]);
  }
  w.flag(c.penetrating);
}

// A depth tracker's state between queries (not its per-query scratch, its record of the last
// full solve, which the next rebuild rewrites, or its counters).
void writeTracker(StateWriter& w, const DepthTracker& t) {
  w.flag(t.valid);
  if (!t.valid)
    return;
  w.f64(t.drift);
  w.f64(t.limit);
  w.u64(t.tick);
  w.glm(t.last.R);
  w.glm(t.last.t);
  w.integer(t.heap.size());
  for (const DepthTracker::Entry& e : t.heap) {
    w.f64(e.key);
    w.integer(e.code);
    w.integer(e.hint);
  }
  w.array(t.face_support_a.data(), std::min(t.face_support_a.size(), t.a->faces().size()));
}

}  // namespace

void CollisionWorld::writeState(StateWriter& w) const {
  w.f64(options_.box_margin);
  w.integer(options_.budget.max_pairs);
  w.f64(options_.budget.max_microseconds);
  w.flag(options_.skip_unmoved_pairs);
  w.f64(options_.far_distance);
  w.f64(options_.far_distance_static);
  sap_.writeState(w);
  w.integer(bodies_.size());
  for (const Body& b : bodies_) {
    w.integer(b.desc.kind);
    w.integer(b.desc.group);
    w.integer(b.desc.mask);
    w.integer(b.desc.primitives.size());
    for (const PrimitiveDesc& p : b.desc.primitives) {
      w.integer(p.group);
      w.integer(p.mask);
    }
    w.glm(b.X_WB.translation);
    w.glm(b.X_WB.rotation);
    w.glm(b.T_WB.R);
    w.glm(b.T_WB.t);
    w.array(b.prims);
    for (const bool f : {b.live, b.moved, b.asleep, b.enabled})
      w.flag(f);
    w.u64(b.moved_tick);
    w.f64(b.radius);
    w.f64(b.margin);
    w.f64(b.base_margin);
    w.integer(b.tree.size());
    if (!b.tree.empty())
      w.integer(b.box);
  }
  w.integer(prims_.size());
  for (const Prim& p : prims_) {
    for (const std::uint32_t v : {p.body, p.index, p.box})
      w.integer(v);
    w.array(p.hint);
    w.flag(p.live);
  }
  w.integer(pair_states_.size());
  for (const PairState& state : pair_states_) {
    // a free slot is reset before it is used again: only its being free is state
    w.flag(state.live);
    if (!state.live)
      continue;
    // a fresh state as it will be once listed (its lazy fields are not state until then)
    PairState lazy_reset;
    if (state.fresh) {
      lazy_reset = state;
      resetLazy(lazy_reset);
    }
    const PairState& s = state.fresh ? lazy_reset : state;
    w.integer(s.prim_a);
    w.integer(s.prim_b);
    writePairCache(w, s.cache);
    writeContact(w, s.last);
    w.u64(s.last_tested);
    w.flag(s.in_contact);
    w.flag(s.from_tree);
    w.u64(s.seen);
    w.integer(s.tracker);
    w.integer(s.depth_misses);
    w.u64(s.track_from);
    if (s.tracker != kNil)
      writeTracker(w, trackers_[s.tracker]);
    w.glm(s.sep_n);
    // a plane kept as the boxes' bound: the exact gap it stands for (the same state either way)
    w.f64(s.sep_rough ? centroidPlaneGap(s) : s.sep_d);
    for (const geom::Pose* X : {&s.X_WA_test, &s.X_WB_test}) {
      w.glm(X->translation);
      w.glm(X->rotation);
    }
  }
  w.array(free_trackers_);
  w.u64(steal_failed_);
  w.integer(tree_pairs_.size());
  for (const TreePair& tp : tree_pairs_) {
    w.integer(tp.lo);
    w.integer(tp.hi);
    w.flag(tp.fresh);
    w.integer(tp.front_size);
    for (std::uint32_t k = 0; k < tp.front_size; ++k) {
      const NodePair& e = front_[tp.front_begin + k];
      w.integer(e.a);
      w.integer(e.b);
      w.u64(e.sides);
      w.integer(e.depth);
      w.flag(e.apart);
      w.integer(e.state);
    }
  }
  for (const auto* list : {&prim_of_box_, &free_pair_states_, &free_prims_, &free_bodies_, &moved_})
    w.array(*list);
  w.integer(contacts_.size());
  for (const Contact& c : contacts_)
    writeContact(w, c);
  w.u64(tick_);
}

}  // namespace hapticd::collision
