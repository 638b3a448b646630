#pragma once
/// \file
/// `hapticctl check FILE`: loads a scene offline (core/scene/loader.h) and lists its bodies,
/// primitives and simulation plan, or every problem found (docs/scenes.md).

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

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

/// Two bodies (not both static) that overlap at the poses the scene gives them.
struct Overlap {
  std::size_t a = 0, b = 0;  ///< scene body indices, a < b
  double depth_m = 0.0;      ///< of their deepest pair of primitives
};

/// Two bodies start overlapping when their deepest pair of primitives is deeper than this fraction
/// of the smaller body's size (its largest primitive radius): a stack placed touching is not
/// reported, a part placed into a floor is.
inline constexpr double kOverlapFraction = 1e-3;

/// The pairs of bodies that start overlapping, deepest first: what the scene's first ticks push
/// apart (a part imported with `--at` at its origin, half into the floor). The collision world of
/// the scene, one step at the scene's poses (collision filters, inactive bodies and triggers as
/// the daemon has them). Any thread but the servo thread.
std::vector<Overlap> startingOverlaps(const scene::SceneModel& scene);

}  // namespace hapticd::client
