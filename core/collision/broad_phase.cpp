#include "core/collision/broad_phase.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>

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

// Widths in quarter octaves from 2^-64 to 2^65: the exponent and the two highest mantissa bits
// of a double >= 0 (below 2^-64 in bin 0, above 2^65 in the last).
constexpr int kWidthBins = 4 * 130;
// the grid has at most this many cells per box (and 64): boxes far apart get wider cells
constexpr std::size_t kCellsPerBox = 8;
constexpr int kWidthBase = (1023 - 64) << 2;

inline int widthBin(double w) {
  if (!(w > 0.0))
    return 0;
  std::uint64_t bits = 0;
  std::memcpy(&bits, &w, sizeof bits);
  return std::clamp(static_cast<int>(bits >> 50) - kWidthBase, 0, kWidthBins - 1);
}

// the upper edge of a width bin (every width in it or below is smaller)
inline double binTop(int bin) {
  const std::uint64_t bits = static_cast<std::uint64_t>(bin + 1 + kWidthBase) << 50;
  double v = 0.0;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// two boxes' sort keys overlap on every axis (closed intervals), computed without a branch per
// axis
template <class G>
inline bool overlapKeys(const G& a, const G& b) {
  return static_cast<bool>(
      static_cast<int>(a.lo[0] <= b.hi[0]) & static_cast<int>(b.lo[0] <= a.hi[0]) &
      static_cast<int>(a.lo[1] <= b.hi[1]) & static_cast<int>(b.lo[1] <= a.hi[1]) &
      static_cast<int>(a.lo[2] <= b.hi[2]) & static_cast<int>(b.lo[2] <= a.hi[2]));
}

// admissible() on the grid's copies of two filters of different boxes
template <class T>
inline bool admissibleTags(const T& a, const T& b) {
  return a.body != b.body && !(a.is_static && b.is_static) && (a.group & b.mask) != 0 &&
         (b.group & a.mask) != 0;
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
  width_.reserve(boxes);
  cell_of_.reserve(boxes);
  cell_start_.reserve(kCellsPerBox * boxes + 65);
  grid_.reserve(boxes);
  grid_tag_.reserve(boxes);
  occupied_.reserve(boxes + 1);
  cand_.reserve(boxes + 4);
  large_.reserve(boxes);
  found_.reserve(pairs);
  seen_.reserve(pairs);
  // the grid's scratch is written for the first time by the first commit that moves most boxes:
  // write it here, so that its pages are resident before then (without mlockall, a first grid
  // commit among 100 000 boxes spent 30 ms of its 40 in page faults on this machine)
  auto touch = [](auto& v) {
    v.resize(v.capacity());
    v.clear();
  };
  touch(width_);
  touch(cell_of_);
  touch(cell_start_);
  touch(grid_);
  touch(grid_tag_);
  touch(large_);
  touch(occupied_);
  touch(cand_);
  touch(found_);
  touch(seen_);
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
  if (!positions_valid_ && !lists_stale_)
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
  const bool many = !dirty_.empty() && dirty_.size() * 3 >= live_;
  if (lists_stale_ && !dirty_.empty()) {
    // the lists hold an older order than the last pairs: only a recomputation is right
    gridCommit(true);
    clearDirty();
    if (!many)
      resortLists();
  } else if (many && live_ >= grid_min_boxes_ && gridCommit(false)) {
    clearDirty();
    lists_stale_ = true;
  } else if (!dirty_.empty()) {
    applyMoves();
  }
  if (!added_.empty()) {
    if (lists_stale_)
      resortLists();
    insertAdded();
  }
}

void SweepAndPrune::clearDirty() {
  for (const std::uint32_t h : dirty_)
    boxes_[h].dirty = false;
  dirty_.clear();
}

void SweepAndPrune::resortLists() {
  const EndpointLess less;
  for (int k = 0; k < 3; ++k) {
    auto& axis = axes_[k];
    for (Endpoint& e : axis)
      e.key = key_[k][e.data];
    // insertion sort while the order is nearly right (a frame or two of motion), a full sort when
    // it turns out not to be
    Endpoint* a = axis.data();
    const std::size_t n = axis.size();
    std::size_t budget = 8 * n + 64;
    for (std::size_t i = 1; i < n && budget != 0; ++i) {
      const Endpoint e = a[i];
      std::size_t j = i;
      for (; j > 0 && e.key < a[j - 1].key && budget != 0; --j, --budget)
        a[j] = a[j - 1];
      a[j] = e;
    }
    if (budget == 0)
      std::sort(axis.begin(), axis.end(), less);
  }
  lists_stale_ = false;
  positions_valid_ = false;
}

bool SweepAndPrune::gridCommit(bool forced) {
  // 1. each box's widest extent; boxes wider than the smallest quarter-octave edge that at most
  //    1/64 of the boxes exceed are large (tested against the cells they cover)
  const std::size_t nb = boxes_.size();
  width_.resize(nb);
  cell_of_.resize(nb);
  std::uint32_t hist[kWidthBins] = {};
  std::size_t n = 0;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (std::uint32_t h = 0; h < nb; ++h) {
    const Box& b = boxes_[h];
    if (!b.live || b.added) {
      width_[h] = -1.0;
      continue;
    }
    const geom::Vec3 d = b.box.hi - b.box.lo;
    const bool finite = std::isfinite(b.box.lo.x + b.box.lo.y + b.box.lo.z + d.x + d.y + d.z);
    const double w = finite ? std::max({d.x, d.y, d.z, 0.0}) : kInf;
    width_[h] = w;
    ++hist[widthBin(w)];
    ++n;
  }
  const std::size_t max_large = n / 64;
  std::size_t above = 0;
  int bin = kWidthBins - 1;
  while (bin > 0 && above + hist[bin] <= max_large)
    above += hist[bin--];
  const double small_limit = binTop(bin);

  // 2. the grid over the small boxes' low corners; a cell a little wider than any small box, so
  //    that two small boxes that overlap have low corners in neighbouring cells despite rounding
  double lo_W[3] = {kInf, kInf, kInf};
  double top_W[3] = {-kInf, -kInf, -kInf};
  std::size_t n_small = 0;
  double max_small = 0.0;
  large_.clear();
  for (std::uint32_t h = 0; h < nb; ++h) {
    const double w = width_[h];
    if (w < 0.0)
      continue;
    if (w > small_limit) {
      large_.push_back(h);
      continue;
    }
    ++n_small;
    max_small = std::max(max_small, w);
    for (int k = 0; k < 3; ++k) {
      lo_W[k] = std::min(lo_W[k], boxes_[h].box.lo[k]);
      top_W[k] = std::max(top_W[k], boxes_[h].box.lo[k]);
    }
  }
  if (!forced && large_.size() * large_.size() > 16 * n + 64)
    return false;
  // the cell as wide as the widest small box (not small_limit, the top of its quarter octave:
  // up to 19 % more per axis, 68 % more boxes tested)
  double size = (max_small > 0.0 ? max_small : small_limit) * (1.0 + 0x1p-20);
  const double max_cells = static_cast<double>(kCellsPerBox * n_small + 64);
  int dims[3] = {0, 0, 0};
  if (n_small != 0) {
    // sparse boxes (or points): cells wider, as far as to keep the grid's size
    for (;;) {
      double count = 1.0;
      for (int k = 0; k < 3; ++k)
        count *= std::floor((top_W[k] - lo_W[k]) / size) + 1.0;
      if (count <= max_cells)
        break;
      size *= std::max(std::cbrt(count / max_cells), 1.0 + 0x1p-10);
    }
    for (int k = 0; k < 3; ++k)
      dims[k] = static_cast<int>(std::floor((top_W[k] - lo_W[k]) / size)) + 1;
  }
  const double inv = 1.0 / size;
  const std::size_t cells = static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) *
                            static_cast<std::size_t>(dims[2]);

  // 3. small boxes sorted by cell (a counting sort), their keys side by side
  cell_start_.assign(cells + 1, 0);
  for (std::uint32_t h = 0; h < nb; ++h) {
    const double w = width_[h];
    if (w < 0.0 || w > small_limit)
      continue;
    int i[3];
    for (int k = 0; k < 3; ++k)
      i[k] = std::min(static_cast<int>((boxes_[h].box.lo[k] - lo_W[k]) * inv), dims[k] - 1);
    const std::uint32_t c = static_cast<std::uint32_t>((i[2] * dims[1] + i[1]) * dims[0] + i[0]);
    cell_of_[h] = c;
    ++cell_start_[c + 1];
  }
  if (!forced) {
    // most boxes in a few cells (a dense cluster): the sweep does better
    std::size_t crowd = 0;
    for (std::size_t c = 1; c <= cells; ++c)
      crowd += static_cast<std::size_t>(cell_start_[c]) * cell_start_[c];
    if (crowd > 32 * n_small + 64)
      return false;
  }
  // prefix sums, and the list of the cells that hold a box (in order; written without a branch,
  // since whether a cell is empty is random)
  occupied_.resize(n_small + 1);
  std::uint32_t* occupied = occupied_.data();
  std::size_t n_occupied = 0;
  for (std::size_t c = 1; c <= cells; ++c) {
    occupied[n_occupied] = static_cast<std::uint32_t>(c - 1);
    n_occupied += static_cast<std::size_t>(cell_start_[c] != 0);
    cell_start_[c] += cell_start_[c - 1];
  }
  grid_.resize(n_small);
  grid_tag_.resize(n_small);
  for (std::uint32_t h = 0; h < nb; ++h) {
    const double w = width_[h];
    if (w < 0.0 || w > small_limit)
      continue;
    const std::uint32_t at = cell_start_[cell_of_[h]]++;
    GridBox& g = grid_[at];
    for (int k = 0; k < 3; ++k) {
      g.lo[k] = key_[k][h << 1];
      g.hi[k] = key_[k][h << 1 | 1];
    }
    const BoxFilter& f = boxes_[h].filter;
    grid_tag_[at] = {h, f.body, f.group, f.mask, f.is_static};
  }
  for (std::size_t c = cells; c > 0; --c)
    cell_start_[c] = cell_start_[c - 1];
  if (cells != 0)
    cell_start_[0] = 0;

  // 4. each small box against the rest of its cell and the 13 cells after it (the other 13
  //    neighbours find it): (x+1, y, z), (x-1..x+1, y+1, z), (x-1..x+1, y-1..y+1, z+1)
  found_.clear();
  const std::uint32_t* start = cell_start_.data();
  const GridBox* g = grid_.data();
  const GridTag* tag = grid_tag_.data();
  // the overlap test without a branch per axis (its outcome is random; a hit is rare), the
  // filters read only on a hit
  auto test = [this, g, tag](std::uint32_t i, std::uint32_t j) {
    if (overlapKeys(g[i], g[j]) && admissibleTags(tag[i], tag[j]))
      found_.push_back(key(tag[i].handle, tag[j].handle));
  };
  const int dx = dims[0], dy = dims[1], dz = dims[2];
  // a cell's candidates are distinct boxes of other cells: fewer than n_small, and four more
  // written past the last
  cand_.resize(n_small + 4);
  std::uint32_t* cand = cand_.data();
  {
    // the occupied cells only, their coordinates carried from one to the next
    int x = 0, y = 0, z = 0;
    std::uint32_t at = 0;
    for (std::size_t o = 0; o < n_occupied; ++o) {
      const std::uint32_t c = occupied[o];
      x += static_cast<int>(c - at);
      at = c;
      while (x >= dx) {
        x -= dx;
        if (++y == dy) {
          y = 0;
          ++z;
        }
      }
      const int row = static_cast<int>(c) - x;
      const std::uint32_t b = start[c], e = start[c + 1];
      // the rest of the cell and the cell (x+1, y, z) are one run of grid_
      const std::uint32_t run_end = x + 1 < dx ? start[row + x + 2] : e;
      // the four runs of three cells (empty outside the grid)
      std::uint32_t rb[4] = {0, 0, 0, 0}, re[4] = {0, 0, 0, 0};
      const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, dx - 1);
      auto span = [&](int s, int yy, int zz) {
        if (yy < 0 || yy >= dy || zz >= dz)
          return;
        const int r = (zz * dy + yy) * dx;
        rb[s] = start[r + x0];
        re[s] = start[r + x1 + 1];
      };
      span(0, y + 1, z);
      span(1, y - 1, z + 1);
      span(2, y, z + 1);
      span(3, y + 1, z + 1);
      // the cell x+1 and the four runs gathered into one list of candidates: four indices copied
      // per run without a branch (a run holds one or two boxes mostly), the rest one by one
      std::uint32_t n_cand = 0;
      auto gather = [&](std::uint32_t from, std::uint32_t to) {
        const std::uint32_t count = to - from;
        for (std::uint32_t t = 0; t < 4; ++t)
          cand[n_cand + t] = from + t;
        for (std::uint32_t t = 4; t < count; ++t)
          cand[n_cand + t] = from + t;
        n_cand += count;
      };
      gather(e, run_end);
      for (int r = 0; r < 4; ++r)
        gather(rb[r], re[r]);
      for (std::uint32_t i = b; i < e; ++i) {
        for (std::uint32_t j = i + 1; j < e; ++j)
          test(i, j);
        for (std::uint32_t k = 0; k < n_cand; ++k)
          test(i, cand[k]);
      }
    }
  }
  if (!gridLarge(lo_W, inv, dims, forced))
    return false;
  applyFound();
  ++grid_commits_;
  return true;
}

bool SweepAndPrune::gridLarge(const double* lo_W, double inv, const int* dims, bool forced) {
  // a large box against the small boxes whose low corners lie in the cells from one below its
  // own low corner's to one above its high corner's (or all of them), then against each other
  const std::size_t n_small = grid_.size();
  std::size_t work = 0;
  auto keys = [this](std::uint32_t h) {
    GridBox a{};
    for (int k = 0; k < 3; ++k) {
      a.lo[k] = key_[k][h << 1];
      a.hi[k] = key_[k][h << 1 | 1];
    }
    return a;
  };
  auto test = [this](const GridBox& a, std::uint32_t ha, const GridBox& b, std::uint32_t hb) {
    if (overlapKeys(a, b) && admissible(ha, hb))
      found_.push_back(key(ha, hb));
  };
  for (const std::uint32_t h : large_) {
    const GridBox a = keys(h);
    int lo[3] = {0, 0, 0}, hi[3] = {-1, -1, -1};
    double covered = 0.0;
    if (std::isfinite(width_[h]) && n_small != 0) {
      covered = 1.0;
      for (int k = 0; k < 3; ++k) {
        const double d = dims[k];
        const double l = std::clamp((boxes_[h].box.lo[k] - lo_W[k]) * inv, -4.0, d + 4.0);
        const double t = std::clamp((boxes_[h].box.hi[k] - lo_W[k]) * inv, -4.0, d + 4.0);
        lo[k] = std::max(static_cast<int>(std::floor(l)) - 1, 0);
        hi[k] = std::min(static_cast<int>(std::floor(t)) + 1, dims[k] - 1);
        covered *= std::max(hi[k] - lo[k] + 1, 0);
      }
    }
    if (!std::isfinite(width_[h]) || covered > static_cast<double>(n_small)) {
      work += n_small;
      for (std::size_t j = 0; j < n_small; ++j)
        test(a, h, grid_[j], grid_tag_[j].handle);
      continue;
    }
    work += static_cast<std::size_t>(covered);
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        const int row = (z * dims[1] + y) * dims[0];
        const std::uint32_t* start = cell_start_.data() + row;
        for (std::uint32_t j = start[lo[0]]; j < start[hi[0] + 1]; ++j)
          test(a, h, grid_[j], grid_tag_[j].handle);
      }
    }
  }
  if (!forced && work > 16 * (n_small + large_.size()) + 64)
    return false;
  for (std::size_t i = 0; i < large_.size(); ++i) {
    const GridBox a = keys(large_[i]);
    for (std::size_t j = i + 1; j < large_.size(); ++j)
      test(a, large_[i], keys(large_[j]), large_[j]);
  }
  return true;
}

void SweepAndPrune::applyFound() {
  // the pairs found again are kept; the others removed, then the new ones added
  seen_.assign(pairs_.size(), 0);
  std::size_t fresh = 0;
  for (const std::uint64_t k : found_) {
    const std::uint32_t i = index_.find(k);
    if (i == FlatMap::kNone)
      found_[fresh++] = k;
    else
      seen_[i] = 1;
  }
  // downwards: a removal moves the last pair, already seen, into the hole
  for (std::size_t i = pairs_.size(); i-- > 0;) {
    if (seen_[i] == 0)
      removePair(pairs_[i].lo, pairs_[i].hi);
  }
  for (std::size_t f = 0; f < fresh; ++f) {
    addPair(static_cast<std::uint32_t>(found_[f] >> 32),
            static_cast<std::uint32_t>(found_[f] & 0xffffffffu));
  }
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
  clearDirty();
}

void SweepAndPrune::prewarm() {
  commit();
  if (lists_stale_)
    resortLists();
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
  w.flag(lists_stale_);
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
