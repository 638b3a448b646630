#pragma once
// Small fakes of the simulation and the device for the daemon's unit tests: the interfaces are
// virtual for this. Neither allocates in its servo-thread calls.
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/sim/simulation.h"
#include "daemon/device/device.h"

namespace hapticd::testing {

/// A "scene" of one wall at y = 0: penalty force k * depth pushing +y when the device is below.
/// Optional NaN at one tick. Tracks ramp restarts and the ticks it has seen.
class FakeSimulation final : public sim::Simulation {
 public:
  explicit FakeSimulation(double stiffness = 600.0, std::uint32_t bodies = 2)
      : stiffness_(stiffness), poses_(bodies) {
    for (std::uint32_t i = 0; i < bodies; ++i)
      poses_[i].body = i;
  }
  sim::TickOutput step(const sim::TickInput& in) override {
    ++steps;
    last_input = in;
    sim::TickOutput out;
    out.X_W_proxy = in.X_W_device;
    const double depth = -in.X_W_device.translation.y;
    if (in.device_ok && depth > 0.0) {
      out.force_W_n = geom::Vec3(0.0, stiffness_ * depth, 0.0);
      out.torque_W_nm = geom::Vec3(0.0, 0.0, 0.1 * stiffness_ * depth);
      out.contacts = 1;
      out.max_penetration_m = depth;
      out.X_W_proxy.translation.y = 0.0;
    }
    if (nan_at_step != 0 && steps == nan_at_step)
      out.force_W_n.x = std::nan("");
    out.pairs_tested = 1;
    for (auto& p : poses_)
      p.X_WB.translation = in.X_W_device.translation + geom::Vec3(p.body);
    return out;
  }
  std::span<const sim::BodyPose> bodyPoses() const override { return poses_; }
  void restartRamp() override { ++ramp_restarts; }
  const scene::SceneModel& scene() const override { return scene_; }
  void prepareThread() override { ++prepared; }

  std::uint64_t steps = 0;
  std::uint64_t nan_at_step = 0;
  std::uint32_t ramp_restarts = 0;
  std::uint32_t prepared = 0;
  sim::TickInput last_input;

 private:
  double stiffness_;
  std::vector<sim::BodyPose> poses_;
  scene::SceneModel scene_;
};

/// A device moving along a known path (y = -0.01 sin(t)), lost during [lost_from, lost_until)
/// ticks, ending after end_after ticks (0: never). Records what it was asked to display.
class FakeDevice final : public device::Device {
 public:
  FakeDevice() {
    info_.name = "fake";
    info_.capabilities = device::kCapPosition | device::kCapForce | device::kCapPoseCommands;
  }
  const device::DeviceInfo& info() const override { return info_; }
  device::DeviceStatus read(double t_s, device::DeviceSample& out) noexcept override {
    const std::uint64_t n = reads++;
    if (end_after != 0 && n >= end_after)
      return device::DeviceStatus::kEndOfStream;
    if (n >= lost_from && n < lost_until)
      return device::DeviceStatus::kLost;
    if (lost_flag.load())
      return device::DeviceStatus::kLost;
    out.X_WD.translation = geom::Vec3(0.001 * t_s, -0.01 * std::sin(t_s * 3.0) - depth_offset, 0.0);
    return device::DeviceStatus::kOk;
  }
  device::DeviceStatus write(const geom::Vec3& f, const geom::Vec3& tau) noexcept override {
    ++writes;
    last_force = f;
    last_torque = tau;
    const double len = glm::length(f);
    if (len > max_written_n)
      max_written_n = len;
    const double step = glm::length(f - prev_force);
    if (step > max_step_n)
      max_step_n = step;
    prev_force = f;
    return device::DeviceStatus::kOk;
  }
  void command(const device::PoseCommand& cmd) noexcept override {
    ++commands;
    last_command = cmd;
  }

  device::DeviceInfo info_;
  std::uint64_t reads = 0, writes = 0, commands = 0;
  std::uint64_t lost_from = ~0ull, lost_until = ~0ull, end_after = 0;
  std::atomic<bool> lost_flag{false};
  double depth_offset = 0.0;
  geom::Vec3 last_force{0.0}, last_torque{0.0}, prev_force{0.0};
  double max_written_n = 0.0, max_step_n = 0.0;
  device::PoseCommand last_command;
};

}  // namespace hapticd::testing
