#pragma once
/// \file
/// The scene loader's second pass (internal to hapticd_scene): the bytes of every buffer (the GLB
/// BIN chunk, `data:` URIs, external files under the folder policy) and the decoding of accessors
/// into vertex positions and triangle indices, each value checked (finite, in range).
/// Any thread but the servo thread.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/scene/document.h"

namespace hapticd::scene::detail {

/// The bytes of every buffer of a document, in buffer order; each holds at least its byteLength.
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

  /// Appends the accessor's VEC3 FLOAT positions to `out`; false (with a problem naming `use`)
  /// for another type, more than max_hull_input_points vertices, or a value that is not finite.
  bool readPositions(std::size_t accessor, const std::string& use, std::vector<Vec3>* out);
  /// Appends the accessor's unsigned SCALAR indices, each below `vertex_count`, a whole number of
  /// triangles.
  bool readIndices(std::size_t accessor,
                   std::size_t vertex_count,
                   const std::string& use,
                   std::vector<std::uint32_t>* out);

 private:
  /// The first byte of the accessor's data and its stride; null when the data runs past its
  /// buffer (a problem added).
  const std::uint8_t* base(const AccessorDef& a,
                           std::size_t index,
                           std::uint64_t element,
                           std::uint64_t* stride);

  const Document& doc_;
  const BufferData& data_;
  const SceneLimits& limits_;
  Problems* p_;
};

}  // namespace hapticd::scene::detail
