#pragma once
/// \file
/// Convex polytope with full feature adjacency and the Voronoi-region planes of every feature
/// (Lin & Canny 1991; Mirtich, "V-Clip", ACM TOG 17(3) 1998, §3), plus the directional lookup
/// table of Ehmann & Lin 2000 for cold starts. Built once, off the servo thread; immutable after.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/geometry/pose.h"

namespace hapticd::geom {

enum class FeatureType : std::uint8_t { kVertex = 0, kEdge = 1, kFace = 2, kNone = 3 };

/// A vertex, edge or face of one polytope, by index.
struct Feature {
  FeatureType type = FeatureType::kNone;
  std::uint32_t index = 0;

  static Feature vertex(std::uint32_t i) { return {FeatureType::kVertex, i}; }
  static Feature edge(std::uint32_t i) { return {FeatureType::kEdge, i}; }
  static Feature face(std::uint32_t i) { return {FeatureType::kFace, i}; }
  bool valid() const { return type != FeatureType::kNone; }
  friend bool operator==(const Feature&, const Feature&) = default;
  /// "V3", "E7", "F2" or "-" (the names of the query format).
  std::string name() const;
};

/// Limits and tolerances of hull construction. Defaults are documented in config/hapticd.toml.
struct HullOptions {
  /// Hull vertices above this refuse the hull (the lookup table stores 16-bit indices).
  std::size_t max_vertices = 4096;
  /// Input points above this are refused before any work.
  std::size_t max_input_points = 1000000;
  /// Points closer than this fraction of the bounding-box diagonal are merged into one.
  double merge_tolerance = 1e-9;
};

/// A closed convex polytope. All coordinates are in the polytope's own frame.
/// Faces are convex polygons (coplanar hull triangles merged), boundary counter-clockwise seen
/// from outside. Immutable; any thread may read it concurrently.
class Polytope {
 public:
  struct Vertex {
    Vec3 p;
    std::uint32_t first = 0;  ///< incident edges: vertexEdges()[first, first + count)
    std::uint32_t count = 0;
  };
  /// An incident edge seen from a vertex.
  struct VertexEdge {
    std::uint32_t edge = 0;   ///< edge index
    std::uint32_t other = 0;  ///< the edge's other vertex
    Vec3 out;  ///< unit direction from this vertex along the edge; VR(vertex): (x - v)·out <= 0
  };
  struct Edge {
    std::uint32_t tail = 0, head = 0;  ///< vertex indices
    /// face[0]: the face whose boundary runs tail -> head; face[1]: the one running head -> tail.
    std::array<std::uint32_t, 2> face{0, 0};
    Vec3 dir{0.0};  ///< unit, tail -> head
    double length = 0.0;
    /// Voronoi plane normals against face[i], through the edge: (x - tail)·fe_normal[i] >= 0
    /// holds inside VR(edge); the other side belongs to VR(face[i]).
    std::array<Vec3, 2> fe_normal{Vec3{0.0}, Vec3{0.0}};
  };
  /// One boundary edge of a face, in counter-clockwise order.
  struct FaceEdge {
    std::uint32_t edge = 0;    ///< edge index
    std::uint32_t vertex = 0;  ///< the vertex where this boundary edge starts (CCW)
    Vec3 side;  ///< inward unit normal of the side plane: VR(face) has (x - vertex)·side >= 0
  };
  struct Face {
    Vec3 normal{0.0};         ///< outward unit normal
    double offset = 0.0;      ///< normal·x == offset on the face plane
    std::uint32_t first = 0;  ///< boundary: faceEdges()[first, first + count)
    std::uint32_t count = 0;
  };

  /// Builds the convex hull of `points` with Qhull. Errors (never a crash): fewer than 4 points,
  /// NaN or Inf, all points coplanar or collinear after merging near-duplicates, more hull vertices
  /// than options.max_vertices, or more input points than options.max_input_points.
  /// Any thread but the servo thread (allocates).
  static Result<Polytope> fromPoints(std::span<const Vec3> points, const HullOptions& options = {});

  std::span<const Vertex> vertices() const { return vertices_; }
  std::span<const Edge> edges() const { return edges_; }
  std::span<const Face> faces() const { return faces_; }
  std::span<const VertexEdge> vertexEdges(std::uint32_t v) const {
    return {vertex_edges_.data() + vertices_[v].first, vertices_[v].count};
  }
  std::span<const FaceEdge> faceEdges(std::uint32_t f) const {
    return {face_edges_.data() + faces_[f].first, faces_[f].count};
  }
  /// All faces in depth-first order over face adjacency: consecutive faces are near each other,
  /// so support queries warm-started from the previous face's answer climb few steps.
  std::span<const std::uint32_t> faceOrder() const { return face_order_; }

  /// Centre of the bounding sphere used for cold starts (mean of the vertices).
  const Vec3& centroid() const { return centroid_; }
  /// Largest vertex distance from centroid(): the object's size for relative tolerances.
  double radius() const { return radius_; }

  /// Index of a vertex maximising dot(p, dir), by hill climbing from `hint` over the vertex graph
  /// (expected O(1) when `hint` is last tick's answer). Ties resolve to the first maximum found.
  std::uint32_t support(const Vec3& dir, std::uint32_t hint) const;
  /// The directional lookup table (Ehmann & Lin 2000): the stored extreme vertex for the table cell
  /// containing `dir` (need not be normalised, must be non-zero). A start for support().
  std::uint32_t lookup(const Vec3& dir) const;
  /// Bytes used by the lookup table (<= 1024).
  static constexpr std::size_t kLookupBytes = std::size_t{2} * 16 * 16;

 private:
  // the steps of fromPoints
  Result<bool> takeHull(const std::vector<Vec3>& merged,
                        std::vector<std::vector<std::uint32_t>>* loops,
                        std::vector<Vec3>* normals);
  Result<bool> buildFacesAndEdges(const std::vector<std::vector<std::uint32_t>>& loops,
                                  const std::vector<Vec3>& normals);
  void buildVertexEdges();
  Result<bool> buildFaceOrder();
  void buildLookup();

  std::vector<Vertex> vertices_;
  std::vector<VertexEdge> vertex_edges_;
  std::vector<Edge> edges_;
  std::vector<Face> faces_;
  std::vector<FaceEdge> face_edges_;
  std::vector<std::uint32_t> face_order_;
  Vec3 centroid_{0.0};
  double radius_ = 0.0;
  std::array<std::uint16_t, std::size_t{16} * 16> lookup_{};
};

}  // namespace hapticd::geom
