#pragma once
/// \file
/// The closed-loop part of the accuracy study on one scene and pose stream, shared by
/// `hapticstudy` (the demo scenes, docs/accuracy.md) and `hapticctl study` (the user's scene): the
/// real tick (core/sim with the one output stage) replayed from the stream on simulated time, once
/// at its most accurate settings (the truth) and once per setting of each knob that trades accuracy
/// for time, each run's force and torque against the truth's at the same tick. Then the decision:
/// the most accurate settings whose p99.9 tick fits a budget, as a config snippet.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench/study/report.h"
#include "bench/study/study.h"
#include "core/collision/collision_world.h"
#include "core/common/result.h"
#include "core/scene/loader.h"
#include "core/sim/simulation.h"
#include "protocol/pose_stream.h"

namespace hapticd::study {

/// The settings of one run, as the daemon's config names them (`[response] max_pairs_per_tick`,
/// `[scene] tessellation_tolerance`), plus the predictive distance, which no config key turns off.
struct Knobs {
  std::uint32_t max_pairs_per_tick = 0;  ///< 0: no limit
  double tessellation_tolerance = 1e-3;  ///< the loader's default
  bool predictive = true;
  /// The servo rate as a multiple of the study's (1: the study's rate). A run at m times the rate
  /// takes m ticks per truth tick and is scored at the truth's tick times. The user sets the rate
  /// (`[servo] rate_hz`, `hapticctl study --rate`): no recommendation changes it.
  std::uint32_t rate_multiple = 1;
  /// The dynamics solver's iterations (`[response] dynamics_velocity_iterations`,
  /// `dynamics_position_iterations`).
  std::uint32_t velocity_iterations = sim::SimOptions{}.dynamics_velocity_iterations;
  std::uint32_t position_iterations = sim::SimOptions{}.dynamics_position_iterations;
  /// The settling iterations beyond them (`dynamics_velocity_iterations_max`,
  /// `dynamics_position_iterations_max`; at most the counts above: none).
  std::uint32_t velocity_iterations_max = sim::SimOptions{}.dynamics_velocity_iterations_max;
  std::uint32_t position_iterations_max = sim::SimOptions{}.dynamics_position_iterations_max;
  /// The output stage's step limit F_max (`[device] max_force_step_n`, N per tick); its torque
  /// twin (`max_torque_step_nm`) is scaled with it, in the default ratio.
  double max_force_step_n = sim::ResponseOptions{}.max_force_step_n;
  /// Force shading across edges bent less than this (`[response] crease_angle_deg`; 0: off).
  double crease_angle_deg = sim::ResponseOptions{}.crease_angle_deg;

  bool operator==(const Knobs&) const = default;
};

/// The truth's setting text (its row in the tables).
inline constexpr const char* kTruthSetting = "exact, budget unlimited, δ on (the truth)";

/// A method answering the tick's pair queries inside the closed loop in place of its own
/// (bench/study/loop_methods.h has hapticstudy's), counting the queries it could not answer
/// (answered as far apart: no force).
class LoopQuery : public collision::PairQueryMethod {
 public:
  std::uint64_t unanswered = 0;

 protected:
  /// `out` as far apart, with no plane (no force; the pair is asked again next step).
  static void farApart(collision::PairResult& out, collision::PairCache& cache) {
    out.status = collision::ContactStatus::kSeparated;
    out.distance = std::numeric_limits<double>::max();
    out.normal = geom::Vec3{1.0, 0.0, 0.0};
    out.point_a = out.point_b = geom::Vec3{0.0};
    out.fa = out.fb = collision::Feature{};
    out.manifold.count = 0;
    out.manifold.truncated = false;
    out.iterations = 0;
    cache.penetrating = false;
  }
};

/// A closed-loop method: its name (the method family of its row) and a new instance per run.
struct LoopMethod {
  std::string name;
  std::function<std::unique_ptr<LoopQuery>()> make;
};

/// One run of the sweep: its setting text (the table's), its knobs.
struct PlannedRun {
  PlannedRun() = default;
  PlannedRun(std::string setting_text, const Knobs& run_knobs)
      : setting(std::move(setting_text)), knobs(run_knobs) {}

  std::string setting;
  Knobs knobs;
  /// runSweep only: this run's scene instead of the sweep's (null: the sweep's).
  std::shared_ptr<const scene::SceneModel> model;
  /// runSweep only: another method answers every pair query of this run (its row's method is the
  /// method's name; empty `make`: the tick's own, row method "hapticd-tick").
  LoopMethod method;
};

/// The runs of a scene's study, the truth first: the scheduler budget (8, 4, 2, 1 pairs per tick),
/// δ off, and, when the scene has curved implicit shapes (sphere, capsule, cylinder), the
/// tessellation tolerance 0.003, 0.01 and 0.03 (coarser than the truth's 0.001); then the servo
/// rate at each of `rate_multiples` times the study's.
std::vector<PlannedRun> planRuns(const scene::SceneModel& scene,
                                 const std::vector<std::uint32_t>& rate_multiples = {},
                                 double rate_hz = 1000.0);

/// The knobs a setting text stands for, when the config can express them (nullopt for δ off and
/// for any text this study does not write).
std::optional<Knobs> knobsOf(const std::string& setting);

/// What to run.
struct SceneStudyOptions {
  double rate_hz = 1000.0;  ///< servo rate: the response's tick is 1 / rate_hz
  /// Runs at these multiples of rate_hz too (hapticstudy: 2 and 4, for 2 and 4 kHz).
  std::vector<std::uint32_t> rate_multiples;
  /// At most this many seconds of the stream (0: all of it).
  double max_seconds = 0.0;
  /// The probe sphere's radius for a scene without a probe body (SimOptions).
  double probe_sphere_radius_m = sim::SimOptions{}.probe_sphere_radius_m;
  /// Base load options (limits, decomposition); each run's tessellation tolerance is its own.
  scene::LoadOptions load;
  /// One line per run as it ends ("[3/9] budget=4 pairs/tick: ..."); may be empty.
  std::function<void(const std::string&)> progress;
  /// After the planned runs (runSceneStudy): one run per method at the default settings, every
  /// pair query the method's, scored against the truth like the others (row method: its name,
  /// setting "closed loop"; `no_answer`: the ticks in which it left a query unanswered).
  std::vector<LoopMethod> loop_methods;
};

/// A sweep with a truth of its own (hapticstudy's knob parts): `runs[0]` is the truth, every run
/// (the truth's own row included) is scored against it tick by tick at the study's rate: the
/// force and torque to the device and, for a scene with dynamic bodies, the drift of their
/// positions and the difference of their energy (Row::drift_m, Row::energy_err_j). Runs with the
/// same knobs as an earlier one reuse its ticks (a default that lies on two lines). Appends one
/// row per run (part `part`, method "hapticd-tick"). The knobs' tessellation and rate are not
/// swept here (they stay at the model's and options.rate_hz). Error when the scene does not
/// simulate at a setting.
Result<bool> runSweep(const std::string& part,
                      const std::shared_ptr<const scene::SceneModel>& model,
                      const std::vector<proto::PoseStreamRow>& stream,
                      const SceneStudyOptions& options,
                      const std::vector<PlannedRun>& runs,
                      std::vector<Row>& rows);

/// The number of ticks a run takes over `stream` at `options`.
std::size_t ticksOf(const std::vector<proto::PoseStreamRow>& stream,
                    const SceneStudyOptions& options);

/// Measures the truth's time per tick over its first `ticks` ticks: {mean, p99.9} in ns (for the
/// estimate before a study starts). Error when the scene does not simulate.
Result<std::pair<double, double>> probeTickNs(const std::shared_ptr<const scene::SceneModel>& model,
                                              const std::vector<proto::PoseStreamRow>& stream,
                                              const SceneStudyOptions& options,
                                              std::size_t ticks);

/// Runs every planned run of `file` (already loaded as `model` at the base options) over `stream`;
/// appends one row per run to `rows` (part `part`, method "hapticd-tick"). The proxy poses of the
/// truth run go to `truth_proxy` when it is not null (the open-loop methods use them), with the
/// truth's contact wrench. Error when the scene does not simulate or a tessellation reload fails.
struct TruthTick {
  geom::Pose proxy;
  geom::Vec3 contact_force{0.0}, contact_torque{0.0};
};
Result<bool> runSceneStudy(const std::string& part,
                           const std::filesystem::path& file,
                           const std::shared_ptr<const scene::SceneModel>& model,
                           const std::vector<proto::PoseStreamRow>& stream,
                           const SceneStudyOptions& options,
                           std::vector<Row>& rows,
                           std::vector<TruthTick>* truth_proxy = nullptr);

/// A pose stream for a scene that comes without one: the held body (or, without a probe body, the
/// config's probe sphere above the scene's highest point) rests, approaches the nearest other body
/// until it touches it, presses in (about 4 N at the body's stiffness), slides across and tilts
/// while pressing, and backs out. `seconds` scales the whole path (about 6.5 s at 1).
std::vector<proto::PoseStreamRow> approachStream(const scene::SceneModel& scene,
                                                 double scale = 1.0);

/// The CSV text of a pose stream (the interface format).
std::string poseStreamCsv(const std::vector<proto::PoseStreamRow>& rows);

/// The decision: of the rows whose settings the config can express (knobsOf), the one with the
/// smallest p99 force error (then mean force error, then p99.9 tick) whose p99.9 tick fits
/// `budget_ns`. When none fits: the one with the smallest p99.9 tick, `fits` false.
struct Recommendation {
  const Summary* row = nullptr;  ///< null when no row is expressible
  Knobs knobs;
  bool fits = false;
};
Recommendation recommend(const std::vector<const Summary*>& rows, double budget_ns);

/// The config snippet of a recommendation: `comment` lines first (each prefixed "# "), then
/// [response] max_pairs_per_tick and [scene] tessellation_tolerance.
std::string configSnippet(const Knobs& knobs, const std::vector<std::string>& comment);

}  // namespace hapticd::study
