#include "core/scene/accessors.h"

#include <cmath>
#include <cstring>
#include <limits>

#include "core/scene/glb.h"
#include "core/scene/uri.h"

namespace hapticd::scene::detail {
namespace {

/// One component at `p` of glTF component type `type`, as a double; normalized integers map to
/// [0, 1] or [-1, 1] as glTF says (max(c / 127, -1) for BYTE, and so on).
double componentAt(const std::uint8_t* p, std::uint32_t type, bool normalized) {
  switch (type) {
    case kComponentByte: {
      const auto v = static_cast<std::int8_t>(p[0]);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case kComponentUnsignedByte:
      return normalized ? p[0] / 255.0 : p[0];
    case kComponentShort: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case kComponentUnsignedShort: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case kComponentUnsignedInt: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

/// A value decoded as an integer of `type` (Draco streams give integer attributes as numbers),
/// normalized as glTF says.
double normalizedInteger(double v, std::uint32_t type) {
  switch (type) {
    case kComponentByte:
      return std::max(v / 127.0, -1.0);
    case kComponentUnsignedByte:
      return v / 255.0;
    case kComponentShort:
      return std::max(v / 32767.0, -1.0);
    case kComponentUnsignedShort:
      return v / 65535.0;
    default:
      return v;
  }
}

/// POSITION may be FLOAT, or (KHR_mesh_quantization) BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT,
/// normalized or not.
bool positionTypeAllowed(const AccessorDef& a) {
  if (a.type != "VEC3")
    return false;
  if (a.component_type == kComponentFloat)
    return !a.normalized;
  return a.component_type == kComponentByte || a.component_type == kComponentUnsignedByte ||
         a.component_type == kComponentShort || a.component_type == kComponentUnsignedShort;
}

/// Triangles from a primitive's vertex list by its mode (4 list, 5 strip, 6 fan), offset by
/// `first` (`bad` stays itself); false when a list is not a whole number of triangles.
bool triangulate(std::int32_t mode,
                 const std::vector<std::uint32_t>& v,
                 std::uint32_t first,
                 std::optional<std::uint32_t> bad,
                 std::vector<std::uint32_t>* out) {
  const auto at = [&](std::uint32_t i) { return bad && i == *bad ? i : first + i; };
  const auto put = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    out->insert(out->end(), {at(a), at(b), at(c)});
  };
  if (mode == 4) {
    if (v.size() % 3 != 0)
      return false;
    for (std::size_t i = 0; i < v.size(); i += 3)
      put(v[i], v[i + 1], v[i + 2]);
  } else {
    for (std::size_t i = 2; i < v.size(); ++i) {
      if (mode == 6)
        put(v[0], v[i - 1], v[i]);
      else if (i % 2 == 0)
        put(v[i - 2], v[i - 1], v[i]);
      else
        put(v[i - 1], v[i - 2], v[i]);
    }
  }
  return true;
}

}  // namespace

std::optional<BufferData> loadBuffers(const Document& doc,
                                      const LoadOptions& options,
                                      Problems* problems) {
  BufferData data;
  data.owned.reserve(doc.buffers.size());
  for (std::size_t i = 0; i < doc.buffers.size(); ++i) {
    const BufferDef& def = doc.buffers[i];
    const std::string w = "buffer " + std::to_string(i);
    std::span<const std::uint8_t> bytes;
    if (def.placeholder) {
      data.buffers.push_back(bytes);
      continue;
    }
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

const std::vector<std::uint8_t>* AccessorReader::decodedView(std::size_t view) {
  const auto it = meshopt_.find(view);
  if (it != meshopt_.end())
    return &it->second;
  const MeshoptDef& m = *doc_.views[view].meshopt;
  const std::span<const std::uint8_t> buffer = data_.buffers[m.buffer];
  const std::string w = "bufferView " + std::to_string(view) + " meshopt";
  if (m.byte_offset + m.byte_length > buffer.size()) {
    p_->add(w, "the compressed data runs past the end of buffer " + std::to_string(m.buffer));
    return nullptr;
  }
  auto decoded = decodeMeshopt(buffer.subspan(m.byte_offset, m.byte_length), m.codec);
  if (!decoded) {
    p_->add(w, decoded.error().message);
    return nullptr;
  }
  return &meshopt_.emplace(view, std::move(decoded).value()).first->second;
}

std::span<const std::uint8_t> AccessorReader::viewBytes(std::size_t view, bool* ok) {
  const ViewDef& v = doc_.views[view];
  *ok = true;
  if (v.meshopt) {
    const std::vector<std::uint8_t>* bytes = decodedView(view);
    *ok = bytes != nullptr;
    return bytes ? std::span<const std::uint8_t>(*bytes) : std::span<const std::uint8_t>();
  }
  const std::span<const std::uint8_t> buffer = data_.buffers[v.buffer];
  if (v.byte_offset + v.byte_length > buffer.size()) {
    p_->add("bufferView " + std::to_string(view),
            "data runs past the end of buffer " + std::to_string(v.buffer));
    *ok = false;
    return {};
  }
  return buffer.subspan(v.byte_offset, v.byte_length);
}

bool AccessorReader::applySparse(const AccessorDef& a,
                                 const std::string& w,
                                 std::vector<double>* out) {
  const SparseDef& s = *a.sparse;
  bool ok_i = false, ok_v = false;
  const std::span<const std::uint8_t> iv =
      viewBytes(static_cast<std::size_t>(s.indices_view), &ok_i);
  const std::span<const std::uint8_t> vv =
      viewBytes(static_cast<std::size_t>(s.values_view), &ok_v);
  if (!ok_i || !ok_v)
    return false;
  const std::uint32_t isize = componentBytes(s.indices_component);
  const std::uint32_t csize = componentBytes(a.component_type);
  std::uint64_t previous = 0;
  for (std::uint64_t k = 0; k < s.count; ++k) {
    const auto index = static_cast<std::uint64_t>(
        componentAt(iv.data() + s.indices_offset + k * isize, s.indices_component, false));
    if (index >= a.count || (k > 0 && index <= previous)) {
      p_->add(
          w, "sparse index " + std::to_string(index) + " (entry " + std::to_string(k) + ") " +
                 (index >= a.count ? "runs past the base (" + std::to_string(a.count) + " elements)"
                                   : "is not above the previous one (indices must increase)"));
      return false;
    }
    previous = index;
    for (std::uint32_t c = 0; c < a.components; ++c) {
      const std::uint8_t* p = vv.data() + s.values_offset + (k * a.components + c) * csize;
      (*out)[index * a.components + c] = componentAt(p, a.component_type, a.normalized);
    }
  }
  return true;
}

bool AccessorReader::components(std::size_t index,
                                const std::string& use,
                                std::vector<double>* out) {
  const AccessorDef& a = doc_.accessors[index];
  const auto count = static_cast<std::size_t>(a.count);
  out->assign(count * a.components, 0.0);  // no bufferView: zeros (glTF)
  if (a.view >= 0) {
    bool ok = false;
    const std::span<const std::uint8_t> bytes = viewBytes(static_cast<std::size_t>(a.view), &ok);
    if (!ok)
      return false;
    const std::uint64_t stride = a.strideBytes(doc_.views);
    const std::uint32_t size = componentBytes(a.component_type);
    if (a.byte_offset + (a.count - 1) * stride + a.elementBytes() > bytes.size()) {
      p_->add("accessor " + std::to_string(index), "data runs past the end of its bufferView");
      return false;
    }
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint8_t* element = bytes.data() + a.byte_offset + i * stride;
      for (std::uint32_t c = 0; c < a.components; ++c)
        (*out)[i * a.components + c] = componentAt(element + static_cast<std::size_t>(c) * size,
                                                   a.component_type, a.normalized);
    }
  }
  return !a.sparse || applySparse(a, "accessor " + std::to_string(index) + " " + use, out);
}

bool AccessorReader::readPositions(std::size_t index,
                                   const std::string& use,
                                   std::vector<Vec3>* out) {
  const AccessorDef& a = doc_.accessors[index];
  const std::string w = "accessor " + std::to_string(index);
  if (!positionTypeAllowed(a)) {
    p_->add(w, use +
                   " must be VEC3 of FLOAT, or (KHR_mesh_quantization) of BYTE, UNSIGNED_BYTE, "
                   "SHORT or UNSIGNED_SHORT, normalized or not; got " +
                   a.type + " of " + std::to_string(a.component_type) +
                   (a.normalized ? " normalized" : ""));
    return false;
  }
  if (a.count > limits_.max_hull_input_points) {
    p_->add(w, use + ": " + std::to_string(a.count) + " vertices exceeds max_hull_input_points (" +
                   std::to_string(limits_.max_hull_input_points) + ")");
    return false;
  }
  std::vector<double> v;
  if (!components(index, use, &v))
    return false;
  for (std::size_t i = 0; i < v.size() / 3; ++i) {
    const Vec3 p{v[3 * i], v[3 * i + 1], v[3 * i + 2]};
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      p_->add(w, use + ": vertex " + std::to_string(i) + " is not finite (NaN or Inf)");
      return false;
    }
    out->push_back(p);
  }
  return true;
}

bool AccessorReader::readIndices(std::size_t index,
                                 std::size_t vertex_count,
                                 const std::string& use,
                                 std::vector<std::uint32_t>* out) {
  const AccessorDef& a = doc_.accessors[index];
  const std::string w = "accessor " + std::to_string(index);
  if (a.type != "SCALAR" ||
      (a.component_type != kComponentUnsignedByte && a.component_type != kComponentUnsignedShort &&
       a.component_type != kComponentUnsignedInt) ||
      a.normalized) {
    p_->add(w, use + " indices must be SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    return false;
  }
  if (a.count > 6ull * limits_.max_hull_input_points) {
    p_->add(w, use + ": " + std::to_string(a.count) + " indices is too many for " +
                   "max_hull_input_points");
    return false;
  }
  std::vector<double> v;
  if (!components(index, use, &v))
    return false;
  out->reserve(out->size() + v.size());
  for (const double x : v) {
    if (x >= static_cast<double>(vertex_count)) {
      p_->add(w, use + ": index " + std::to_string(static_cast<std::uint64_t>(x)) +
                     " out of range (" + std::to_string(vertex_count) + " vertices)");
      return false;
    }
    out->push_back(static_cast<std::uint32_t>(x));
  }
  return true;
}

bool AccessorReader::readDraco(const MeshPrimitiveDef& prim,
                               const std::string& use,
                               std::vector<Vec3>* points,
                               std::vector<std::uint32_t>* triangles) {
  const DracoDef& draco = *prim.draco;
  const std::string w = use + " KHR_draco_mesh_compression";
  const AccessorDef& a = doc_.accessors[static_cast<std::size_t>(prim.position)];
  if (!positionTypeAllowed(a)) {
    p_->add(w, "POSITION must be VEC3 of FLOAT, BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT");
    return false;
  }
  bool ok = false;
  const std::span<const std::uint8_t> stream = viewBytes(static_cast<std::size_t>(draco.view), &ok);
  if (!ok)
    return false;
  // the counts the accessors declare bound what the stream may claim
  const std::uint64_t max_faces =
      prim.indices >= 0 ? doc_.accessors[static_cast<std::size_t>(prim.indices)].count / 3
                        : 16 * a.count;
  auto decoded = decodeDraco(stream, draco.position_id, prim.mode >= 4, a.count, max_faces);
  if (!decoded) {
    p_->add(w, decoded.error().message);
    return false;
  }
  const DracoGeometry& g = decoded.value();
  if (g.components != 3 || g.points != a.count || g.points > limits_.max_hull_input_points) {
    p_->add(w, "the stream has " + std::to_string(g.points) + " points of " +
                   std::to_string(g.components) + " components; the POSITION accessor says " +
                   std::to_string(a.count) + " VEC3 (at most max_hull_input_points " +
                   std::to_string(limits_.max_hull_input_points) + ")");
    return false;
  }
  for (std::size_t i = 0; i < g.points; ++i) {
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      const double v = g.values[3 * i + static_cast<std::size_t>(k)];
      p[k] = a.normalized ? normalizedInteger(v, a.component_type) : v;
    }
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      p_->add(w, "vertex " + std::to_string(i) + " is not finite (NaN or Inf)");
      return false;
    }
    points->push_back(p);
  }
  if (!triangles)
    return true;
  if (prim.indices >= 0 &&
      doc_.accessors[static_cast<std::size_t>(prim.indices)].count != g.triangles.size()) {
    p_->add(w, "the stream has " + std::to_string(g.triangles.size()) +
                   " indices; the indices accessor says " +
                   std::to_string(doc_.accessors[static_cast<std::size_t>(prim.indices)].count));
    return false;
  }
  for (const std::uint32_t v : g.triangles) {
    if (v >= g.points) {
      p_->add(w, "index " + std::to_string(v) + " out of range (" + std::to_string(g.points) +
                     " vertices)");
      return false;
    }
    triangles->push_back(v);
  }
  return true;
}

bool readPrimitivePoints(AccessorReader& reader,
                         const MeshPrimitiveDef& prim,
                         const std::string& use,
                         bool triangles,
                         std::vector<Vec3>* points,
                         PrimitiveReading* reading) {
  reading->first = points->size();
  reading->draco.clear();
  const bool read = prim.draco
                        ? reader.readDraco(prim, use, points, triangles ? &reading->draco : nullptr)
                        : reader.readPositions(static_cast<std::size_t>(prim.position),
                                               use + " POSITION", points);
  reading->count = points->size() - reading->first;
  return read;
}

bool readPrimitiveTriangles(AccessorReader& reader,
                            const MeshPrimitiveDef& prim,
                            const std::string& use,
                            const PrimitiveReading& reading,
                            std::optional<std::uint32_t> bad_index,
                            Problems* problems,
                            std::vector<std::uint32_t>* out) {
  std::vector<std::uint32_t> local;
  if (prim.draco) {
    local = reading.draco;
  } else if (prim.indices >= 0) {
    // with bad_index, every index is read and those past the vertices are marked afterwards
    const std::size_t bound = bad_index ? std::numeric_limits<std::size_t>::max() : reading.count;
    if (!reader.readIndices(static_cast<std::size_t>(prim.indices), bound, use, &local))
      return false;
    if (bad_index) {
      for (std::uint32_t& i : local)
        i = i < reading.count ? i : *bad_index;
    }
  } else {
    for (std::size_t v = 0; v < reading.count; ++v)
      local.push_back(static_cast<std::uint32_t>(v));
  }
  if (!triangulate(prim.mode, local, static_cast<std::uint32_t>(reading.first), bad_index, out)) {
    if (prim.indices >= 0 && !prim.draco) {
      problems->add("accessor " + std::to_string(prim.indices),
                    use + ": " + std::to_string(local.size()) +
                        " indices is not a whole number of triangles");
    } else {
      problems->add(use, "has " + std::to_string(reading.count) +
                             " vertices and no indices: not a whole number of triangles");
    }
    return false;
  }
  return true;
}

}  // namespace hapticd::scene::detail
