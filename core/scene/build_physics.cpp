// The model builder's physics: mass properties, collision filters and joints (builder.h).
#include <bit>
#include <cmath>

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
  VolumeIntegrals integrals;
  for (const Primitive& prim : body.primitives)
    integrals.add(polytopeIntegrals(*prim.shape, prim.X_BP.toTransform()));
  const MassProperties computed = massFromIntegrals(integrals, kDensity);
  const bool have_volume = computed.mass > 0.0;
  // node space -> body frame: the body node's scale and shear (its rigid part is X_WB)
  Mat3 R_unused, S;
  splitRigid(Mat3(world_[node]), &R_unused, &S);

  body.mass_declared = motion.mass.has_value();
  body.inertia_declared = motion.inertia_diagonal.has_value();
  if (!have_volume && (!motion.mass || !motion.inertia_diagonal)) {
    p_->add(w, "dynamic body has no collider volume to compute its " +
                   std::string(!motion.mass ? "mass" : "inertia") +
                   " from: declare mass and inertiaDiagonal, or give it colliders");
    return;
  }
  const bool infinite_mass = motion.mass && *motion.mass == 0.0;  // 0 means infinite (KHR)
  body.mass = motion.mass ? *motion.mass : computed.mass;
  body.inverse_mass = infinite_mass ? 0.0 : 1.0 / body.mass;
  body.com_B = motion.center_of_mass ? S * *motion.center_of_mass : computed.com;

  if (motion.inertia_diagonal) {
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
    Mat3 I = computed.inertia;
    const Vec3 dc = body.com_B - computed.com;
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

void Builder::filterBits(SceneModel& scene) {
  std::map<std::string, std::uint32_t> bits;
  for (const auto& f : doc_.filters) {
    for (const auto* list : {&f.systems, &f.collide_with, &f.not_collide_with}) {
      for (const std::string& s : *list) {
        if (bits.count(s))
          continue;
        if (bits.size() == 32) {
          p_->add("collisionFilters", "more than 32 collision systems (at '" + s + "')");
          return;
        }
        const auto bit = static_cast<std::uint32_t>(bits.size());
        bits.emplace(s, 1u << bit);
      }
    }
  }
  const auto mask = [&](const std::vector<std::string>& names) {
    std::uint32_t m = 0;
    for (const std::string& s : names)
      m |= bits[s];
    return m;
  };
  for (Body& body : scene.bodies) {
    for (Primitive& prim : body.primitives) {
      const std::int32_t f = doc_.nodes[static_cast<std::size_t>(prim.node)].collider->filter;
      if (f < 0) {
        // unfiltered: in every system, colliding with every system
        prim.group = ~0u;
        prim.mask = ~0u;
        continue;
      }
      const FilterDef& def = doc_.filters[static_cast<std::size_t>(f)];
      prim.group = def.systems.empty() ? ~0u : mask(def.systems);
      if (!def.collide_with.empty())
        prim.mask = mask(def.collide_with);
      else if (!def.not_collide_with.empty())
        prim.mask = ~mask(def.not_collide_with);
      else
        prim.mask = ~0u;
    }
  }
}

bool Builder::classifyJoint(Joint* joint, const std::string& w) {
  // which axes are locked: a linear limit with max 0 (and min 0 for one axis), an angular
  // limit the same way; soft limits (with stiffness) lock nothing
  std::uint8_t linear = 0, angular = 0;
  std::array<const JointLimit*, 3> angular_limit{nullptr, nullptr, nullptr};
  for (const JointLimit& lim : joint->limits) {
    const int axes = std::popcount(static_cast<unsigned>(lim.linear_axes | lim.angular_axes));
    const bool locks = !lim.stiffness && lim.max && *lim.max == 0.0 &&
                       (axes > 1 ? (!lim.min || *lim.min <= 0.0) : (lim.min && *lim.min == 0.0));
    if (lim.linear_axes) {
      if (locks)
        linear = static_cast<std::uint8_t>(linear | lim.linear_axes);
    } else if (locks) {
      angular = static_cast<std::uint8_t>(angular | lim.angular_axes);
    } else if (axes == 1) {
      angular_limit[static_cast<std::size_t>(
          std::countr_zero(static_cast<unsigned>(lim.angular_axes)))] = &lim;
    }
  }
  if (linear != 7) {
    p_->add(w,
            "is neither fixed nor a hinge: not every linear axis is locked at 0 (only fixed "
            "and hinge joints are supported)");
    return false;
  }
  if (angular == 7) {
    joint->kind = JointKind::kFixed;
    return true;
  }
  if (std::popcount(static_cast<unsigned>(angular)) != 2) {
    p_->add(w, "is neither fixed nor a hinge: " +
                   std::to_string(3 - std::popcount(static_cast<unsigned>(angular))) +
                   " free angular axes (only fixed and hinge joints are supported)");
    return false;
  }
  joint->kind = JointKind::kHinge;
  joint->hinge_axis =
      static_cast<std::uint8_t>(std::countr_zero(static_cast<unsigned>(~angular & 7u)));
  if (const JointLimit* lim = angular_limit[joint->hinge_axis]) {
    joint->hinge_min = lim->min;
    joint->hinge_max = lim->max;
  }
  return true;
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
    joint.limits = doc_.joints[static_cast<std::size_t>(ref.joint)].limits;
    if (classifyJoint(&joint, w))
      scene.joints.push_back(std::move(joint));
  }
}

}  // namespace hapticd::scene::detail
