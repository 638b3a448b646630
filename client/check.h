#pragma once
/// \file
/// `hapticctl check FILE`: loads a scene offline (core/scene/loader.h) and lists its bodies,
/// primitives and simulation plan, or every problem found (docs/scenes.md).

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>

#include "core/scene/loader.h"

namespace hapticd::client {

struct CheckOptions {
  bool json = false;  ///< a machine-readable report (one JSON object) on `out` instead of text
  scene::LoadOptions load;
};

/// Checks the scene file `path`. Exit status: 0 when it loads (the report on `out`), 1 when it
/// does not: every problem as "FILE: where: what" on `err`, one per line (with --json the report,
/// problems included, also goes to `out`). Any thread but the servo thread.
int runCheck(const std::filesystem::path& path,
             const CheckOptions& options,
             std::ostream& out,
             std::ostream& err);

/// The text report of a loaded scene (what runCheck prints on success).
std::string describeScene(const scene::SceneModel& scene);

}  // namespace hapticd::client
