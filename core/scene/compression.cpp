#include "core/scene/compression.h"

#include <draco/compression/decode.h>
#include <meshoptimizer.h>

#include <cstring>
#include <utility>

namespace hapticd::scene::detail {
namespace {

/// Reads the Draco bitstream's header and the vertex and face counts it claims (the layout of the
/// Draco 1.x/2.x bitstream: "DRACO", version, encoder type, method, flags; then a point cloud's
/// int32 count, a sequential mesh's face and point counts, or an edgebreaker mesh's traversal
/// type, new vertices (before 2.2), encoded vertices and faces; uint32 before 2.0 (2.2 for the
/// sequential mesh), LEB128 varints after).
class DracoHeader {
 public:
  explicit DracoHeader(std::span<const std::uint8_t> s) : s_(s) {}

  Result<std::pair<std::uint64_t, std::uint64_t>> claims() {
    if (s_.size() < 11 || std::memcmp(s_.data(), "DRACO", 5) != 0)
      return Error{"Draco: not a Draco stream (no 'DRACO' header)"};
    const unsigned version = 256u * s_[5] + s_[6];
    const std::uint8_t type = s_[7], method = s_[8];
    const unsigned flags = s_[9] | (unsigned{s_[10]} << 8);
    at_ = 11;
    if (version >= 0x0103 && (flags & 0x8000) != 0)
      return Error{"Draco: streams with metadata are not read"};
    std::uint64_t points = 0, faces = 0;
    bool ok = true;
    if (type == 0) {
      ok = u32(&points);
    } else if (method == 0) {
      ok = version < 0x0202 ? u32(&faces) && u32(&points) : varint(&faces) && varint(&points);
    } else {
      std::uint64_t added = 0, traversal = 0;
      ok = byte(&traversal) && (version >= 0x0202 || count(version, &added)) &&
           count(version, &points) && count(version, &faces);
      points += added;
    }
    if (!ok)
      return Error{"Draco: the stream ends inside its header"};
    return std::pair{points, faces};
  }

 private:
  bool byte(std::uint64_t* v) {
    if (at_ >= s_.size())
      return false;
    *v = s_[at_++];
    return true;
  }
  bool u32(std::uint64_t* v) {
    if (at_ + 4 > s_.size())
      return false;
    *v = std::uint64_t{s_[at_]} | (std::uint64_t{s_[at_ + 1]} << 8) |
         (std::uint64_t{s_[at_ + 2]} << 16) | (std::uint64_t{s_[at_ + 3]} << 24);
    at_ += 4;
    return true;
  }
  bool varint(std::uint64_t* v) {
    *v = 0;
    for (int shift = 0; shift < 35; shift += 7) {
      std::uint64_t b = 0;
      if (!byte(&b))
        return false;
      *v |= (b & 0x7F) << shift;
      if ((b & 0x80) == 0)
        return true;
    }
    return false;
  }
  bool count(unsigned version, std::uint64_t* v) { return version < 0x0200 ? u32(v) : varint(v); }

  std::span<const std::uint8_t> s_;
  std::size_t at_ = 0;
};

}  // namespace

Result<DracoGeometry> decodeDraco(std::span<const std::uint8_t> stream,
                                  std::uint32_t attribute_id,
                                  bool mesh,
                                  std::uint64_t max_points,
                                  std::uint64_t max_faces) {
  auto claims = DracoHeader(stream).claims();
  if (!claims)
    return claims.error();
  const auto [claimed_points, claimed_faces] = claims.value();
  if (claimed_points > max_points || claimed_faces > max_faces) {
    return Error{"Draco: the stream claims " + std::to_string(claimed_points) + " vertices and " +
                 std::to_string(claimed_faces) + " triangles, more than the accessors allow (" +
                 std::to_string(max_points) + " and " + std::to_string(max_faces) + ")"};
  }
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(stream.data()), stream.size());
  draco::Decoder decoder;
  std::unique_ptr<draco::PointCloud> cloud;
  const draco::Mesh* as_mesh = nullptr;
  if (mesh) {
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok())
      return Error{"Draco: " + decoded.status().error_msg_string()};
    as_mesh = decoded.value().get();
    cloud = std::move(decoded).value();
  } else {
    auto decoded = decoder.DecodePointCloudFromBuffer(&buffer);
    if (!decoded.ok())
      return Error{"Draco: " + decoded.status().error_msg_string()};
    cloud = std::move(decoded).value();
  }
  const draco::PointAttribute* attribute = cloud->GetAttributeByUniqueId(attribute_id);
  if (!attribute)
    return Error{"Draco: the stream has no attribute with id " + std::to_string(attribute_id)};
  // numbers only: a BOOL (or invalid) attribute does not convert safely
  if (attribute->data_type() <= draco::DT_INVALID || attribute->data_type() >= draco::DT_BOOL)
    return Error{"Draco: attribute " + std::to_string(attribute_id) + " is not numeric"};
  DracoGeometry out;
  out.points = cloud->num_points();
  out.components = attribute->num_components();
  if (out.components == 0 || out.components > 4)
    return Error{"Draco: attribute " + std::to_string(attribute_id) + " has " +
                 std::to_string(out.components) + " components"};
  out.values.resize(static_cast<std::size_t>(out.points) * out.components);
  for (draco::PointIndex i(0); i < cloud->num_points(); ++i) {
    double* v = out.values.data() + static_cast<std::size_t>(i.value()) * out.components;
    if (!attribute->ConvertValue<double>(attribute->mapped_index(i),
                                         static_cast<std::int8_t>(out.components), v)) {
      return Error{"Draco: attribute " + std::to_string(attribute_id) + " value " +
                   std::to_string(i.value()) + " does not convert"};
    }
  }
  if (as_mesh) {
    out.triangles.reserve(static_cast<std::size_t>(as_mesh->num_faces()) * 3);
    for (draco::FaceIndex f(0); f < as_mesh->num_faces(); ++f) {
      for (const draco::PointIndex& v : as_mesh->face(f))
        out.triangles.push_back(v.value());
    }
  }
  return out;
}

Result<std::vector<std::uint8_t>> decodeMeshopt(std::span<const std::uint8_t> stream,
                                                const MeshoptView& view) {
  const auto count = static_cast<std::size_t>(view.count);
  const auto stride = static_cast<std::size_t>(view.stride);
  std::vector<std::uint8_t> out(count * stride);
  int rc = 0;
  switch (view.mode) {
    case MeshoptView::Mode::kAttributes:
      rc = meshopt_decodeVertexBuffer(out.data(), count, stride, stream.data(), stream.size());
      break;
    case MeshoptView::Mode::kTriangles:
      rc = meshopt_decodeIndexBuffer(out.data(), count, stride, stream.data(), stream.size());
      break;
    case MeshoptView::Mode::kIndices:
      rc = meshopt_decodeIndexSequence(out.data(), count, stride, stream.data(), stream.size());
      break;
  }
  if (rc != 0) {
    return Error{"meshopt: the " +
                 std::string(view.mode == MeshoptView::Mode::kAttributes  ? "attribute"
                             : view.mode == MeshoptView::Mode::kTriangles ? "triangle"
                                                                          : "index") +
                 " codec refused the stream (error " + std::to_string(rc) +
                 "; a newer codec version than libmeshoptimizer reads, or corrupt data)"};
  }
  switch (view.filter) {
    case MeshoptView::Filter::kNone:
      break;
    case MeshoptView::Filter::kOctahedral:
      meshopt_decodeFilterOct(out.data(), count, stride);
      break;
    case MeshoptView::Filter::kQuaternion:
      meshopt_decodeFilterQuat(out.data(), count, stride);
      break;
    case MeshoptView::Filter::kExponential:
      meshopt_decodeFilterExp(out.data(), count, stride);
      break;
  }
  return out;
}

}  // namespace hapticd::scene::detail
