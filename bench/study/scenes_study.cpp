// The scene part of the accuracy study: each demo scene replayed from its pose stream through the
// whole tick (core/sim), with the settings that trade accuracy for time, against the same tick at
// its most accurate settings.
//
// - Closed loop (bench/study/scene_study.h, shared with `hapticctl study`): the scheduler budget
//   (pairs tested per tick: unlimited, 8, 4, 2, 1), the predictive distance δ of §5.2 on and off,
//   and the tessellation tolerance of curved shapes. Each run is the real tick, so its error is
//   what the hand would feel: the force and torque sent to the device, against the truth run's,
//   tick by tick on the same pose stream.
// - Open loop: voxel sampling (McNeely et al. 1999) at the truth run's proxy poses: the static
//   bodies as a voxel map, the held body as a point shell, its force against the truth's contact
//   wrench at the same pose (the force the coupling balances), its stiffness fitted by least
//   squares on every fifth tick and scored on the others. Moving bodies are not in the voxel map
//   (McNeely's method voxelises a static scene): contacts with them are misses, and counted.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "bench/study/scene_study.h"
#include "bench/study/study.h"
#include "core/scene/loader.h"
#include "core/voxel/voxel_sampling.h"

#ifndef HAPTICD_SOURCE_DIR
#define HAPTICD_SOURCE_DIR "."
#endif

namespace hapticd::study {
namespace {

using geom::Pose;

}  // namespace

void runScenes(const Options& options, std::vector<Row>& rows) {
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
    SceneStudyOptions so;
    so.max_seconds = options.quick ? 3.0 : 0.0;  // quick: the first 3 s of each stream
    so.rate_multiples = {2, 4};                  // 2 and 4 kHz beside the truth's 1 kHz
    so.progress = [&](const std::string& line) {
      std::fprintf(stderr, "study: %s %s\n", part.c_str(), line.c_str());
    };
    std::vector<TruthTick> truth;
    auto ran = runSceneStudy(part, glb, model, stream, so, rows, &truth);
    if (!ran.ok()) {
      std::fprintf(stderr, "study: %s: %s\n", part.c_str(), ran.error().message.c_str());
      continue;
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
      const double overhead = threadClockOverheadNs();
      for (std::size_t k = 0; k < truth.size(); ++k) {
        if (k % 5 == 0)
          continue;  // scored on the other ticks
        const TruthTick& t = truth[k];
        const double t0 = threadNowNs();
        const auto f =
            voxel::force(map.value(), shell.value(), t.proxy.toTransform(), com(t.proxy), kp);
        const double ns = threadNowNs() - t0 - overhead;
        row.add(glm::length(f.force_W - t.contact_force),
                glm::length(f.torque_W - t.contact_torque), ns,
                glm::dot(t.contact_force, t.contact_force) > 0.0, f.points_in_contact > 0);
      }
      rows.push_back(std::move(row));
    }
  }
}

}  // namespace hapticd::study
