#pragma once
// The real servo loop on the virtual clock over one vendor device backend and the fake simulation
// (a wall at y = 0 pushing up with 600 N/m; fakes.h), as the vendor backends' loop tests use it
// (forcedimension, openhaptics, haply): the loop takes the device's limits (as toServoOptions: the
// tighter of the config's and the device's), runs a number of ticks, and is armed by a command.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>

#include "daemon/clock.h"
#include "daemon/servo_loop.h"
#include "tests/daemon/fakes.h"

namespace hapticd::testing {

template <class DeviceT>
struct LoopRig {
  std::unique_ptr<DeviceT> device;
  daemon::VirtualClock clock;
  std::unique_ptr<daemon::ServoLoop> loop;
  std::uint64_t ticks = 0;

  /// `options.limits` is replaced by the device's.
  explicit LoopRig(std::unique_ptr<DeviceT> d, daemon::ServoOptions options = {})
      : device(std::move(d)) {
    options.limits = device->info().limits;
    loop = std::make_unique<daemon::ServoLoop>(options, clock, *device,
                                               servoSceneOf<FakeSimulation>(1));
    loop->prepareServoThread();
  }
  /// n more ticks; the loop must end at its tick limit.
  void run(std::uint64_t n) {
    ticks += n;
    loop->setMaxTicks(ticks);
    EXPECT_EQ(loop->run(), daemon::ServoExit::kMaxTicks);
  }
  void arm() {
    daemon::ServoCommand c;
    c.kind = daemon::CommandKind::kArm;
    ASSERT_TRUE(loop->sendCommand(c));
  }
};

/// |v| of a force or torque as the fakes record them.
inline double length3(const double v[3]) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

}  // namespace hapticd::testing
