#include "core/scene/decomp_cache.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string_view>
#include <system_error>
#include <tuple>
#include <vector>

#include "core/decomp/sha256.h"

namespace hapticd::scene::detail {
namespace {

constexpr char kMagic[8] = {'H', 'D', 'P', 'I', 'E', 'C', 'E', 'S'};
constexpr std::size_t kHexBytes = 64;
// an entry's file is <key><kEntrySuffix>; a writer's temporary file
// <key><kEntrySuffix><kTmpMark>...
constexpr std::string_view kEntrySuffix = ".pieces";
constexpr std::string_view kTmpMark = ".tmp.";
// magic, version, key, payload length, checksum
constexpr std::size_t kHeaderBytes = sizeof kMagic + 4 + kHexBytes + 8 + kHexBytes;
// an entry larger than this is not one of ours (64 pieces x 64 Ki vertices x 24 bytes is 96 MiB)
constexpr std::uint64_t kMaxPayloadBytes = 128ull << 20;
constexpr std::uint32_t kMaxNoteBytes = 4096;

static_assert(std::endian::native == std::endian::little,
              "the cache's entries are little-endian; add byte swaps for this machine");

void putU32(std::string& out, std::uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out.append(b, 4);
}
void putU64(std::string& out, std::uint64_t v) {
  char b[8];
  std::memcpy(b, &v, 8);
  out.append(b, 8);
}
void putF64(std::string& out, double v) {
  char b[8];
  std::memcpy(b, &v, 8);
  out.append(b, 8);
}

std::string sha256Hex(const std::string& bytes) {
  decomp::Sha256 h;
  h.update(bytes.data(), bytes.size());
  return h.hexDigest();
}

// reads from a byte range with bounds checks: every get fails once past the end
class Reader {
 public:
  Reader(const char* p, std::size_t n) : p_(p), n_(n) {}
  bool u32(std::uint32_t* v) { return get(v, 4); }
  bool u64(std::uint64_t* v) { return get(v, 8); }
  bool f64(double* v) { return get(v, 8); }
  bool bytes(std::string* s, std::size_t n) {
    if (n > n_ - at_)
      return false;
    s->assign(p_ + at_, n);
    at_ += n;
    return true;
  }
  std::size_t left() const { return n_ - at_; }

 private:
  bool get(void* v, std::size_t n) {
    if (n > n_ - at_)
      return false;
    std::memcpy(v, p_ + at_, n);
    at_ += n;
    return true;
  }
  const char* p_;
  std::size_t n_;
  std::size_t at_ = 0;
};

CacheLookup refused(std::string why) {
  CacheLookup r;
  r.status = CacheLookup::Status::kRefused;
  r.why = std::move(why);
  return r;
}

// the payload's pieces, or why not
std::optional<std::string> parsePayload(const std::string& payload,
                                        std::size_t max_pieces,
                                        CachedPieces* out) {
  Reader r(payload.data(), payload.size());
  std::uint32_t note_bytes = 0, count = 0;
  if (!r.u32(&note_bytes) || note_bytes > kMaxNoteBytes || !r.bytes(&out->note, note_bytes))
    return "bad note";
  if (!r.u32(&count))
    return "truncated";
  if (count == 0 || count > max_pieces)
    return std::to_string(count) + " pieces, not 1.." + std::to_string(max_pieces);
  out->pieces.resize(count);
  for (auto& piece : out->pieces) {
    std::uint32_t n = 0;
    if (!r.u32(&n))
      return "truncated";
    if (n < 4 || n > kMaxCachedPieceVertices)
      return "a piece of " + std::to_string(n) + " vertices";
    if (r.left() / 24 < n)
      return "truncated";
    piece.resize(n);
    for (geom::Vec3& v : piece) {
      if (!r.f64(&v.x) || !r.f64(&v.y) || !r.f64(&v.z))
        return "truncated";
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        return "a coordinate that is not finite";
    }
  }
  if (r.left() != 0)
    return std::to_string(r.left()) + " bytes after the last piece";
  return std::nullopt;
}

}  // namespace

std::string decompCacheKey(const decomp::TriangleMesh& mesh,
                           const decomp::DecompOptions& options,
                           std::uint64_t max_hull_vertices) {
  std::string text = "hapticd decomposition cache " + std::to_string(kDecompCacheVersion) + "\n";
  text += decomp::contentHash(mesh, options);
  putF64(text, options.time_limit_s);
  putU64(text, max_hull_vertices);
  return sha256Hex(text);
}

std::filesystem::path cacheEntryPath(const std::filesystem::path& dir, const std::string& key) {
  return dir / (key + std::string(kEntrySuffix));
}

Eviction evictCache(const std::filesystem::path& dir,
                    std::uint64_t max_bytes,
                    const std::string& keep_key,
                    std::chrono::seconds stale_after) {
  Eviction ev;
  const std::string suffix(kEntrySuffix);
  const std::string tmp_mark = suffix + std::string(kTmpMark);
  auto keyed = [](const std::string& name) {
    return name.size() > kHexBytes &&
           std::all_of(name.begin(), name.begin() + kHexBytes,
                       [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
  };
  struct Entry {
    std::filesystem::file_time_type used;
    std::string name;
    std::uint64_t bytes = 0;
  };
  std::vector<Entry> entries;
  std::uint64_t total = 0;
  const auto now = std::filesystem::file_time_type::clock::now();
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec);
  for (; !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    std::error_code fe;
    if (!it->is_regular_file(fe) || fe)
      continue;
    const std::string name = it->path().filename().string();
    if (!keyed(name))
      continue;
    const auto used = it->last_write_time(fe);
    if (fe)
      continue;
    if (name.compare(kHexBytes, tmp_mark.size(), tmp_mark) == 0) {
      // a writer's temporary file: renamed within a second unless its writer died
      if (now - used > stale_after && std::filesystem::remove(it->path(), fe) && !fe)
        ++ev.stale;
      continue;
    }
    if (name.size() != kHexBytes + suffix.size() ||
        name.compare(kHexBytes, suffix.size(), suffix) != 0)
      continue;
    const std::uint64_t bytes = it->file_size(fe);
    if (fe)
      continue;
    total += bytes;
    entries.push_back({used, name, bytes});
  }
  if (max_bytes == 0 || total <= max_bytes)
    return ev;
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.used, a.name) < std::tie(b.used, b.name);
  });
  for (const Entry& e : entries) {
    if (total <= max_bytes)
      break;
    if (e.name == cacheEntryPath(dir, keep_key).filename())
      continue;
    std::error_code fe;
    if (!std::filesystem::remove(dir / e.name, fe) || fe)
      continue;  // gone already, or not ours to remove: left
    total -= e.bytes;
    ++ev.entries;
    ev.bytes += e.bytes;
  }
  return ev;
}

CacheLookup readCacheEntry(const std::filesystem::path& dir,
                           const std::string& key,
                           std::size_t max_pieces) {
  const std::filesystem::path path = cacheEntryPath(dir, key);
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec)
    return {};  // no entry (or not a readable file: it will be written over)
  if (size < kHeaderBytes)
    return refused("truncated (" + std::to_string(size) + " bytes)");
  if (size > kHeaderBytes + kMaxPayloadBytes)
    return refused("too large (" + std::to_string(size) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  std::string file(size, '\0');
  if (!in.read(file.data(), static_cast<std::streamsize>(size)))
    return refused("cannot be read");
  Reader r(file.data(), file.size());
  std::string magic, entry_key, checksum;
  std::uint32_t version = 0;
  std::uint64_t payload_bytes = 0;
  (void)r.bytes(&magic, sizeof kMagic);
  (void)r.u32(&version);
  (void)r.bytes(&entry_key, kHexBytes);
  (void)r.u64(&payload_bytes);
  (void)r.bytes(&checksum, kHexBytes);  // the size check above: the header is all there
  if (std::memcmp(magic.data(), kMagic, sizeof kMagic) != 0)
    return refused("not a hapticd decomposition cache entry");
  if (version != kDecompCacheVersion)
    return refused("format version " + std::to_string(version) + ", not " +
                   std::to_string(kDecompCacheVersion));
  if (entry_key != key)
    return refused("made for another mesh or other options (its key differs from its name)");
  if (payload_bytes != size - kHeaderBytes)
    return refused("truncated or padded (" + std::to_string(size - kHeaderBytes) +
                   " payload bytes, the header says " + std::to_string(payload_bytes) + ")");
  const std::string payload = file.substr(kHeaderBytes);
  if (sha256Hex(payload) != checksum)
    return refused("checksum mismatch (corrupt)");
  CacheLookup found;
  if (auto bad = parsePayload(payload, max_pieces, &found.pieces))
    return refused(*bad);
  found.status = CacheLookup::Status::kHit;
  // used now: the last an eviction removes (a folder that cannot be written still reads)
  std::filesystem::last_write_time(path, std::filesystem::file_time_type::clock::now(), ec);
  return found;
}

Result<bool> writeCacheEntry(const std::filesystem::path& dir,
                             const std::string& key,
                             const CachedPieces& pieces) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    return Error{"cannot create " + dir.string() + ": " + ec.message()};
  std::string payload;
  putU32(payload, static_cast<std::uint32_t>(pieces.note.size()));
  payload += pieces.note;
  putU32(payload, static_cast<std::uint32_t>(pieces.pieces.size()));
  for (const auto& piece : pieces.pieces) {
    putU32(payload, static_cast<std::uint32_t>(piece.size()));
    for (const geom::Vec3& v : piece) {
      putF64(payload, v.x);
      putF64(payload, v.y);
      putF64(payload, v.z);
    }
  }
  std::string file(kMagic, sizeof kMagic);
  putU32(file, kDecompCacheVersion);
  file += key;
  putU64(file, payload.size());
  file += sha256Hex(payload);
  file += payload;
  // a name no other writer uses (process and counter), renamed over the entry when complete
  static std::atomic<std::uint64_t> serial{0};
  const std::filesystem::path final_path = cacheEntryPath(dir, key);
  std::filesystem::path tmp = final_path;
  tmp += std::string(kTmpMark) + std::to_string(::getpid()) + "." + std::to_string(serial++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out || !out.write(file.data(), static_cast<std::streamsize>(file.size())) ||
        !out.flush()) {
      out.close();
      std::filesystem::remove(tmp, ec);
      return Error{"cannot write " + tmp.string()};
    }
  }
  std::filesystem::rename(tmp, final_path, ec);
  if (ec) {
    const std::string why = ec.message();
    std::filesystem::remove(tmp, ec);
    return Error{"cannot rename " + tmp.string() + " to " + final_path.string() + ": " + why};
  }
  return true;
}

}  // namespace hapticd::scene::detail
