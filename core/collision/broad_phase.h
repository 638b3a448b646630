#pragma once
/// \file
/// Incremental sweep and prune (Cohen, Lin, Manocha, Ponamgi, "I-COLLIDE", I3D 1995; §4 of
/// Gregory et al. 2000): one sorted list of box endpoints per axis, kept sorted by insertion sort
/// as boxes move (coherence makes each move a few swaps), and overlap counting: a swap of a min
/// past a max starts or ends an overlap on that axis, and a pair is reported when its boxes
/// overlap on all three axes. Boxes are closed: touching boxes overlap (and so do boxes less
/// than one unit in the last place apart).
/// When most boxes move in one frame (and there are many), the pair set is instead recomputed from
/// scratch on a uniform grid of the boxes' low corners (the spatial hashing of Teschner et al.,
/// "Optimized Spatial Hashing for Collision Detection of Deformable Objects", VMV 2003, on a dense
/// grid; boxes much wider than the cell are tested against the cells they cover) and compared
/// with the last one: the same pairs and the same net added/removed events, at a cost that does
/// not grow with the endpoint swaps. The sorted lists are then left stale and re-sorted, without
/// transitions, at the first frame that moves few boxes again.
/// Capacities grow while boxes are added (between ticks); update() allocates nothing unless the
/// number of overlapping pairs (or of cells of the grid) exceeds every count seen before.

#include <cstdint>
#include <span>
#include <vector>

#include "core/common/flat_map.h"
#include "core/common/reserved_vector.h"
#include "core/common/state_writer.h"
#include "core/geometry/pose.h"

namespace hapticd::collision {

/// An axis-aligned box in world coordinates.
struct Aabb {
  geom::Vec3 lo{0.0};
  geom::Vec3 hi{0.0};
};

/// Who may collide with whom. Pairs of one body, pairs of two static boxes, and pairs whose
/// filters refuse each other never become pairs.
struct BoxFilter {
  std::uint32_t body = 0;    ///< boxes of the same body never pair
  bool is_static = false;    ///< two static boxes never pair
  std::uint32_t group = 1;   ///< collision groups this box belongs to (bits)
  std::uint32_t mask = ~0u;  ///< groups this box collides with (bits)
};

/// A pair of box handles, lo < hi.
struct BoxPair {
  std::uint32_t lo = 0, hi = 0;
  friend bool operator==(const BoxPair&, const BoxPair&) = default;
};

/// What changed in the set of overlapping pairs.
struct PairEvent {
  enum class Kind : std::uint8_t { kAdded, kRemoved };
  Kind kind = Kind::kAdded;
  BoxPair pair;
};

// bugprone-reserved-identifier: clang-tidy 14 reports the loop index `__i0` of the
// compiler-generated copy of the class's array members, not a name of ours
// NOLINTNEXTLINE(bugprone-reserved-identifier)
class SweepAndPrune {
 public:
  /// Adds a box; returns its handle (handles of removed boxes are reused). It enters the lists at
  /// the next commit() (many at once are sorted in and swept in O(n log n)); the pairs it forms are
  /// reported as kAdded events. Not on the servo thread (may allocate).
  std::uint32_t add(const Aabb& box, const BoxFilter& filter);
  /// Removes a box; its pairs are reported as kRemoved. Not on the servo thread.
  void remove(std::uint32_t handle);
  /// Gives a box its new extent; the move takes effect at the next commit(). Servo thread.
  void update(std::uint32_t handle, const Aabb& box);
  /// Applies the moves given since the last commit and reports the pair changes as events.
  /// Fewer than a third of the boxes moved: each endpoint is moved by insertion (cost ~ the swaps
  /// it makes); every change of endpoint order between a min and a max is one overlap transition.
  /// More, among at least gridMinBoxes() boxes: the pairs are recomputed on a grid and compared
  /// with the last ones (the sorted lists are left stale; the next commit that moves fewer boxes
  /// recomputes once more and re-sorts them). More among fewer boxes, or when the grid would be
  /// dense (most boxes in a few cells): all endpoint values are refreshed and each axis is
  /// re-sorted by one insertion-sort pass over contiguous memory, with transitions. Servo
  /// thread: allocates only when the pair set or the grid outgrows its capacity.
  void commit();

  /// The events since the last call, in the order they happened; a pair added and removed in
  /// between shows both events (within one commit that recomputed the pairs, only the net change
  /// shows: removals first, then additions). The span is valid until the next call of any
  /// mutating function.
  std::span<const PairEvent> takeEvents();

  /// The current overlapping pairs (unordered).
  std::span<const BoxPair> pairs() const { return pairs_; }
  bool overlapping(std::uint32_t a, std::uint32_t b) const;
  const Aabb& box(std::uint32_t handle) const { return boxes_[handle].box; }
  /// The lists' own overlap test on two boxes' values: closed, and boxes less than one unit in
  /// the last place apart overlap too. Two boxes the lists would pair (filters aside) pass it.
  static bool overlap(const Aabb& a, const Aabb& b);
  /// Boxes moved since the last commit().
  std::size_t pending() const { return dirty_.size(); }

  /// Reserves room for `boxes` boxes and `pairs` pairs (so that update() never allocates), and
  /// writes the grid's scratch once (so that the first grid commit faults no fresh pages). Not
  /// on the servo thread.
  void reserve(std::size_t boxes, std::size_t pairs);

  /// Endpoint swaps done by update() since construction (a measure of coherence).
  std::uint64_t swaps() const { return swaps_; }
  /// Commits that recomputed the pair set on the grid since construction.
  std::uint64_t gridCommits() const { return grid_commits_; }
  /// The fewest live boxes for which a commit that moves a third of them or more uses the grid
  /// (kGridMinBoxes unless set; 0: always, for tests). Not on the servo thread.
  void setGridMinBoxes(std::size_t boxes) { grid_min_boxes_ = boxes; }
  std::size_t gridMinBoxes() const { return grid_min_boxes_; }
  static constexpr std::size_t kGridMinBoxes = 256;
  /// Cold work since construction (a scene swap's prewarm is judged by these): commits that
  /// sorted added boxes into the lists (the first sort), and rebuilds of the endpoint positions
  /// (a whole pass over the lists, lazily after a sort or an all-axes pass). Not state (not in
  /// writeState()).
  std::uint64_t fullSorts() const { return full_sorts_; }
  std::uint64_t positionRebuilds() const { return position_rebuilds_; }
  /// Commits what is pending, re-sorts the lists if the grid left them stale and rebuilds the
  /// endpoint positions if a sort left them stale, so that the next commit() of a few moved
  /// boxes does no whole pass. Off the servo thread (a
  /// scene's prewarm); allocates only as commit() does.
  void prewarm();

  /// Writes the boxes, the sorted endpoint lists and the pair list in its order (not the hash
  /// index of the pairs or the event lists, which commit() and takeEvents() rewrite). For the
  /// simulation state's hash (core/sim/scene_state.h).
  void writeState(StateWriter& w) const;

 private:
  struct Endpoint {
    std::uint64_t key;   // sort key of the value (see broad_phase.cpp)
    std::uint32_t data;  // handle << 1 | is_max
  };
  struct Box {
    Aabb box;
    BoxFilter filter;
    bool live = false;
    bool dirty = false;
    bool added = false;  // added since the last commit
  };

  // a box on the grid: its sort keys (the lists' overlap test, exactly); read for every test
  struct GridBox {
    std::uint64_t lo[3];
    std::uint64_t hi[3];
  };
  // beside it, in the same order: who it is, read only when two boxes overlap (a copy of the
  // filter, so that a hit does not read boxes_ at random)
  struct GridTag {
    std::uint32_t handle;
    std::uint32_t body;
    std::uint32_t group;
    std::uint32_t mask;
    bool is_static;
  };

  bool admissible(std::uint32_t a, std::uint32_t b) const;
  bool overlapOn(std::uint32_t a, std::uint32_t b, int axis) const;
  void transition(int axis, std::uint32_t moving, std::uint32_t passed);
  void addPair(std::uint32_t a, std::uint32_t b);
  void removePair(std::uint32_t a, std::uint32_t b);
  void moveEndpoint(int axis, std::uint32_t index);
  void sortAxis(int axis);
  void applyMoves();
  void insertAdded();
  void rebuildPositions();
  bool gridCommit(bool forced);
  bool gridLarge(const double* lo_W, double inv, const int* dims, bool forced);
  void clearDirty();
  void applyFound();
  void resortLists();
  static std::uint64_t key(std::uint32_t a, std::uint32_t b);

  ReservedVector<Box> boxes_;
  ReservedVector<std::uint32_t> free_;
  ReservedVector<Endpoint> axes_[3];
  ReservedVector<std::uint64_t> key_[3];  // by endpoint id (handle << 1 | is_max): the new sort key
  ReservedVector<std::uint32_t> pos_[3];  // by endpoint id: index in axes_ (when positions_valid_)
  bool positions_valid_ = true;
  bool lists_stale_ = false;  // after a grid commit: axes_ not sorted by key_ (the pairs are right)
  ReservedVector<std::uint32_t> pair_count_;  // by handle: pairs the box is in
  ReservedVector<std::uint32_t> dirty_;
  ReservedVector<std::uint32_t> added_;
  ReservedVector<BoxPair> pairs_;
  FlatMap index_;  // pair key -> index into pairs_
  ReservedVector<PairEvent> events_;
  ReservedVector<PairEvent> taken_;
  std::size_t live_ = 0;
  std::uint64_t swaps_ = 0;
  std::uint64_t full_sorts_ = 0;
  std::uint64_t position_rebuilds_ = 0;
  std::uint64_t grid_commits_ = 0;
  std::size_t grid_min_boxes_ = kGridMinBoxes;

  // grid scratch (not state): rewritten by every grid commit, grown only past its largest size
  ReservedVector<double> width_;              // by handle: widest extent, < 0 when not on the grid
  ReservedVector<std::uint32_t> cell_of_;     // by handle: cell of the low corner
  ReservedVector<std::uint32_t> cell_start_;  // by cell: first index into grid_ (prefix sums)
  ReservedVector<GridBox> grid_;              // small boxes by cell
  ReservedVector<GridTag> grid_tag_;          // their handles and filters, in the same order
  ReservedVector<std::uint32_t> large_;       // boxes wider than a cell (or not finite)
  ReservedVector<std::uint32_t> occupied_;    // cells that hold a small box, in order
  ReservedVector<std::uint32_t> cand_;        // one cell's candidates (indices into grid_)
  ReservedVector<std::uint64_t> found_;       // pair keys found on the grid
  ReservedVector<std::uint8_t> seen_;         // by index into pairs_: found again
};

}  // namespace hapticd::collision
