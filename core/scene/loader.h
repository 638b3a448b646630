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
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/scene/scene.h"

namespace hapticd::scene {

/// How meshes that are not convex are made convex (core/scene/decompose.h, docs/scenes.md): a
/// TRIMESH collider, a mesh collider without `convexHull` and a plain model's mesh alike.
struct DecompositionOptions {
  /// Target concavity, a fraction of the mesh's bounding-box diagonal, in (0, 1).
  /// `extras.haptic.concavity` on the collider's node or an ancestor overrides it.
  double concavity = 0.01;
  /// At most this many pieces per mesh (>= 1; each a primitive, counted against max_primitives).
  std::uint32_t max_pieces = 64;
  /// Wall-clock limit of one mesh's decomposition, seconds (>= 0; 0: none): past it the best
  /// pieces so far are used and the notes say so.
  double time_limit_s = 5.0;
  /// Folder of the decomposition cache (core/scene/decomp_cache.h): a mesh decomposed once with
  /// the same options is read back instead. Empty: no cache. A folder that cannot be written is
  /// a warning, never a failure.
  std::filesystem::path cache_dir;
  /// Most bytes of entries the cache folder keeps (0: no limit). After an entry is written, the
  /// least recently used entries (their files' modification times: a read refreshes it) are
  /// removed until the entries fit, the new one kept whatever its size.
  std::uint64_t cache_max_bytes = std::uint64_t{512} << 20;
};

/// Where a load is, for a progress line ("decomposing mesh 3 (Bunny), 12 pieces, 1.4 s").
struct LoadProgress {
  std::size_t mesh = 0;   ///< 1-based: the how-manieth mesh this load decomposes
  std::string mesh_name;  ///< "mesh 2 'Bunny'"
  std::size_t pieces = 0;
  double elapsed_s = 0.0;  ///< of this mesh's decomposition
  const char* stage = "";  ///< core/decomp's stage: "repair", "cut", "merge", "finish"
};
/// Called on the loading thread, often (throttle yourself); must not throw.
using LoadProgressFn = std::function<void(const LoadProgress&)>;

struct LoadOptions {
  SceneLimits limits;
  DecompositionOptions decomposition;
  /// Told while meshes are decomposed (not for meshes read from the cache). Empty: none.
  LoadProgressFn progress;
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
/// What the load did with meshes that are not convex.
struct DecompositionCounts {
  std::size_t decomposed = 0;     ///< meshes decomposed by core/decomp in this load
  std::size_t cache_hits = 0;     ///< meshes whose pieces were read from the cache
  std::size_t cache_refused = 0;  ///< cache entries refused (corrupt, foreign, old): rebuilt
  std::size_t cache_written = 0;  ///< entries written
  std::size_t cache_evicted = 0;  ///< least recently used entries removed to keep the size limit
};

struct LoadReport {
  std::optional<SceneModel> scene;
  std::vector<Problem> problems;  ///< empty exactly when scene is set
  /// Not problems, each a sentence: a cache entry refused and rebuilt, a cache folder that
  /// cannot be written. The scene loads all the same.
  std::vector<std::string> warnings;
  DecompositionCounts decomposition;
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

/// The folder a cache setting names (config [scene] cache_dir, hapticctl check --cache-dir):
/// "auto" is $CACHE_DIRECTORY (systemd's CacheDirectory=, its first entry), else
/// $XDG_CACHE_HOME/hapticd, else $HOME/.cache/hapticd, else none (empty); "" is none (no cache);
/// anything else is itself. Reads the environment; any thread that does not set it.
std::filesystem::path decompositionCacheDir(const std::string& setting);

/// Reads and loads a file (size checked before reading). External URIs resolve inside the file's
/// own folder unless options.allowed_uri_dir names another, with the same guards.
LoadReport loadSceneFile(const std::filesystem::path& path, const LoadOptions& options = {});

}  // namespace hapticd::scene
