// readSceneTriangles: the loader's first two passes (document.h, accessors.h), then a walk of the
// scene's mesh nodes that reads each triangle primitive as the loader's colliders do.
#include "core/scene/triangles.h"

#include <algorithm>

#include "core/scene/accessors.h"
#include "core/scene/scene_file.h"

namespace hapticd::scene {
namespace {

TrianglesReport readImpl(std::span<const std::uint8_t> bytes, const TrianglesOptions& options) {
  detail::Problems problems;
  TrianglesReport report;
  const auto finish = [&]() {
    report.problems = problems.take();
    if (!report.problems.empty())
      report.triangles.reset();
    return std::move(report);
  };
  const LoadOptions& load = options.load;
  detail::Document doc;
  if (!detail::parseDocument(bytes, load, &doc, &problems))
    return finish();
  const auto data = detail::loadBuffers(doc, load, &problems);
  if (!data)
    return finish();
  detail::AccessorReader reader(doc, *data, load.limits, &problems);
  const std::optional<std::uint32_t> bad =
      options.keep_bad_indices ? std::optional<std::uint32_t>(kBadIndex) : std::nullopt;
  // every vertex index must stay below kBadIndex
  const std::uint64_t max_total =
      std::min<std::uint64_t>(load.limits.max_total_hull_input_points, kBadIndex - 1);
  SceneTriangles out;
  std::vector<std::uint32_t> flat;
  // the nodes' world transforms as the loader computes them (a non-finite one refused as there)
  const std::vector<glm::dmat4> worlds = detail::worldTransforms(doc, &problems);
  if (problems.any())
    return finish();
  // the scene's nodes, parents first, children in document order (validation refused cycles and
  // nodes with two parents, so each is reached once)
  std::vector<std::uint32_t> stack(doc.scene_roots.rbegin(), doc.scene_roots.rend());
  while (!stack.empty() && !problems.full()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    const detail::NodeDef& def = doc.nodes[node];
    const glm::dmat4& world = worlds[node];
    for (auto it = def.children.rbegin(); it != def.children.rend(); ++it)
      stack.push_back(*it);
    if (def.mesh < 0)
      continue;
    const auto mi = static_cast<std::size_t>(def.mesh);
    // a mirroring transform turns the winding round (glTF 2.0 §3.7.4)
    const bool mirrored = glm::determinant(Mat3(world)) < 0.0;
    for (std::size_t k = 0; k < doc.meshes[mi].primitives.size(); ++k) {
      const detail::MeshPrimitiveDef& prim = doc.meshes[mi].primitives[k];
      if (prim.mode < 4 || prim.mode > 6)
        continue;  // points and lines: no triangles
      const std::string use = detail::meshWhere(doc, mi) + " primitive " + std::to_string(k);
      if (prim.position < 0) {
        problems.add(use, "has no POSITION attribute");
        continue;
      }
      const std::uint64_t count = doc.accessors[static_cast<std::size_t>(prim.position)].count;
      if (out.positions.size() + count > max_total) {
        problems.add(detail::nodeWhere(doc, node),
                     "the scene's meshes have more than " + std::to_string(max_total) +
                         " vertices in all (max_total_hull_input_points)");
        return finish();
      }
      detail::PrimitiveReading reading;
      flat.clear();
      if (!detail::readPrimitivePoints(reader, prim, use, true, &out.positions, &reading) ||
          !detail::readPrimitiveTriangles(reader, prim, use, reading, bad, &problems, &flat))
        continue;
      for (std::size_t v = reading.first; v < out.positions.size(); ++v)
        out.positions[v] = Vec3(world * glm::dvec4(out.positions[v], 1.0));
      for (std::size_t t = 0; t + 2 < flat.size(); t += 3) {
        if (mirrored)
          out.triangles.push_back({flat[t], flat[t + 2], flat[t + 1]});
        else
          out.triangles.push_back({flat[t], flat[t + 1], flat[t + 2]});
      }
    }
  }
  report.triangles = std::move(out);
  return finish();
}

}  // namespace

std::string TrianglesReport::message() const {
  return detail::problemLines(problems);
}

TrianglesReport readSceneTriangles(std::span<const std::uint8_t> bytes,
                                   const TrianglesOptions& options) {
  try {
    return readImpl(bytes, options);
  } catch (const std::exception& e) {
    TrianglesReport report;
    report.problems.push_back(
        {"file", std::string("internal error while reading triangles: ") + e.what()});
    return report;
  }
}

TrianglesReport readSceneTrianglesFile(const std::filesystem::path& path,
                                       const TrianglesOptions& options) {
  auto file = detail::readSceneFile(path, options.load);
  if (!file) {
    TrianglesReport report;
    report.problems.push_back({"file", file.error().message});
    return report;
  }
  TrianglesOptions beside = options;
  beside.load = file.value().options;
  return readSceneTriangles(file.value().bytes, beside);
}

}  // namespace hapticd::scene
