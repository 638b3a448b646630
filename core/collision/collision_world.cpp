#include "core/collision/collision_world.h"

#include <algorithm>
#include <chrono>
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
  c.manifold = r.manifold;
  c.feature_a = r.fa;
  c.feature_b = r.fb;
  for (std::size_t i = 0; i < c.manifold.count; ++i) {
    c.manifold.points[i].point = X_WA.apply(r.manifold.points[i].point);
    c.manifold.points[i].normal = X_WA.rotate(r.manifold.points[i].normal);
  }
}

}  // namespace

CollisionWorld::CollisionWorld(const WorldOptions& options) : options_(options) {}

void CollisionWorld::reserve(std::size_t primitives, std::size_t pairs) {
  reserved_pairs_ = std::max(reserved_pairs_, pairs);
  sap_.reserve(primitives, pairs);
  prims_.reserve(primitives);
  prim_of_box_.reserve(primitives);
  pair_states_.reserve(pairs);
  moved_.reserve(primitives);
  free_pair_states_.reserve(pairs);
  state_of_pair_.reserve(pairs);
  order_.reserve(pairs);
  contact_order_.reserve(pairs);
  contacts_.reserve(pairs);
}

Transform CollisionWorld::primitiveTransform(const Prim& p) const {
  const Body& b = bodies_[p.body];
  return b.T_WB * b.desc.primitives[p.index].X_BP;
}

// shapes of at most this many vertices get their boxes by one pass over the vertices
constexpr std::size_t kSmallShape = 16;

Aabb CollisionWorld::primitiveBox(Prim& p) {
  const Polytope& shape = *bodies_[p.body].desc.primitives[p.index].shape;
  const Transform X = primitiveTransform(p);
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
      box.lo[k] = lo[k] + X.t[k] - options_.box_margin;
      box.hi[k] = hi[k] + X.t[k] + options_.box_margin;
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
    box.lo[k] = glm::dot(row, shape.vertices()[lo_hint].p) + X.t[k] - options_.box_margin;
    box.hi[k] = glm::dot(row, shape.vertices()[hi_hint].p) + X.t[k] + options_.box_margin;
  }
  return box;
}

std::uint32_t CollisionWorld::addBody(const BodyDesc& desc, const geom::Pose& X_WB) {
  const std::uint32_t id = takeSlot(bodies_, free_bodies_);
  Body& b = bodies_[id];
  b.desc = desc;
  b.X_WB = X_WB;
  b.T_WB = X_WB.toTransform();
  b.live = true;
  for (std::uint32_t i = 0; i < desc.primitives.size(); ++i) {
    const std::uint32_t pi = takeSlot(prims_, free_prims_);
    Prim& p = prims_[pi];
    p.body = id;
    p.index = i;
    p.live = true;
    const Polytope& shape = *desc.primitives[i].shape;
    depth_scratch_.reserve(shape.faces().size());
    for (std::size_t h = 0; h < 6; ++h)
      p.hint[h] = shape.lookup(Vec3{h / 2 == 0, h / 2 == 1, h / 2 == 2} * (h % 2 ? 1.0 : -1.0));
    BoxFilter filter;
    filter.body = id;
    filter.is_static = desc.kind == BodyKind::kStatic;
    filter.group = desc.group & desc.primitives[i].group;
    filter.mask = desc.mask & desc.primitives[i].mask;
    p.box = sap_.add(primitiveBox(p), filter);
    if (prim_of_box_.size() <= p.box)
      prim_of_box_.resize(p.box + 1);
    prim_of_box_[p.box] = pi;
    b.prims.push_back(pi);
  }
  applyEvents(nullptr);
  return id;
}

void CollisionWorld::removeBody(std::uint32_t id) {
  if (id >= bodies_.size() || !bodies_[id].live)
    return;
  for (const std::uint32_t pi : bodies_[id].prims) {
    sap_.remove(prims_[pi].box);
    applyEvents(nullptr);
    prims_[pi].live = false;
    free_prims_.push_back(pi);
  }
  bodies_[id].live = false;
  bodies_[id].prims.clear();
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
}

void CollisionWorld::setEnabled(std::uint32_t body, bool enabled) {
  Body& b = bodies_[body];
  if (enabled && !b.enabled) {
    // its pairs' answers are from before it left: as if it moved in the next step
    b.moved_tick = tick_ + 1;
  }
  b.enabled = enabled;
}

void CollisionWorld::applyEvents(StepStats* stats) {
  for (const PairEvent& e : sap_.takeEvents()) {
    const std::uint64_t k = pairKey(e.pair.lo, e.pair.hi);
    if (e.kind == PairEvent::Kind::kAdded) {
      const std::uint32_t si = takeSlot(pair_states_, free_pair_states_);
      PairState& s = pair_states_[si];
      std::uint32_t pa = prim_of_box_[e.pair.lo], pb = prim_of_box_[e.pair.hi];
      if (prims_[pa].body > prims_[pb].body)
        std::swap(pa, pb);
      s.prim_a = pa;
      s.prim_b = pb;
      s.live = true;
      s.last.body_a = prims_[pa].body;
      s.last.body_b = prims_[pb].body;
      s.last.prim_a = prims_[pa].index;
      s.last.prim_b = prims_[pb].index;
      s.last_tested = tick_ - 1;  // never tested: as stale as one tick
      state_of_pair_.insert(k, si);
      if (stats != nullptr)
        ++stats->pairs_added;
    } else {
      const std::uint32_t si = state_of_pair_.find(k);
      if (si == FlatMap::kNone)
        continue;
      state_of_pair_.erase(k);
      pair_states_[si].live = false;
      free_pair_states_.push_back(si);
      if (stats != nullptr)
        ++stats->pairs_removed;
    }
  }
}

void CollisionWorld::prewarm() {
  sap_.prewarm();
  applyEvents(nullptr);
}

void CollisionWorld::test(PairState& s) {
  if (!s.last.answered)
    ++cold_queries_;
  const Prim& pa = prims_[s.prim_a];
  const Prim& pb = prims_[s.prim_b];
  const Transform X_WA = primitiveTransform(pa);
  const Transform X_WB = primitiveTransform(pb);
  // X_AB = X_WA^-1 X_WB, translations subtracted first (far from the origin stays exact)
  const geom::Mat3 Rt = glm::transpose(X_WA.R);
  const Transform X_AB{Rt * X_WB.R, Rt * (X_WB.t - X_WA.t)};
  const PairResult r = queryPair(*bodies_[pa.body].desc.primitives[pa.index].shape,
                                 *bodies_[pb.body].desc.primitives[pb.index].shape, X_AB, s.cache,
                                 depth_scratch_, options_.query);
  toWorld(X_WA, r, s.last);
  s.last.answered = true;
  s.last_tested = tick_;
  s.in_contact = r.distance <= options_.box_margin;
}

StepStats CollisionWorld::step() {
  ++tick_;
  StepStats stats;
  // boxes of the bodies that moved
  for (const std::uint32_t bi : moved_) {
    Body& b = bodies_[bi];
    if (!b.live || !b.moved)
      continue;
    for (const std::uint32_t pi : b.prims)
      sap_.update(prims_[pi].box, primitiveBox(prims_[pi]));
    b.moved = false;
    b.moved_tick = tick_;
  }
  moved_.clear();
  sap_.commit();
  applyEvents(&stats);

  // the scheduler (§4.2): overdue pairs first (so that none waits more than ceil(P/B) ticks),
  // then pairs in contact last tick, then the rest by time since their last test
  order_.clear();
  for (std::uint32_t si = 0; si < pair_states_.size(); ++si) {
    const PairState& s = pair_states_[si];
    if (!s.live || resting(s))
      continue;
    if (options_.skip_unmoved_pairs && unchanged(s))
      continue;
    order_.push_back(si);
  }
  const auto count = static_cast<std::uint32_t>(order_.size());
  stats.pairs_overlapping = count;
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
  // (each pair's test reads only its own cache), so it is left in state order, unsorted
  if (!timed && budget < count) {
    std::nth_element(order_.begin(), order_.begin() + budget, order_.end(), std::greater<>());
    std::sort(order_.begin(), order_.begin() + budget, std::greater<>());
  } else if (timed) {
    std::sort(order_.begin(), order_.end(), std::greater<>());
  }
  const auto start = std::chrono::steady_clock::now();
  std::uint32_t tested = 0;
  for (; tested < budget; ++tested) {
    if (timed && tested > 0 &&
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                .count() >= options_.budget.max_microseconds) {
      break;
    }
    test(pair_states_[0xffffffffull - (order_[tested] & 0xffffffffull)]);
  }
  stats.pairs_tested = tested;
  stats.pairs_skipped = count - tested;
  for (std::uint32_t i = tested; i < count; ++i) {
    const PairState& s = pair_states_[0xffffffffull - (order_[i] & 0xffffffffull)];
    const std::uint64_t age = tick_ - s.last_tested;
    stats.worst_staleness =
        std::max(stats.worst_staleness,
                 static_cast<std::uint32_t>(std::min<std::uint64_t>(age, 0xffffffffu)));
  }

  // every close pair's latest answer, grouped by body pair: the states' indices sorted (not the
  // answers, which are large), then the answers copied in that order
  contact_order_.clear();
  for (std::uint32_t si = 0; si < pair_states_.size(); ++si) {
    const PairState& s = pair_states_[si];
    if (s.live && !resting(s))
      contact_order_.push_back(si);
  }
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
  contacts_.clear();
  for (const std::uint32_t si : contact_order_) {
    const PairState& s = pair_states_[si];
    contacts_.push_back(s.last);
    contacts_.back().age =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(tick_ - s.last_tested, 0xffffffffu));
  }
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

}  // namespace

void CollisionWorld::writeState(StateWriter& w) const {
  w.f64(options_.box_margin);
  w.integer(options_.budget.max_pairs);
  w.f64(options_.budget.max_microseconds);
  w.flag(options_.skip_unmoved_pairs);
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
  }
  w.integer(prims_.size());
  for (const Prim& p : prims_) {
    for (const std::uint32_t v : {p.body, p.index, p.box})
      w.integer(v);
    w.array(p.hint);
    w.flag(p.live);
  }
  w.integer(pair_states_.size());
  for (const PairState& s : pair_states_) {
    // a free slot is reset before it is used again: only its being free is state
    w.flag(s.live);
    if (!s.live)
      continue;
    w.integer(s.prim_a);
    w.integer(s.prim_b);
    writePairCache(w, s.cache);
    writeContact(w, s.last);
    w.u64(s.last_tested);
    w.flag(s.in_contact);
  }
  for (const auto* list : {&prim_of_box_, &free_pair_states_, &free_prims_, &free_bodies_, &moved_})
    w.array(*list);
  w.integer(contacts_.size());
  for (const Contact& c : contacts_)
    writeContact(w, c);
  w.u64(tick_);
}

}  // namespace hapticd::collision
