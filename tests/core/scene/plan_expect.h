#pragma once
/// \file
/// Test helper: what a scene's simulation plan must be, in one line. Header-only, test code.

#include <gtest/gtest.h>

#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>

#include "core/scene/scene.h"

namespace hapticd::scene::testing {

/// Contact forces are on; of the stages "dynamics gravity friction restitution joints" exactly
/// those named in `on` (space-separated) are on; the broad phase has `static_primitives` and
/// `moving_primitives`.
inline void expectPlan(const SimulationPlan& plan,
                       std::string_view on,
                       std::uint32_t static_primitives,
                       std::uint32_t moving_primitives) {
  std::istringstream words{std::string(on)};
  bool named[5] = {};
  static constexpr std::string_view kStages[5] = {"dynamics", "gravity", "friction", "restitution",
                                                  "joints"};
  for (std::string w; words >> w;) {
    bool known = false;
    for (int i = 0; i < 5; ++i) {
      if (w == kStages[i])
        named[i] = known = true;
    }
    if (!known)
      ADD_FAILURE() << "expectPlan: no stage '" << w << "'";
  }
  const bool actual[5] = {plan.dynamics, plan.gravity, plan.friction, plan.restitution,
                          plan.joints};
  EXPECT_TRUE(plan.contact_forces);
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(actual[i], named[i]) << kStages[i];
  EXPECT_EQ(plan.static_primitives, static_primitives);
  EXPECT_EQ(plan.moving_primitives, moving_primitives);
}

/// Two plans switch the same stages on and count the same primitives.
inline void expectSamePlan(const SimulationPlan& a, const SimulationPlan& b) {
  EXPECT_EQ(describePlan(a), describePlan(b));
}

}  // namespace hapticd::scene::testing
