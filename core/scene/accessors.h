#pragma once
/// \file
/// The scene loader's second pass (internal to hapticd_scene): the bytes of every buffer (the GLB
/// BIN chunk, `data:` URIs, external files under the folder policy), bufferViews decoded from
/// meshopt compression, and accessors decoded into vertex positions (FLOAT, or the integer types
/// of KHR_mesh_quantization, normalized or not; sparse storage applied) and triangle indices, or a
/// primitive's Draco stream into both; each value checked (finite, in range).
/// Any thread but the servo thread.

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/scene/document.h"

namespace hapticd::scene::detail {

/// The bytes of every buffer of a document, in buffer order; each holds at least its byteLength
/// (a placeholder buffer holds none).
struct BufferData {
  std::vector<std::span<const std::uint8_t>> buffers;
  std::vector<std::vector<std::uint8_t>> owned;  ///< decoded data URIs and external files
};

/// Reads every buffer; nullopt (with problems) when one cannot be read or is too short.
std::optional<BufferData> loadBuffers(const Document& doc,
                                      const LoadOptions& options,
                                      Problems* problems);

/// Decodes accessors of a validated document.
class AccessorReader {
 public:
  AccessorReader(const Document& doc,
                 const BufferData& data,
                 const SceneLimits& limits,
                 Problems* problems);

  /// Appends the accessor's VEC3 positions to `out`; false (with a problem naming `use`) for
  /// another type, more than max_hull_input_points vertices, or a value that is not finite.
  bool readPositions(std::size_t accessor, const std::string& use, std::vector<Vec3>* out);
  /// Appends the accessor's unsigned SCALAR indices, each below `vertex_count`.
  bool readIndices(std::size_t accessor,
                   std::size_t vertex_count,
                   const std::string& use,
                   std::vector<std::uint32_t>* out);
  /// Appends a Draco primitive's positions (converted as its POSITION accessor says) and, when
  /// `triangles` is given, its triangles (indices into the appended positions, from 0).
  bool readDraco(const MeshPrimitiveDef& prim,
                 const std::string& use,
                 std::vector<Vec3>* points,
                 std::vector<std::uint32_t>* triangles);

 private:
  /// The bytes of a view (decoded once when meshopt-compressed); null with a problem.
  const std::vector<std::uint8_t>* decodedView(std::size_t view);
  std::span<const std::uint8_t> viewBytes(std::size_t view, bool* ok);
  /// Every component of the accessor as a double (normalized when the accessor says so), its
  /// sparse storage applied; false with a problem.
  bool components(std::size_t accessor, const std::string& use, std::vector<double>* out);
  bool applySparse(const AccessorDef& a, const std::string& w, std::vector<double>* out);

  const Document& doc_;
  const BufferData& data_;
  const SceneLimits& limits_;
  Problems* p_;
  std::map<std::size_t, std::vector<std::uint8_t>> meshopt_;  // decoded views
};

/// A mesh primitive read in two steps, so that a caller may check the vertex count between them
/// (the loader's collider meshes and readSceneTriangles share them): its vertices, then its
/// triangles. Draco, meshopt, quantized and sparse data alike.
struct PrimitiveReading {
  std::size_t first = 0;             ///< where the primitive's vertices start in the points
  std::size_t count = 0;             ///< how many it has
  std::vector<std::uint32_t> draco;  ///< a Draco primitive's triangle list (when wanted)
};
/// Appends the vertices of `prim` (which has a POSITION) to `points`, as stored (not placed);
/// `triangles`: keep a Draco stream's triangle list for the second step. `use` names the primitive
/// in problems ("mesh 2 'Bunny' primitive 0").
bool readPrimitivePoints(AccessorReader& reader,
                         const MeshPrimitiveDef& prim,
                         const std::string& use,
                         bool triangles,
                         std::vector<Vec3>* points,
                         PrimitiveReading* reading);
/// Appends the triangles of a primitive whose points were read (mode 4 list, 5 strip, 6 fan: the
/// caller checks the mode) to `out`, three indices each into the points; a list that is not a
/// whole number of triangles is a problem. `bad_index` set: an index past the primitive's
/// vertices becomes that value (for a caller that repairs such triangles) instead of a problem.
bool readPrimitiveTriangles(AccessorReader& reader,
                            const MeshPrimitiveDef& prim,
                            const std::string& use,
                            const PrimitiveReading& reading,
                            std::optional<std::uint32_t> bad_index,
                            Problems* problems,
                            std::vector<std::uint32_t>* out);

}  // namespace hapticd::scene::detail
