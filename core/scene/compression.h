#pragma once
/// \file
/// The compressed geometry of glTF (internal to hapticd_scene): KHR_draco_mesh_compression
/// (libdraco: a primitive's vertices and triangles from a Draco bitstream) and
/// EXT_meshopt_compression / KHR_meshopt_compression (libmeshoptimizer: a bufferView's bytes from
/// the attribute, triangle or index codec, then the filter). Every parameter is checked before a
/// library is called; a stream the library refuses is an error with its words, never a crash.
/// Any thread but the servo thread (allocates).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"

namespace hapticd::scene::detail {

/// A Draco stream decoded: `components` values per point of one attribute, and the triangles.
struct DracoGeometry {
  std::vector<double> values;            ///< point-major, `components` each, as stored
  std::uint32_t components = 0;          ///< of the attribute asked for
  std::uint32_t points = 0;              ///< vertices
  std::vector<std::uint32_t> triangles;  ///< 3 point indices each; empty for a point cloud
};

/// Decodes `stream` (a mesh when `mesh`, else a point cloud) and the attribute with Draco unique
/// id `attribute_id`; an error naming what is wrong ("Draco: ..."). The counts the stream's header
/// claims are read first and refused above `max_points` vertices or `max_faces` triangles, so that
/// a hostile header cannot make the library allocate without bound; streams with Draco metadata
/// are refused (their header cannot be checked).
Result<DracoGeometry> decodeDraco(std::span<const std::uint8_t> stream,
                                  std::uint32_t attribute_id,
                                  bool mesh,
                                  std::uint64_t max_points,
                                  std::uint64_t max_faces);

/// The meshopt compression of one bufferView (already validated: mode, filter, stride, count).
struct MeshoptView {
  enum class Mode : std::uint8_t { kAttributes, kTriangles, kIndices };
  enum class Filter : std::uint8_t { kNone, kOctahedral, kQuaternion, kExponential };
  Mode mode = Mode::kAttributes;
  Filter filter = Filter::kNone;
  std::uint64_t count = 0;
  std::uint64_t stride = 0;
};

/// Decodes `stream` into count * stride bytes; an error when the codec refuses the stream.
Result<std::vector<std::uint8_t>> decodeMeshopt(std::span<const std::uint8_t> stream,
                                                const MeshoptView& view);

}  // namespace hapticd::scene::detail
