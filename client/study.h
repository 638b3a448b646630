#pragma once
/// \file
/// `hapticctl study SCENE.glb [STREAM.csv]`: the accuracy study (docs/accuracy.md) on the user's
/// own scene and pose stream, or on an approach stream generated for the scene: the real tick at
/// its most accurate settings and at each setting of the knobs that trade accuracy for time, the
/// tables, CSV and plots written to a folder, and the most accurate settings whose p99.9 tick fits
/// the budget printed as a config snippet.

#include <ostream>
#include <string>

#include "core/scene/loader.h"

namespace hapticd::client {

struct StudyOptions {
  std::string scene;       ///< .glb or .gltf
  std::string stream;      ///< pose stream CSV; empty: an approach stream generated for the scene
  double budget_us = 0.0;  ///< p99.9 tick budget, µs; 0: one tick at rate_hz
  double rate_hz = 1000.0;
  std::string out_dir;  ///< empty: "study-<scene stem>"
  bool quick = false;   ///< at most 3 s of stream (and a half-length generated stream)
  /// Refused before it starts when the estimate is longer (seconds; 0: no limit).
  double time_limit_s = 600.0;
  scene::LoadOptions load;
};

/// Runs the study. Exit status: 0 with the snippet on `out` (the settings fit the budget); 1 when
/// the scene or stream cannot be used (every problem on `err`, as `check` says them), when no
/// setting fits the budget (the fastest printed, marked as not fitting), when the estimate exceeds
/// the time limit (said before anything runs), or when a file cannot be written; 2 for bad option
/// values or a file that does not exist. Progress lines go to `err`.
int runStudy(const StudyOptions& options, std::ostream& out, std::ostream& err);

}  // namespace hapticd::client
