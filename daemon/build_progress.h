#pragma once
/// \file
/// What a scene build is doing, for `hapticctl status`, the status file and the web API while a
/// SIGHUP reload or an upload is built ("loading scene 'part.glb': decomposing mesh 3 (mesh 2
/// 'Bunny' (node 4 'Bunny')), 12 pieces, 1.4 s"). The builder thread writes it, the main thread
/// reads it; the servo thread never sees it.
///
/// Threads: BuildProgress on any normal thread (a mutex); reportBuildProgress() and
/// loadProgressReporter()'s function on the builder thread (they reach the BuildProgress of the
/// build running on the calling thread, set by BuildProgressScope).

#include <chrono>
#include <mutex>
#include <string>

#include "core/scene/loader.h"

namespace hapticd::daemon {

/// One line of progress text.
class BuildProgress {
 public:
  void set(std::string text);
  std::string text() const;

 private:
  mutable std::mutex mutex_;
  std::string text_;
};

/// While it lives, reportBuildProgress() on this thread writes to `progress`.
class BuildProgressScope {
 public:
  explicit BuildProgressScope(BuildProgress* progress);
  ~BuildProgressScope();
  BuildProgressScope(const BuildProgressScope&) = delete;
  BuildProgressScope& operator=(const BuildProgressScope&) = delete;

 private:
  BuildProgress* previous_;
};

/// Sets the progress of the build running on the calling thread; nothing when none runs here
/// (start-up, `--check-config`). The backends' scene loaders call it.
void reportBuildProgress(std::string text);

/// A loader progress function that reports "loading scene 'NAME': decomposing mesh N (WHICH),
/// P pieces, T s" through reportBuildProgress(), at most every 50 ms of wall time.
scene::LoadProgressFn loadProgressReporter(const std::string& scene_name);

}  // namespace hapticd::daemon
