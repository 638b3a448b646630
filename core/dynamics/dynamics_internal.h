#pragma once
/// \file
/// The dynamics' per-body, per-contact and per-joint state and the small helpers that the files
/// of core/dynamics share (dynamics.cpp: create and the accessors; dynamics_step.cpp: the tick;
/// dynamics_solver.cpp: the impulse and position solvers). Not a public interface.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>

#include "core/dynamics/dynamics.h"
#include "core/geometry/rotation.h"

namespace hapticd::dynamics {
namespace detail {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// velocity iterations always run at least this many times per solve
inline constexpr std::uint32_t kMinIterations = 2;

inline Mat3 skew(const Vec3& v) {
  // column-major: columns are the images of e_x, e_y, e_z under v x .
  return Mat3{0.0, v.z, -v.y, -v.z, 0.0, v.x, v.y, -v.x, 0.0};
}

inline void tangents(const Vec3& n, Vec3* t1, Vec3* t2) {
  const Vec3 a = std::abs(n.x) < 0.57 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  *t1 = glm::normalize(glm::cross(n, a));
  *t2 = glm::cross(n, *t1);
}

inline std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
  if (a > b)
    std::swap(a, b);
  return static_cast<std::uint64_t>(a) << 32 | b;
}

}  // namespace detail

struct Dynamics::BodyState {
  scene::Motion motion = scene::Motion::kStatic;
  bool infinite = true;  // this tick: infinite mass (static, kinematic, held kinematic)
  double inv_mass = 0.0;
  Mat3 inertia_B{0.0}, inv_inertia_B{0.0};
  Quat q_BP{1.0, 0.0, 0.0, 0.0};  // principal axes in the body frame
  Vec3 inertia_P{1.0};            // principal moments (0: infinite about that axis)
  Vec3 inv_inertia_P{1.0};        // their inverses (0 for an infinite one)
  bool coast = false;  // infinite mass (declared 0, or kinematic with a declared velocity): moves
                       // at v_coast / w_coast whenever no target is given
  Vec3 v_coast{0.0}, w_coast{0.0};
  bool driven = false;       // a dynamic body the caller moves (setDriven): infinite mass
  bool asleep = false;       // its island sleeps: infinite mass, at rest, not integrated
  double rest_s = 0.0;       // how long it has been still
  std::uint32_t island = 0;  // its island's id (the root body) when it fell asleep
  bool enabled = true;       // false: out of the scene (setEnabled): frozen, no contacts
  bool isotropic = false;    // all three equal (cubes, regular polyhedra)
  Mat3 inv_inertia_W{0.0};
  Vec3 com_B{0.0};
  Vec3 x_W{0.0};  // centre of mass
  Quat q{1.0, 0.0, 0.0, 0.0};
  Mat3 R{1.0};
  Vec3 v_W{0.0}, w_W{0.0};
  Vec3 gravity_W{0.0};
  Vec3 force_W{0.0}, torque_W{0.0};
  Vec3 pv{0.0}, pw{0.0};  // split-impulse pseudo-velocities
  double size = 0.0;      // radius about the centre of mass
  bool has_target = false;
  Vec3 target_x{0.0};
  Quat target_q{1.0, 0.0, 0.0, 0.0};

  // R and inv_inertia_W were last made by updateInertia for finite mass from inertia_q (bit for
  // bit; a direct write of either clears it)
  bool inertia_made = false;
  Quat inertia_q{1.0, 0.0, 0.0, 0.0};

  void updateInertia() {
    R = glm::mat3_cast(q);
    inv_inertia_W = infinite ? Mat3{0.0} : R * inv_inertia_B * glm::transpose(R);
    inertia_made = !infinite;
    inertia_q = q;
  }
  // updateInertia for finite mass, unless made from this very q already (the start of a tick:
  // the end of the last one made them)
  void updateInertiaIfTurned() {
    if (!infinite && inertia_made && geom::sameBits(inertia_q, q))
      return;
    updateInertia();
  }
  double invMass() const { return infinite ? 0.0 : inv_mass; }
  Vec3 velocityAt(const Vec3& r) const { return v_W + glm::cross(w_W, r); }
  Vec3 pseudoAt(const Vec3& r) const { return pv + glm::cross(pw, r); }
  void applyImpulse(const Vec3& J, const Vec3& r) {
    if (infinite)
      return;
    v_W += inv_mass * J;
    w_W += inv_inertia_W * glm::cross(r, J);
  }
  void applyPseudo(const Vec3& J, const Vec3& r) {
    if (infinite)
      return;
    pv += inv_mass * J;
    pw += inv_inertia_W * glm::cross(r, J);
  }
};

// one constraint row of a contact point along a unit direction u: the angular parts and the
// effective mass
// (no default values: prepareRows writes them before any solve reads them, and a point made in
// gatherContacts is then not zeroed here)
struct Dynamics::Row {
  Vec3 ca, cb;  // ra x u, rb x u
  Vec3 ia, ib;  // inverse world inertia times those
  double mass;
};

struct Dynamics::ContactPoint {
  // user-provided, so that points_.emplace_back() does not zero the whole point first (its rows
  // are written by prepareRows before they are read)
  ContactPoint() {}  // NOLINT(modernize-use-equals-default)
  // (its primitive pair and its points on the two surfaces are in warm_next_, at the same index:
  // the next tick's warm start is written there as the point is made)
  // what the velocity iterations read, first and together (464 bytes of 656)
  std::uint32_t a = 0, b = 0;
  bool active = false;
  bool speculative = false;
  bool resting = false;    // not sliding when it became active (static friction)
  std::uint8_t group = 0;  // the first of a primitive pair's points: how many it has (else 0)
  double ima = 0.0, imb = 0.0;
  double mu = 0.0;
  double min_vn = 0.0;                    // speculative: closing allowed up to this (<= 0), else 0
  double ln = 0.0, lt1 = 0.0, lt2 = 0.0;  // this episode
  double ln_max = 0.0;  // largest normal impulse per solve (held_max_force_n), 0: none
  Vec3 n{0.0}, t1{0.0}, t2{0.0};
  Row rn, rt1, rt2;
  // the rest
  Vec3 ra_B{0.0}, rb_B{0.0};  // from each centre of mass, body frames
  Vec3 ra{0.0}, rb{0.0};      // world, current
  double gap = 0.0;           // > 0 apart, < 0 penetrating (tracked through the tick)
  double size = 0.0;          // the smaller body's size
  double mass_n = 0.0;        // normal effective mass (the split impulses use it)
  double e = 0.0, mu_s = 0.0, mu_d = 0.0;
  double bounce = 0.0;   // restitution of this impact (0 below the threshold, or done)
  double total_n = 0.0;  // whole tick
  Vec3 total_t{0.0};     // whole tick, world
  double lp = 0.0;       // split impulse
};

// the velocities of a contact's two bodies while its rows are solved (a flat contact's rows in an
// iteration: in registers instead of the bodies' states)
struct Dynamics::PairVelocity {
  Vec3 va, wa, vb, wb;
};

// a primitive pair's normal rows solved together (Dynamics::solveNormalBlock): the points of a
// flat contact with one normal, their rows written as the three rows of the contact's centroid
// (the push along n there, and the turns about the two tangents) times each point's place
// (1, u, v) in the contact plane
struct Dynamics::NormalBlock {
  bool ok = false;  // this episode: solved together (else point by point)
  std::uint8_t count = 0;
  std::array<std::uint32_t, 4> idx{};  // its points (indices into points_)
  std::array<Vec3, 4> phi{};           // each point's (1, u, v)
  Mat3 kc_inv{0.0};                    // inverse of the centroid rows' effective-mass matrix
  Mat3 g_inv{0.0};                     // inverse of sum phi phi^T
  std::array<double, 4> z{};           // four points: the distribution that is no wrench
};

struct Dynamics::JointState {
  const scene::Joint* joint = nullptr;
  bool off = false;  // this tick: a body of the joint is disabled (setEnabled): the joint is inert
  std::uint32_t a = 0;
  std::int32_t b = -1;  // -1: the scene frame
  Vec3 ra{0.0}, rb{0.0};
  Mat3 point_mass{0.0};  // inverse of K
  Mat3 ang_mass{0.0};    // fixed: inverse of angular K
  Vec3 axis{0.0}, p1{0.0}, p2{0.0};
  double m1 = 0.0, m2 = 0.0, m_axis = 0.0;
  bool has_min = false, has_max = false;
  double c_min = 0.0, c_max = 0.0;  // distance to the limits (rad), > 0 inside
  Vec3 l_point{0.0}, l_ang{0.0};    // this episode
  double l1 = 0.0, l2 = 0.0, l_lo = 0.0, l_hi = 0.0;
  Vec3 err_point{0.0}, err_ang{0.0};  // end of tick: b's anchor from a's; rotation error
  double size = 0.0;                  // the larger body's size: turns angular errors into speeds
  double tot_lo = 0.0, tot_hi = 0.0;  // whole tick: limit impulses (part of total_L)
  Vec3 warm_J{0.0}, warm_L{0.0};      // last tick's, for the warm start
  double warm_lo = 0.0, warm_hi = 0.0;
  Vec3 total_J{0.0},
      total_L{0.0};  // whole tick: impulse on b at its anchor (-J on a), pure angular impulse on b
};

// one row of a general joint (dynamics_joints.cpp), fixed at create: what it measures along which
// axis of the attachment frame, and what it does with it
struct Dynamics::JointRowSpec {
  enum class Measure : std::uint8_t {
    kLinear,   // d_J[axis]: b's anchor from a's along an axis of a's attachment frame
    kAngular,  // the XYZ Euler angle `axis` of b's attachment frame in a's
    kRadial,   // |d_J| over the axes of `mask` (2: from a line, 3: from a point)
    kCone,     // the angle between the two frames' axis `axis` (a cone about it)
  };
  enum class Bound : std::uint8_t { kLock, kMin, kMax, kDrive };
  Measure measure = Measure::kLinear;
  Bound bound = Bound::kLock;
  std::uint8_t axis = 0;
  std::uint8_t mask = 0;
  double value = 0.0;  // kLock, kMin, kMax: the bound (m or rad)
  bool soft = false;   // a limit with a stiffness: an implicit spring-damper beyond the bound
  double stiffness = 0.0, damping = 0.0;  // soft limits and drives
  // drives
  bool acceleration = false;
  bool has_position = false, has_velocity = false;
  double position_target = 0.0, velocity_target = 0.0;
  double max_impulse_rate = 0.0;  // maxForce (N or N m); 0: not limited
};

// a row's state this tick: its Jacobian (b gets +u at its anchor and +cb, a the opposite), the
// soft-constraint terms and the accumulated impulse
struct Dynamics::JointRow {
  bool active = false;
  bool was_active = false;  // last tick (its warm start)
  Vec3 u{0.0}, ca{0.0}, cb{0.0};
  Vec3 ia{0.0}, ib{0.0};  // inverse world inertias times ca, cb
  double mass = 0.0;      // effective mass of the (hard) row
  double soft_mass = 0.0;
  double bias = 0.0;   // the solve drives u.(v_b - v_a) + cb.w_b - ca.w_a + bias + gamma acc to 0
  double gamma = 0.0;  // 0: a hard row
  double lo = -detail::kInf, hi = detail::kInf;  // bounds of acc
  double acc = 0.0;                              // this tick (N s or N m s)
  double warm = 0.0;                             // last tick's
  double position = 0.0;                         // the measure at the start of the tick
  double lp = 0.0;                               // split impulse
  bool pos_on = false;   // the drift correction acts on it (end of tick: a hard row to correct)
  double pos_err = 0.0;  // its error then (lock: position - bound; limits: the violation)
};

// a joint solved by the general rows (dynamics_joints.cpp): every joint but plain fixed joints and
// hinges
struct Dynamics::GeneralJoint {
  const scene::Joint* joint = nullptr;
  bool off = false;
  std::uint32_t a = 0;
  std::int32_t b = -1;
  double size = 0.0;
  std::uint8_t euler_shift = 0;  // the angles are about axes shift, shift + 1, shift + 2 (mod 3)
  std::vector<JointRowSpec> specs;
  std::vector<JointRow> rows;  // one per spec
};

// a contact point kept from one tick to the next (persistent, as Bullet's btPersistentManifold
// keeps them): its primitive pair, where it sits on each surface (from each centre of mass, body
// frames) and its impulses of the tick (the next tick's warm start)
struct Dynamics::WarmPoint {
  WarmPoint() = default;
  // a pair's key (a search's probe)
  WarmPoint(std::uint32_t a_, std::uint32_t b_, std::uint32_t prim_a_, std::uint32_t prim_b_)
      : a(a_), b(b_), prim_a(prim_a_), prim_b(prim_b_) {}
  // a point of the pair at its surface points, its normal and impulses zero (made in place by
  // gatherContacts: a temporary copied in stalled on its store forwarding)
  WarmPoint(std::uint32_t a_,
            std::uint32_t b_,
            std::uint32_t prim_a_,
            std::uint32_t prim_b_,
            const Vec3& sa,
            const Vec3& sb)
      : a(a_), b(b_), prim_a(prim_a_), prim_b(prim_b_), sa_B(sa), sb_B(sb) {}
  std::uint32_t a = 0, b = 0, prim_a = 0, prim_b = 0;
  Vec3 sa_B{0.0}, sb_B{0.0};  // on a's surface (a's frame), on b's surface (b's frame)
  Vec3 na_B{0.0}, nb_B{0.0};  // the normal in a's frame and in b's
  double ln = 0.0;
  Vec3 lt{0.0};
  auto key() const { return std::tie(a, b, prim_a, prim_b); }
};

}  // namespace hapticd::dynamics
