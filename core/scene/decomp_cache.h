#pragma once
/// \file
/// The decomposition cache (internal to hapticd_scene; docs/scenes.md, "Decomposition cache"): the
/// convex pieces of a mesh, kept in a folder under a key that hashes the mesh's bytes and every
/// option that changes the pieces, so that loading the same scene again does not decompose again.
///
/// An entry is one file `<key>.pieces`, little-endian:
///
///     magic "HDPIECES" | u32 format version | key (64 hex digits) | u64 payload bytes |
///     SHA-256 of the payload (64 hex digits) | payload
///     payload: u32 note bytes, note | u32 pieces | per piece: u32 vertices, 3 x f64 each
///
/// Nothing in an entry is trusted: a wrong magic, version or key, a length that is not the file's,
/// a checksum that does not match, a piece count over the load's max_pieces, a piece of fewer
/// than 4 or over kMaxCachedPieceVertices vertices, or a coordinate that is not finite refuses the
/// entry (the caller decomposes again and writes a fresh one). Entries are written to a temporary
/// file beside the final one and renamed over it, so a reader never sees half an entry.
///
/// Any thread but the servo thread (file I/O, allocates); two loads may share a folder.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/decomp/decompose.h"

namespace hapticd::scene::detail {

/// Version of the entry format; an entry of another version is refused and rebuilt.
inline constexpr std::uint32_t kDecompCacheVersion = 1;
/// Vertices of one cached piece at most (core/decomp keeps 512 by default).
inline constexpr std::uint32_t kMaxCachedPieceVertices = 1u << 16;

/// The pieces of one mesh as cached: each a point set whose convex hull is the piece, and the
/// note the loader prints about how they were made.
struct CachedPieces {
  std::vector<std::vector<geom::Vec3>> pieces;
  std::string note;
};

/// The cache key (64 hex digits) of `mesh` decomposed with `options` by a loader whose hull limit
/// is `max_hull_vertices`: SHA-256 over the entry format version, core/decomp's contentHash (the
/// mesh's bytes and the options that change the pieces, with its algorithm's version), the time
/// limit (a limit that cut a decomposition short gives other pieces) and the hull limit (it
/// decides whether a convex mesh is decomposed at all). Any thread.
std::string decompCacheKey(const decomp::TriangleMesh& mesh,
                           const decomp::DecompOptions& options,
                           std::uint64_t max_hull_vertices);

/// What a lookup found.
struct CacheLookup {
  enum class Status {
    kMiss,     ///< no entry
    kHit,      ///< `pieces` holds it
    kRefused,  ///< an entry was there and was refused; `why` says why
  };
  Status status = Status::kMiss;
  CachedPieces pieces;
  std::string why;
};

/// The entry of `key` in `dir`, checked as the file comment says (at most `max_pieces` pieces).
/// A hit sets the entry's modification time to now (its use, for evictCache; a folder that
/// cannot be written still reads).
CacheLookup readCacheEntry(const std::filesystem::path& dir,
                           const std::string& key,
                           std::size_t max_pieces);

/// Writes the entry of `key` (the folder is created when missing). Error: why it could not be
/// written (the folder cannot be made or written); nothing is left behind but a stale temporary
/// file in the worst case.
Result<bool> writeCacheEntry(const std::filesystem::path& dir,
                             const std::string& key,
                             const CachedPieces& pieces);

/// What evictCache removed.
struct Eviction {
  std::size_t entries = 0;  ///< `.pieces` entries removed
  std::uint64_t bytes = 0;  ///< their bytes
  std::size_t stale = 0;    ///< temporary files of writers that died, removed
};

/// Keeps the entries in `dir` within `max_bytes` (0: no limit): while their sizes add up to
/// more, removes the least recently used entry (the oldest modification time; readCacheEntry
/// refreshes it on a hit; ties by name), never `keep_key`'s. Also removes temporary files of
/// writers older than `stale_after`. Files that are not entries or temporary files are never
/// touched; a file that cannot be removed is skipped (another process may hold the folder).
Eviction evictCache(const std::filesystem::path& dir,
                    std::uint64_t max_bytes,
                    const std::string& keep_key,
                    std::chrono::seconds stale_after = std::chrono::hours(1));

/// The file of `key` in `dir`.
std::filesystem::path cacheEntryPath(const std::filesystem::path& dir, const std::string& key);

}  // namespace hapticd::scene::detail
