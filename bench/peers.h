#pragma once
/// \file
/// The peer libraries measured beside hapticd in hapticbench, all from Debian packages, all in
/// double precision: libccd 2.1 (GJK+EPA and MPR penetration; it has no distance query), FCL 0.7
/// (GJK with its libccd solver: distance, and collision with contacts for depth), Bullet 3.24
/// (btGjkPairDetector with btGjkEpaPenetrationDepthSolver, and btGjkEpaSolver2).

#include <memory>
#include <string>
#include <vector>

#include "core/geometry/polytope.h"

namespace hapticd::bench {

/// A peer's whole answer, in A's frame, in our conventions (each library's own converted here).
struct PeerAnswer {
  bool ok = false;         ///< false: no answer for this configuration
  double distance = 0.0;   ///< > 0 gap, < 0 minus the penetration depth
  geom::Vec3 normal{0.0};  ///< unit, from A toward B (penetrating: the direction to move B out)
  geom::Vec3 point{0.0};   ///< the contact point: midway between the two witnesses
};

/// One peer method on one pair of convex hulls. Poses are B in A's frame.
class PeerMethod {
 public:
  virtual ~PeerMethod() = default;
  /// Distance, normal and contact point (the accuracy study's force and torque need all three).
  virtual PeerAnswer answer(const geom::Transform& X_AB) = 0;
  /// Signed distance: > 0 gap, < 0 minus the penetration depth; `ok` false when the method has no
  /// answer for this configuration (e.g. a distance method on overlapping shapes).
  virtual double query(const geom::Transform& X_AB, bool& ok) = 0;
};

struct PeerInfo {
  std::string name;  ///< "libccd-GJK-EPA", ...
  bool distance;     ///< answers separated configurations
  bool penetration;  ///< answers overlapping configurations
};

/// The peers, in a fixed order.
std::vector<PeerInfo> peerList();

/// A method of peer `name` for hulls of points a and b (each the hull's vertices).
std::unique_ptr<PeerMethod> makePeer(const std::string& name,
                                     const geom::Polytope& a,
                                     const geom::Polytope& b);

}  // namespace hapticd::bench
