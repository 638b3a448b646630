// The contact rows of one tick (§5.1–5.3 of Gregory et al. 2000): from the collision world's
// contacts to the rows the proxy solves and the penalty wrench reads, and the contact points the
// state stream shows.
#include <algorithm>

#include "core/response/face_contact.h"
#include "core/sim/tick.h"

namespace hapticd::sim::detail {
namespace {

using collision::BodyKind;
using geom::Transform;
using response::ContactRow;

// faces within ~18 degrees of the pair's normal on both sides make a face-face contact
constexpr double kFaceCosTolerance = 0.95;

void pushRow(SceneState& s, const ContactRow& row, std::uint32_t env) {
  const std::size_t n = s.rows.rows().size();
  s.rows.push(row);
  if (s.rows.rows().size() > n)
    s.row_env.push_back(env);
}

// One contact of the world as the rows see it: which side is held (or driven), the environment
// body and primitive and their features, the rows' roles, the backstop shift, the stiffness.
struct PairSides {
  bool held_is_a = false;
  std::uint32_t env = 0, env_prim = 0, held = 0, held_prim = 0;
  geom::Feature env_feature, held_feature;
  std::int32_t row_first = -1, row_second = -1;
  double shift = 0.0;             // the backstop of a body the dynamics move
  double kp = 0.0;                // the proxy's contact stiffness for this pair
  double mu_s = 0.0, mu_d = 0.0;  // the pair's friction (0: none)
};

// the material of primitive `prim` of world body `body`: its own, or scene::defaultMaterial()
// when it declares none (docs/scenes.md); the probe sphere of the config, which is not in the
// scene, has the model's no_material (no friction, as in the dynamics)
const scene::Material& primMaterial(const SimModel& m, std::uint32_t body, std::uint32_t prim) {
  const std::int32_t index = m.info[body].scene_index;
  if (index < 0)
    return m.no_material;
  const auto& prims = m.scene->bodies[static_cast<std::size_t>(index)].primitives;
  if (prim >= prims.size())
    return m.no_material;
  return scene::materialOf(*m.scene, prims[prim].material);
}

// false: the contact makes no rows (both sides held or fixed, a joint's pair, or too far)
bool pairSides(const SimModel& m, const SceneState& s, const collision::Contact& c, PairSides* p) {
  // roles: the held set (-2), a driven hinge (d >= 0), fixed (-1); a row's first side is the
  // held set if either side is, else a driven hinge; its second side is the other
  const std::int32_t ra = role(s, c.body_a), rb = role(s, c.body_b);
  if (ra == kRoleHeld && rb == kRoleHeld)
    return false;
  if (ra == kRoleFixed && rb == kRoleFixed)
    return false;
  if (m.excluded(c.body_a, c.body_b))
    return false;
  const bool ha = ra == kRoleHeld || (rb != kRoleHeld && ra >= 0);  // side a is the first
  const std::int32_t first = ha ? ra : rb, second = ha ? rb : ra;
  p->held_is_a = ha;
  p->env = ha ? c.body_b : c.body_a;
  p->env_prim = ha ? c.prim_b : c.prim_a;
  p->held = ha ? c.body_a : c.body_b;
  p->held_prim = ha ? c.prim_a : c.prim_b;
  p->env_feature = ha ? c.feature_b : c.feature_a;
  p->held_feature = ha ? c.feature_a : c.feature_b;
  p->row_first = first == kRoleHeld ? -1 : first;
  p->row_second = second < 0 ? -1 : second;
  // a body the dynamics move: its contacts with the held set are the dynamics' (impulses on
  // the held body, spread, reach the hand in step()). Its penalty rows act only behind a
  // backstop, the held set deeper than backstop_m into it: when the dynamics cannot push it out
  // of the way (wedged against something fixed), the proxy stops there as at a fixed body
  // (docs/dynamics.md, "In the Simulation")
  p->shift = backstopShift(m, s, p->env);
  // the pair's stiffness: the environment body's felt stiffness k_f through the proxy's
  // contact spring k_p = k_f k_c / (k_c - k_f), so that k_c and k_p in series give k_f
  const double kf = m.info[p->env].stiffness;
  p->kp = kf * m.k_c / (m.k_c - kf);
  // friction of the held set's rows against a body the dynamics do not move (those contacts
  // are the dynamics', with their own friction): the pair's combined materials
  p->mu_s = p->mu_d = 0.0;
  if (m.friction && p->row_first < 0 && p->shift == 0.0) {
    const scene::Material& a = primMaterial(m, p->held, p->held_prim);
    const scene::Material& b = primMaterial(m, p->env, p->env_prim);
    p->mu_s = scene::combineMaterials(a, b, scene::MaterialValue::kStaticFriction);
    p->mu_d = scene::combineMaterials(a, b, scene::MaterialValue::kDynamicFriction);
  }
  return true;
}

// rows of one contact; the deepest penetration of its points goes into *pen
void contactRows(const SimModel& m,
                 SceneState& s,
                 const collision::Contact& c,
                 const PairSides& p,
                 response::FaceContact& fc,
                 double* pen) {
  const double sign = p.held_is_a ? -1.0 : 1.0;  // normals run from a to b: out of the environment
  const BodyInfo& ei = m.info[p.env];
  const response::ShadingTable* table =
      p.env_prim < ei.shading.size() ? &ei.shading[p.env_prim] : nullptr;
  const geom::Polytope& env_shape = m.primShape(p.env, p.env_prim);
  const Transform X_WE = primTransform(m, s, p.env, p.env_prim);
  const Vec3 n_pair = sign * c.normal;
  ContactRow row;
  row.first = p.row_first;
  row.second = p.row_second;
  row.mu_s = p.mu_s;
  row.mu_d = p.mu_d;

  // a face against a face: the whole clipped region, each point with its own gap
  if (response::faceContact(env_shape, X_WE, p.env_feature, m.primShape(p.held, p.held_prim),
                            primTransform(m, s, p.held, p.held_prim), p.held_feature, n_pair,
                            kFaceCosTolerance, &fc)) {
    for (std::uint32_t i = 0; i < fc.count; ++i)
      *pen = std::max(*pen, -fc.gap[i]);
    for (std::uint32_t i = 0; i < fc.count; ++i) {
      row.p_W = fc.p_W[i];
      row.n_W = fc.n_W;
      if (table != nullptr) {
        const Vec3 x_E = glm::transpose(X_WE.R) * (fc.p_W[i] - X_WE.t);
        row.n_W = X_WE.rotate(table->shadedNormalOnFace(env_shape, fc.env_face, x_E));
      }
      row.gap = fc.gap[i] + p.shift;
      row.stiffness = p.kp / static_cast<double>(fc.count);
      pushRow(s, row, p.env);
    }
    return;
  }

  auto shade = [&](const Vec3& p_W, const Vec3& n_W) {
    if (table == nullptr)
      return n_W;
    const Vec3 x_P = glm::transpose(X_WE.R) * (p_W - X_WE.t);
    const Vec3 n_P = glm::transpose(X_WE.R) * n_W;
    return X_WE.R * table->shadedNormal(env_shape, x_P, n_P, p.env_feature);
  };
  const std::size_t count = c.manifold.count;
  if (count == 0) {
    row.p_W = 0.5 * (c.point_a + c.point_b);
    row.n_W = shade(row.p_W, n_pair);
    row.gap = c.distance + p.shift;
    row.stiffness = p.kp;
    pushRow(s, row, p.env);
    return;
  }
  for (std::size_t i = 0; i < count; ++i) {
    const collision::ContactPoint& cp = c.manifold.points[i];
    row.p_W = cp.point;
    row.n_W = shade(cp.point, sign * cp.normal);
    row.gap = -cp.depth + p.shift;
    row.stiffness = p.kp / static_cast<double>(count);
    pushRow(s, row, p.env);
  }
}

}  // namespace

bool isHeld(const SceneState& s, std::uint32_t body) {
  for (std::uint32_t i = 0; i < s.held.count; ++i) {
    if (s.held.ids[i] == body)
      return true;
  }
  return false;
}

std::int32_t role(const SceneState& s, std::uint32_t body) {
  if (isHeld(s, body))
    return kRoleHeld;
  for (std::uint32_t d = 0; d < s.driven.count; ++d) {
    if (s.driven.ids[d] == body)
      return static_cast<std::int32_t>(d);
  }
  return kRoleFixed;
}

bool movedByDynamics(const SimModel& m, const SceneState& s, std::uint32_t body) {
  return m.dynamics_active && m.info[body].kind == BodyKind::kDynamic &&
         role(s, body) == kRoleFixed;
}

double backstopShift(const SimModel& m, const SceneState& s, std::uint32_t body) {
  if (!movedByDynamics(m, s, body))
    return 0.0;
  const ResponseOptions& r = m.options.response;
  const double delta_at_rest =
      r.predictive ? std::min(m.max_travel_m, r.min_predictive_fraction * s.held.radius_m) : 0.0;
  return std::max(m.backstop_m, delta_at_rest);
}

Vec3 comW(const SimModel& m, const SceneState& s, std::uint32_t body) {
  const geom::Pose& X = s.world.pose(body);
  return X.translation + X.rotation * m.info[body].com_B;
}

Transform primTransform(const SimModel& m,
                        const SceneState& s,
                        std::uint32_t body,
                        std::uint32_t prim) {
  const BodyInfo& bi = m.info[body];
  const Transform X_WB = s.world.pose(body).toTransform();
  if (bi.scene_index < 0)
    return X_WB;
  return X_WB * m.scene->bodies[static_cast<std::size_t>(bi.scene_index)]
                    .primitives[prim]
                    .X_BP.toTransform();
}

double radiusAbout(const SimModel& m, const SceneState& s, std::uint32_t body, const Vec3& c_W) {
  return m.radiusAbout(body, s.world.pose(body), c_W);
}

double heldRadius(const SimModel& m, const SceneState& s, const Vec3& c_W) {
  double r = 0.0;
  for (std::uint32_t i = 0; i < s.held.count; ++i)
    r = std::max(r, radiusAbout(m, s, s.held.ids[i], c_W));
  return r;
}

double gatherRows(const SimModel& m, SceneState& s) {
  s.rows.clear();
  s.row_env.clear();
  double pen = 0.0;
  s.deepest_normal_W = Vec3{0.0};
  response::FaceContact fc;
  for (const collision::Contact& c : s.world.contacts()) {
    if (!c.answered)
      continue;
    PairSides p;
    if (!pairSides(m, s, c, &p))
      continue;
    if (-c.distance > pen) {
      pen = -c.distance;
      // out of the environment toward the held set (normals run from a to b)
      s.deepest_normal_W = p.row_first < 0 ? (p.held_is_a ? -1.0 : 1.0) * c.normal : Vec3{0.0};
    }
    // a pair farther than the largest delta plus what one step can close (one safe distance
    // per moving side) cannot act next tick: no rows
    const double sides = p.row_second >= 0 ? 2.0 : 1.0;
    if (c.distance + p.shift > m.max_travel_m * (1.0 + sides))
      continue;
    contactRows(m, s, c, p, fc, &pen);
  }
  s.last_penetration_m = pen;
  return pen;
}

std::uint32_t heldDynamicContacts(const SimModel& m, const SceneState& s) {
  std::uint32_t n = 0;
  if (!m.dynamics_active)
    return n;
  for (const collision::Contact& c : s.world.contacts()) {
    if (!c.answered || !(c.distance < s.delta_m))
      continue;
    const bool held_a = isHeld(s, c.body_a), held_b = isHeld(s, c.body_b);
    if (held_a == held_b)
      continue;
    const std::uint32_t env = held_a ? c.body_b : c.body_a;
    // deeper than the backstop, the pair's rows act: counted as rows
    if (!movedByDynamics(m, s, env) || c.distance + backstopShift(m, s, env) < s.delta_m)
      continue;
    n += std::max<std::uint32_t>(c.manifold.count, 1u);
  }
  return n;
}

bool rowsWithDynamicBody(const SimModel& m, const SceneState& s) {
  for (const std::uint32_t env : s.row_env) {
    if (movedByDynamics(m, s, env))
      return true;
  }
  return false;
}

void fillContactPoints(const SimModel& m, SceneState& s, TickOutput* out) {
  // the rows the response used this tick (the held set's, within delta), as TickOutput::contacts
  // counts them; the depth without the backstop's shift
  s.contact_points.clear();
  const auto rows = s.rows.rows();
  for (std::size_t i = 0; i < rows.size() && i < s.row_env.size(); ++i) {
    const ContactRow& r = rows[i];
    if (!(r.gap < s.delta_m && r.first < 0))
      continue;
    if (s.contact_points.size() == response::kMaxRows) {
      out->flags |= kTickCapacityFull;
      break;
    }
    const std::uint32_t env = s.row_env[i];
    const double shift = backstopShift(m, s, env);
    ContactPoint cp;
    cp.p_W = r.p_W;
    cp.n_W = r.n_W;
    cp.depth_m = -(r.gap - shift);
    cp.body = m.info[env].scene_index;
    s.contact_points.push_back(cp);
  }
}

}  // namespace hapticd::sim::detail
