// The table of config keys agrees with what the real users of each value refuse: every value the
// table accepts at the ends of its ranges is accepted by sim::Simulation::create ([response]),
// by the sim device ([device] sim_*) and by the scene loader ([scene]), so that a config that
// passes `--check-config` never fails at start-up on a range.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/scene/loader.h"
#include "core/sim/simulation.h"
#include "daemon/config.h"
#include "daemon/config_keys.h"
#include "daemon/device/device.h"
#include "scenes/demo_scenes.h"

namespace hapticd::daemon {
namespace {

// the values at the ends of a key's range that the range contains (an open end nudged inside)
std::vector<double> ends(const Range& r) {
  const double lo = r.lo_open ? std::nextafter(r.lo, r.hi) : r.lo;
  const double hi = r.hi_open ? std::nextafter(r.hi, r.lo) : r.hi;
  return {lo, hi};
}

// every number key of `section`, set to each end of its range in turn
template <class Use>
void forEveryEnd(std::string_view section, const Use& use) {
  for (const ConfigKey& k : configKeys()) {
    if (k.section != section || !std::holds_alternative<double*>(k.in(Config{})))
      continue;
    for (const double v : ends(k.range)) {
      Config c;
      *std::get<double*>(k.in(c)) = v;
      ASSERT_TRUE(validateConfig(c)) << k.label() << " = " << v;
      use(c, k.label() + " = " + shortestNumber(v));
    }
  }
}

std::shared_ptr<const scene::SceneModel> demo(const std::string& name,
                                              const scene::LoadOptions& options = {}) {
  const auto bytes = scenes::makeDemoScene(name);
  auto report = scene::loadScene(bytes, name, options);
  EXPECT_TRUE(report.ok()) << report.message();
  if (!report.ok())
    return nullptr;
  return std::make_shared<scene::SceneModel>(std::move(*report.scene));
}

TEST(ConfigAgreement, TheSimulationTakesEveryResponseValueTheTableTakes) {
  const auto model = demo("dynamic");  // dynamics on: its options are checked too
  ASSERT_TRUE(model);
  int checked = 0;
  forEveryEnd("response", [&](const Config& c, const std::string& what) {
    auto sim = sim::Simulation::create(model, toSimOptions(c));
    EXPECT_TRUE(sim) << what << ": " << (sim ? "" : sim.error().message);
    ++checked;
  });
  EXPECT_GT(checked, 30);
}

TEST(ConfigAgreement, TheSimDeviceTakesEveryDeviceValueTheTableTakes) {
  int checked = 0;
  forEveryEnd("device", [&](const Config& c, const std::string& what) {
    auto d = device::makeDevice("sim", c.device.options);
    EXPECT_TRUE(d) << what << ": " << (d ? "" : d.error().message);
    ++checked;
  });
  EXPECT_GT(checked, 20);
}

TEST(ConfigAgreement, TheLoaderTakesEveryTessellationToleranceTheTableTakes) {
  forEveryEnd("scene", [&](const Config& c, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_TRUE(demo("gears", toLoadOptions(c)));
  });
}

}  // namespace
}  // namespace hapticd::daemon
