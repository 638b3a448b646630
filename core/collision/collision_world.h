#pragma once
/// \file
/// The collision step of one tick (§4, §4.2 of Gregory et al. 2000): bodies made of convex
/// primitives; per-primitive boxes tightened incrementally (extreme vertices climbed from last
/// tick's); sweep and prune; a pair cache that keeps each close pair's narrow-phase state across
/// ticks; the real-time scheduler that tests no more pairs than the budget allows and never
/// silently forgets one; the narrow phase on the chosen pairs.
///
/// Threads: build and change the world (addBody, removeBody, reserve) off the servo thread;
/// setPose() and step() are servo-thread calls that allocate nothing once the capacities have
/// grown to the scene's size (reserve() makes that so from the start; the narrow phase's depth
/// scratch is sized by addBody for every shape the world holds).

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "core/collision/broad_phase.h"
#include "core/collision/pair_query.h"
#include "core/common/flat_map.h"
#include "core/common/reserved_vector.h"
#include "core/common/state_writer.h"

namespace hapticd::collision {

enum class BodyKind : std::uint8_t { kStatic, kKinematic, kDynamic, kProbe };

struct PrimitiveDesc {
  std::shared_ptr<const Polytope> shape;
  Transform X_BP;  ///< the primitive's pose in its body's frame
  /// Per-primitive collision filter, combined with the body's (bitwise and): two primitives
  /// collide when (group_a & mask_b) && (group_b & mask_a). Default: the body's alone.
  std::uint32_t group = ~0u;
  std::uint32_t mask = ~0u;
};

struct BodyDesc {
  BodyKind kind = BodyKind::kStatic;
  std::uint32_t group = 1;   ///< collision filter: groups of this body (bits)
  std::uint32_t mask = ~0u;  ///< groups it collides with (bits)
  std::vector<PrimitiveDesc> primitives;
  /// Its boxes grow by this much (scene units) on every side; negative: WorldOptions::box_margin.
  /// A pair is found while its two bodies' margins summed exceed its gap (on every axis). The
  /// dynamics give a free dynamic body a margin of its own size and speed (setMargin), so that a
  /// small body in a large scene is not near everything within the scene's margin.
  double margin = -1.0;
};

/// How many pairs the narrow phase may test per tick (§4.2).
struct SchedulerBudget {
  /// At most this many pair tests per tick; 0 means no limit.
  std::uint32_t max_pairs = 0;
  /// Stop starting pair tests once this much time has gone in the narrow phase; 0 means no limit.
  /// A time budget makes runs depend on the machine: replays that must be bitwise identical use
  /// max_pairs only.
  double max_microseconds = 0.0;
};

/// Another method answering the pair queries in place of queryPair, for studies that run a
/// method inside the closed loop (hapticstudy: the depth along the motion, the peer libraries;
/// docs/accuracy.md). The daemon never sets one. Called on the thread that steps the world; it
/// may allocate (a study's tick is not the servo thread).
class PairQueryMethod {
 public:
  virtual ~PairQueryMethod() = default;
  /// Sets every field of `out` as queryPair does, for B at X_AB in A's frame (the manifold may
  /// be empty: the response then makes one row of the witnesses' midpoint and the normal).
  /// `X_AB_last`: the pair's pose at its previous test, null at its first. `cache`: the pair's.
  virtual void query(const Polytope& a,
                     const Polytope& b,
                     const Transform& X_AB,
                     const Transform* X_AB_last,
                     PairCache& cache,
                     PairResult& out) = 0;
};

struct WorldOptions {
  /// Boxes grow by this much (scene units) on every side, so that pairs closer than it are found
  /// (the predictive distance δ of §5.2 belongs here).
  double box_margin = 0.0;
  /// A probe body's boxes (BodyKind::kProbe, unless its BodyDesc::margin says) grow by this
  /// instead; negative: box_margin. The Simulation sets it, in a scene with dynamics, to what
  /// the proxy reads (its rows' and attach distances), below the dynamics' box_margin.
  double probe_margin = -1.0;
  SchedulerBudget budget;
  QueryOptions query;
  /// A pair whose bodies have not been given a pose since its last test keeps that answer (it
  /// is exact still) instead of being tested again; it stays listed in contacts() with its age.
  bool skip_unmoved_pairs = false;
  /// Flush seams (docs/collision-pipeline.md "Flush seams"): a body resting on a face, whose
  /// contact with another piece lying wholly below that face's plane (the next tile of a floor,
  /// the next piece of a decomposed surface) is given that plane's normal instead of the
  /// piece's edge's or side's: what slides over the seam is not caught on it. false: the
  /// contacts as the pair queries answer them.
  bool level_flush_seams = true;
  /// A body of at least this many primitives is one box in the sweep and prune, with a tree of
  /// its pieces' boxes (in its own frame) below it: moving it costs one box, and a pair of such
  /// bodies (or one and another body's box) is resolved to piece pairs by descending the trees.
  /// The pieces' pairs are exactly those the sweep and prune would find with a box per piece
  /// (the leaves are compared on the same exact boxes by the same closed test). 0: every
  /// primitive is a box of its own in the sweep and prune.
  std::uint32_t piece_tree_min = 8;
  /// A descent of two trees starts from where the last one stopped (its front: the node pairs
  /// found apart and the overlapping leaf pairs), not from the roots, when the front fits in
  /// what reserve() set aside; the same piece pairs either way (StepStats::node_pairs_visited
  /// counts the difference). false: every descent from the roots.
  bool descent_fronts = true;
  /// A front entry that cannot have changed is not looked at again: two nodes found apart by a
  /// gap g, or two leaves whose boxes overlap by o on every axis (and their pieces' exact boxes
  /// overlap, or not, by as much), stay so while the two bodies' bounds of how far any face of
  /// their boxes can have moved grow by less than g or o (docs/collision-pipeline.md). The same
  /// fronts, pairs and states either way (StepStats::node_pairs_kept counts the entries kept).
  /// false: every entry of a front looked at again.
  bool descent_keep = true;
  /// A pair found farther than far_distance by a margin M stays far, its separating plane not
  /// evaluated again, while its two bodies have moved less than M / 2 in all since (each body
  /// keeps the sum over steps of its origin's translation plus its turn's chord times its
  /// radius); the same pairs are far either way (the plane's bound loses at most what they
  /// moved). false: the plane evaluated every step.
  bool far_by_travel = true;
  /// A pair not yet tested is first tried against the centroids' plane by its pieces' world
  /// boxes' extremes along it (a lower bound of the plane's gap: the pieces' vertices are not
  /// read) and, found far so, keeps that bound; far() puts the plane's exact gap in its place
  /// before the bound could find the pair near. The same pairs are far either way. false: the
  /// exact gap at once.
  bool far_box_bound = true;
  /// The coherent exact depth (penetrationDepthCoherent, docs/narrow-phase.md "Coherent exact
  /// depth" and "In the collision world"): at most this many pairs track their penetration depth
  /// at once, each with a DepthTracker from a pool the world reserves as bodies are added (off
  /// the servo thread), sized for the largest shape of at most kMaxTrackedFaces faces it holds. A
  /// pair takes a tracker at its first test after one that found it penetrating and gives it
  /// back once apart; a penetrating pair that finds the pool empty takes one from a pair not
  /// tested for two steps, else is answered by the untracked method (the same exact answer,
  /// slower) and counted
  /// (StepStats::depth_untracked). A pair whose certificate fails at two tests in a row (a
  /// degenerate pose that lasts) is answered untracked for 2, 4, ... up to 64 steps before it
  /// tries again. kAutoTrackers (the default): the pool grows with the scene as bodies are
  /// added, to depth_trackers_per_primitive trackers per tracked primitive (a resting stack of
  /// n boxes has n penetrating pairs; a pile, up to about 3 per box, of which not all at once),
  /// at least kMinAutoTrackers and at most what depth_tracker_bytes holds (whichever is more);
  /// it never shrinks. 0: no tracking (every depth by penetrationDepth). Any other number: a
  /// pool of exactly that many.
  std::uint32_t depth_trackers = kAutoTrackers;
  static constexpr std::uint32_t kAutoTrackers = 0xffffffffu;
  static constexpr std::uint32_t kMinAutoTrackers = 64;
  /// The automatic pool's trackers per primitive of at most kMaxTrackedFaces faces.
  std::uint32_t depth_trackers_per_primitive = 2;
  /// The automatic pool's memory bound (bytes; DepthTracker::bytesFor the largest tracked
  /// shape, times the trackers): 4 MiB holds 64 trackers for shapes of 512 faces, about 4 000
  /// for boxes.
  std::size_t depth_tracker_bytes = std::size_t{4} << 20;
  /// Shapes of more faces than this are not tracked (their pairs keep penetrationDepth): bounds
  /// the pool's memory, which grows as the largest tracked shape (about 100 bytes per face).
  static constexpr std::size_t kMaxTrackedFaces = 512;
  /// Pairs certainly farther apart than this (scene units; never less than box_margin) are
  /// neither tested nor listed in contacts(): at their last test their closest points (or, for
  /// a pair not yet tested, their pieces' boxes along one axis) were farther apart than this by
  /// more than their two bodies can have moved toward each other since (along that direction,
  /// plus each body's turn times its radius). For
  /// readers of the contacts that need no answer beyond a known distance (the proxy's rows, its
  /// attach distance), when the boxes' margin finds many pairs farther than that. 0: every pair
  /// whose boxes overlap is tested and listed.
  double far_distance = 0.0;
  /// The same for a pair with a static body; 0: far_distance.
  double far_distance_static = 0.0;
  /// Not null: every pair query is this method's (no depth tracking); studies only.
  PairQueryMethod* query_method = nullptr;
};

/// One primitive pair's answer this tick, in world coordinates.
struct Contact {
  std::uint32_t body_a = 0, body_b = 0;  ///< body_a < body_b
  std::uint32_t prim_a = 0, prim_b = 0;  ///< primitive indices within their bodies
  ContactStatus status = ContactStatus::kSeparated;
  double distance = 0.0;            ///< > 0 gap, <= 0 minus the penetration depth
  Vec3 normal{0.0};                 ///< world, unit, from a toward b
  Vec3 point_a{0.0}, point_b{0.0};  ///< world
  Manifold manifold;                ///< world
  /// The closest features (separated or touching) or the MTD's features (penetrating; Feature{}
  /// on the side whose face the MTD does not name), on primitive a and b.
  Feature feature_a, feature_b;
  std::uint32_t age = 0;  ///< ticks since this answer was computed (0: this tick)
  /// false for a close pair the scheduler has not tested yet (the fields above are then empty):
  /// such a pair is listed all the same, so that none is ever silently left out.
  bool answered = false;
};

/// Figures of one step.
struct StepStats {
  std::uint32_t pairs_overlapping = 0;  ///< box pairs after the broad phase
  std::uint32_t pairs_tested = 0;       ///< narrow-phase tests this tick
  std::uint32_t pairs_skipped = 0;      ///< overlapping pairs not tested this tick
  std::uint32_t worst_staleness = 0;    ///< ticks since the stalest skipped pair was tested
  std::uint32_t pairs_added = 0, pairs_removed = 0;  ///< broad-phase events this tick
  /// Pair states the step looked at to schedule and list (those of the awake bodies; a pair of
  /// two sleeping or static bodies is never looked at): what the step's bookkeeping costs,
  /// independent of how many bodies sleep.
  std::uint32_t pairs_visited = 0;
  /// Penetration depths of this step's pair tests (the coherent exact depth: docs/narrow-phase.md
  /// "In the collision world"): proven from the pair's tracker; its certificate failed, so the
  /// full method ran (and rebuilt the tracker); no tracked state (a pair's first penetrating
  /// test, which has no tracker yet, or the first with a tracker just taken), full method;
  /// penetrating answers of pairs that penetrated before and have no tracker (pool empty, backed
  /// off, shapes not tracked, DepthTracker::pays false, or depth_trackers 0).
  std::uint32_t depth_certified = 0;
  std::uint32_t depth_fallbacks = 0;
  std::uint32_t depth_cold = 0;
  std::uint32_t depth_untracked = 0;
  /// Overlapping pairs neither tested nor listed this step: certainly farther apart than
  /// WorldOptions::far_distance (not pairs_skipped: nothing is missed).
  std::uint32_t pairs_far = 0;
  /// Of those, the pairs known far without evaluating their separating plane again: their
  /// bodies have moved less than half the margin they were found far by (WorldOptions::
  /// far_by_travel).
  std::uint32_t pairs_far_kept = 0;
  /// Of those, the pairs found far by the boxes' bound of their centroids' plane (WorldOptions::
  /// far_box_bound), not by the plane's exact gap: their pieces' vertices not read.
  std::uint32_t pairs_far_box_bound = 0;
  /// Node pairs of two piece trees the descents looked at this step (WorldOptions::
  /// descent_fronts).
  std::uint32_t node_pairs_visited = 0;
  /// Front entries the descents kept as they were without looking at them (WorldOptions::
  /// descent_keep; not in node_pairs_visited).
  std::uint32_t node_pairs_kept = 0;
};

class CollisionWorld {
 public:
  explicit CollisionWorld(const WorldOptions& options = {});

  /// Adds a body at pose X_WB; returns its id (ids of removed bodies are reused).
  std::uint32_t addBody(const BodyDesc& desc, const geom::Pose& X_WB);
  void removeBody(std::uint32_t body);
  /// Room for this many primitives and close pairs, so that steps never allocate.
  void reserve(std::size_t primitives, std::size_t pairs);
  /// The close pairs reserve() made room for (the largest count given).
  std::size_t reservedPairs() const { return reserved_pairs_; }

  /// Moves a non-static body. Servo thread.
  void setPose(std::uint32_t body, const geom::Pose& X_WB);
  /// A non-static body's boxes grow by `margin` (scene units, >= 0; BodyDesc::margin) from the
  /// next step on, as if it had moved (its pairs are tested again). Not a finite number >= 0:
  /// ignored. Servo thread; no allocation.
  void setMargin(std::uint32_t body, double margin);
  /// The margin its boxes grow by (setMargin; first its base margin).
  double margin(std::uint32_t body) const { return bodies_[body].margin; }
  /// The margin it was added with: BodyDesc::margin, else probe_margin for a probe, else
  /// box_margin.
  double baseMargin(std::uint32_t body) const { return bodies_[body].base_margin; }
  const geom::Pose& pose(std::uint32_t body) const { return bodies_[body].X_WB; }
  BodyKind kind(std::uint32_t body) const { return bodies_[body].desc.kind; }
  /// A sleeping body is not moving and nothing about it is asked: its pairs with sleeping and
  /// static bodies are neither tested nor listed in contacts() (pairs with an awake body are),
  /// nor looked at by step(): their answers stay where they are, and a world of any number of
  /// sleeping bodies costs a step what its awake bodies' pairs cost (StepStats::pairs_visited).
  /// For bodies no stage moves (a scene without dynamics) and the dynamics' sleeping islands.
  /// Woken, its pairs are listed again, and tested again where it moved while asleep. Takes
  /// effect at the next step() or relist(). Servo thread; no allocation.
  void setAsleep(std::uint32_t body, bool asleep);
  bool asleep(std::uint32_t body) const { return bodies_[body].asleep; }
  /// A disabled body is out of the scene: none of its pairs is tested or listed in contacts()
  /// (its boxes stay in the sweep and prune, so that disabling and enabling allocate nothing and
  /// cost no sort). Enabled again, its pairs are tested at the next step even when
  /// skip_unmoved_pairs would keep their old answers. Bodies start enabled. Servo thread; no
  /// allocation.
  void setEnabled(std::uint32_t body, bool enabled);
  bool enabled(std::uint32_t body) const { return bodies_[body].enabled; }

  /// One tick: boxes, sweep and prune, scheduling, narrow phase. Servo thread.
  StepStats step();
  /// Lists contacts() again after setAsleep() or setEnabled() changed what is asked, within the
  /// same tick: the pairs that are now asked about and have no answer at the current poses are
  /// tested (within the budget), the others keep theirs. Poses given since the last step() take
  /// effect at the next step(), not here. Servo thread; no allocation.
  StepStats relist();

  /// Bodies given a pose (setPose) since the last clearPosed(), each once (in the order of their
  /// first pose): what a reader of the poses must read again; a body not listed has the pose it
  /// had then. Servo thread.
  std::span<const std::uint32_t> posed() const { return posed_; }
  void clearPosed();

  /// Every close primitive pair after the last step, grouped by body pair (sorted by body_a, then
  /// body_b); pairs skipped this tick carry their last answer with age > 0.
  std::span<const Contact> contacts() const { return contacts_; }

  const WorldOptions& options() const { return options_; }
  std::uint64_t tick() const { return tick_; }

  /// Cold work since construction: what a new scene's first steps do once and its later steps
  /// should not (a scene swap's prewarm does it off the servo thread, core/sim/scene_state.h).
  /// Not state (not in writeState()). Any thread that may read the world.
  struct ColdCounters {
    std::uint64_t cold_queries = 0;       ///< pair queries with no cache yet (a pair's first)
    std::uint64_t full_sorts = 0;         ///< SweepAndPrune::fullSorts()
    std::uint64_t position_rebuilds = 0;  ///< SweepAndPrune::positionRebuilds()
  };
  ColdCounters coldCounters() const {
    return {cold_queries_, sap_.fullSorts(), sap_.positionRebuilds()};
  }
  /// The penetration depths since construction, as StepStats counts them per step, and the
  /// tracker pool (WorldOptions::depth_trackers). Not state (not in writeState()): counters. Any
  /// thread that may read the world.
  struct DepthCounters {
    std::uint64_t certified = 0, fallbacks = 0, cold = 0, untracked = 0;
    std::uint64_t taken = 0;   ///< trackers taken from the pool by a pair
    std::uint64_t stolen = 0;  ///< of them, taken from a pair not tested for two steps
    std::uint32_t in_use = 0;  ///< trackers held by pairs now
    std::uint32_t peak = 0;    ///< the most held at once
  };
  const DepthCounters& depthCounters() const { return depth_counters_; }
  /// The tracker pool: its trackers and the bytes they have reserved (all of them, every
  /// tracker sized for the largest tracked shape).
  std::size_t depthTrackers() const { return trackers_.size(); }
  std::size_t depthTrackerBytes() const;

  /// Makes the broad phase's lazily rebuilt tables ready (SweepAndPrune::prewarm) and applies
  /// its events, so that the next step of a few moved bodies does no whole-list pass. Off the
  /// servo thread (a scene's prewarm, after its first steps).
  void prewarm();

  /// Writes the world's state: bodies' poses and flags, primitives' extreme-vertex hints, the
  /// sweep and prune, every pair's caches and last answer, contacts(), the tick (not the shapes,
  /// the scheduler's scratch or the hash index of the pairs). For the simulation state's hash
  /// and comparison (core/sim/scene_state.h). Any thread that may read the world.
  void writeState(StateWriter& w) const;

 private:
  // a node of a body's piece tree: a box in the body's frame around the vertices of the pieces
  // below it; a leaf holds one piece (`prim`, an index into prims_)
  struct TreeNode {
    Vec3 c{0.0}, e{0.0};  // centre and half extents, body frame
    double scale = 0.0;   // the largest coordinate magnitude met in computing a piece's box
    std::uint32_t left = 0, right = 0;
    std::uint32_t prim = 0xffffffffu;  // leaf: its piece
  };
  // a node of a body's piece tree in the world (what the descent reads: one cache line)
  struct WorldNode {
    Aabb box;
    std::uint32_t left = 0, right = 0;
    std::uint32_t prim = 0xffffffffu;    // leaf: its piece
    std::uint32_t parent = 0xffffffffu;  // the root: none
  };
  struct Body {
    BodyDesc desc;
    geom::Pose X_WB;
    Transform T_WB;
    std::vector<std::uint32_t> prims;  // indices into prims_
    bool live = false;
    bool moved = false;
    bool asleep = false;
    bool enabled = true;
    bool posed = false;            // in posed_
    std::uint64_t moved_tick = 0;  // the step in which its last pose took effect
    // its pair states: a doubly linked list through PairState::next / prev (kNil: none)
    std::uint32_t pairs_head = 0xffffffffu;
    std::uint32_t awake_at = 0xffffffffu;  // its index in awake_ (kNil: not awake)
    // piece tree (options_.piece_tree_min): empty for a body whose pieces are boxes of their own
    std::vector<TreeNode> tree;
    // node boxes in the world, refitted bottom-up when the body has moved: a leaf's is its piece's
    // exact box (a static body) or the box of its body-frame box turned into the world (a
    // moving one: no pass over the vertices), a node's the union of its children's
    std::vector<WorldNode> tree_W;
    std::uint64_t refit_at = 0;  // tick + 1 of the last refit (0: never)
    std::uint32_t box = 0;       // the body's broad-phase handle (a tree body)
    double radius = 0.0;         // the farthest of its vertices from its origin (far())
    double margin = 0.0;         // its boxes grow by this (setMargin; first base_margin)
    double base_margin = 0.0;    // BodyDesc::margin, probe_margin (a probe) or box_margin
    // how far any point of it can have moved since it was added: the sum over steps of its
    // origin's translation plus its turn's chord times its radius (a bound that only grows;
    // far() compares its growth with a pair's margin); its pose at the last step
    double travel = 0.0;
    geom::Pose X_stepped;
    // how far any face of any of its boxes in the descent (its tree's nodes, its pieces' boxes)
    // can have moved since it was added: the sum over steps of the largest change of a
    // translation coordinate plus the largest change of an entry of its rotation matrix times
    // box_r1, the largest sum of magnitudes of a point's body coordinates over its vertices and
    // its tree's leaf boxes' corners (a bound read off the matrices: no unit quaternion
    // assumed). A front entry found apart (or two leaves certain to overlap) by a gap g stays so
    // while the two sides' sums grow by less than g (descend)
    double box_travel = 0.0;
    double box_r1 = 0.0;
    // every piece small enough that primitiveBox takes one pass over its vertices (a larger
    // one's box is climbed to from the last one's hints, so its values may depend on which
    // steps computed it: the descent then leaves its leaf pairs' calls as they were)
    bool small_pieces = true;
  };
  struct Prim {
    std::uint32_t body = 0, index = 0;  // body and index within it
    std::uint32_t box = 0;              // broad-phase handle
    // its collision filter, its body's and its own combined (the descent reads it for every
    // pair of leaves that overlap)
    std::uint32_t group = 0, mask = 0;
    // its shape (its body's description's): what newPairState fetches ahead without reading
    // the description first
    const Polytope* shape = nullptr;
    std::array<std::uint32_t, 6> hint{};  // extreme-vertex hints: -x +x -y +y -z +z
    bool live = false;
    // a piece of a tree body: its exact box (primitiveBox), computed lazily, and the tick + 1 at
    // which it was (0: never)
    Aabb box_W;
    std::uint64_t box_at = 0;
  };
  // a pair state's first cache line holds what the descent, the listing and far() read of every
  // pair each step (most pairs overlapping are far and kept so: that line is all they cost); the
  // rest, many lines, only for the pairs near or tested
  struct alignas(64) PairState {
    std::uint32_t prim_a = 0, prim_b = 0;  // prims_ indices, ordered by body
    std::uint32_t body_a = 0;  // prims_[prim_a].body (last.body_a): whose links are which
    bool in_contact = false;
    bool live = false;
    bool from_tree = false;  // found by a descent of piece trees, not by the sweep and prune
    // made and not listed yet: its depth tracking fields, query cache and last answer (`lazy`
    // below) are not reset yet (a freed state's are stale), which resetLazy does when it is
    // first listed; most pairs never are (found far all their life)
    bool fresh = false;
    std::uint64_t visit = 0;  // the listing pass (visit_) that last looked at it
    std::uint64_t seen = 0;   // the last step whose descent found it
    // links in the pair lists of last.body_a ([0]) and last.body_b ([1])
    std::array<std::uint32_t, 2> next{0xffffffffu, 0xffffffffu};
    std::array<std::uint32_t, 2> prev{0xffffffffu, 0xffffffffu};
    // far(): a plane that separated the two by sep_d along sep_n (unit, from a toward b) when
    // its bodies were at X_WA_test, X_WB_test (from its last test, or, for a pair not yet
    // tested, from its pieces' boxes or support points); sep_d <= 0: none
    double sep_d = 0.0;
    // far() found the pair far by a margin M while its bodies' travels summed to T: it stays far
    // while they sum to less than T + M / 2 (-inf: not known far)
    double far_travel = -std::numeric_limits<double>::infinity();
    // ---- the second cache line on, set when the state is made
    std::uint64_t last_tested = 0;  // tick of the last test (the tick before it appeared, if none)
    // sep_d is a lower bound of the centroids' plane's gap, from the pieces' world boxes (the
    // pieces' vertices not read); far() puts the exact gap (the extreme vertices' at the same
    // poses) in its place before the plane could find the pair near
    bool sep_rough = false;
    Vec3 sep_n{0.0};
    geom::Pose X_WA_test, X_WB_test;
    // ---- `lazy`: reset when first listed (fresh)
    std::uint32_t tracker = 0xffffffffu;  // its depth tracker (trackers_), kNil: none
    // the tracker's certificate failed at this many tests in a row; from two on the pair is
    // answered untracked until step track_from (a back-off that doubles, up to 64 steps)
    std::uint32_t depth_misses = 0;
    std::uint64_t track_from = 0;
    PairCache cache;
    Contact last;
  };
  // a fresh state's lazy fields set as a new state's (its bodies' and pieces' ids in `last`)
  void resetLazy(PairState& s) const;
  // two broad-phase boxes that overlap, one of them (at least) a tree body's
  struct TreePair {
    std::uint32_t lo = 0, hi = 0;  // broad-phase handles
    bool fresh = true;             // not yet descended
    // its last descent's front, front_[front_begin, front_begin + front_size): the node pairs
    // where the descent stopped, depth first; the next descent starts there instead of at the
    // roots. front_size 0: none kept (it did not fit), the next descent starts at the roots
    std::uint32_t front_begin = 0, front_size = 0;
  };
  static constexpr std::uint32_t kBodyBox = 0x80000000u;  // prim_of_box_ tag: a body's box
  static constexpr std::uint32_t kNil = 0xffffffffu;

  Aabb primitiveBox(Prim& p);
  Transform primitiveTransform(const Prim& p) const;
  void applyEvents(StepStats* stats);
  // a new pair state; `mapped`: entered in state_of_pair_ (a pair of the sweep and prune, or one
  // made by a descent that looks its pairs up there: see state_of_pair_)
  std::uint32_t newPairState(std::uint32_t pa,
                             std::uint32_t pb,
                             StepStats* stats,
                             bool mapped = true);
  void freePairState(std::uint32_t si, StepStats* stats);
  void buildTree(Body& b);
  void refit(std::uint32_t body);
  const Aabb& pieceBox(std::uint32_t prim);
  void descend(TreePair& tp, StepStats* stats);
  void dropTreePair(std::uint32_t lo, std::uint32_t hi, StepStats* stats);
  // enters the tree pair's states in state_of_pair_ (and mapped_tree_states_) for a descent from
  // its roots
  void mapTreeStates(const TreePair& tp);
  // whether pair state s is one of the piece pairs of the tree pair of handles lo, hi
  bool ofTreePair(const PairState& s, std::uint32_t lo, std::uint32_t hi) const;
  void resolveTreePairs(StepStats* stats);
  void test(std::uint32_t si);
  // depth trackers: whether the pair's shapes are tracked, take one from the pool (or from a
  // pair not tested for two steps), give it back
  bool trackable(const PairState& s) const;
  void takeTracker(std::uint32_t si, bool steal);
  void releaseTracker(PairState& s);
  // the pool's trackers made and sized for the largest tracked shape so far (addBody)
  void reserveTrackers();
  // the pool's size by WorldOptions::depth_trackers (and the scene so far, when automatic)
  std::uint32_t trackerPoolSize() const;
  void linkPair(std::uint32_t si);
  void unlinkPair(std::uint32_t si);
  // the next pair state in `body`'s list after state si
  std::uint32_t nextPair(std::uint32_t si, std::uint32_t body) const {
    const PairState& s = pair_states_[si];
    return s.next[s.body_a == body ? 0 : 1];
  }
  // a body that is asked about: live, enabled, neither static nor asleep (in awake_ or not)
  void updateAwake(std::uint32_t body);
  // lists, schedules and tests the asked pairs, and fills contacts()
  void schedule(StepStats* stats);
  // contacts_ at flush seams given their support's normal (WorldOptions::level_flush_seams)
  void levelFlushSeams();
  // the largest value of dir · x over primitive `prim` of `body` (world)
  double supportValue(std::uint32_t body, std::uint32_t prim, const Vec3& dir) const;
  bool unchanged(const PairState& s) const {
    return s.last.answered && bodies_[prims_[s.prim_a].body].moved_tick <= s.last_tested &&
           bodies_[prims_[s.prim_b].body].moved_tick <= s.last_tested;
  }
  // a pair certainly farther apart than WorldOptions::far_distance
  bool far(PairState& s, bool* kept = nullptr) const;
  // the gap between the pieces' extreme vertices along sep_n at the poses X_WA_test, X_WB_test
  // (the centroids' plane's exact gap; farByBoxes)
  double centroidPlaneGap(const PairState& s) const;
  double farLimit(const PairState& s) const;
  // a pair not yet tested whose pieces' boxes are farther apart than far_distance on one axis,
  // or whose pieces are, along the line between their centroids: that axis or line as its
  // separating plane (far() then holds)
  bool farByBoxes(PairState& s);
  // a pair nothing asks about: both sides asleep or static, or either side disabled
  bool resting(const PairState& s) const {
    const Body& a = bodies_[prims_[s.prim_a].body];
    const Body& b = bodies_[prims_[s.prim_b].body];
    if (!a.enabled || !b.enabled)
      return true;
    return (a.asleep || a.desc.kind == BodyKind::kStatic) &&
           (b.asleep || b.desc.kind == BodyKind::kStatic);
  }

  WorldOptions options_;
  SweepAndPrune sap_;
  ReservedVector<Body> bodies_;
  ReservedVector<Prim> prims_;
  ReservedVector<std::uint32_t> prim_of_box_;  // handle -> prims_ index, or kBodyBox | body
  ReservedVector<TreePair> tree_pairs_;
  // a node of each side, reached from the two roots by `depth` openings of one side's node; bit
  // k of `sides` says which the k-th opened (1: b's). In a front: `apart`, the two boxes do not
  // overlap (else they are two overlapping leaves), and `state`, two leaves' pair state when
  // they had one (a hint, checked before use: spares the lookup in state_of_pair_)
  //
  // `until`: the entry is as the descent would find it again (apart; or two leaves whose boxes
  // overlap, and their pieces' exact boxes overlap or not, as found) while the two sides'
  // Body::box_travel sum to less than this (-inf: not known)
  struct NodePair {
    std::uint32_t a = 0, b = 0;
    std::uint32_t state = 0xffffffffu;
    std::uint8_t depth = 0;
    bool apart = false;
    std::uint64_t sides = 0;
    double until = -std::numeric_limits<double>::infinity();
  };
  static constexpr std::uint32_t kMaxFrontDepth = 64;  // openings a front entry can record
  ReservedVector<NodePair> descent_;  // scratch: the descent's stack, sized by addBody
  // the tree pairs' fronts (TreePair::front_begin), and the next step's being written; sized by
  // reserve() once a body has a tree
  ReservedVector<NodePair> front_, front_next_;
  void reserveFronts();
  ReservedVector<PairState> pair_states_;
  ReservedVector<std::uint32_t> free_pair_states_;
  // prim-pair key (prims_ indices) -> pair_states_ index, for the pairs of the sweep and prune.
  // A tree pair's piece pairs are not in it: a descent from the tree pair's kept front finds
  // each of its states by the front's hint (every state it has is a leaf entry of that front),
  // and a fresh tree pair has none; only a descent from the roots of a tree pair that has states
  // (its front not kept) enters them, for that descent (mapped_tree_states_). The map is sized
  // for every pair the scene can make and so is mostly cold in the cache: a lookup there was a
  // cache miss per piece pair made or dropped
  FlatMap state_of_pair_;
  ReservedVector<std::uint32_t> mapped_tree_states_;  // scratch: the states such a descent mapped
  ReservedVector<std::uint32_t> free_prims_;
  ReservedVector<std::uint32_t> free_bodies_;
  ReservedVector<std::uint32_t> moved_;  // bodies given a pose since the last step
  ReservedVector<std::uint32_t> posed_;  // bodies given a pose since clearPosed()
  // the awake bodies (updateAwake): every pair anything asks about has one of them (derived from
  // the bodies' flags: not state)
  ReservedVector<std::uint32_t> awake_;
  std::uint64_t visit_ = 0;                      // listing passes so far (PairState::visit)
  ReservedVector<std::uint64_t> order_;          // scheduler scratch: priority << 32 | state index
  ReservedVector<std::uint32_t> contact_order_;  // scratch: states listed in contacts(), sorted
  ReservedVector<Contact> contacts_;
  // a plane a piece rests on, this tick (levelFlushSeams): the piece (body, primitive), the
  // plane (normal toward the piece, offset), the piece's radius, how far the piece is above it
  // and the contact that made it (kSeveral: more than one, the same plane)
  struct Support {
    static constexpr std::size_t kSeveral = ~std::size_t{0};
    std::uint32_t body = 0, prim = 0;
    Vec3 normal{0.0};
    double offset = 0.0;
    double radius = 0.0;
    double gap = 0.0;
    std::size_t contact = 0;
  };
  ReservedVector<Support> supports_;
  DepthScratch depth_scratch_;  // the narrow phase's, sized for every shape added
  // the depth tracker pool (WorldOptions::depth_trackers), every tracker reserved by addBody for
  // tracker_faces_ faces and tracker_edges_ edges (the largest tracked shape's)
  ReservedVector<DepthTracker> trackers_;
  ReservedVector<std::uint32_t> free_trackers_;
  ReservedVector<std::uint32_t> tracker_owner_;  // per tracker: its pair state, kNil: free
  std::size_t tracker_faces_ = 0, tracker_edges_ = 0;
  std::size_t tracked_prims_ = 0;   // primitives added of at most kMaxTrackedFaces faces
  std::uint64_t steal_failed_ = 0;  // tick + 1 of the last step in which no tracker could be taken
  DepthCounters depth_counters_;
  PairResult result_;  // test()'s answer in A's frame, reused (no zeroing per query)
  std::uint64_t tick_ = 0;
  std::size_t reserved_pairs_ = 0;
  std::uint64_t cold_queries_ = 0;
};

}  // namespace hapticd::collision
