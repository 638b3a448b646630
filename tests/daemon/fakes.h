#pragma once
// Small fakes of the simulation and the device for the daemon's unit tests: the interfaces are
// virtual for this. Neither allocates in its servo-thread calls.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/sim/simulation.h"
#include "daemon/device/device.h"
#include "daemon/servo_loop.h"

namespace hapticd::testing {

/// A "scene" of one wall at y = 0: penalty force k * depth pushing +y when the device is below.
/// Optional NaN at one tick. Tracks the ticks it has seen.
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
  const scene::SceneModel& scene() const override { return scene_; }
  void prepareThread() override { ++prepared; }

  std::uint64_t steps = 0;
  std::uint64_t nan_at_step = 0;
  std::uint32_t prepared = 0;
  sim::TickInput last_input;

 private:
  double stiffness_;
  std::vector<sim::BodyPose> poses_;
  scene::SceneModel scene_;
};

/// The scene EditableSimulation expects (and the daemon tests load): 0 "floor" static, 1 "Probe"
/// kinematic and the probe, 2 "lid" dynamic, 3 "slider" kinematic, 4 "door" kinematic and
/// inactive at the start, 5 "crate" dynamic.
inline std::shared_ptr<scene::SceneModel> editableSceneModel(const std::string& name = "edits") {
  auto m = std::make_shared<scene::SceneModel>();
  m->name = name;
  const char* names[] = {"floor", "Probe", "lid", "slider", "door", "crate"};
  const scene::Motion motions[] = {scene::Motion::kStatic,    scene::Motion::kKinematic,
                                   scene::Motion::kDynamic,   scene::Motion::kKinematic,
                                   scene::Motion::kKinematic, scene::Motion::kDynamic};
  m->bodies.resize(6);
  for (std::size_t i = 0; i < 6; ++i) {
    m->bodies[i].name = names[i];
    m->bodies[i].motion = motions[i];
    m->bodies[i].X_WB.translation = geom::Vec3(static_cast<double>(i), 0.0, 0.0);
  }
  m->bodies[1].probe = true;
  m->probe_body = 1;
  m->bodies[4].active = false;
  return m;
}

/// A simulation of editableSceneModel() with the scene-edit contract of sim::Simulation (the
/// same refusals as the real one), a wall at y = 0 like FakeSimulation, and `contacts_per_touch`
/// contact points while the device is below the wall. An edit takes effect in the next step();
/// it records the step count at which each edit arrived (applied_at_step), for the "one tick
/// boundary" checks. No allocation in its servo-thread calls (fixed arrays).
class EditableSimulation final : public sim::Simulation {
 public:
  static constexpr std::size_t kBodies = 6;
  static constexpr std::size_t kMaxContacts = 64;
  static constexpr std::size_t kLogCapacity = 4096;

  explicit EditableSimulation(std::shared_ptr<const scene::SceneModel> model = nullptr)
      : model_(model ? std::move(model) : editableSceneModel()) {
    for (std::size_t i = 0; i < kBodies; ++i) {
      target_[i] = model_->bodies[i].X_WB;
      active_[i] = model_->bodies[i].active;
    }
    publish();
  }
  sim::TickOutput step(const sim::TickInput& in) override {
    ++steps;
    sim::TickOutput out;
    out.X_W_proxy = in.X_W_device;
    const double depth = -in.X_W_device.translation.y;
    contact_count_ = 0;
    out.pairs_tested = 1;
    if (in.device_ok && depth > 0.0) {
      out.force_W_n = geom::Vec3(0.0, 600.0 * depth, 0.0);
      out.contacts = contacts_per_touch;
      out.max_penetration_m = depth;
      out.pairs_tested = 3;
      out.X_W_proxy.translation.y = 0.0;
      contact_count_ = std::min<std::size_t>(contacts_per_touch, kMaxContacts);
      for (std::size_t i = 0; i < contact_count_; ++i) {
        contacts_[i].p_W = in.X_W_device.translation + geom::Vec3(0.001 * static_cast<double>(i));
        contacts_[i].n_W = geom::Vec3(0.0, 1.0, 0.0);
        contacts_[i].depth_m = depth;
        contacts_[i].body = 0;
      }
    }
    publish();
    return out;
  }
  std::span<const sim::BodyPose> bodyPoses() const override {
    return std::span<const sim::BodyPose>(poses_.data(), pose_count_);
  }
  std::span<const sim::ContactPoint> contactPoints() const override {
    return std::span<const sim::ContactPoint>(contacts_.data(), contact_count_);
  }
  void restartRamp() override {}
  const scene::SceneModel& scene() const override { return *model_; }
  void prepareThread() override {}

  sim::EditStatus setKinematicPose(std::uint32_t body, const geom::Pose& X_WB) override {
    const sim::EditStatus st = check(body);
    if (st != sim::EditStatus::kOk)
      return log(body, st);
    if (model_->bodies[body].motion != scene::Motion::kKinematic)
      return log(body, sim::EditStatus::kNotKinematic);
    if (!active_[body])
      return log(body, sim::EditStatus::kInactive);
    target_[body] = X_WB;
    return log(body, sim::EditStatus::kOk);
  }
  sim::EditStatus setBodyActive(std::uint32_t body, bool active, const geom::Pose& X_WB) override {
    const sim::EditStatus st = check(body);
    if (st != sim::EditStatus::kOk)
      return log(body, st);
    active_[body] = active;
    if (active)
      target_[body] = X_WB;
    return log(body, sim::EditStatus::kOk);
  }
  bool bodyActive(std::uint32_t body) const override { return body < kBodies && active_[body]; }

  /// One accepted or refused edit: the body, the answer, and how many steps had run.
  struct Edit {
    std::uint32_t body = 0;
    sim::EditStatus status = sim::EditStatus::kOk;
    std::uint64_t steps_before = 0;
    geom::Pose X_WB;
  };
  std::size_t editCount() const { return edit_count_.load(); }
  const Edit& edit(std::size_t i) const { return edits_[i]; }

  std::atomic<std::uint64_t> steps{0};
  std::uint32_t contacts_per_touch = 2;

 private:
  sim::EditStatus check(std::uint32_t body) const {
    if (body >= kBodies)
      return sim::EditStatus::kNoSuchBody;
    if (static_cast<std::int32_t>(body) == model_->probe_body)
      return sim::EditStatus::kHeldBody;
    if (model_->bodies[body].motion == scene::Motion::kStatic)
      return sim::EditStatus::kStaticBody;
    return sim::EditStatus::kOk;
  }
  sim::EditStatus log(std::uint32_t body, sim::EditStatus st) {
    const std::size_t n = edit_count_.load();
    if (n < kLogCapacity) {
      edits_[n] = Edit{body, st, steps.load(), body < kBodies ? target_[body] : geom::Pose{}};
      edit_count_.store(n + 1);
    }
    return st;
  }
  void publish() {
    pose_count_ = 0;
    for (std::uint32_t i = 0; i < kBodies; ++i) {
      if (model_->bodies[i].motion == scene::Motion::kStatic || !active_[i])
        continue;
      poses_[pose_count_++] = sim::BodyPose{i, target_[i]};
    }
  }

  std::shared_ptr<const scene::SceneModel> model_;
  std::array<geom::Pose, kBodies> target_{};
  std::array<bool, kBodies> active_{};
  std::array<sim::BodyPose, kBodies> poses_{};
  std::size_t pose_count_ = 0;
  std::array<sim::ContactPoint, kMaxContacts> contacts_{};
  std::size_t contact_count_ = 0;
  std::array<Edit, kLogCapacity> edits_{};
  std::atomic<std::size_t> edit_count_{0};
};

/// A device moving along a known path (y = -0.01 sin(t)), lost during [lost_from, lost_until)
/// ticks, ending after end_after ticks (0: never). Records what it was asked to display.
class FakeDevice final : public device::Device {
 public:
  FakeDevice() {
    info_.name = "fake";
    info_.capabilities = device::kCapPosition | device::kCapForce | device::kCapPoseCommands;
  }
  ~FakeDevice() override {
    if (on_close)
      on_close(*this);
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
    if (follow_commands && commands > 0)
      out.X_WD = last_command.X_W_target;  // a perfectly stiff commanded device
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
  void setHome(const geom::Pose& X_D_home) noexcept override {
    if (on_home)
      on_home(X_D_home);  // servo thread
  }

  device::DeviceInfo info_;
  std::uint64_t reads = 0, writes = 0, commands = 0;
  std::uint64_t lost_from = ~0ull, lost_until = ~0ull, end_after = 0;
  std::atomic<bool> lost_flag{false};
  double depth_offset = 0.0;
  bool follow_commands = false;  ///< read() returns the last commanded pose once there is one
  geom::Vec3 last_force{0.0}, last_torque{0.0}, prev_force{0.0};
  double max_written_n = 0.0, max_step_n = 0.0;
  device::PoseCommand last_command;
  std::function<void(const FakeDevice&)> on_close;  ///< called as the daemon destroys it
  std::function<void(const geom::Pose&)> on_home;   ///< setHome(), on the servo thread
};

/// A scene for the servo loop holding a new `Sim` (FakeSimulation, EditableSimulation) as
/// generation `gen`; `*out`, when given, points at the simulation.
template <class Sim>
std::unique_ptr<daemon::ServoScene> servoSceneOf(std::uint64_t gen = 1, Sim** out = nullptr) {
  auto sim = std::make_unique<Sim>();
  if (out != nullptr)
    *out = sim.get();
  auto s = std::make_unique<daemon::ServoScene>();
  s->sim = std::move(sim);
  s->generation = gen;
  return s;
}

/// Every event the loop has queued, in order (the test is the events' one consumer).
inline std::vector<daemon::ServoEvent> drainEvents(daemon::ServoLoop& loop) {
  std::vector<daemon::ServoEvent> events;
  daemon::ServoEvent e;
  while (loop.popEvent(e))
    events.push_back(e);
  return events;
}

}  // namespace hapticd::testing
