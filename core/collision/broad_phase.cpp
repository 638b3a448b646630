#include "core/collision/broad_phase.h"

#include <algorithm>
#include <cassert>
#include <cstring>

#include "core/common/slots.h"

namespace hapticd::collision {
namespace {

// Endpoint sort keys: the double's bits mapped to an unsigned integer of the same order, its
// lowest bit replaced by the endpoint kind (0 min, 1 max). Integer compares are branch-free, and
// at equal values a min sorts before a max, so boxes touching at one value overlap (closed
// boxes). Dropping the lowest mantissa bit makes boxes less than one ulp apart overlap too: the
// broad phase may only err on the side of a pair.
inline std::uint64_t sortKey(double v, std::uint32_t is_max) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  bits = (bits >> 63) != 0 ? ~bits : bits | (1ull << 63);
  return (bits & ~1ull) | is_max;
}

struct EndpointLess {
  template <class E>
  bool operator()(const E& x, const E& y) const {
    return x.key < y.key;
  }
};

}  // namespace

std::uint64_t SweepAndPrune::key(std::uint32_t a, std::uint32_t b) {
  if (a > b)
    std::swap(a, b);
  return static_cast<std::uint64_t>(a) << 32 | b;
}

bool SweepAndPrune::overlap(const Aabb& a, const Aabb& b) {
  for (int k = 0; k < 3; ++k) {
    if (!(sortKey(a.lo[k], 0) <= sortKey(b.hi[k], 1) && sortKey(b.lo[k], 0) <= sortKey(a.hi[k], 1)))
      return false;
  }
  return true;
}

bool SweepAndPrune::admissible(std::uint32_t a, std::uint32_t b) const {
  const BoxFilter& fa = boxes_[a].filter;
  const BoxFilter& fb = boxes_[b].filter;
  return a != b && fa.body != fb.body && !(fa.is_static && fb.is_static) &&
         (fa.group & fb.mask) != 0 && (fb.group & fa.mask) != 0;
}

bool SweepAndPrune::overlapOn(std::uint32_t a, std::uint32_t b, int axis) const {
  const auto& v = key_[axis];
  return v[a << 1] <= v[b << 1 | 1] && v[b << 1] <= v[a << 1 | 1];
}

// Endpoint `moving` (an endpoint id) now comes before endpoint `passed` on `axis`, after having
// come after it: a min passing below a max starts an overlap on this axis (a pair when the other
// two axes overlap at their new values); a max passing below a min ends one.
inline void SweepAndPrune::transition(int axis, std::uint32_t moving, std::uint32_t passed) {
  const bool m_max = (moving & 1u) != 0, p_max = (passed & 1u) != 0;
  if (m_max == p_max)
    return;
  const std::uint32_t a = moving >> 1, b = passed >> 1;
  if (!m_max) {
    const int k1 = axis == 2 ? 0 : axis + 1;
    const int k2 = axis == 0 ? 2 : axis - 1;
    if (overlapOn(a, b, k1) && overlapOn(a, b, k2))
      addPair(a, b);
  } else if (pair_count_[a] != 0 && pair_count_[b] != 0) {
    removePair(a, b);
  }
}

void SweepAndPrune::addPair(std::uint32_t a, std::uint32_t b) {
  if (!admissible(a, b))
    return;
  const std::uint64_t k = key(a, b);
  if (index_.find(k) != FlatMap::kNone)
    return;
  index_.insert(k, static_cast<std::uint32_t>(pairs_.size()));
  const BoxPair p{std::min(a, b), std::max(a, b)};
  pairs_.push_back(p);
  ++pair_count_[a];
  ++pair_count_[b];
  events_.push_back({PairEvent::Kind::kAdded, p});
}

void SweepAndPrune::removePair(std::uint32_t a, std::uint32_t b) {
  const std::uint64_t k = key(a, b);
  const std::uint32_t index = index_.find(k);
  if (index == FlatMap::kNone)
    return;
  index_.erase(k);
  events_.push_back({PairEvent::Kind::kRemoved, pairs_[index]});
  --pair_count_[a];
  --pair_count_[b];
  // swap-remove from the dense array, re-pointing the moved pair
  const std::uint32_t last = static_cast<std::uint32_t>(pairs_.size() - 1);
  if (index != last) {
    pairs_[index] = pairs_[last];
    index_.insert(key(pairs_[index].lo, pairs_[index].hi), index);
  }
  pairs_.pop_back();
}

bool SweepAndPrune::overlapping(std::uint32_t a, std::uint32_t b) const {
  return index_.find(key(a, b)) != FlatMap::kNone;
}

void SweepAndPrune::reserve(std::size_t boxes, std::size_t pairs) {
  boxes_.reserve(boxes);
  dirty_.reserve(boxes);
  for (int k = 0; k < 3; ++k) {
    axes_[k].reserve(2 * boxes);
    key_[k].reserve(2 * boxes);
    pos_[k].reserve(2 * boxes);
  }
  pairs_.reserve(pairs);
  events_.reserve(pairs);
  taken_.reserve(pairs);
  index_.reserve(pairs);
}

void SweepAndPrune::rebuildPositions() {
  ++position_rebuilds_;
  for (int k = 0; k < 3; ++k) {
    const auto& axis = axes_[k];
    for (std::size_t i = 0; i < axis.size(); ++i)
      pos_[k][axis[i].data] = static_cast<std::uint32_t>(i);
  }
  positions_valid_ = true;
}

std::uint32_t SweepAndPrune::add(const Aabb& box, const BoxFilter& filter) {
  const std::uint32_t h = takeSlot(boxes_, free_);
  if (key_[0].size() < 2 * boxes_.size()) {
    for (int k = 0; k < 3; ++k) {
      key_[k].resize(2 * boxes_.size());
      pos_[k].resize(2 * boxes_.size());
    }
    pair_count_.resize(boxes_.size());
  }
  pair_count_[h] = 0;
  Box& b = boxes_[h];
  b.box = box;
  b.filter = filter;
  b.live = true;
  b.added = true;
  ++live_;
  for (int k = 0; k < 3; ++k) {
    key_[k][h << 1] = sortKey(box.lo[k], 0);
    key_[k][h << 1 | 1] = sortKey(box.hi[k], 1);
  }
  added_.push_back(h);
  return h;
}

void SweepAndPrune::insertAdded() {
  ++full_sorts_;
  const EndpointLess less;
  if (added_.size() < 16) {
    // a few boxes: insert each endpoint in place, then test the new boxes against all
    for (const std::uint32_t h : added_) {
      for (int k = 0; k < 3; ++k) {
        auto& axis = axes_[k];
        for (std::uint32_t id : {h << 1, h << 1 | 1}) {
          const Endpoint e{key_[k][id], id};
          axis.insert(std::upper_bound(axis.begin(), axis.end(), e, less), e);
        }
      }
    }
    for (const std::uint32_t h : added_) {
      for (std::uint32_t o = 0; o < boxes_.size(); ++o) {
        if (o == h || !boxes_[o].live || (boxes_[o].added && o < h))
          continue;
        if (overlapOn(h, o, 0) && overlapOn(h, o, 1) && overlapOn(h, o, 2))
          addPair(h, o);
      }
    }
  } else {
    // many boxes: sort every axis, then one sweep along x pairs each new box with the boxes
    // whose x-intervals it meets
    for (int k = 0; k < 3; ++k) {
      auto& axis = axes_[k];
      for (const std::uint32_t h : added_) {
        axis.push_back({key_[k][h << 1], h << 1});
        axis.push_back({key_[k][h << 1 | 1], h << 1 | 1});
      }
      std::sort(axis.begin(), axis.end(), less);
    }
    std::vector<std::uint32_t> active;
    std::vector<std::uint32_t> slot(boxes_.size(), 0);
    for (const Endpoint& e : axes_[0]) {
      const std::uint32_t h = e.data >> 1;
      if ((e.data & 1u) == 0) {
        for (const std::uint32_t o : active) {
          if ((boxes_[h].added || boxes_[o].added) && overlapOn(h, o, 1) && overlapOn(h, o, 2)) {
            addPair(h, o);
          }
        }
        slot[h] = static_cast<std::uint32_t>(active.size());
        active.push_back(h);
      } else {
        const std::uint32_t at = slot[h];
        active[at] = active.back();
        slot[active[at]] = at;
        active.pop_back();
      }
    }
  }
  for (const std::uint32_t h : added_)
    boxes_[h].added = false;
  added_.clear();
  positions_valid_ = false;
}

void SweepAndPrune::remove(std::uint32_t h) {
  if (h >= boxes_.size() || !boxes_[h].live)
    return;
  commit();
  if (!positions_valid_)
    rebuildPositions();
  for (std::size_t i = pairs_.size(); i-- > 0;) {
    if (i < pairs_.size() && (pairs_[i].lo == h || pairs_[i].hi == h)) {
      removePair(pairs_[i].lo, pairs_[i].hi);
    }
  }
  for (auto& axis : axes_) {
    axis.erase(std::remove_if(axis.begin(), axis.end(),
                              [h](const Endpoint& e) { return (e.data >> 1) == h; }),
               axis.end());
  }
  positions_valid_ = false;
  boxes_[h].live = false;
  --live_;
  free_.push_back(h);
}

void SweepAndPrune::moveEndpoint(int k, std::uint32_t i) {
  auto& axis = axes_[k];
  auto& pos = pos_[k];
  Endpoint e = axis[i];
  e.key = key_[k][e.data];
  const EndpointLess less;
  while (i > 0 && less(e, axis[i - 1])) {
    const Endpoint o = axis[i - 1];
    transition(k, e.data, o.data);
    axis[i] = o;
    pos[o.data] = i;
    --i;
    ++swaps_;
  }
  while (i + 1 < axis.size() && less(axis[i + 1], e)) {
    const Endpoint o = axis[i + 1];
    transition(k, o.data, e.data);
    axis[i] = o;
    pos[o.data] = i;
    ++i;
    ++swaps_;
  }
  axis[i] = e;
  pos[e.data] = i;
}

void SweepAndPrune::sortAxis(int k) {
  auto& axis = axes_[k];
  const auto& key = key_[k];
  for (Endpoint& e : axis)
    e.key = key[e.data];
  const std::size_t n = axis.size();
  Endpoint* a = axis.data();
  // Insertion sort. Coherent motion moves most endpoints by a few places: the count of larger
  // predecessors among the last kW (the prefix is sorted, so they are its last ones) is taken
  // without branches and gives the move at once; a longer move takes the plain loop. Passed
  // endpoints of the other kind are overlap transitions.
  constexpr std::size_t kW = 8;
  for (std::size_t i = 1; i < n; ++i) {
    const Endpoint e = a[i];
    if (i > kW) {
      std::size_t d = 0;
      for (std::size_t w = 1; w <= kW; ++w)
        d += static_cast<std::size_t>(a[i - w].key > e.key);
      if (d == 0)
        continue;
      if (d < kW || a[i - kW - 1].key <= e.key) {
        const std::uint32_t kind = e.data & 1u;
        for (std::size_t w = 1; w <= d; ++w) {
          const Endpoint o = a[i - w];
          if ((o.data & 1u) != kind)
            transition(k, e.data, o.data);
          a[i - w + 1] = o;
        }
        a[i - d] = e;
        swaps_ += d;
        continue;
      }
    }
    std::size_t j = i;
    while (j > 0 && e.key < a[j - 1].key) {
      const Endpoint o = a[j - 1];
      if ((o.data & 1u) != (e.data & 1u))
        transition(k, e.data, o.data);
      a[j] = o;
      --j;
      ++swaps_;
    }
    a[j] = e;
  }
}

void SweepAndPrune::update(std::uint32_t h, const Aabb& box) {
  assert(h < boxes_.size() && boxes_[h].live);
  Box& b = boxes_[h];
  b.box = box;
  for (int k = 0; k < 3; ++k) {
    key_[k][h << 1] = sortKey(box.lo[k], 0);
    key_[k][h << 1 | 1] = sortKey(box.hi[k], 1);
  }
  if (!b.dirty && !b.added) {
    b.dirty = true;
    dirty_.push_back(h);
  }
}

void SweepAndPrune::commit() {
  if (!dirty_.empty())
    applyMoves();
  if (!added_.empty())
    insertAdded();
}

void SweepAndPrune::applyMoves() {
  // moving endpoints one by one costs about the swaps they make; a full pass costs every endpoint
  // of the axis: with coherent motion the moves win up to about a third of the boxes moving (a
  // held body of 100 pieces among 600 boxes: Tick/decomposed in bench/README.md)
  if (dirty_.size() * 3 >= live_) {
    for (int k = 0; k < 3; ++k)
      sortAxis(k);
    positions_valid_ = false;
  } else {
    if (!positions_valid_)
      rebuildPositions();
    for (const std::uint32_t h : dirty_) {
      for (int k = 0; k < 3; ++k) {
        // a min never passes its own max: move the one on the side the box moves to first
        const std::uint32_t lo = h << 1, hi = h << 1 | 1;
        if (key_[k][lo] < axes_[k][pos_[k][lo]].key) {
          moveEndpoint(k, pos_[k][lo]);
          moveEndpoint(k, pos_[k][hi]);
        } else {
          moveEndpoint(k, pos_[k][hi]);
          moveEndpoint(k, pos_[k][lo]);
        }
      }
    }
  }
  for (const std::uint32_t h : dirty_)
    boxes_[h].dirty = false;
  dirty_.clear();
}

void SweepAndPrune::prewarm() {
  commit();
  if (!positions_valid_)
    rebuildPositions();
}

std::span<const PairEvent> SweepAndPrune::takeEvents() {
  commit();
  taken_.swap(events_);
  events_.clear();
  return taken_;
}

void SweepAndPrune::writeState(StateWriter& w) const {
  w.integer(boxes_.size());
  for (const Box& b : boxes_) {
    w.glm(b.box.lo);
    w.glm(b.box.hi);
    for (const std::uint32_t v : {b.filter.body, b.filter.group, b.filter.mask})
      w.integer(v);
    for (const bool f : {b.filter.is_static, b.live, b.dirty, b.added})
      w.flag(f);
  }
  for (int k = 0; k < 3; ++k) {
    w.integer(axes_[k].size());
    for (const Endpoint& e : axes_[k]) {
      w.u64(e.key);
      w.integer(e.data);
    }
    w.array(key_[k]);
    w.array(pos_[k]);
  }
  w.flag(positions_valid_);
  for (const auto* list : {&free_, &pair_count_, &dirty_, &added_})
    w.array(*list);
  w.integer(pairs_.size());
  for (const BoxPair& p : pairs_) {
    w.integer(p.lo);
    w.integer(p.hi);
  }
  w.integer(live_);
  w.u64(swaps_);
}

}  // namespace hapticd::collision
