#pragma once
// Test-side reading of the demo GLBs, independent of the generator: the chunks, index checks of
// every reference, mesh data, node transforms in the scene frame. Used by demo_scenes_test and
// round_trip_test.

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace hapticd::scenes::testing {

using Json = nlohmann::json;
using Vec3 = glm::dvec3;
using Quat = glm::dquat;

std::vector<std::uint8_t> readFile(const std::string& path);

struct Glb {
  Json json;
  std::vector<std::uint8_t> bin;
};
/// Splits a GLB into its JSON and BIN chunks; a problem is appended for every header or chunk
/// field that is wrong (magic, version, total length, chunk types, lengths, padding).
std::optional<Glb> splitGlb(const std::vector<std::uint8_t>& bytes,
                            std::vector<std::string>& problems);

/// Every index in the document in range, every accessor inside its view, every view inside the
/// buffer, every vertex index below the vertex count, POSITION min/max equal to the data, each
/// node with at most one parent and no cycle, the physics extensions' references in range.
std::vector<std::string> checkReferences(const Glb& glb);

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};
Mesh readMesh(const Glb& glb, int mesh_index);

/// Closed (every edge in exactly two triangles, opposite ways) and convex with outward triangles
/// (every vertex on or behind every triangle's plane, within 1e-6 of the mesh size).
std::vector<std::string> checkClosedConvex(const Mesh& mesh);

struct Rigid {
  Quat q{1.0, 0.0, 0.0, 0.0};
  Vec3 t{0.0};
  Vec3 apply(const Vec3& p) const { return q * p + t; }
  Rigid operator*(const Rigid& o) const { return {q * o.q, q * o.t + t}; }
};
/// The node's local transform (translation and rotation; the demo scenes use no scale).
Rigid localTransform(const Json& node);
/// The node's transform in the scene frame (parents composed).
Rigid worldTransform(const Glb& glb, int node);
/// Parent of every node, -1 for roots and unreferenced nodes.
std::vector<int> parents(const Glb& glb);

/// The node's KHR_physics_rigid_bodies object, or null.
const Json* physicsOf(const Json& node);
/// Index of the node named `name`, -1 if none.
int nodeNamed(const Glb& glb, const std::string& name);
/// Collider nodes at or under `node` (including itself).
std::vector<int> collidersUnder(const Glb& glb, int node);

}  // namespace hapticd::scenes::testing
