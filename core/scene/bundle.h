#pragma once
/// \file
/// A scene and the external files its buffers name, bundled into one GLB: what `hapticctl load`
/// sends, so that the daemon never resolves a client's relative path against its own folders.
/// Any thread but the servo thread (file I/O, allocates).

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "core/common/result.h"
#include "core/scene/loader.h"

namespace hapticd::scene {

/// The scene `bytes` (a .glb or a .gltf) with every external buffer read in: external URIs are
/// resolved with the loader's folder policy (LoadOptions::allowed_uri_dir: relative, no `..`, no
/// scheme, no symbolic link out, max_file_bytes), the buffers' bytes become the GLB's BIN chunk
/// (bufferViews and meshopt references renumbered), external images become empty data URIs (the
/// daemon never reads images). Bytes with no external URI, and bytes that are not glTF the
/// bundler can parse, come back unchanged (the daemon's loader then says what is wrong). An error
/// names the buffer and why its file cannot be read ("buffer 0: external URI 'x.bin': no such
/// file in the allowed folder").
Result<std::vector<std::uint8_t>> bundleScene(std::span<const std::uint8_t> bytes,
                                              const LoadOptions& options);

/// bundleScene() of a file, its external URIs resolved in the file's own folder (or in
/// options.allowed_uri_dir when that is set).
Result<std::vector<std::uint8_t>> bundleSceneFile(const std::filesystem::path& path,
                                                  const LoadOptions& options = {});

}  // namespace hapticd::scene
