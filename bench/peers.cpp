#include "bench/peers.h"

#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <ccd/ccd.h>
#include <ccd/quat.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <cmath>
#include <limits>

namespace hapticd::bench {
namespace {

using geom::Polytope;
using geom::Transform;
using geom::Vec3;

// ---------------------------------------------------------------- libccd
struct CcdObject {
  std::vector<Vec3> local;
  Transform X;  // object -> A's frame
};

void ccdSupport(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* o = static_cast<const CcdObject*>(obj);
  const Vec3 d_local = glm::transpose(o->X.R) * Vec3{dir->v[0], dir->v[1], dir->v[2]};
  double best = -std::numeric_limits<double>::infinity();
  Vec3 p{0.0};
  for (const Vec3& v : o->local) {
    const double s = glm::dot(v, d_local);
    if (s > best)
      best = s, p = v;
  }
  const Vec3 w = o->X.apply(p);
  ccdVec3Set(out, w.x, w.y, w.z);
}

void ccdCenter(const void* obj, ccd_vec3_t* out) {
  const auto* o = static_cast<const CcdObject*>(obj);
  Vec3 c{0.0};
  for (const Vec3& v : o->local)
    c += v;
  c = o->X.apply(c / static_cast<double>(o->local.size()));
  ccdVec3Set(out, c.x, c.y, c.z);
}

class CcdPeer : public PeerMethod {
 public:
  CcdPeer(const Polytope& a, const Polytope& b, bool mpr) : mpr_(mpr) {
    for (const auto& v : a.vertices())
      a_.local.push_back(v.p);
    for (const auto& v : b.vertices())
      b_.local.push_back(v.p);
    CCD_INIT(&ccd_);
    ccd_.support1 = ccdSupport;
    ccd_.support2 = ccdSupport;
    ccd_.center1 = ccdCenter;
    ccd_.center2 = ccdCenter;
    ccd_.max_iterations = 500;
    ccd_.epa_tolerance = 1e-9 * std::max(a.radius(), b.radius());
    ccd_.mpr_tolerance = 1e-9 * std::max(a.radius(), b.radius());
  }
  double query(const Transform& X_AB, bool& ok) override {
    b_.X = X_AB;
    ccd_real_t depth = 0;
    ccd_vec3_t dir, pos;
    const int r = mpr_ ? ccdMPRPenetration(&a_, &b_, &ccd_, &depth, &dir, &pos)
                       : ccdGJKPenetration(&a_, &b_, &ccd_, &depth, &dir, &pos);
    ok = true;
    // -1: no intersection (libccd gives no distance then)
    if (r != 0) {
      ok = false;
      return 0.0;
    }
    return -depth;
  }
  // libccd: dir moves obj2 (B) out of obj1 (A), pos is the midpoint; no distance when apart
  PeerAnswer answer(const Transform& X_AB) override {
    b_.X = X_AB;
    ccd_real_t depth = 0;
    ccd_vec3_t dir, pos;
    const int r = mpr_ ? ccdMPRPenetration(&a_, &b_, &ccd_, &depth, &dir, &pos)
                       : ccdGJKPenetration(&a_, &b_, &ccd_, &depth, &dir, &pos);
    PeerAnswer out;
    if (r != 0)
      return out;
    out.ok = true;
    out.distance = -depth;
    out.normal = {dir.v[0], dir.v[1], dir.v[2]};
    out.point = {pos.v[0], pos.v[1], pos.v[2]};
    return out;
  }

 private:
  bool mpr_;
  CcdObject a_, b_;
  ccd_t ccd_{};
};

// ---------------------------------------------------------------- FCL
std::shared_ptr<fcl::Convexd> fclConvex(const Polytope& p) {
  auto verts = std::make_shared<std::vector<fcl::Vector3d>>();
  for (const auto& v : p.vertices())
    verts->emplace_back(v.p.x, v.p.y, v.p.z);
  auto faces = std::make_shared<std::vector<int>>();
  for (std::uint32_t f = 0; f < p.faces().size(); ++f) {
    faces->push_back(static_cast<int>(p.faceEdges(f).size()));
    for (const auto& fe : p.faceEdges(f))
      faces->push_back(static_cast<int>(fe.vertex));
  }
  return std::make_shared<fcl::Convexd>(verts, static_cast<int>(p.faces().size()), faces);
}

fcl::Transform3d fclTransform(const Transform& X) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  fcl::Matrix3d R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      R(r, c) = X.R[c][r];
  }
  t.linear() = R;
  t.translation() = fcl::Vector3d(X.t.x, X.t.y, X.t.z);
  return t;
}

class FclPeer : public PeerMethod {
 public:
  FclPeer(const Polytope& a, const Polytope& b, bool depth)
      : depth_(depth), a_(fclConvex(a)), b_(fclConvex(b)) {}
  double query(const Transform& X_AB, bool& ok) override {
    const fcl::Transform3d I = fcl::Transform3d::Identity();
    const fcl::Transform3d T = fclTransform(X_AB);
    ok = true;
    if (!depth_) {
      fcl::DistanceRequestd req;
      req.gjk_solver_type = fcl::GST_LIBCCD;
      req.enable_signed_distance = false;
      fcl::DistanceResultd res;
      fcl::distance(a_.get(), I, b_.get(), T, req, res);
      if (res.min_distance <= 0.0)
        ok = false;  // overlapping: no distance
      return res.min_distance;
    }
    fcl::CollisionRequestd req(1, true);
    req.gjk_solver_type = fcl::GST_LIBCCD;
    fcl::CollisionResultd res;
    fcl::collide(a_.get(), I, b_.get(), T, req, res);
    if (!res.isCollision()) {
      ok = false;
      return 0.0;
    }
    return -res.getContact(0).penetration_depth;
  }
  // FCL: nearest points p1 on A, p2 on B; a contact's normal points from A to B
  PeerAnswer answer(const Transform& X_AB) override {
    const fcl::Transform3d I = fcl::Transform3d::Identity();
    const fcl::Transform3d T = fclTransform(X_AB);
    PeerAnswer out;
    if (!depth_) {
      fcl::DistanceRequestd req;
      req.gjk_solver_type = fcl::GST_LIBCCD;
      req.enable_signed_distance = false;
      req.enable_nearest_points = true;
      fcl::DistanceResultd res;
      fcl::distance(a_.get(), I, b_.get(), T, req, res);
      if (!(res.min_distance > 0.0))
        return out;
      const Vec3 p1{res.nearest_points[0][0], res.nearest_points[0][1], res.nearest_points[0][2]};
      const Vec3 p2{res.nearest_points[1][0], res.nearest_points[1][1], res.nearest_points[1][2]};
      out.ok = true;
      out.distance = res.min_distance;
      out.normal = (p2 - p1) / glm::length(p2 - p1);
      out.point = 0.5 * (p1 + p2);
      return out;
    }
    fcl::CollisionRequestd req(1, true);
    req.gjk_solver_type = fcl::GST_LIBCCD;
    fcl::CollisionResultd res;
    fcl::collide(a_.get(), I, b_.get(), T, req, res);
    if (!res.isCollision())
      return out;
    const auto& c = res.getContact(0);
    out.ok = true;
    out.distance = -c.penetration_depth;
    out.normal = {c.normal[0], c.normal[1], c.normal[2]};
    out.point = {c.pos[0], c.pos[1], c.pos[2]};
    return out;
  }

 private:
  bool depth_;
  std::shared_ptr<fcl::Convexd> a_, b_;
};

// ---------------------------------------------------------------- Bullet
btTransform btFrom(const Transform& X) {
  btMatrix3x3 R(X.R[0][0], X.R[1][0], X.R[2][0], X.R[0][1], X.R[1][1], X.R[2][1], X.R[0][2],
                X.R[1][2], X.R[2][2]);
  return btTransform(R, btVector3(X.t.x, X.t.y, X.t.z));
}

std::unique_ptr<btConvexHullShape> btHull(const Polytope& p) {
  auto s = std::make_unique<btConvexHullShape>();
  for (const auto& v : p.vertices())
    s->addPoint(btVector3(v.p.x, v.p.y, v.p.z), false);
  s->recalcLocalAabb();
  s->setMargin(0.0);
  return s;
}

class BulletGjkPeer : public PeerMethod {
 public:
  BulletGjkPeer(const Polytope& a, const Polytope& b) : a_(btHull(a)), b_(btHull(b)) {}
  double query(const Transform& X_AB, bool& ok) override {
    btPointCollector out;
    closestPoints(X_AB, out);
    ok = out.m_hasResult;
    return out.m_distance;
  }
  // Bullet: the normal on B points from B toward A, the point is on B
  PeerAnswer answer(const Transform& X_AB) override {
    btPointCollector res;
    closestPoints(X_AB, res);
    PeerAnswer out;
    if (!res.m_hasResult)
      return out;
    const Vec3 n_ba{res.m_normalOnBInWorld.x(), res.m_normalOnBInWorld.y(),
                    res.m_normalOnBInWorld.z()};
    const Vec3 p_b{res.m_pointInWorld.x(), res.m_pointInWorld.y(), res.m_pointInWorld.z()};
    out.ok = true;
    out.distance = res.m_distance;
    out.normal = -n_ba;
    out.point = p_b + n_ba * (0.5 * res.m_distance);
    return out;
  }

 private:
  // one GJK (EPA when they overlap) query, A at the origin and B at X_AB
  void closestPoints(const Transform& X_AB, btPointCollector& out) const {
    btVoronoiSimplexSolver simplex;
    btGjkEpaPenetrationDepthSolver epa;
    btGjkPairDetector gjk(a_.get(), b_.get(), &simplex, &epa);
    btDiscreteCollisionDetectorInterface::ClosestPointInput in;
    in.m_transformA.setIdentity();
    in.m_transformB = btFrom(X_AB);
    gjk.getClosestPoints(in, out, nullptr);
  }

  std::unique_ptr<btConvexHullShape> a_, b_;
};

class BulletEpa2Peer : public PeerMethod {
 public:
  BulletEpa2Peer(const Polytope& a, const Polytope& b, bool depth)
      : depth_(depth), a_(btHull(a)), b_(btHull(b)) {}
  double query(const Transform& X_AB, bool& ok) override {
    btTransform I;
    I.setIdentity();
    const btTransform T = btFrom(X_AB);
    btGjkEpaSolver2::sResults res;
    const btVector3 guess(1, 0, 0);
    if (!depth_) {
      ok = btGjkEpaSolver2::Distance(a_.get(), I, b_.get(), T, guess, res);
      return res.distance;
    }
    ok = btGjkEpaSolver2::Penetration(a_.get(), I, b_.get(), T, guess, res);
    return res.distance;
  }
  // Bullet: witnesses[0] on A, [1] on B; the normal points from B toward A
  PeerAnswer answer(const Transform& X_AB) override {
    btTransform I;
    I.setIdentity();
    const btTransform T = btFrom(X_AB);
    btGjkEpaSolver2::sResults res;
    const btVector3 guess(1, 0, 0);
    PeerAnswer out;
    out.ok = depth_ ? btGjkEpaSolver2::Penetration(a_.get(), I, b_.get(), T, guess, res)
                    : btGjkEpaSolver2::Distance(a_.get(), I, b_.get(), T, guess, res);
    if (!out.ok)
      return out;
    out.distance = res.distance;
    out.normal = -Vec3{res.normal.x(), res.normal.y(), res.normal.z()};
    const Vec3 w0{res.witnesses[0].x(), res.witnesses[0].y(), res.witnesses[0].z()};
    const Vec3 w1{res.witnesses[1].x(), res.witnesses[1].y(), res.witnesses[1].z()};
    out.point = 0.5 * (w0 + w1);
    return out;
  }

 private:
  bool depth_;
  std::unique_ptr<btConvexHullShape> a_, b_;
};

}  // namespace

std::vector<PeerInfo> peerList() {
  return {
      {"libccd-GJK-EPA", false, true},
      {"libccd-MPR", false, true},
      {"FCL-GJK-libccd", true, false},
      {"FCL-GJK-EPA-libccd", false, true},
      {"Bullet-btGjkPairDetector", true, true},
      {"Bullet-btGjkEpaSolver2", true, false},
      {"Bullet-btGjkEpaSolver2-Penetration", false, true},
  };
}

std::unique_ptr<PeerMethod> makePeer(const std::string& name,
                                     const Polytope& a,
                                     const Polytope& b) {
  if (name == "libccd-GJK-EPA")
    return std::make_unique<CcdPeer>(a, b, false);
  if (name == "libccd-MPR")
    return std::make_unique<CcdPeer>(a, b, true);
  if (name == "FCL-GJK-libccd")
    return std::make_unique<FclPeer>(a, b, false);
  if (name == "FCL-GJK-EPA-libccd")
    return std::make_unique<FclPeer>(a, b, true);
  if (name == "Bullet-btGjkPairDetector")
    return std::make_unique<BulletGjkPeer>(a, b);
  if (name == "Bullet-btGjkEpaSolver2")
    return std::make_unique<BulletEpa2Peer>(a, b, false);
  if (name == "Bullet-btGjkEpaSolver2-Penetration")
    return std::make_unique<BulletEpa2Peer>(a, b, true);
  return nullptr;
}

}  // namespace hapticd::bench
