#include "daemon/build_progress.h"

#include <cstdio>
#include <memory>
#include <utility>

namespace hapticd::daemon {
namespace {

thread_local BuildProgress* t_progress = nullptr;

}  // namespace

void BuildProgress::set(std::string text) {
  std::lock_guard<std::mutex> lock(mutex_);
  text_ = std::move(text);
}

std::string BuildProgress::text() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return text_;
}

BuildProgressScope::BuildProgressScope(BuildProgress* progress) : previous_(t_progress) {
  t_progress = progress;
}

BuildProgressScope::~BuildProgressScope() {
  t_progress = previous_;
}

void reportBuildProgress(std::string text) {
  if (t_progress != nullptr)
    t_progress->set(std::move(text));
}

scene::LoadProgressFn loadProgressReporter(const std::string& scene_name) {
  using Clock = std::chrono::steady_clock;
  // shared by the copies of the function the loader makes
  auto last = std::make_shared<Clock::time_point>();
  return [scene_name, last](const scene::LoadProgress& p) {
    const Clock::time_point now = Clock::now();
    if (*last != Clock::time_point{} && now - *last < std::chrono::milliseconds(50))
      return;
    *last = now;
    char figures[96];
    std::snprintf(figures, sizeof figures, "%zu pieces, %.1f s", p.pieces, p.elapsed_s);
    reportBuildProgress("loading scene '" + scene_name + "': decomposing mesh " +
                        std::to_string(p.mesh) + " (" + p.mesh_name + "), " + figures);
  };
}

}  // namespace hapticd::daemon
