#pragma once
/// \file
/// The glTF binary container (GLB: a 12-byte header, a JSON chunk, an optional BIN chunk; glTF 2.0
/// specification, "Binary glTF Layout") read and written, and the sizes of accessor components and
/// types. The one implementation used by the scene loader, the scene bundler, the demo-scene
/// generator (scenes/) and the tests. No dependency but the standard library; any thread.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/result.h"

namespace hapticd::scene {

inline constexpr std::uint32_t kGlbMagic = 0x46546C67u;      ///< "glTF"
inline constexpr std::uint32_t kGlbChunkJson = 0x4E4F534Au;  ///< "JSON"
inline constexpr std::uint32_t kGlbChunkBin = 0x004E4942u;   ///< "BIN\0"

/// glTF accessor componentType values.
enum ComponentType : std::uint32_t {
  kComponentByte = 5120,
  kComponentUnsignedByte = 5121,
  kComponentShort = 5122,
  kComponentUnsignedShort = 5123,
  kComponentUnsignedInt = 5125,
  kComponentFloat = 5126,
};
/// glTF bufferView targets and the triangle primitive mode.
inline constexpr int kTargetArrayBuffer = 34962;
inline constexpr int kTargetElementArrayBuffer = 34963;
inline constexpr int kModeTriangles = 4;

/// The two chunks of a GLB, views into the bytes given to splitGlb.
struct GlbChunks {
  std::string_view json;              ///< the JSON chunk, padding included
  std::span<const std::uint8_t> bin;  ///< the BIN chunk (empty when there is none)
};

/// True when the bytes start with the GLB magic "glTF".
bool isGlb(std::span<const std::uint8_t> bytes);

/// Splits a GLB into its chunks, checking the header (magic, version 2, total length equal to the
/// size), the JSON chunk (type, non-empty, inside the file, length a multiple of 4) and the BIN
/// chunk when present (inside the file, type, length a multiple of 4). Bytes after the BIN chunk
/// are ignored (the specification allows further chunks). The error names the first field that is
/// wrong, e.g. "truncated GLB: the header says 1156 bytes, the file has 578".
Result<GlbChunks> splitGlb(std::span<const std::uint8_t> bytes);

/// Packs JSON text and a binary buffer as GLB: the JSON padded with spaces and the BIN with zeros
/// to 4 bytes; no BIN chunk when `bin` is empty. Throws std::length_error over 4 GiB.
std::vector<std::uint8_t> packGlb(std::string_view json_text, std::span<const std::uint8_t> bin);

/// Bytes of one component of a glTF componentType (5120..5126 but 5124), 0 for any other value.
std::uint32_t componentBytes(std::uint64_t component_type);

/// Components of a glTF accessor type ("SCALAR" 1, "VEC2" 2, "VEC3" 3, "VEC4" 4, "MAT2" 4,
/// "MAT3" 9, "MAT4" 16), 0 for any other string.
std::uint32_t typeComponents(std::string_view type);

/// Little-endian 32-bit read and append.
std::uint32_t readLe32(const std::uint8_t* p);
void appendLe32(std::vector<std::uint8_t>& out, std::uint32_t v);

}  // namespace hapticd::scene
