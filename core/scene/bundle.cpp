#include "core/scene/bundle.h"

#include <nlohmann/json.hpp>

#include "core/scene/extensions.h"
#include "core/scene/glb.h"
#include "core/scene/json_checker.h"
#include "core/scene/uri.h"

namespace hapticd::scene {
namespace {

using nlohmann::json;

bool externalUri(const json& o) {
  return o.is_object() && o.contains("uri") && o["uri"].is_string() &&
         !detail::isDataUri(o["uri"].get<std::string>());
}

/// A buffer's bytes for the BIN chunk; nullopt when it is a placeholder (no uri, not the GLB
/// chunk: a meshopt fallback, kept as it is).
Result<std::optional<std::vector<std::uint8_t>>> bufferBytes(const json& b,
                                                             std::size_t i,
                                                             std::span<const std::uint8_t> bin,
                                                             bool glb,
                                                             const LoadOptions& options) {
  using Bytes = std::optional<std::vector<std::uint8_t>>;
  const std::string w = "buffer " + std::to_string(i) + ": ";
  const std::string uri =
      b.contains("uri") && b["uri"].is_string() ? b["uri"].get<std::string>() : std::string();
  if (uri.empty()) {
    if (glb && i == 0)
      return Bytes(std::vector<std::uint8_t>(bin.begin(), bin.end()));
    return Bytes();
  }
  if (detail::isDataUri(uri)) {
    auto decoded = detail::decodeDataUri(uri);
    if (!decoded)
      return Error{w + decoded.error().message};
    return Bytes(std::move(decoded).value());
  }
  std::string why;
  const auto path = detail::resolveUri(uri, options, &why);
  if (!path)
    return Error{w + why};
  auto read = detail::readFileLimited(*path, options.limits.max_file_bytes);
  if (!read)
    return Error{w + "external URI " + detail::inQuotes(uri) + ": " + read.error().message};
  return Bytes(std::move(read).value());
}

/// Points a bufferView (or its meshopt extension) at its buffer's place in the new BIN chunk.
void renumber(json& o,
              const std::vector<std::size_t>& index,
              const std::vector<std::uint64_t>& offset) {
  if (!o.is_object() || !o.contains("buffer") || !o["buffer"].is_number_unsigned())
    return;
  const auto old = o["buffer"].get<std::uint64_t>();
  if (old >= index.size())
    return;  // out of range: the loader says so
  o["buffer"] = index[old];
  if (index[old] == 0) {
    const std::uint64_t at = o.contains("byteOffset") && o["byteOffset"].is_number_unsigned()
                                 ? o["byteOffset"].get<std::uint64_t>()
                                 : 0;
    o["byteOffset"] = at + offset[old];
  }
}

}  // namespace

Result<std::vector<std::uint8_t>> bundleScene(std::span<const std::uint8_t> bytes,
                                              const LoadOptions& options) {
  const std::vector<std::uint8_t> unchanged(bytes.begin(), bytes.end());
  const bool glb = isGlb(bytes);
  std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  std::span<const std::uint8_t> bin;
  if (glb) {
    const auto chunks = splitGlb(bytes);
    if (!chunks)
      return unchanged;
    text = chunks.value().json;
    bin = chunks.value().bin;
  }
  json doc = json::parse(text.begin(), text.end(), nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("buffers") ||
      !doc["buffers"].is_array()) {
    return unchanged;
  }
  json& buffers = doc["buffers"];
  bool external = false;
  for (const json& b : buffers)
    external |= externalUri(b);
  if (doc.contains("images") && doc["images"].is_array()) {
    for (json& image : doc["images"]) {
      if (externalUri(image)) {
        image["uri"] = "data:application/octet-stream;base64,";
        external = true;
      }
    }
  }
  if (!external)
    return unchanged;

  std::vector<std::uint8_t> out_bin;
  std::vector<std::size_t> index(buffers.size(), 0);
  std::vector<std::uint64_t> offset(buffers.size(), 0);
  json out_buffers = json::array({json::object()});
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    if (!buffers[i].is_object())
      return unchanged;
    auto data = bufferBytes(buffers[i], i, bin, glb, options);
    if (!data)
      return data.error();
    if (!data.value()) {
      index[i] = out_buffers.size();
      out_buffers.push_back(buffers[i]);
      continue;
    }
    out_bin.resize((out_bin.size() + 3) / 4 * 4, 0);
    offset[i] = out_bin.size();
    out_bin.insert(out_bin.end(), data.value()->begin(), data.value()->end());
  }
  if (out_bin.empty())
    return unchanged;
  out_buffers[0] = {{"byteLength", out_bin.size()}};
  buffers = out_buffers;
  if (doc.contains("bufferViews") && doc["bufferViews"].is_array()) {
    for (json& view : doc["bufferViews"]) {
      renumber(view, index, offset);
      if (!view.is_object() || !view.contains("extensions") || !view["extensions"].is_object())
        continue;
      for (const std::string_view name : detail::kMeshoptNames) {
        auto it = view["extensions"].find(std::string(name));
        if (it != view["extensions"].end())
          renumber(*it, index, offset);
      }
    }
  }
  return packGlb(doc.dump(), out_bin);
}

Result<std::vector<std::uint8_t>> bundleSceneFile(const std::filesystem::path& path,
                                                  const LoadOptions& options) {
  auto bytes = detail::readFileLimited(path.string(), options.limits.max_file_bytes);
  if (!bytes)
    return bytes.error();
  LoadOptions beside = options;
  if (!beside.allowed_uri_dir)
    beside.allowed_uri_dir = std::filesystem::absolute(path).parent_path();
  return bundleScene(bytes.value(), beside);
}

}  // namespace hapticd::scene
