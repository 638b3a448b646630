#pragma once
/// \file
/// The triangles of a glTF file in world coordinates, read by the scene loader's own passes (the
/// document and its validation, the buffers, the accessors: quantized, sparse, Draco and meshopt
/// geometry alike), for tools that want a model's surface rather than a scene (`hapticctl
/// import`). Any thread but the servo thread.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/scene/loader.h"

namespace hapticd::scene {

/// An index of SceneTriangles that names no vertex (TrianglesOptions::keep_bad_indices).
inline constexpr std::uint32_t kBadIndex = 0xFFFFFFFFu;

struct SceneTriangles {
  std::vector<Vec3> positions;  ///< world coordinates, in the file's units
  /// Three indices into positions each, wound counter-clockwise seen from the front in world
  /// coordinates (a node whose transform mirrors has its primitives' winding reversed, as glTF
  /// says).
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

struct TrianglesOptions {
  /// The limits (max_file_bytes, max_nodes; max_hull_input_points bounds one primitive's vertices,
  /// max_total_hull_input_points all of them) and the folder of external buffers, as for a load.
  LoadOptions load;
  /// An index past its primitive's vertices becomes kBadIndex (for a caller that repairs such
  /// triangles) rather than a problem.
  bool keep_bad_indices = false;
};

struct TrianglesReport {
  std::optional<SceneTriangles> triangles;
  std::vector<Problem> problems;  ///< the loader's words; empty exactly when triangles is set
  bool ok() const { return triangles.has_value(); }
  /// All problems, one line each: "where: what".
  std::string message() const;
};

/// The triangles of every mesh node of the scene the loader loads (`scene`, else scene 0, else
/// every root node), each TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN primitive (POINTS and LINES
/// have none), placed by the node's world transform. A file the loader refuses in its first two
/// passes (JSON, validation including node cycles and two parents, buffers) is refused with the
/// same problems; a primitive is read with the loader's checks (POSITION type, finite values,
/// indices in range, whole triangles). Never throws.
TrianglesReport readSceneTriangles(std::span<const std::uint8_t> bytes,
                                   const TrianglesOptions& options = {});

/// Reads the file (size checked first) and its triangles; external buffer URIs resolve inside the
/// file's folder unless options.load.allowed_uri_dir names another, as loadSceneFile does.
TrianglesReport readSceneTrianglesFile(const std::filesystem::path& path,
                                       const TrianglesOptions& options = {});

}  // namespace hapticd::scene
