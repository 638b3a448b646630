#include "core/scene/accessors.h"

#include <cmath>
#include <cstring>

#include "core/scene/uri.h"

namespace hapticd::scene::detail {

std::optional<BufferData> loadBuffers(const Document& doc,
                                      const LoadOptions& options,
                                      Problems* problems) {
  BufferData data;
  data.owned.reserve(doc.buffers.size());
  for (std::size_t i = 0; i < doc.buffers.size(); ++i) {
    const BufferDef& def = doc.buffers[i];
    const std::string w = "buffer " + std::to_string(i);
    std::span<const std::uint8_t> bytes;
    if (def.uri.empty()) {
      bytes = doc.bin;
    } else {
      auto read = isDataUri(def.uri) ? decodeDataUri(def.uri)
                                     : readFileLimited(def.path, options.limits.max_file_bytes);
      if (!read) {
        problems->add(w, (isDataUri(def.uri) ? "glTF: Failed to decode 'uri': "
                                             : "external URI " + inQuotes(def.uri) + ": ") +
                             read.error().message);
        continue;
      }
      data.owned.push_back(std::move(read).value());
      bytes = data.owned.back();
    }
    if (bytes.size() < def.byte_length) {
      problems->add(
          w, (isDataUri(def.uri) ? "glTF: Failed to decode 'uri': the data URI holds " : "holds ") +
                 std::to_string(bytes.size()) + " bytes, less than its byteLength " +
                 std::to_string(def.byte_length));
    }
    data.buffers.push_back(bytes);
  }
  if (problems->any())
    return std::nullopt;
  return data;
}

AccessorReader::AccessorReader(const Document& doc,
                               const BufferData& data,
                               const SceneLimits& limits,
                               Problems* problems)
    : doc_(doc), data_(data), limits_(limits), p_(problems) {}

const std::uint8_t* AccessorReader::base(const AccessorDef& a,
                                         std::size_t index,
                                         std::uint64_t element,
                                         std::uint64_t* stride) {
  const ViewDef& view = doc_.views[static_cast<std::size_t>(a.view)];
  const std::span<const std::uint8_t> data = data_.buffers[view.buffer];
  *stride = a.strideBytes(doc_.views);
  const std::uint64_t start = view.byte_offset + a.byte_offset;  // checked by validation
  if (start + (a.count - 1) * *stride + element > data.size()) {
    p_->add("accessor " + std::to_string(index),
            "data runs past the end of buffer " + std::to_string(view.buffer));
    return nullptr;
  }
  return data.data() + start;
}

bool AccessorReader::readPositions(std::size_t index,
                                   const std::string& use,
                                   std::vector<Vec3>* out) {
  const AccessorDef& a = doc_.accessors[index];
  const std::string w = "accessor " + std::to_string(index);
  if (a.type != "VEC3" || a.component_type != 5126 || a.normalized) {
    p_->add(w, use + " must be VEC3 of FLOAT (5126), got " + a.type + " of " +
                   std::to_string(a.component_type));
    return false;
  }
  if (a.count > limits_.max_hull_input_points) {
    p_->add(w, use + ": " + std::to_string(a.count) + " vertices exceeds max_hull_input_points (" +
                   std::to_string(limits_.max_hull_input_points) + ")");
    return false;
  }
  const auto count = static_cast<std::size_t>(a.count);
  const std::size_t start = out->size();
  out->resize(start + count, Vec3{0.0});
  if (a.view < 0)
    return true;  // all zeros (glTF)
  std::uint64_t stride = 0;
  const std::uint8_t* p = base(a, index, 12, &stride);
  if (!p)
    return false;
  for (std::size_t i = 0; i < count; ++i) {
    float f[3];
    std::memcpy(f, p + i * stride, sizeof f);
    if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2])) {
      p_->add(w, use + ": vertex " + std::to_string(i) + " is not finite (NaN or Inf)");
      return false;
    }
    (*out)[start + i] = {f[0], f[1], f[2]};
  }
  return true;
}

bool AccessorReader::readIndices(std::size_t index,
                                 std::size_t vertex_count,
                                 const std::string& use,
                                 std::vector<std::uint32_t>* out) {
  const AccessorDef& a = doc_.accessors[index];
  const std::string w = "accessor " + std::to_string(index);
  const std::uint32_t size = a.component_type == 5121   ? 1
                             : a.component_type == 5123 ? 2
                             : a.component_type == 5125 ? 4
                                                        : 0;
  if (a.type != "SCALAR" || size == 0) {
    p_->add(w, use + " indices must be SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    return false;
  }
  if (a.count % 3 != 0) {
    p_->add(w,
            use + ": " + std::to_string(a.count) + " indices is not a whole number of triangles");
    return false;
  }
  if (a.count > 6ull * limits_.max_hull_input_points) {
    p_->add(w, use + ": " + std::to_string(a.count) + " indices is too many for " +
                   "max_hull_input_points");
    return false;
  }
  const auto count = static_cast<std::size_t>(a.count);
  if (a.view < 0) {
    out->insert(out->end(), count, 0u);
    return true;
  }
  std::uint64_t stride = 0;
  const std::uint8_t* p = base(a, index, size, &stride);
  if (!p)
    return false;
  out->reserve(out->size() + count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint8_t* q = p + i * stride;
    std::uint32_t v = 0;
    if (size == 1) {
      v = q[0];
    } else if (size == 2) {
      std::uint16_t s;
      std::memcpy(&s, q, 2);
      v = s;
    } else {
      std::memcpy(&v, q, 4);
    }
    if (v >= vertex_count) {
      p_->add(w, use + ": index " + std::to_string(v) + " out of range (" +
                     std::to_string(vertex_count) + " vertices)");
      return false;
    }
    out->push_back(v);
  }
  return true;
}

}  // namespace hapticd::scene::detail
