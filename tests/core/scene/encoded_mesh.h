#pragma once
/// \file
/// Meshes as exporters write them, for the loader's tests, the corpus generator, the fuzz seeds
/// and the load benchmark: positions quantized (KHR_mesh_quantization, every component type),
/// sparse accessors, Draco streams (libdraco's encoder) and meshopt-compressed bufferViews
/// (libmeshoptimizer's encoder) on a GltfBuilder. Header-only, test code.

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "tests/core/scene/gltf_builder.h"

namespace hapticd::scene::testing {

/// The largest value of an integer component type (127, 255, 32767, 65535).
inline double componentMax(std::uint32_t component) {
  switch (component) {
    case 5120:
      return 127.0;
    case 5121:
      return 255.0;
    case 5122:
      return 32767.0;
    default:
      return 65535.0;
  }
}

inline std::uint32_t componentSize(std::uint32_t component) {
  return component <= 5121 ? 1u : 2u;
}

/// A mesh with POSITION of integer `component` (BYTE 5120, UNSIGNED_BYTE 5121, SHORT 5122,
/// UNSIGNED_SHORT 5123): normalized, a coordinate v is stored as round(v * max) (v in [-1, 1],
/// or [0, 1] unsigned); not normalized, as round(v). Elements padded to 4 bytes (byteStride).
inline int addQuantizedMesh(GltfBuilder& b,
                            const Mesh& mesh,
                            std::uint32_t component,
                            bool normalized,
                            const std::string& name = "") {
  const std::uint32_t size = componentSize(component);
  const std::size_t stride = (3 * size + 3) / 4 * 4;
  std::vector<std::uint8_t> data(mesh.vertices.size() * stride, 0);
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double v = mesh.vertices[i][k] * (normalized ? componentMax(component) : 1.0);
      const auto q = static_cast<std::int32_t>(std::lround(v));
      std::memcpy(data.data() + i * stride + static_cast<std::size_t>(k) * size, &q, size);
    }
  }
  const int pv = b.addView(data.data(), data.size(), stride);
  json accessor = {{"bufferView", pv},
                   {"componentType", component},
                   {"count", mesh.vertices.size()},
                   {"type", "VEC3"}};
  if (normalized)
    accessor["normalized"] = true;
  const int pa = b.addAccessor(accessor);
  const int iv = b.addView(mesh.triangles.data(), mesh.triangles.size() * sizeof(std::uint32_t));
  const int ia = b.addAccessor({{"bufferView", iv},
                                {"componentType", 5125},
                                {"count", mesh.triangles.size()},
                                {"type", "SCALAR"}});
  json m = {{"primitives", json::array({{{"attributes", {{"POSITION", pa}}}, {"indices", ia}}})}};
  if (!name.empty())
    m["name"] = name;
  b.doc["meshes"].push_back(m);
  b.useExtension("KHR_mesh_quantization", true);
  return static_cast<int>(b.doc["meshes"].size()) - 1;
}

/// Float positions whose elements `indices` (increasing) are replaced by `values` through sparse
/// storage; `base` false: no bufferView (zeros) under the sparse values. Returns the accessor.
inline int addSparsePositions(GltfBuilder& b,
                              const std::vector<Vec3>& base_values,
                              bool base,
                              const std::vector<std::uint16_t>& indices,
                              const std::vector<Vec3>& values) {
  std::vector<float> floats;
  for (const Vec3& v : base_values)
    floats.insert(floats.end(), {float(v.x), float(v.y), float(v.z)});
  json accessor = {{"componentType", 5126}, {"count", base_values.size()}, {"type", "VEC3"}};
  if (base)
    accessor["bufferView"] = b.addView(floats.data(), floats.size() * sizeof(float));
  std::vector<float> sparse;
  for (const Vec3& v : values)
    sparse.insert(sparse.end(), {float(v.x), float(v.y), float(v.z)});
  accessor["sparse"] = {
      {"count", indices.size()},
      {"indices",
       {{"bufferView", b.addView(indices.data(), indices.size() * 2)}, {"componentType", 5123}}},
      {"values", {{"bufferView", b.addView(sparse.data(), sparse.size() * sizeof(float))}}}};
  return b.addAccessor(accessor);
}

/// A triangle mesh as a KHR_draco_mesh_compression primitive (positions quantized to `bits` by
/// the Draco encoder); the accessors carry the decoded counts and no bufferView.
inline int addDracoMesh(GltfBuilder& b, const Mesh& mesh, const std::string& name, int bits = 16) {
  draco::Mesh dm;
  dm.set_num_points(static_cast<std::uint32_t>(mesh.vertices.size()));
  draco::GeometryAttribute ga;
  ga.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false,
          sizeof(float) * 3, 0);
  const int att = dm.AddAttribute(ga, true, static_cast<std::uint32_t>(mesh.vertices.size()));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const float v[3] = {float(mesh.vertices[i].x), float(mesh.vertices[i].y),
                        float(mesh.vertices[i].z)};
    dm.attribute(att)->SetAttributeValue(draco::AttributeValueIndex(static_cast<std::uint32_t>(i)),
                                         v);
  }
  for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
    dm.AddFace({draco::PointIndex(mesh.triangles[t]), draco::PointIndex(mesh.triangles[t + 1]),
                draco::PointIndex(mesh.triangles[t + 2])});
  }
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  draco::EncoderBuffer out;
  if (!encoder.EncodeMeshToBuffer(dm, &out).ok())
    throw std::runtime_error("draco encoder failed");
  // the decoded counts (the encoder may reorder and merge points)
  draco::DecoderBuffer in;
  in.Init(out.data(), out.size());
  auto decoded = draco::Decoder().DecodeMeshFromBuffer(&in);
  if (!decoded.ok())
    throw std::runtime_error("draco round trip failed");
  const int view = b.addView(out.data(), out.size());
  const std::uint32_t points = decoded.value()->num_points();
  const std::uint32_t indices = decoded.value()->num_faces() * 3;
  const int pa = b.addAccessor({{"componentType", 5126}, {"count", points}, {"type", "VEC3"}});
  const int ia = b.addAccessor({{"componentType", 5125}, {"count", indices}, {"type", "SCALAR"}});
  json draco_ext = {{"bufferView", view},
                    {"attributes", {{"POSITION", dm.attribute(att)->unique_id()}}}};
  json prim = {{"attributes", {{"POSITION", pa}}}, {"indices", ia}};
  prim["extensions"]["KHR_draco_mesh_compression"] = draco_ext;
  b.doc["meshes"].push_back({{"name", name}, {"primitives", json::array({prim})}});
  b.useExtension("KHR_draco_mesh_compression", true);
  return static_cast<int>(b.doc["meshes"].size()) - 1;
}

/// A meshopt-compressed bufferView of `count` elements of `stride` bytes (mode "ATTRIBUTES",
/// "TRIANGLES" or "INDICES"; filter "NONE" or "EXPONENTIAL", whose input is floats), whose
/// uncompressed place is in the fallback buffer 1 (made on first use).
inline int addMeshoptView(GltfBuilder& b,
                          const void* data,
                          std::size_t count,
                          std::size_t stride,
                          const std::string& mode,
                          const std::string& filter = "NONE") {
  std::vector<std::uint8_t> raw(static_cast<const std::uint8_t*>(data),
                                static_cast<const std::uint8_t*>(data) + count * stride);
  if (filter == "EXPONENTIAL") {
    std::vector<std::uint8_t> filtered(raw.size());
    meshopt_encodeFilterExp(filtered.data(), count, stride, 23,
                            reinterpret_cast<const float*>(raw.data()));
    raw = filtered;
  }
  std::vector<std::uint8_t> encoded;
  if (mode == "ATTRIBUTES") {
    encoded.resize(meshopt_encodeVertexBufferBound(count, stride));
    encoded.resize(
        meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), raw.data(), count, stride));
  } else {
    std::vector<unsigned int> indices(count);
    for (std::size_t i = 0; i < count; ++i) {
      std::uint32_t v = 0;
      std::memcpy(&v, raw.data() + i * stride, stride);
      indices[i] = v;
    }
    encoded.resize(meshopt_encodeIndexBufferBound(count, count));
    encoded.resize(
        mode == "TRIANGLES"
            ? meshopt_encodeIndexBuffer(encoded.data(), encoded.size(), indices.data(), count)
            : meshopt_encodeIndexSequence(encoded.data(), encoded.size(), indices.data(), count));
  }
  if (b.more_buffers.empty())
    b.more_buffers.push_back(
        {{"byteLength", 0}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
  json& fallback = b.more_buffers[0];
  const std::size_t at = (fallback["byteLength"].get<std::size_t>() + 3) / 4 * 4;
  fallback["byteLength"] = at + raw.size();
  const int compressed = b.addView(encoded.data(), encoded.size());
  json& view = b.doc["bufferViews"][static_cast<std::size_t>(compressed)];
  const json ext = {{"buffer", 0},
                    {"byteOffset", view["byteOffset"]},
                    {"byteLength", encoded.size()},
                    {"byteStride", stride},
                    {"count", count},
                    {"mode", mode},
                    {"filter", filter}};
  view = {{"buffer", 1},
          {"byteOffset", at},
          {"byteLength", raw.size()},
          {"extensions", {{"EXT_meshopt_compression", ext}}}};
  if (mode == "ATTRIBUTES")
    view["byteStride"] = stride;
  b.useExtension("EXT_meshopt_compression", true);
  return compressed;
}

/// A triangle mesh whose positions (float, optionally EXPONENTIAL-filtered) and uint32 indices
/// are meshopt-compressed.
inline int addMeshoptMesh(GltfBuilder& b,
                          const Mesh& mesh,
                          const std::string& name,
                          const std::string& filter = "NONE",
                          const std::string& index_mode = "TRIANGLES") {
  std::vector<float> pos;
  for (const Vec3& v : mesh.vertices)
    pos.insert(pos.end(), {float(v.x), float(v.y), float(v.z)});
  const int pv = addMeshoptView(b, pos.data(), mesh.vertices.size(), 12, "ATTRIBUTES", filter);
  const int pa = b.addAccessor({{"bufferView", pv},
                                {"componentType", 5126},
                                {"count", mesh.vertices.size()},
                                {"type", "VEC3"}});
  const int iv = addMeshoptView(b, mesh.triangles.data(), mesh.triangles.size(), 4, index_mode);
  const int ia = b.addAccessor({{"bufferView", iv},
                                {"componentType", 5125},
                                {"count", mesh.triangles.size()},
                                {"type", "SCALAR"}});
  b.doc["meshes"].push_back(
      {{"name", name},
       {"primitives", json::array({{{"attributes", {{"POSITION", pa}}}, {"indices", ia}}})}});
  return static_cast<int>(b.doc["meshes"].size()) - 1;
}

}  // namespace hapticd::scene::testing
