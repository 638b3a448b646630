// loadScene and loadSceneFile: the three passes of the scene loader in order (document.h,
// accessors.h, builder.h), each run only when the earlier ones found nothing.
#include "core/scene/loader.h"

#include <cmath>
#include <cstdlib>

#include "core/scene/builder.h"
#include "core/scene/scene_file.h"
#include "core/scene/uri.h"

namespace hapticd::scene {
namespace {

LoadReport loadImpl(std::span<const std::uint8_t> bytes,
                    const std::string& name,
                    const LoadOptions& options) {
  detail::Problems problems;
  LoadReport report;
  const auto finish = [&]() {
    report.problems = problems.take();
    if (!report.problems.empty())
      report.scene.reset();
    return report;
  };
  const SceneLimits& limits = options.limits;
  if (!(limits.tessellation_tolerance > 0.0 && limits.tessellation_tolerance < 0.5)) {
    problems.add("options", "tessellation_tolerance " +
                                detail::formatNumber(limits.tessellation_tolerance) +
                                " must be in (0, 0.5)");
    return finish();
  }
  const DecompositionOptions& decomposition = options.decomposition;
  if (!(decomposition.concavity > 0.0 && decomposition.concavity < 1.0)) {
    problems.add("options", "concavity " + detail::formatNumber(decomposition.concavity) +
                                " must be in (0, 1)");
    return finish();
  }
  if (decomposition.max_pieces < 1) {
    problems.add("options", "max_pieces must be at least 1");
    return finish();
  }
  if (!(decomposition.time_limit_s >= 0.0 && std::isfinite(decomposition.time_limit_s))) {
    problems.add("options", "decompose_time_limit_s " +
                                detail::formatNumber(decomposition.time_limit_s) +
                                " must be finite and >= 0");
    return finish();
  }
  detail::Document doc;
  if (!detail::parseDocument(bytes, options, &doc, &problems))
    return finish();
  const auto data = detail::loadBuffers(doc, options, &problems);
  if (!data)
    return finish();
  detail::Builder builder(doc, *data, options, &problems);
  report.scene = builder.build(name);
  report.decomposition = builder.decomposer().counts();
  report.warnings = builder.decomposer().takeWarnings();
  return finish();
}

}  // namespace

namespace detail {

std::string problemLines(std::span<const Problem> problems) {
  std::string out;
  for (const Problem& p : problems) {
    out += p.where;
    out += ": ";
    out += p.what;
    out += '\n';
  }
  return out;
}

Result<SceneFile> readSceneFile(const std::filesystem::path& path, const LoadOptions& options) {
  auto bytes = readFileLimited(path.string(), options.limits.max_file_bytes);
  if (!bytes)
    return bytes.error();
  SceneFile file{std::move(bytes).value(), options};
  // external URIs resolve beside the file unless a folder is given
  if (!file.options.allowed_uri_dir)
    file.options.allowed_uri_dir = std::filesystem::absolute(path).parent_path();
  return file;
}

}  // namespace detail

std::string LoadReport::message() const {
  return detail::problemLines(problems);
}

LoadReport loadScene(std::span<const std::uint8_t> bytes,
                     const std::string& name,
                     const LoadOptions& options) {
  try {
    return loadImpl(bytes, name, options);
  } catch (const std::exception& e) {
    LoadReport report;
    report.problems.push_back({"file", std::string("internal error while loading: ") + e.what()});
    return report;
  }
}

LoadReport loadSceneFile(const std::filesystem::path& path, const LoadOptions& options) {
  auto file = detail::readSceneFile(path, options);
  if (!file) {
    LoadReport report;
    report.problems.push_back({"file", file.error().message});
    return report;
  }
  return loadScene(file.value().bytes, path.filename().string(), file.value().options);
}

std::filesystem::path decompositionCacheDir(const std::string& setting) {
  if (setting != "auto")
    return setting;
  // an environment variable that is set and not empty
  const auto env = [](const char* name) -> std::string {
    const char* v = std::getenv(name);  // NOLINT(concurrency-mt-unsafe): read-only here
    return v ? std::string(v) : std::string();
  };
  if (const std::string systemd = env("CACHE_DIRECTORY"); !systemd.empty())
    return systemd.substr(0, systemd.find(':'));  // one folder per CacheDirectory= entry
  if (const std::string xdg = env("XDG_CACHE_HOME"); !xdg.empty())
    return std::filesystem::path(xdg) / "hapticd";
  if (const std::string home = env("HOME"); !home.empty())
    return std::filesystem::path(home) / ".cache" / "hapticd";
  return {};
}

}  // namespace hapticd::scene
