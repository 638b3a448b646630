// The Simulation the daemon drives: a compiled model (core/sim/model.h) and its state
// (core/sim/scene_state.h), stepped by sim::step.
#include "core/sim/simulation.h"

#include "core/sim/model.h"
#include "core/sim/scene_state.h"
#include "core/sim/tick.h"

namespace hapticd::sim {
namespace {

class SimulationImpl final : public Simulation {
 public:
  SimulationImpl(std::shared_ptr<const SimModel> model, SceneState state)
      : model_(std::move(model)), state_(std::move(state)) {}

  TickOutput step(const TickInput& input) override { return sim::step(*model_, state_, input); }
  std::span<const BodyPose> bodyPoses() const override { return state_.body_poses; }
  const scene::SceneModel& scene() const override { return *model_->scene; }
  DynamicsStatus dynamicsStatus() const override { return sim::dynamicsStatus(*model_, state_); }
  void prepareThread() override {}  // nothing per thread: the world owns its scratch
  EditStatus setKinematicPose(std::uint32_t body, const Pose& X_WB) override {
    return sim::setKinematicPose(*model_, state_, body, X_WB);
  }
  EditStatus setBodyActive(std::uint32_t body, bool active, const Pose& X_WB) override {
    return sim::setBodyActive(*model_, state_, body, active, X_WB);
  }
  bool bodyActive(std::uint32_t body) const override {
    return body < model_->scene->bodies.size() && state_.active[body] != 0;
  }
  std::span<const ContactPoint> contactPoints() const override { return state_.contact_points; }
  PrewarmReport prewarm(const std::optional<Pose>& X_W_device) override {
    return prewarmState(*model_, state_, X_W_device);
  }
  ColdWork coldWork() const override { return sim::coldWork(state_); }
  const SimModel* model() const override { return model_.get(); }
  const SceneState* state() const override { return &state_; }

 private:
  std::shared_ptr<const SimModel> model_;
  SceneState state_;
};

}  // namespace

Result<std::unique_ptr<Simulation>> Simulation::create(
    std::shared_ptr<const scene::SceneModel> scene,
    const SimOptions& options) {
  auto model = SimModel::compile(std::move(scene), options);
  if (!model.ok())
    return model.error();
  auto state = makeState(*model.value());
  if (!state.ok())
    return state.error();
  return std::unique_ptr<Simulation>(
      std::make_unique<SimulationImpl>(std::move(model).value(), std::move(state).value()));
}

std::uint64_t Simulation::stateHash() const {
  const SceneState* s = state();
  return s != nullptr ? sim::stateHash(*s) : 0;
}

}  // namespace hapticd::sim
