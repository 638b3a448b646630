#pragma once
/// \file
/// The face-against-face contact region of a close pair, for the proxy's contact rows.
///
/// The narrow phase's manifold of a separated pair comes from its closest features (§4.1): when a
/// face rests on a face slightly tilted, the closest features are an edge and a face, and the
/// manifold holds that edge's two points only, although the whole face lies within the predictive
/// distance delta. The proxy would then pivot freely about the edge into the far side. So, when
/// the pair's normal is within a tolerance of a face normal on both sides, the held face is
/// clipped (Sutherland–Hodgman) against the side planes of the environment's face, and every
/// clipped vertex becomes a point with its own gap to the environment's face plane.

#include <array>
#include <cstdint>

#include "core/geometry/polytope.h"

namespace hapticd::response {

using geom::Feature;
using geom::Polytope;
using geom::Transform;
using geom::Vec3;

/// The face of `shape` whose outward normal is closest to n_P (the shape's frame), searched
/// among the faces around `feature` (all faces around the extreme vertex along n_P when the
/// feature is unknown). Any thread; no allocation.
std::uint32_t bestFace(const Polytope& shape, const Vec3& n_P, Feature feature);

/// Points of a face-face contact, world frame.
struct FaceContact {
  static constexpr std::size_t kMaxPoints = 32;
  std::array<Vec3, kMaxPoints> p_W{};    ///< on the held face
  std::array<double, kMaxPoints> gap{};  ///< to the environment's face plane, > 0 apart
  std::uint32_t count = 0;
  Vec3 n_W{0.0};  ///< the environment face's outward normal
  std::uint32_t env_face = 0;
};

/// The clipped region (see the file comment) when both faces are within `cos_tolerance` of the
/// pair's normal n_out_W (out of the environment); false otherwise or when the faces are too
/// large for the fixed buffers (the caller keeps the manifold). Servo thread; no allocation.
bool faceContact(const Polytope& env,
                 const Transform& X_WE,
                 Feature env_feature,
                 const Polytope& held,
                 const Transform& X_WH,
                 Feature held_feature,
                 const Vec3& n_out_W,
                 double cos_tolerance,
                 FaceContact* out);

}  // namespace hapticd::response
