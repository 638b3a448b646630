#pragma once
/// \file
/// The virtual proxy of §3.2 of Gregory et al. 2000 (after Ruspini, Kolarov & Khatib 1997), in six
/// degrees of freedom, with the predictive penalty forces of §5.1–5.2.
///
/// The proxy is the held body's virtual copy. Each tick it takes one quasi-static step toward
/// the device: the step minimises
///   E(x) = 1/2 |coupling error after the step|^2_K  +  sum_i 1/2 k_i (delta - gap_i(x))_+^2
/// over the proxy's free coordinates x (6 for a free body, 1 for a body on a hinge), where the
/// coupling pulls toward the device pose (its stretch clamped to the device limits, so the proxy
/// is never pushed much harder than the device can display, but to no less than two safe
/// distances, so that the clamp never limits free motion: couplingReach) and each contact row i
/// is a point of a
/// manifold within the predictive distance delta of the environment (§5.2: "growing" the
/// surface by delta). One Newton step on E with the gaps linearised (gap_i + J_i x), the set of
/// active rows found by re-solving until it settles (rows that would pull are dropped, rows that
/// would come within delta are added; at most a fixed number of passes). The Newton matrix holds
/// the contact stiffness, so the step is implicit: stable for any contact stiffness. The step is
/// then scaled so that no point of the held set moves farther than the safe distance
/// delta = v_c * dt (§5.2): it can never pass through a surface it has not seen.
///
/// Penalty force of each row (§5.1–5.2): f_i = k_i (delta - gap_i) along its normal, which is
/// k (delta - d) within delta and k (delta + D_p) on penetration; a pair's stiffness k is split
/// over its manifold's points, so that the total does not depend on how many there are. The
/// restoring torque is T = sum_i R_i x f_i about the reference point (the held set's centre).
///
/// Friction (Coulomb, after the god-object friction cone of Salisbury et al. 1995 and Ruspini
/// et al. 1997): rows pressed after the step load the proxy with N (their total normal force,
/// along their force-weighted normal) and carry the pair's static and dynamic coefficients. The
/// coupling's tangential pull, were the proxy not to slide, is F_t = k_c |e_t|. Within the cone
/// (F_t <= mu_s N, or mu_d N while already sliding) the proxy sticks: its tangential translation
/// is removed. Beyond it the proxy slides on the cone's edge: its tangential translation is cut
/// so that the pull left is mu_d N. Friction acts on the translation of a freely held set (not on
/// its rotation, nor on a hinge's coordinate); it only removes motion, so the coupling stays the
/// passive spring and damper it is.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/common/reserved_vector.h"
#include "core/common/state_writer.h"
#include "core/response/wrench.h"

namespace hapticd::response {

/// One contact point of the held set against the environment, world frame.
struct ContactRow {
  Vec3 p_W{0.0};           ///< contact point
  Vec3 n_W{0.0};           ///< unit; the direction that pushes the held set out (possibly shaded)
  double gap = 0.0;        ///< along n_W: > 0 apart, < 0 penetrating (scene units)
  double stiffness = 0.0;  ///< this point's share of its pair's stiffness (N per scene unit)
  /// The side n_W pushes: -1 the held set, d >= 0 driven hinge d of the problem.
  std::int32_t first = -1;
  /// The side n_W pushes against: -1 fixed, d >= 0 driven hinge d.
  std::int32_t second = -1;
  /// Coulomb friction of the pair (the combined materials, KHR_physics_rigid_bodies' rule):
  /// static and dynamic coefficients; 0: frictionless.
  double mu_s = 0.0;
  double mu_d = 0.0;
};

/// Fixed-capacity row buffer: reserve() off the servo thread, then push() never allocates; a full
/// buffer drops the row and says so. Copies keep the capacity.
class ContactRows {
 public:
  void reserve(std::size_t n) {
    rows_.reserve(n);
    capacity_ = rows_.capacity();
  }
  void clear() {
    rows_.clear();
    full_ = false;
  }
  void push(const ContactRow& r) {
    if (rows_.size() < capacity_)
      rows_.push_back(r);
    else
      full_ = true;
  }
  std::span<const ContactRow> rows() const { return rows_; }
  std::span<ContactRow> rows() { return rows_; }
  bool full() const { return full_; }

  /// Writes the rows and the full flag (for the simulation state's hash, core/sim/scene_state.h).
  void writeState(StateWriter& w) const;

 private:
  ReservedVector<ContactRow> rows_;
  std::size_t capacity_ = 0;
  bool full_ = false;
};

/// The penalty wrench of §5.1–5.2 on the held set: sum over its rows (first == -1) with gap < delta
/// of f_i = k_i (delta - gap_i) n_i, torque about c_W. Any thread; no allocation.
Wrench penaltyWrench(std::span<const ContactRow> rows, const Vec3& c_W, double delta);

/// How the proxy may move: its velocity twist (dc, dtheta) about the reference point is
/// basis * x for the free coordinates x.
struct ProxyBasis {
  std::uint32_t dofs = 6;
  /// Columns (linear 3, angular 3); only the first `dofs` are used.
  std::array<std::array<double, 6>, 6> column{};
  static ProxyBasis free();
  /// Rotation about the unit axis a_W through o_W, the twist taken about the reference point c_W.
  static ProxyBasis hinge(const Vec3& o_W, const Vec3& a_W, const Vec3& c_W);
};

struct ProxyParams {
  double coupling_stiffness = 600.0;    ///< k_c, N per scene unit
  double rot_coupling_stiffness = 1.0;  ///< k_r, N m per radian
  double delta = 0.0005;                ///< predictive distance, scene units
  double max_travel = 0.0005;           ///< safe distance per tick, scene units
  double max_force_n = 10.0;            ///< coupling force on the proxy is clamped to this
  double max_torque_nm = 1.0;
  std::uint32_t max_passes = 8;  ///< active-set passes
};

/// A body on a hinge that the held set may turn (a gear meshing with the held one): a massless,
/// quasi-static extra coordinate, its angle about the axis a_W through o_W.
struct DrivenHinge {
  Vec3 o_W{0.0};
  Vec3 a_W{0.0, 0.0, 1.0};
  double radius = 0.0;  ///< largest distance of its points from the axis (for the safe distance)
  double drag = 1e-6;   ///< rotational stiffness holding it when untouched (N m per radian)
};

/// One tick's problem.
struct ProxyProblem {
  static constexpr std::size_t kMaxDriven = 4;
  Vec3 c_W{0.0};              ///< reference point (the held set's centre), world
  Vec3 h_W{0.0};              ///< the proxy's handle point (coupled to the device), world
  bool handle_fixed = false;  ///< the handle point does not move with the proxy (centre attach)
  Vec3 h_target_W{0.0};       ///< the device's handle point
  Quat q_handle{1.0, 0.0, 0.0, 0.0};  ///< the proxy handle's orientation
  Quat q_target{1.0, 0.0, 0.0, 0.0};  ///< the device's orientation
  double radius = 0.0;                ///< largest distance of a held point from c_W
  ProxyBasis basis = ProxyBasis::free();
  std::array<DrivenHinge, kMaxDriven> driven{};
  std::uint32_t driven_count = 0;
  /// The proxy was sliding on a surface with friction at the end of the last step: it goes on
  /// sliding while the coupling's tangential pull exceeds the dynamic friction, where a proxy at
  /// rest breaks away only beyond the static friction.
  bool sliding = false;
};

/// What the step decided.
struct ProxyStep {
  Vec3 dc_W{0.0};             ///< translation of the reference point
  Vec3 dtheta_W{0.0};         ///< rotation vector about the reference point
  std::array<double, 6> x{};  ///< the free coordinates' step
  std::array<double, ProxyProblem::kMaxDriven> driven_angle{};  ///< each driven hinge's turn
  bool travel_limited = false;
  bool rows_dropped = false;  ///< more rows than the solver holds (kMaxRows): the rest ignored
  /// Friction (rows with mu_s or mu_d > 0 pressed this step): the proxy stuck (its tangential
  /// motion removed), or slid on the edge of the friction cone.
  bool stuck = false;
  bool sliding = false;
  double normal_force_n = 0.0;    ///< the pressed rows' total normal force (friction's N)
  double friction_force_n = 0.0;  ///< the tangential force friction holds (N)
  std::uint32_t passes = 0;
  std::uint32_t active = 0;  ///< rows active at the end
};

/// How far the coupling's stretch reaches when it pulls the proxy in one step: the stretch is
/// clamped to the device's limits (max_force_n / k_c, max_torque_nm / k_r), so that the proxy is
/// never pushed into a surface much harder than the device can display, but never to less than
/// two safe distances of travel (2 max_travel, and 2 max_travel / radius radians): the clamp
/// limits how hard the proxy presses, never how far it moves in one step. Without that floor the
/// proxy moved at most max_force_n / k_c per tick in free space (an absolute length: 16.3 scene
/// units / 1000 at the defaults), so in a scene whose safe distance is longer than that (a scene
/// authored in mm with the default stiffness) it crept behind the device (issue 17).
struct CouplingReach {
  double linear = 0.0;   ///< scene units
  double angular = 0.0;  ///< radians
};
CouplingReach couplingReach(const ProxyParams& params, double radius);

/// Rows the solver takes; more are ignored (ProxyStep::rows_dropped).
inline constexpr std::size_t kMaxRows = 256;

/// One proxy step (see the file comment). Driven hinges are coordinates of their own, moved only
/// by their rows with the held set. Servo thread; no allocation.
ProxyStep solveProxyStep(const ProxyProblem& problem,
                         std::span<const ContactRow> rows,
                         const ProxyParams& params);

}  // namespace hapticd::response
