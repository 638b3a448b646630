#include "core/scene/glb.h"

#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace hapticd::scene {

std::uint32_t readLe32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

void appendLe32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i)
    out.push_back(static_cast<std::uint8_t>((v >> (8 * i)) & 0xffu));
}

bool isGlb(std::span<const std::uint8_t> bytes) {
  return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

Result<GlbChunks> splitGlb(std::span<const std::uint8_t> bytes) {
  const std::uint64_t size = bytes.size();
  const std::uint8_t* p = bytes.data();
  if (!isGlb(bytes))
    return Error{"not a GLB: wrong magic"};
  if (size < 20) {
    return Error{"truncated GLB: " + std::to_string(size) +
                 " bytes, the header and first chunk header need 20"};
  }
  const std::uint32_t version = readLe32(p + 4);
  const std::uint32_t length = readLe32(p + 8);
  if (version != 2)
    return Error{"GLB version " + std::to_string(version) + " (only 2 is supported)"};
  if (length > size) {
    return Error{"truncated GLB: the header says " + std::to_string(length) +
                 " bytes, the file has " + std::to_string(size)};
  }
  if (length < size) {
    return Error{"GLB header length " + std::to_string(length) + " does not match the file size " +
                 std::to_string(size)};
  }
  const std::uint64_t json_length = readLe32(p + 12);
  const std::uint32_t json_type = readLe32(p + 16);
  if (json_type != kGlbChunkJson) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "%08X", json_type);
    return Error{"GLB chunk 0 is not JSON (type 0x" + std::string(hex) + ")"};
  }
  if (json_length == 0 || 20 + json_length > size) {
    return Error{"GLB JSON chunk length " + std::to_string(json_length) +
                 " runs past the end of the file (" + std::to_string(size) + " bytes)"};
  }
  GlbChunks chunks;
  chunks.json = std::string_view(reinterpret_cast<const char*>(p + 20), json_length);
  const std::uint64_t at = 20 + json_length;
  if (at % 4 != 0) {
    return Error{"GLB JSON chunk length " + std::to_string(json_length) +
                 " is not a multiple of 4"};
  }
  if (at == size)
    return chunks;
  if (at + 8 > size)
    return Error{"truncated GLB: chunk 1 header runs past the end of the file"};
  const std::uint64_t bin_length = readLe32(p + at);
  const std::uint32_t bin_type = readLe32(p + at + 4);
  if (at + 8 + bin_length > size) {
    return Error{"GLB BIN chunk length " + std::to_string(bin_length) +
                 " runs past the end of the file (" + std::to_string(size - at - 8) +
                 " bytes left)"};
  }
  if (bin_type != kGlbChunkBin)
    return Error{"GLB chunk 1 is not BIN"};
  if (bin_length % 4 != 0) {
    return Error{"GLB BIN chunk length " + std::to_string(bin_length) + " is not a multiple of 4"};
  }
  chunks.bin = bytes.subspan(at + 8, bin_length);
  return chunks;
}

std::vector<std::uint8_t> packGlb(std::string_view json_text, std::span<const std::uint8_t> bin) {
  const std::size_t text_size = (json_text.size() + 3) / 4 * 4;
  const std::size_t bin_size = (bin.size() + 3) / 4 * 4;
  std::size_t total = 12 + 8 + text_size;
  if (bin_size > 0)
    total += 8 + bin_size;
  if (total > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error("GLB over 4 GiB");
  std::vector<std::uint8_t> out;
  out.reserve(total);
  appendLe32(out, kGlbMagic);
  appendLe32(out, 2u);
  appendLe32(out, static_cast<std::uint32_t>(total));
  appendLe32(out, static_cast<std::uint32_t>(text_size));
  appendLe32(out, kGlbChunkJson);
  out.insert(out.end(), json_text.begin(), json_text.end());
  out.resize(out.size() + text_size - json_text.size(), ' ');
  if (bin_size > 0) {
    appendLe32(out, static_cast<std::uint32_t>(bin_size));
    appendLe32(out, kGlbChunkBin);
    out.insert(out.end(), bin.begin(), bin.end());
    out.resize(out.size() + bin_size - bin.size(), 0);
  }
  return out;
}

std::uint32_t componentBytes(std::uint64_t component_type) {
  switch (component_type) {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    case 5125:
    case 5126:
      return 4;
    default:
      return 0;
  }
}

std::uint32_t typeComponents(std::string_view type) {
  struct Entry {
    std::string_view name;
    std::uint32_t components;
  };
  static constexpr Entry kTypes[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                     {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
  for (const Entry& e : kTypes) {
    if (e.name == type)
      return e.components;
  }
  return 0;
}

}  // namespace hapticd::scene
