// The model builder's physics: mass properties, collision filters and joints (builder.h).
#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>

#include "core/decomp/union_integrals.h"
#include "core/geometry/rotation.h"
#include "core/scene/builder.h"

namespace hapticd::scene::detail {
namespace {

bool finite(const Mat3& m) {
  return geom::finite(m[0]) && geom::finite(m[1]) && geom::finite(m[2]);
}

}  // namespace

void Builder::massProperties(Body& body, const MotionDef& motion, std::uint32_t node) {
  const std::string w = where(node);
  // the union of the colliders (a trigger volume has no mass): colliders that overlap (a
  // decomposition's merged pieces reach into their neighbours) count once, colliders that only
  // touch give bitwise their sum
  std::vector<decomp::Cell> cells;
  std::vector<VolumeIntegrals> own;
  for (const Primitive& prim : body.primitives) {
    if (prim.trigger)
      continue;
    own.push_back(polytopeIntegrals(*prim.shape, prim.X_BP.toTransform()));
    cells.push_back(decomp::polytopeCell(*prim.shape, prim.X_BP.toTransform()));
  }
  const decomp::UnionIntegrals integrals = decomp::unionIntegrals(cells, own);
  if (!integrals.exact) {
    p_->note(w + ": its colliders overlap too much to weigh their union (the work passed " +
             std::to_string(decomp::kUnionWorkBudget) +
             " plane tests): their volumes are summed; declare mass, centerOfMass and "
             "inertiaDiagonal");
  } else if (integrals.overlapping > 0 && !motion.inertia_diagonal) {
    p_->note(w + ": " + std::to_string(integrals.overlapping) +
             " of its colliders overlap others: its mass properties count their union once");
  }
  const MassProperties computed = massFromIntegrals(integrals.integrals, kDensity);
  const bool have_volume = computed.mass > 0.0;
  // node space -> body frame: the body node's scale and shear (its rigid part is X_WB)
  Mat3 R_unused, S;
  splitRigid(Mat3(world_[node]), &R_unused, &S);

  body.mass_declared = motion.mass.has_value();
  body.inertia_declared = motion.inertia_diagonal.has_value();
  if (!have_volume && !motion.mass) {
    p_->add(w,
            "dynamic body has no collider volume to compute its mass from: declare mass (and "
            "inertiaDiagonal), or give it colliders");
    return;
  }
  const bool infinite_mass = motion.mass && *motion.mass == 0.0;  // 0 means infinite (KHR)
  body.mass = motion.mass ? *motion.mass : computed.mass;
  body.inverse_mass = infinite_mass ? 0.0 : 1.0 / body.mass;
  body.com_B = motion.center_of_mass ? S * *motion.center_of_mass
                                     : (have_volume ? computed.com_B : Vec3{0.0});

  if (!have_volume && !motion.inertia_diagonal && !infinite_mass) {
    // a declared mass with nothing to take a shape from (a driver or anchor body of joints, a
    // body of triggers only): the inertia of a solid sphere of that mass at the density the
    // loader assumes, about the centre of mass
    const double radius = std::cbrt(3.0 * body.mass / (4.0 * std::numbers::pi * kDensity));
    const double moment = 0.4 * body.mass * radius * radius;
    body.inertia_B = Mat3(moment);
    body.inverse_inertia_B = Mat3(1.0 / moment);
    p_->note(w + ": no collider volume: inertia of a solid sphere of its mass at " +
             formatNumber(kDensity) + " kg/m^3 (radius " + formatNumber(radius) + " m)");
  } else if (motion.inertia_diagonal) {
    const Mat3 Rq = glm::mat3_cast(motion.inertia_orientation);
    const Vec3 d = *motion.inertia_diagonal;
    Mat3 D(0.0), Dinv(0.0);
    for (int k = 0; k < 3; ++k) {
      D[k][k] = d[k];
      Dinv[k][k] = d[k] == 0.0 ? 0.0 : 1.0 / d[k];  // 0 means infinite (KHR)
    }
    body.inertia_B = Rq * D * glm::transpose(Rq);
    body.inverse_inertia_B = Rq * Dinv * glm::transpose(Rq);
  } else if (infinite_mass) {
    body.inertia_B = Mat3(0.0);
    body.inverse_inertia_B = Mat3(0.0);
  } else {
    // computed about the computed centre; moved to the declared centre and scaled to the
    // declared mass (uniform density)
    Mat3 I = computed.inertia_B;
    const Vec3 dc = body.com_B - computed.com_B;
    I += computed.mass * (glm::dot(dc, dc) * Mat3(1.0) - glm::outerProduct(dc, dc));
    I *= body.mass / computed.mass;
    body.inertia_B = I;
    body.inverse_inertia_B = glm::inverse(I);
  }
  if (!std::isfinite(body.mass) || !std::isfinite(body.inverse_mass) || !geom::finite(body.com_B) ||
      !finite(body.inertia_B) || !finite(body.inverse_inertia_B)) {
    p_->add(w, "mass properties are not finite (mass " + formatNumber(body.mass) + ")");
  }
}

namespace {

bool contains(const std::vector<std::string>& list, const std::string& s) {
  return std::find(list.begin(), list.end(), s) != list.end();
}

/// Does `b` accept `a`, as KHR_physics_rigid_bodies says: "A collides with B if A.collisionSystems
/// is a subset of B.collideWithSystems and not a subset of B.notCollideWithSystems", the field B
/// leaves out being the inverse of the one it gives (neither given: B collides with everything).
/// A collider in no system is accepted where B lists exclusions only. Null: unfiltered.
bool accepts(const FilterDef* b, const FilterDef* a) {
  if (!b || (b->collide_with.empty() && b->not_collide_with.empty()))
    return true;
  static const FilterDef kNone;
  const std::vector<std::string>& systems = (a ? a : &kNone)->systems;
  if (!b->collide_with.empty()) {
    if (systems.empty())
      return false;
    for (const std::string& s : systems) {
      if (!contains(b->collide_with, s))
        return false;
    }
    return true;
  }
  for (const std::string& s : systems) {
    if (contains(b->not_collide_with, s))
      return false;
  }
  return true;
}

}  // namespace

bool Builder::filterClasses() {
  // entry 0 unfiltered, entry f + 1 filter f; two entries collide when each accepts the other.
  // Entries whose rows of that table are equal share one bit (at most 32 bits)
  const std::size_t n = doc_.filters.size() + 1;
  const auto def = [&](std::size_t e) { return e == 0 ? nullptr : &doc_.filters[e - 1]; };
  std::vector<std::vector<bool>> collide(n, std::vector<bool>(n));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j)
      collide[i][j] = accepts(def(i), def(j)) && accepts(def(j), def(i));
  }
  std::vector<std::size_t> class_of(n);
  std::vector<std::size_t> representative;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t c = 0;
    while (c < representative.size() && collide[representative[c]] != collide[i])
      ++c;
    if (c == representative.size())
      representative.push_back(i);
    class_of[i] = c;
  }
  if (representative.size() > 32) {
    p_->add("collisionFilters", std::to_string(representative.size()) +
                                    " different collision behaviours, more than 32 (filters "
                                    "that collide with the same filters count once)");
    return false;
  }
  filter_group_.assign(n, 0);
  filter_mask_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    filter_group_[i] = 1u << class_of[i];
    for (std::size_t j = 0; j < n; ++j) {
      if (collide[i][j])
        filter_mask_[i] |= 1u << class_of[j];
    }
  }
  return true;
}

void Builder::classifyJoint(Joint* joint) {
  // which axes are locked: a hard limit (no stiffness) with max 0 and, for one axis, min 0 (more
  // axes: min absent or <= 0); soft and ranged limits lock nothing
  std::uint8_t linear = 0, angular = 0;
  std::array<const JointLimit*, 3> angular_limit{nullptr, nullptr, nullptr};
  for (const JointLimit& lim : joint->limits) {
    const int axes = std::popcount(static_cast<unsigned>(lim.linear_axes | lim.angular_axes));
    const bool locks = !lim.stiffness && lim.max && *lim.max == 0.0 &&
                       (axes > 1 ? (!lim.min || *lim.min <= 0.0) : (lim.min && *lim.min == 0.0));
    const std::uint8_t bits = lim.linear_axes ? lim.linear_axes : lim.angular_axes;
    if (locks) {
      (lim.linear_axes ? linear : angular) |= bits;
    } else if (axes == 1 && lim.angular_axes) {
      angular_limit[static_cast<std::size_t>(std::countr_zero(static_cast<unsigned>(bits)))] = &lim;
    }
  }
  const int free_linear = 3 - std::popcount(static_cast<unsigned>(linear));
  const int free_angular = 3 - std::popcount(static_cast<unsigned>(angular));
  joint->kind = JointKind::kGeneric;
  if (free_linear == 0 && free_angular == 0) {
    joint->kind = JointKind::kFixed;
  } else if (free_linear == 0 && free_angular == 1) {
    joint->kind = JointKind::kHinge;
    joint->hinge_axis =
        static_cast<std::uint8_t>(std::countr_zero(static_cast<unsigned>(~angular & 7u)));
    if (const JointLimit* lim = angular_limit[joint->hinge_axis]) {
      joint->hinge_min = lim->min;
      joint->hinge_max = lim->max;
    }
  } else if (free_linear == 1 && free_angular == 0) {
    joint->kind = JointKind::kSlider;
    joint->hinge_axis =
        static_cast<std::uint8_t>(std::countr_zero(static_cast<unsigned>(~linear & 7u)));
  } else if (free_linear == 0) {
    joint->kind = JointKind::kBall;
  }
}

void Builder::buildJoints(SceneModel& scene) {
  const auto bodyOf = [&](std::size_t node) -> std::int32_t {
    const std::int32_t o = owner_[node];
    return o < 0 ? -1 : body_of_node_[static_cast<std::size_t>(o)];
  };
  // a node's attachment frame in its body's frame (the scene frame for static nodes); rigid only
  const auto frameIn = [&](std::int32_t body, std::size_t node) {
    Mat3 R, S;
    splitRigid(Mat3(world_[node]), &R, &S);
    Pose X_WJ{Vec3(world_[node][3]), glm::normalize(glm::quat_cast(R))};
    if (body < 0)
      return X_WJ;
    const Pose& X_WB = scene.bodies[static_cast<std::size_t>(body)].X_WB;
    const Transform X_BJ = geom::relativeTransform(X_WB, X_WJ);
    return Pose{X_BJ.t, glm::normalize(glm::quat_cast(X_BJ.R))};
  };
  for (std::uint32_t node : order_) {
    const NodeDef& def = doc_.nodes[node];
    if (!def.joint)
      continue;
    const std::string w = where(node) + " joint";
    const JointRef& ref = *def.joint;
    const auto connected = static_cast<std::size_t>(ref.connected_node);
    if (!in_scene_[connected]) {
      p_->add(w, "connectedNode " + where(connected) + " is not in the scene");
      continue;
    }
    Joint joint;
    joint.body_a = bodyOf(node);
    joint.body_b = bodyOf(connected);
    joint.X_AJ = frameIn(joint.body_a, node);
    joint.X_BJ = frameIn(joint.body_b, connected);
    if (joint.body_a < 0) {
      std::swap(joint.body_a, joint.body_b);
      std::swap(joint.X_AJ, joint.X_BJ);
    }
    if (joint.body_a < 0) {
      p_->add(w, "connects two static frames (neither node has motion above it)");
      continue;
    }
    if (joint.body_a == joint.body_b) {
      p_->add(w, "connects body '" + scene.bodies[static_cast<std::size_t>(joint.body_a)].name +
                     "' to itself");
      continue;
    }
    joint.enable_collision = ref.enable_collision;
    joint.node = static_cast<std::int32_t>(node);
    joint.limits = doc_.joints[static_cast<std::size_t>(ref.joint)].limits;
    joint.drives = doc_.joints[static_cast<std::size_t>(ref.joint)].drives;
    classifyJoint(&joint);
    // the dynamics simulate every kind (SceneModel::unsimulated_joints stays empty)
    scene.joints.push_back(std::move(joint));
  }
}

}  // namespace hapticd::scene::detail
