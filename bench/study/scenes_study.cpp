// The scene part of the accuracy study: each demo scene replayed from its pose stream through the
// whole tick (core/sim), with the settings that trade accuracy for time, against the same tick at
// its most accurate settings.
//
// - Closed loop: the scheduler budget (pairs tested per tick: unlimited, 8, 4, 2, 1) and the
//   predictive distance δ of §5.2 on and off. Each run is the real tick, so its error is what the
//   hand would feel: the force and torque sent to the device, against the truth run's, tick by
//   tick on the same pose stream.
// - Open loop: voxel sampling (McNeely et al. 1999) at the truth run's proxy poses: the static
//   bodies as a voxel map, the held body as a point shell, its force against the truth's contact
//   wrench at the same pose (the force the coupling balances), its stiffness fitted by least
//   squares on every fifth tick and scored on the others. Moving bodies are not in the voxel map
//   (McNeely's method voxelises a static scene): contacts with them are misses, and counted.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "bench/study/study.h"
#include "core/scene/loader.h"
#include "core/sim/output_shaping.h"
#include "core/sim/simulation.h"
#include "core/voxel/voxel_sampling.h"
#include "daemon/device/replay_device.h"

#ifndef HAPTICD_SOURCE_DIR
#define HAPTICD_SOURCE_DIR "."
#endif

namespace hapticd::study {
namespace {

using geom::Pose;
using geom::Transform;
using geom::Vec3;

struct TickRecord {
  Vec3 force{0.0}, torque{0.0};                  // to the device
  Vec3 contact_force{0.0}, contact_torque{0.0};  // the penalty wrench on the proxy
  Pose proxy;
  double ns = 0.0;
};

double nowNs() {
  return static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                 std::chrono::steady_clock::now().time_since_epoch())
                                 .count());
}

// Runs the tick over the stream; false with a message when something cannot be opened.
bool run(const std::shared_ptr<const scene::SceneModel>& model,
         const sim::SimOptions& options,
         const std::vector<proto::PoseStreamRow>& rows,
         std::size_t ticks,
         std::vector<TickRecord>& out) {
  auto created = sim::Simulation::create(model, options);
  if (!created.ok()) {
    std::fprintf(stderr, "study: %s: %s\n", model->name.c_str(), created.error().message.c_str());
    return false;
  }
  // the wrench a device would be sent: the simulation, then the one output stage
  const auto shaped = sim::withOutputStage(std::move(created).value(), options.response);
  auto& simulation = *shaped;
  device::ReplayDevice replay("study", rows, device::DeviceOptions{});
  const double overhead = timerOverheadNs();
  out.clear();
  out.reserve(ticks);
  for (std::size_t k = 0; k < ticks; ++k) {
    sim::TickInput in;
    in.t_s = static_cast<double>(k) * options.response.tick_s;
    in.X_W_device = replay.poseAt(in.t_s, &in.buttons);
    const double t0 = nowNs();
    const sim::TickOutput o = simulation.step(in);
    const double ns = nowNs() - t0 - overhead;
    out.push_back(
        {o.force_W_n, o.torque_W_nm, o.contact_force_W_n, o.contact_torque_W_nm, o.X_W_proxy, ns});
  }
  return true;
}

void scoreRun(Row& row, const std::vector<TickRecord>& truth, const std::vector<TickRecord>& got) {
  for (std::size_t k = 0; k < truth.size() && k < got.size(); ++k) {
    const bool t = glm::dot(truth[k].contact_force, truth[k].contact_force) > 0.0;
    const bool g = glm::dot(got[k].contact_force, got[k].contact_force) > 0.0;
    row.add(glm::length(got[k].force - truth[k].force),
            glm::length(got[k].torque - truth[k].torque), got[k].ns, t, g);
  }
}

}  // namespace

void runScenes(const Options& options, std::vector<Row>& rows) {
  (void)options;  // whole streams in both modes: a run costs a few microseconds per tick
  for (const char* name : {"peg_in_hole", "gears", "dynamic", "stress"}) {
    const std::string part = std::string("scene/") + name;
    const std::string glb = std::string(HAPTICD_SOURCE_DIR) + "/scenes/" + name + ".glb";
    const std::string csv = std::string(HAPTICD_SOURCE_DIR) + "/tests/streams/" + name + ".csv";
    scene::LoadReport report = scene::loadSceneFile(glb);
    if (!report.ok()) {
      std::fprintf(stderr, "study: %s: %s\n", glb.c_str(), report.message().c_str());
      continue;
    }
    auto model = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
    auto text = proto::readPoseStreamFile(csv);
    if (!text.ok()) {
      std::fprintf(stderr, "study: cannot read %s: %s\n", csv.c_str(),
                   text.error().message.c_str());
      continue;
    }
    auto parsed =
        proto::parsePoseStream(text.value(), csv, 1e-3, proto::PoseStreamDialect::kStrict);
    if (!parsed.ok()) {
      std::fprintf(stderr, "study: %s\n", parsed.error().message.c_str());
      continue;
    }
    const auto& stream = parsed.value();
    const sim::SimOptions base;
    const double span = stream.back().t_s;
    const auto ticks = static_cast<std::size_t>(span / base.response.tick_s);
    std::fprintf(stderr, "study: %s: %zu ticks per run\n", part.c_str(), ticks);

    std::vector<TickRecord> truth;
    if (!run(model, base, stream, ticks, truth))
      continue;
    {
      Row row{
          part, "hapticd-tick", "exact, budget unlimited, δ on (the truth)", {}, {}, {}, 0, 0, 0,
          0};
      scoreRun(row, truth, truth);
      rows.push_back(std::move(row));
    }
    for (const std::uint32_t budget : {8u, 4u, 2u, 1u}) {
      sim::SimOptions o = base;
      o.max_pairs_per_tick = budget;
      std::vector<TickRecord> got;
      if (!run(model, o, stream, ticks, got))
        continue;
      Row row{part,
              "hapticd-tick",
              "budget=" + std::to_string(budget) + " pairs/tick",
              {},
              {},
              {},
              0,
              0,
              0,
              0};
      scoreRun(row, truth, got);
      rows.push_back(std::move(row));
    }
    {
      sim::SimOptions o = base;
      o.response.predictive = false;
      std::vector<TickRecord> got;
      if (run(model, o, stream, ticks, got)) {
        Row row{part, "hapticd-tick", "δ off", {}, {}, {}, 0, 0, 0, 0};
        scoreRun(row, truth, got);
        rows.push_back(std::move(row));
      }
    }

    // voxel sampling at the truth's proxy poses
    const std::int32_t held = model->probe_body;
    if (held < 0) {
      std::fprintf(stderr, "study: %s: no probe body: voxel sampling left out\n", part.c_str());
      continue;
    }
    std::vector<voxel::PlacedShape> statics, shell_shapes;
    for (const auto& body : model->bodies) {
      if (body.motion != scene::Motion::kStatic)
        continue;
      for (const auto& p : body.primitives) {
        statics.push_back({p.shape.get(), (body.X_WB.toTransform() * p.X_BP.toTransform())});
      }
    }
    const scene::Body& hb = model->bodies[static_cast<std::size_t>(held)];
    for (const auto& p : hb.primitives)
      shell_shapes.push_back({p.shape.get(), p.X_BP.toTransform()});
    if (statics.empty() || shell_shapes.empty())
      continue;
    double size = 0.0;
    for (const auto& s : shell_shapes)
      size = std::max(size, s.shape->radius());
    for (const double fraction : {0.1, 0.05, 0.025}) {
      const double h = fraction * size;
      auto map = voxel::VoxelMap::build(statics, h);
      auto shell = voxel::makePointShell(shell_shapes, h);
      if (!map.ok() || !shell.ok()) {
        std::fprintf(stderr, "study: %s: voxel h=%g: %s\n", part.c_str(), h,
                     (!map.ok() ? map.error() : shell.error()).message.c_str());
        continue;
      }
      const auto com = [&](const Pose& X) { return X.toTransform().apply(hb.com_B); };
      double num = 0.0, den = 0.0;
      for (std::size_t k = 0; k < truth.size(); k += 5) {  // fitted on every fifth tick
        const auto u = voxel::force(map.value(), shell.value(), truth[k].proxy.toTransform(),
                                    com(truth[k].proxy), 1.0);
        num += glm::dot(u.force_W, truth[k].contact_force);
        den += glm::dot(u.force_W, u.force_W);
      }
      const double kp = den > 0.0 ? num / den : 0.0;
      char setting[96];
      std::snprintf(setting, sizeof setting, "h=%.3gmm (open loop)", h * 1e3);
      Row row{part, "voxel-McNeely", setting, {}, {}, {}, 0, 0, 0, 0};
      const double overhead = timerOverheadNs();
      for (std::size_t k = 0; k < truth.size(); ++k) {
        if (k % 5 == 0)
          continue;  // scored on the other ticks
        const TickRecord& t = truth[k];
        const double t0 = nowNs();
        const auto f =
            voxel::force(map.value(), shell.value(), t.proxy.toTransform(), com(t.proxy), kp);
        const double ns = nowNs() - t0 - overhead;
        row.add(glm::length(f.force_W - t.contact_force),
                glm::length(f.torque_W - t.contact_torque), ns,
                glm::dot(t.contact_force, t.contact_force) > 0.0, f.points_in_contact > 0);
      }
      rows.push_back(std::move(row));
    }
  }
}

}  // namespace hapticd::study
