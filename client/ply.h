#pragma once
/// \file
/// The Stanford PLY reader of `hapticctl import` (written here: Debian's assimp 5.2 reads a
/// triangle-strip PLY as one triangle and dies on some valid binary files). ASCII, binary
/// little- and big-endian; `vertex` x, y, z of any scalar type; `face` polygons (a
/// `vertex_indices` or `vertex_index` list) into triangles (client/polygon.h: fanned, or
/// ear-clipped where a fan would fold); `tristrips` (a `vertex_indices`
/// list, -1 restarting the strip, alternate triangles turned to keep the winding, the strips'
/// joining triangles with a repeated vertex left out); every other element and property skipped
/// by its type. An index outside the vertices is kept as it is (the decomposition's repair drops
/// and counts such triangles). docs/decomposition.md.

#include <string>
#include <string_view>

#include "core/common/result.h"
#include "core/decomp/decompose.h"

namespace hapticd::client {

/// The triangles of the PLY file at `path`. Errors name the file and say what is wrong and where
/// (the header's line, or the element and its instance).
Result<decomp::TriangleMesh> readPly(const std::string& path);

/// The same from the file's bytes (`name` only for the messages).
Result<decomp::TriangleMesh> parsePly(std::string_view bytes, const std::string& name);

}  // namespace hapticd::client
