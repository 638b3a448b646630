#pragma once
/// \file
/// glTF 2.0 scenes (.glb, or .gltf with its data; KHR_physics_rigid_bodies and KHR_implicit_shapes,
/// Godot's OMI_physics_body / OMI_physics_shape / OMI_collider, or a plain model whose meshes
/// become static geometry; quantized, sparse, Draco and meshopt geometry) to a SceneModel, in three
/// passes, each run only when the earlier ones found nothing: the document (the container split,
/// the JSON parsed once and validated in one walk: core/scene/document.h), the buffers and
/// accessors (accessors.h), then bodies, primitives (hulls), materials, filters, joints and the
/// plan (builder.h). Any thread but the servo thread (allocates, builds hulls).
///
/// This header is the contract between the loader, the daemon, the protocol's scene upload and
/// hapticctl: functions may be added, none renamed or removed.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/scene/scene.h"

namespace hapticd::scene {

struct LoadOptions {
  SceneLimits limits;
  /// The base folder of external buffer URIs (images are never read): a URI is a relative path
  /// inside it (no scheme, not absolute, no `..`, no symbolic link out of it). Unset: external
  /// URIs are refused, which is what bytes from elsewhere (an upload) must use.
  std::optional<std::filesystem::path> allowed_uri_dir;
};

/// One problem found in a scene: what is wrong and where (node or accessor index and name).
struct Problem {
  std::string where;  ///< e.g. "node 3 'Peg'", "accessor 7", "file"
  std::string what;   ///< e.g. "index 12 out of range (4 nodes)"
};

/// Everything the loader found: the model when there is no problem.
struct LoadReport {
  std::optional<SceneModel> scene;
  std::vector<Problem> problems;  ///< empty exactly when scene is set
  bool ok() const { return scene.has_value(); }
  /// All problems, one line each: "where: what".
  std::string message() const;
};

/// Loads from bytes already in memory (a file's contents, an upload): no file is written or read
/// but the external URIs `options.allowed_uri_dir` lets through. `name` names the scene in messages
/// and SceneModel::name. Never throws, never crashes, never hangs on any input.
LoadReport loadScene(std::span<const std::uint8_t> bytes,
                     const std::string& name,
                     const LoadOptions& options = {});

/// Reads and loads a file (size checked before reading). External URIs resolve inside the file's
/// own folder unless options.allowed_uri_dir names another, with the same guards.
LoadReport loadSceneFile(const std::filesystem::path& path, const LoadOptions& options = {});

}  // namespace hapticd::scene
