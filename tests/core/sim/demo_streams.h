#pragma once
// The demo scenes that have a recorded pose stream (scenes/NAME.glb, tests/streams/NAME.csv), as
// the parameters of the tests that replay each (demo_scenes_test.cpp, determinism_test.cpp).
#include <gtest/gtest.h>

#include <string>

namespace hapticd::simtest {

/// The names, as test parameters.
inline auto demoStreams() {
  return ::testing::Values("peg_in_hole", "gears", "dynamic", "stress", "decomposed");
}

/// A parameterised test's name suffix: the scene's name.
inline std::string demoStreamName(const ::testing::TestParamInfo<const char*>& info) {
  return info.param;
}

}  // namespace hapticd::simtest
