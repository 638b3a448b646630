#pragma once
/// \file
/// The scene loader's URIs (internal to hapticd_scene, also used by the scene bundler): `data:`
/// URIs decoded, external URIs resolved under the folder policy of LoadOptions::allowed_uri_dir
/// (a relative path, percent-decoded, no scheme, not absolute, no `..`, a regular file whose
/// canonical path, symbolic links resolved, is inside the folder) and read with a size limit.
/// Any thread but the servo thread (file I/O).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/scene/loader.h"

namespace hapticd::scene::detail {

/// True for a `data:` URI.
bool isDataUri(const std::string& uri);

/// The bytes of a base64 `data:` URI (`data:[<media type>][;base64],<data>`); an error for a URI
/// that is not base64 or whose data does not decode.
Result<std::vector<std::uint8_t>> decodeDataUri(const std::string& uri);

/// Percent-decodes an external URI and checks it against the folder policy; the file's canonical
/// path, or nullopt with the reason in `why` (e.g. "external URI '../x.bin' traverses out of the
/// allowed folder ('..')").
std::optional<std::string> resolveUri(const std::string& uri,
                                      const LoadOptions& options,
                                      std::string* why);

/// Reads a whole file of at most `max_bytes` (checked before reading).
Result<std::vector<std::uint8_t>> readFileLimited(const std::string& path, std::uint64_t max_bytes);

}  // namespace hapticd::scene::detail
