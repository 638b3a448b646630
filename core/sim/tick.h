#pragma once
/// \file
/// The parts of one tick that the files of core/sim share (not a public interface): each takes
/// the compiled model and the state it reads and writes. The thread that owns the state; no
/// allocation.

#include <cstdint>

#include "core/sim/model.h"
#include "core/sim/scene_state.h"

namespace hapticd::sim::detail {

/// A body's role in the contact rows: the held set, a driven hinge d (>= 0), or fixed.
inline constexpr std::int32_t kRoleHeld = -2, kRoleFixed = -1;

bool isHeld(const SceneState& s, std::uint32_t body);
std::int32_t role(const SceneState& s, std::uint32_t body);
/// A dynamic body the dynamics move (not held, not driven by this tick's proxy step).
bool movedByDynamics(const SimModel& m, const SceneState& s, std::uint32_t body);
/// How much farther than they are the rows of `body` are put (their gap is the distance plus
/// this): for a body the dynamics move, backstop_m, and never less than the predictive distance
/// delta of a still device (min_predictive_fraction of the held set's radius), so that its rows
/// do not act before the held set touches it when the device is still. delta is relative to the
/// held body's size and backstop_m derives from the device: in a scene in mm (geometry scaled by
/// 1e3, the default options) delta exceeded backstop_m and the rows stopped the proxy short of a
/// gear tooth that the dynamics then never touched, the hand feeling 10 N with no contact. At
/// the sizes where backstop_m is the larger (a scene in metres) nothing changes. 0 for any other
/// body.
double backstopShift(const SimModel& m, const SceneState& s, std::uint32_t body);
/// A body's centre of mass, world, at its pose in the collision world.
Vec3 comW(const SimModel& m, const SceneState& s, std::uint32_t body);
/// The pose in the world of primitive `prim` of `body`.
geom::Transform primTransform(const SimModel& m,
                              const SceneState& s,
                              std::uint32_t body,
                              std::uint32_t prim);
/// Largest distance of a point of `body` (at its world pose) or of the held set from c_W.
double radiusAbout(const SimModel& m, const SceneState& s, std::uint32_t body, const Vec3& c_W);
double heldRadius(const SimModel& m, const SceneState& s, const Vec3& c_W);

/// The contact rows of the held set and the driven hinges from the world's contacts (§5.1–5.2,
/// force shading §5.3); returns the deepest penetration (>= 0) and keeps it in the state.
double gatherRows(const SimModel& m, SceneState& s);
/// The held set's contact points with bodies the dynamics move, within this tick's predictive
/// distance delta, that made no active penalty row (those are TickOutput::contacts): the
/// dynamics' contacts with the held set (TickOutput::held_dynamic_contacts).
std::uint32_t heldDynamicContacts(const SimModel& m, const SceneState& s);
/// Whether any of the held set's rows is with a body the dynamics move (their step leaves
/// those rows, and the depth they give, stale until the world is stepped again).
bool rowsWithDynamicBody(const SimModel& m, const SceneState& s);
/// Simulation::contactPoints() from this tick's rows.
void fillContactPoints(const SimModel& m, SceneState& s, TickOutput* out);

/// The attachment (§6.2): buttons pressed attach the probe to the nearest body it touches,
/// released detach it.
void updateAttachment(const SimModel& m, SceneState& s, const TickInput& input);
void attach(const SimModel& m, SceneState& s, std::uint32_t body);
void detach(const SimModel& m, SceneState& s);
/// The hinges the held set may turn: every active hinged body not held (nor the dynamics').
void updateDriven(const SimModel& m, SceneState& s);
/// k_r = k_c r^2 for the held set's mode (unless the options fix it).
void setRotationalStiffness(const SimModel& m, SceneState& s);
/// The proxy step's motion applied to the probe, an attached body and the driven hinges.
void applyStep(const SimModel& m, SceneState& s, const response::ProxyStep& step);

}  // namespace hapticd::sim::detail
