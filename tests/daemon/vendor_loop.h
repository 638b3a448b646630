#pragma once
// The set-up the vendor-backend loop tests share (forcedimension_loop_test.cpp,
// openhaptics_loop_test.cpp, haply_loop_test.cpp): the real servo loop on the virtual clock over a
// device opened on a fake vendor library (tests/daemon/device/), with the fake simulation (a wall
// at y = 0 pushing up with 600 N/m) and the device's limits; and the vector measures of the forces
// the fakes record.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>

#include "daemon/servo_loop.h"
#include "tests/daemon/fakes.h"

namespace hapticd::testing {

/// |v| of a 3-vector as the fakes record it.
inline double length(const double v[3]) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/// |force - previous|, then previous = force: the step from one recorded force to the next.
inline double stepFrom(double previous[3], const double force[3]) {
  const double d[3] = {force[0] - previous[0], force[1] - previous[1], force[2] - previous[2]};
  std::copy(force, force + 3, previous);
  return length(d);
}

/// The loop over a device of type Device; start() takes the opened device.
template <class Device>
struct VendorLoopRig {
  std::unique_ptr<Device> device;
  daemon::VirtualClock clock;
  std::unique_ptr<daemon::ServoLoop> loop;
  std::uint64_t ticks = 0;

  /// Takes `opened` (a failure fails the test) and builds the loop over it with options `so`
  /// limited as toServoOptions does (the tighter of config and device: here the device's), the
  /// output stage's ramp-in off (the fake simulation never had one).
  template <class Opened>
  void start(Opened opened, daemon::ServoOptions so = {}) {
    EXPECT_TRUE(opened.ok()) << opened.error().message;
    device = std::move(opened).value();
    so.limits = device->info().limits;
    so.ramp_in_s = 0.0;  // full force from the start (the output stage's ramp-in is tested apart)
    loop = std::make_unique<daemon::ServoLoop>(so, clock, *device, servoSceneOf<FakeSimulation>(1));
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

}  // namespace hapticd::testing
