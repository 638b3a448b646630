// loadScene and loadSceneFile: the three passes of the scene loader in order (document.h,
// accessors.h, builder.h), each run only when the earlier ones found nothing.
#include "core/scene/loader.h"

#include "core/scene/builder.h"
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
  detail::Document doc;
  if (!detail::parseDocument(bytes, options, &doc, &problems))
    return finish();
  const auto data = detail::loadBuffers(doc, options, &problems);
  if (!data)
    return finish();
  detail::Builder builder(doc, *data, options, &problems);
  report.scene = builder.build(name);
  return finish();
}

}  // namespace

std::string LoadReport::message() const {
  std::string out;
  for (const Problem& p : problems) {
    out += p.where;
    out += ": ";
    out += p.what;
    out += '\n';
  }
  return out;
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
  auto bytes = detail::readFileLimited(path.string(), options.limits.max_file_bytes);
  if (!bytes) {
    LoadReport report;
    report.problems.push_back({"file", bytes.error().message});
    return report;
  }
  // external URIs resolve beside the file unless a folder is given
  LoadOptions beside = options;
  if (!beside.allowed_uri_dir)
    beside.allowed_uri_dir = std::filesystem::absolute(path).parent_path();
  return loadScene(bytes.value(), path.filename().string(), beside);
}

}  // namespace hapticd::scene
