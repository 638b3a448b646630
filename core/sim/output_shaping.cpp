// The simulation's raw wrench through the one output stage, for offline users
// (core/sim/output_shaping.h).
#include "core/sim/output_shaping.h"

namespace hapticd::sim {
namespace {

// A Simulation and the output stage after it; every other call goes to the simulation.
class ShapedSimulation final : public Simulation {
 public:
  ShapedSimulation(std::unique_ptr<Simulation> sim, const ResponseOptions& r)
      : sim_(std::move(sim)), stage_(outputLimits(r)) {}

  TickOutput step(const TickInput& input) override {
    TickOutput out = sim_->step(input);
    response::OutputInputs in;
    in.device_ok = out.device_ok;
    response::OutputReport rep;
    const response::Wrench w =
        stage_.apply({out.force_W_n, out.torque_W_nm}, in, response::OutputFrame{}, &rep);
    out.force_W_n = w.force_n;
    out.torque_W_nm = w.torque_nm;
    out.flags |= outputFlags(rep);
    return out;
  }
  void restartRamp() override { stage_.restartRamp(); }
  std::span<const BodyPose> bodyPoses() const override { return sim_->bodyPoses(); }
  const scene::SceneModel& scene() const override { return sim_->scene(); }
  DynamicsStatus dynamicsStatus() const override { return sim_->dynamicsStatus(); }
  void prepareThread() override { sim_->prepareThread(); }
  EditStatus setKinematicPose(std::uint32_t body, const Pose& X_WB) override {
    return sim_->setKinematicPose(body, X_WB);
  }
  EditStatus setBodyActive(std::uint32_t body, bool active, const Pose& X_WB) override {
    return sim_->setBodyActive(body, active, X_WB);
  }
  bool bodyActive(std::uint32_t body) const override { return sim_->bodyActive(body); }
  std::span<const ContactPoint> contactPoints() const override { return sim_->contactPoints(); }
  const SimModel* model() const override { return sim_->model(); }
  const SceneState* state() const override { return sim_->state(); }

 private:
  std::unique_ptr<Simulation> sim_;
  response::OutputStage stage_;
};

}  // namespace

response::OutputLimits outputLimits(const ResponseOptions& r) {
  const response::OutputLimits defaults;
  return {.max_force_n = r.max_force_n,
          .max_torque_nm = r.max_torque_nm,
          .max_force_step_n = r.max_force_step_n,
          .max_torque_step_nm = r.max_torque_step_nm,
          .ramp_s = r.ramp_s,
          .fault_fade_s = defaults.fault_fade_s,
          .hold_fade_s = defaults.hold_fade_s,
          .tick_s = r.tick_s};
}

std::unique_ptr<Simulation> withOutputStage(std::unique_ptr<Simulation> sim,
                                            const ResponseOptions& r) {
  if (sim == nullptr)
    return nullptr;
  return std::make_unique<ShapedSimulation>(std::move(sim), r);
}

}  // namespace hapticd::sim
