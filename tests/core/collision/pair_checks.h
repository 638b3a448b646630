#pragma once
/// \file
/// Checks shared by the narrow-phase tests: one answer of the code under test against the
/// brute-force reference (tests/reference/reference.h), every property the narrow-phase issue
/// asks for, with a message naming the inputs when one fails. Test code only.

#include <array>
#include <cstdint>
#include <map>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "core/collision/pair_query.h"
#include "core/geometry/rotation.h"
#include "tests/core/geometry_helpers.h"
#include "tests/reference/reference.h"

namespace hapticd::collision::checks {

/// Signed distance, depth and witness tolerance, relative to the pair's size (larger radius).
inline constexpr double kDistTol = 1e-9;
/// Normal tolerance, radians.
inline constexpr double kAngleTol = 1e-6;
/// The closest-feature walk's Voronoi plane tolerance, relative to the size (docs/narrow-phase.md):
/// a final feature pair may violate a Voronoi plane by this much, so each witness may sit this far
/// from the exact closest point, and a separated normal (witness to witness) may turn by this over
/// the gap: checkPairResult allows kAngleTol + kPlaneTol * size / distance for separated pairs
/// (checkClosest compares normals only beyond gaps of 1e-6 of the size, where this is < kAngleTol).
inline constexpr double kPlaneTol = 1e-12;
/// Around the touch threshold (QueryOptions::touch_tolerance of the size) either neighbouring
/// status is accepted within this band, relative to the size.
inline constexpr double kStatusBand = 1e-12;
/// The minimal translation direction counts as unique when every candidate axis more than
/// kAngleTol away from the best one is deeper by this much, relative to the size.
inline constexpr double kUniqueMargin = 1e-8;

// --- shapes -------------------------------------------------------------------------------------

/// The hull of `points`; throws std::runtime_error with Qhull's message when refused (a test
/// shape that cannot be built is a test failure, reported by GoogleTest).
Polytope hullOf(std::span<const Vec3> points);
/// Corners of the box [-x, x] x [-y, y] x [-z, z].
std::vector<Vec3> box(double x, double y, double z);
/// A prism over a regular k-gon of circumradius r, z in [-h, h].
using testing::prism;
/// Every point times s.
std::vector<Vec3> scaled(std::vector<Vec3> points, double s);
/// The larger radius of the two: the pair's size.
double pairSize(const Polytope& a, const Polytope& b);

// --- small measures -----------------------------------------------------------------------------

double angle(const Vec3& u, const Vec3& v);
using geom::finite;
/// Largest signed distance of p (A's frame) above the face planes of q placed by X (q -> A):
/// 0 on q's surface, < 0 inside, > 0 outside (a lower bound of the distance to q).
double outside(const Polytope& q, const Transform& X, const Vec3& p);
/// Distance from p (A's frame) to feature f of q placed by X, from the vertex/edge/face lists.
double distanceToFeature(const Polytope& q, const Transform& X, Feature f, const Vec3& p);

/// The best and second-best minimal-translation axes by brute force (long double, every face
/// normal and every edge-pair cross product, both orientations). `second` is the smallest depth
/// over the axes more than kAngleTol away from `axis`.
struct AxisMargin {
  double best = 0.0;
  Vec3 axis{0.0};
  double second = 0.0;
  bool unique(double size) const { return second - best > kUniqueMargin * size; }
};
AxisMargin axisMargin(const Polytope& a, const Polytope& b, const Transform& X_AB);

/// The status the reference implies (the touch threshold of QueryOptions{}), and whether
/// `status` is acceptable for the reference's signed distance (the band above).
ContactStatus statusOf(double signed_distance, double size);
bool statusAcceptable(ContactStatus status, double ref_signed_distance, double size);
const char* name(ContactStatus s);

// --- figures ------------------------------------------------------------------------------------

/// What a test saw, printed as one line to stdout.
struct Figures {
  std::size_t pairs = 0, separated = 0, touching = 0, penetrating = 0;
  std::size_t normals_checked = 0, normals_skipped = 0;  ///< skipped: the reference's is not unique
  double max_dist_err = 0.0;                             ///< |ours - reference| / size
  double max_normal_err = 0.0;                           ///< radians
  double max_witness_err = 0.0;   ///< |point_b - point_a - distance * normal| / size, and off-hull
  double max_manifold_err = 0.0;  ///< |deepest contact depth + distance| / size
  std::uint32_t max_iterations = 0;
  std::size_t walk_handoffs =
      0;  ///< overlapping pairs the walk ended as touching (docs: settled by the depth)
  std::array<std::size_t, 5> manifold_sizes{};
  /// Counts one answer of status `s` (separated, touching or penetrating).
  void countStatus(ContactStatus s);
  void print(const std::string& what) const;
};

/// A case label from its parts.
template <class... T>
std::string label(const T&... parts) {
  std::ostringstream s;
  (s << ... << parts);
  return s.str();
}

/// The failures of one test, by kind (the "[...]" that starts a check's message): counted, the
/// first few kept in full, so that a run reports every kind of wrong answer and how often.
class Failures {
 public:
  /// Records a check's answer for the case `label`; an empty message is a pass. True on failure.
  bool add(const std::string& label, const std::string& message);
  std::size_t total() const { return total_; }
  /// One line per kind with its count, then the first examples of each in full.
  std::string summary() const;

 private:
  std::map<std::string, std::size_t> count_;
  std::map<std::string, std::vector<std::string>> examples_;
  std::map<std::string, std::vector<std::string>> labels_;
  std::size_t total_ = 0;
};

// --- the checks (empty string: every property holds; else what failed, with the inputs) --------

/// The inputs of one checked answer: the two hulls, B placed in A's frame by X_AB, and the
/// reference's answer for them.
struct PairCase {
  const Polytope& a;
  const Polytope& b;
  const Transform& X_AB;
  const reference::RefAnswer& ref;
};

/// A queryPair answer: status, signed distance, normal (when unique), witnesses, features,
/// manifold, no NaN.
std::string checkPairResult(const PairCase& in, const PairResult& r, Figures& fig);
/// A closestFeatures answer: never the iteration cap; separated pairs converge to the reference
/// distance with witnesses on the reported features; overlapping pairs report penetration.
std::string checkClosest(const PairCase& in, const ClosestResult& c, Figures& fig);
/// Runs a cold queryPair and a cold closestFeatures and both checks above.
std::string checkPair(const Polytope& a, const Polytope& b, const Transform& X_AB, Figures& fig);

/// The inputs of a pair, printable (vertex lists when short, X_AB to 17 digits).
std::string describe(const Polytope& a, const Polytope& b, const Transform& X_AB);

/// A uniformly random rigid transform with a Gaussian translation of standard deviation `spread`.
Transform randomTransform(std::mt19937_64& rng, double spread);

}  // namespace hapticd::collision::checks
