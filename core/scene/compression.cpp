#include "core/scene/compression.h"

#include <draco/compression/decode.h>
#include <meshoptimizer.h>

namespace hapticd::scene::detail {

Result<DracoGeometry> decodeDraco(std::span<const std::uint8_t> stream,
                                  std::uint32_t attribute_id,
                                  bool mesh) {
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
