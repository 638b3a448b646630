#pragma once
/// \file
/// What loadSceneFile and readSceneTrianglesFile share (internal to core/scene): the problems as
/// lines, and a scene file read with its external URIs resolved beside it.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/scene/loader.h"

namespace hapticd::scene::detail {

/// All problems, one line each: "where: what".
std::string problemLines(std::span<const Problem> problems);

/// A scene file's bytes (its size checked against options.limits.max_file_bytes before reading)
/// and the options to load them with: external URIs resolve inside the file's own folder unless
/// options.allowed_uri_dir names another.
struct SceneFile {
  std::vector<std::uint8_t> bytes;
  LoadOptions options;
};
Result<SceneFile> readSceneFile(const std::filesystem::path& path, const LoadOptions& options);

}  // namespace hapticd::scene::detail
