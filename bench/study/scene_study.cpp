// The closed-loop study of one scene and stream (bench/study/scene_study.h): the runs, the
// approach stream for a scene without one, and the recommendation.
#include "bench/study/scene_study.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <sstream>

#include "core/collision/pair_query.h"
#include "core/sim/output_shaping.h"
#include "core/sim/simulation.h"

namespace hapticd::study {
namespace {

using geom::Pose;
using geom::Vec3;

struct TickRecord {
  Vec3 force{0.0}, torque{0.0};  // to the device
  TruthTick truth;
  double ns = 0.0;
  // with dynamics: the dynamic bodies' positions (by body index order) and their energy
  std::vector<Vec3> positions;
  double energy_j = 0.0;
  bool unanswered = false;  // a closed-loop method left a pair query unanswered this tick
};

std::string fmt(double x, const char* f = "%.3g") {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

sim::SimOptions simOptions(const Knobs& k, const SceneStudyOptions& options) {
  sim::SimOptions o;
  o.response.tick_s = 1.0 / (options.rate_hz * k.rate_multiple);
  o.max_pairs_per_tick = k.max_pairs_per_tick;
  o.probe_sphere_radius_m = options.probe_sphere_radius_m;
  o.response.predictive = k.predictive;
  o.dynamics_velocity_iterations = k.velocity_iterations;
  o.dynamics_position_iterations = k.position_iterations;
  o.dynamics_velocity_iterations_max = k.velocity_iterations_max;
  o.dynamics_position_iterations_max = k.position_iterations_max;
  const sim::ResponseOptions defaults;
  o.response.max_force_step_n = k.max_force_step_n;
  o.response.max_torque_step_nm =
      k.max_force_step_n * defaults.max_torque_step_nm / defaults.max_force_step_n;
  o.response.crease_angle_deg = k.crease_angle_deg;
  return o;
}

// Runs the tick over the stream (the simulation, then the one output stage).
Result<bool> run(const std::shared_ptr<const scene::SceneModel>& model,
                 const sim::SimOptions& options,
                 const std::vector<proto::PoseStreamRow>& stream,
                 std::size_t ticks,
                 std::vector<TickRecord>& out) {
  auto created = sim::Simulation::create(model, options);
  if (!created.ok())
    return Error{model->name + ": " + created.error().message};
  const auto shaped = sim::withOutputStage(std::move(created).value(), options.response);
  auto& simulation = *shaped;
  const double overhead = threadClockOverheadNs();
  std::size_t cursor = 0;
  out.clear();
  out.reserve(ticks);
  const scene::SceneModel& sc = *model;
  const bool dynamics = std::any_of(sc.bodies.begin(), sc.bodies.end(), [](const scene::Body& b) {
    return b.motion == scene::Motion::kDynamic;
  });
  const auto* loop = dynamic_cast<const LoopQuery*>(options.query_method);
  for (std::size_t k = 0; k < ticks; ++k) {
    sim::TickInput in;
    in.t_s = static_cast<double>(k) * options.response.tick_s;
    const proto::PoseStreamRow s = proto::samplePoseStream(stream, in.t_s, cursor);
    in.X_W_device = s.X_WD;
    in.buttons = s.buttons;
    const std::uint64_t unanswered = loop != nullptr ? loop->unanswered : 0;
    const double t0 = threadNowNs();
    const sim::TickOutput o = simulation.step(in);
    const double ns = std::max(0.0, threadNowNs() - t0 - overhead);
    out.push_back({o.force_W_n,
                   o.torque_W_nm,
                   {o.X_W_proxy, o.contact_force_W_n, o.contact_torque_W_nm},
                   ns,
                   {},
                   0.0,
                   loop != nullptr && loop->unanswered != unanswered});
    if (dynamics) {
      // outside the timed step: the bodies' state for the drift and the energy
      TickRecord& r = out.back();
      for (const sim::BodyPose& b : simulation.bodyPoses()) {
        if (b.body < sc.bodies.size() && sc.bodies[b.body].motion == scene::Motion::kDynamic)
          r.positions.push_back(b.X_WB.translation);
      }
      const sim::DynamicsStatus d = simulation.dynamicsStatus();
      r.energy_j = d.kinetic_energy_j + d.potential_energy_j;
    }
  }
  return true;
}

// Every tick of `got` counts for the time; its errors are scored at the truth's tick times (every
// m-th tick of a run at m times the rate).
void score(Row& row,
           const std::vector<TickRecord>& truth,
           const std::vector<TickRecord>& got,
           std::size_t m = 1) {
  for (std::size_t k = 0; k < truth.size() && k * m < got.size(); ++k) {
    const TickRecord& g = got[k * m];
    const bool t = glm::dot(truth[k].truth.contact_force, truth[k].truth.contact_force) > 0.0;
    const bool c = glm::dot(g.truth.contact_force, g.truth.contact_force) > 0.0;
    row.add(glm::length(g.force - truth[k].force), glm::length(g.torque - truth[k].torque), g.ns, t,
            c);
    if (g.unanswered)
      ++row.no_answer;
    if (!truth[k].positions.empty() && g.positions.size() == truth[k].positions.size()) {
      double drift = 0.0;
      for (std::size_t i = 0; i < g.positions.size(); ++i)
        drift = std::max(drift, glm::length(g.positions[i] - truth[k].positions[i]));
      row.drift_m.push_back(drift);
      row.energy_err_j.push_back(std::abs(g.energy_j - truth[k].energy_j));
    }
  }
  // the times of the ticks between
  if (m > 1) {
    for (std::size_t i = 0; i < got.size(); ++i) {
      if (i % m != 0)
        row.time_ns.push_back(got[i].ns);
    }
  }
}

bool curved(const scene::SceneModel& s) {
  for (const scene::Body& b : s.bodies) {
    for (const scene::Primitive& p : b.primitives) {
      if (p.source == scene::ShapeSource::kSphere || p.source == scene::ShapeSource::kCapsule ||
          p.source == scene::ShapeSource::kCylinder)
        return true;
    }
  }
  return false;
}

}  // namespace

std::vector<PlannedRun> planRuns(const scene::SceneModel& scene,
                                 const std::vector<std::uint32_t>& rate_multiples,
                                 double rate_hz) {
  std::vector<PlannedRun> runs;
  runs.push_back({kTruthSetting, Knobs{}});
  for (const std::uint32_t budget : {8u, 4u, 2u, 1u}) {
    Knobs k;
    k.max_pairs_per_tick = budget;
    runs.push_back({"budget=" + std::to_string(budget) + " pairs/tick", k});
  }
  Knobs off;
  off.predictive = false;
  runs.push_back({"δ off", off});
  if (curved(scene)) {
    for (const double tol : {0.003, 0.01, 0.03}) {
      Knobs k;
      k.tessellation_tolerance = tol;
      runs.push_back({"tessellation=" + fmt(tol, "%g"), k});
    }
  }
  for (const std::uint32_t m : rate_multiples) {
    Knobs k;
    k.rate_multiple = m;
    runs.push_back({"servo rate=" + fmt(rate_hz * m / 1e3, "%g") + " kHz", k});
  }
  return runs;
}

std::optional<Knobs> knobsOf(const std::string& setting) {
  if (setting == kTruthSetting)
    return Knobs{};
  Knobs k;
  const std::string pre = "budget=", post = " pairs/tick";
  if (setting.size() > pre.size() + post.size() && setting.rfind(pre, 0) == 0 &&
      setting.compare(setting.size() - post.size(), post.size(), post) == 0) {
    const std::string n = setting.substr(pre.size(), setting.size() - pre.size() - post.size());
    if (n.size() <= 9 &&
        std::all_of(n.begin(), n.end(), [](char c) { return c >= '0' && c <= '9'; }) && n != "0") {
      k.max_pairs_per_tick = static_cast<std::uint32_t>(std::stoul(n));
      return k;
    }
  }
  const std::string tess = "tessellation=";
  if (setting.rfind(tess, 0) == 0) {
    char* end = nullptr;
    const double tol = std::strtod(setting.c_str() + tess.size(), &end);
    if (end != nullptr && *end == '\0' && std::isfinite(tol) && tol > 0.0 && tol < 0.5) {
      k.tessellation_tolerance = tol;
      return k;
    }
  }
  return std::nullopt;
}

Result<bool> runSweep(const std::string& part,
                      const std::shared_ptr<const scene::SceneModel>& model,
                      const std::vector<proto::PoseStreamRow>& stream,
                      const SceneStudyOptions& options,
                      const std::vector<PlannedRun>& runs,
                      std::vector<Row>& rows) {
  const std::size_t ticks = ticksOf(stream, options);
  // the ticks of each distinct setting, in the order first met
  std::vector<std::pair<std::optional<Knobs>, std::vector<TickRecord>>> done;
  std::size_t index = 0;
  for (const PlannedRun& planned : runs) {
    ++index;
    Knobs k = planned.knobs;
    k.rate_multiple = 1;
    // a run of another scene or method is its own; runs of the same knobs share their ticks
    const bool own = planned.model != nullptr || planned.method.make != nullptr;
    const auto same = own ? done.end() : std::find_if(done.begin(), done.end(), [&](const auto& d) {
      return d.first.has_value() && *d.first == k;
    });
    const std::vector<TickRecord>* got = nullptr;
    if (same != done.end()) {
      got = &same->second;
    } else {
      std::vector<TickRecord> ran;
      sim::SimOptions so = simOptions(k, options);
      const std::unique_ptr<LoopQuery> query =
          planned.method.make ? planned.method.make() : nullptr;
      so.query_method = query.get();
      auto r = run(planned.model ? planned.model : model, so, stream, ticks, ran);
      if (!r.ok())
        return Error{part + " at " + planned.setting + ": " + r.error().message};
      done.emplace_back(own ? std::nullopt : std::optional<Knobs>(k), std::move(ran));
      got = &done.back().second;
    }
    Row row{part,
            planned.method.make ? planned.method.name : "hapticd-tick",
            planned.setting,
            {},
            {},
            {},
            0,
            0,
            0,
            0,
            {},
            {}};
    score(row, done.front().second, *got);
    if (options.progress) {
      const Stats t = stats(row.time_ns), f = stats(row.force_err_n), d = stats(row.drift_m);
      options.progress("[" + std::to_string(index) + "/" + std::to_string(runs.size()) + "] " +
                       planned.setting + ": p99.9 tick " + fmt(t.p999 / 1e3) +
                       " µs, p99 force error " + fmt(f.p99) + " N" +
                       (row.drift_m.empty() ? "" : ", largest drift " + fmt(d.max * 1e3) + " mm"));
    }
    rows.push_back(std::move(row));
  }
  return true;
}

std::size_t ticksOf(const std::vector<proto::PoseStreamRow>& stream,
                    const SceneStudyOptions& options) {
  double span = stream.empty() ? 0.0 : stream.back().t_s;
  if (options.max_seconds > 0.0)
    span = std::min(span, options.max_seconds);
  return static_cast<std::size_t>(span * options.rate_hz) + 1;
}

Result<std::pair<double, double>> probeTickNs(const std::shared_ptr<const scene::SceneModel>& model,
                                              const std::vector<proto::PoseStreamRow>& stream,
                                              const SceneStudyOptions& options,
                                              std::size_t ticks) {
  std::vector<TickRecord> got;
  auto r = run(model, simOptions(Knobs{}, options), stream, ticks, got);
  if (!r.ok())
    return r.error();
  std::vector<double> ns;
  ns.reserve(got.size());
  for (const TickRecord& t : got)
    ns.push_back(t.ns);
  const Stats s = stats(ns);
  return std::pair<double, double>{s.mean, s.p999};
}

Result<bool> runSceneStudy(const std::string& part,
                           const std::filesystem::path& file,
                           const std::shared_ptr<const scene::SceneModel>& model,
                           const std::vector<proto::PoseStreamRow>& stream,
                           const SceneStudyOptions& options,
                           std::vector<Row>& rows,
                           std::vector<TruthTick>* truth_proxy) {
  const std::size_t ticks = ticksOf(stream, options);
  const auto runs = planRuns(*model, options.rate_multiples, options.rate_hz);
  std::vector<TickRecord> truth;
  std::size_t index = 0;
  for (const PlannedRun& planned : runs) {
    ++index;
    std::shared_ptr<const scene::SceneModel> m = model;
    if (planned.knobs.tessellation_tolerance != options.load.limits.tessellation_tolerance) {
      scene::LoadOptions load = options.load;
      load.limits.tessellation_tolerance = planned.knobs.tessellation_tolerance;
      scene::LoadReport report = scene::loadSceneFile(file, load);
      if (!report.ok())
        return Error{file.string() + " at " + planned.setting + ": " + report.message()};
      m = std::make_shared<const scene::SceneModel>(std::move(*report.scene));
    }
    std::vector<TickRecord> got;
    const std::size_t mult = planned.knobs.rate_multiple;
    auto ran = run(m, simOptions(planned.knobs, options), stream, (ticks - 1) * mult + 1, got);
    if (!ran.ok())
      return ran.error();
    if (index == 1)
      truth = got;
    Row row{part, "hapticd-tick", planned.setting, {}, {}, {}, 0, 0, 0, 0, {}, {}};
    score(row, truth, got, mult);
    if (options.progress) {
      const Stats t = stats(row.time_ns), f = stats(row.force_err_n);
      options.progress("[" + std::to_string(index) + "/" +
                       std::to_string(runs.size() + options.loop_methods.size()) + "] " +
                       planned.setting + ": " + std::to_string(got.size()) + " ticks, p99.9 tick " +
                       fmt(t.p999 / 1e3) + " µs, p99 force error " + fmt(f.p99) + " N");
    }
    rows.push_back(std::move(row));
  }
  // the methods inside the closed loop, at the default settings
  for (const LoopMethod& method : options.loop_methods) {
    ++index;
    const std::unique_ptr<LoopQuery> query = method.make();
    sim::SimOptions so = simOptions(Knobs{}, options);
    so.query_method = query.get();
    std::vector<TickRecord> got;
    auto ran = run(model, so, stream, ticks, got);
    if (!ran.ok())
      return Error{part + " with " + method.name + ": " + ran.error().message};
    Row row{part, method.name, "closed loop", {}, {}, {}, 0, 0, 0, 0, {}, {}};
    score(row, truth, got);
    if (options.progress) {
      const Stats t = stats(row.time_ns), f = stats(row.force_err_n);
      options.progress("[" + std::to_string(index) + "/" +
                       std::to_string(runs.size() + options.loop_methods.size()) + "] " +
                       method.name + " (closed loop): p99.9 tick " + fmt(t.p999 / 1e3) +
                       " µs, p99 force error " + fmt(f.p99) + " N, ticks with a query unanswered " +
                       std::to_string(row.no_answer));
    }
    rows.push_back(std::move(row));
  }
  if (truth_proxy != nullptr) {
    truth_proxy->clear();
    for (const TickRecord& t : truth)
      truth_proxy->push_back(t.truth);
  }
  return true;
}

// --- the approach stream -------------------------------------------------------------------------

namespace {

struct Placed {
  const geom::Polytope* shape;
  geom::Transform X_WP;
};

std::vector<Placed> placed(const scene::Body& b, const Pose& X_WB) {
  std::vector<Placed> out;
  for (const scene::Primitive& p : b.primitives) {
    if (!p.trigger)
      out.push_back({p.shape.get(), X_WB.toTransform() * p.X_BP.toTransform()});
  }
  return out;
}

// Smallest signed distance between two sets of placed convex shapes (+inf when either is empty).
double distance(const std::vector<Placed>& a, const std::vector<Placed>& b) {
  double d = std::numeric_limits<double>::infinity();
  for (const Placed& p : a) {
    for (const Placed& q : b) {
      collision::PairCache cache;
      const auto r = collision::queryPair(*p.shape, *q.shape, p.X_WP.inverse() * q.X_WP, cache);
      d = std::min(d, r.distance);
    }
  }
  return d;
}

double smooth(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

Vec3 anyPerpendicular(const Vec3& u) {
  const Vec3 a = std::abs(u.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  return glm::normalize(glm::cross(u, a));
}

}  // namespace

std::vector<proto::PoseStreamRow> approachStream(const scene::SceneModel& scene, double scale) {
  // the held body, its size, and the nearest other body (by centre)
  Pose X0;
  double r = 0.01;  // the config's default probe sphere
  Vec3 dir(0.0, -1.0, 0.0);
  double contact = 0.0, stiffness = 600.0;
  // the scene's highest point (y up): a probe sphere coming straight down onto it touches it
  // first, whatever the shape (the middle of the bounding box may be empty: an arch, a dragon)
  Vec3 top(0.0);
  bool any = false;
  for (const scene::Body& b : scene.bodies) {
    if (!b.active)
      continue;
    for (const Placed& p : placed(b, b.X_WB)) {
      for (const auto& v : p.shape->vertices()) {
        const Vec3 w = p.X_WP.apply(v.p);
        if (!any || w.y > top.y)
          top = w;
        any = true;
      }
    }
  }
  if (scene.probe_body >= 0) {
    const scene::Body& held = scene.bodies[static_cast<std::size_t>(scene.probe_body)];
    X0 = held.X_WB;
    if (held.stiffness_n_per_m)
      stiffness = *held.stiffness_n_per_m;
    double radius = 0.0;
    for (const Placed& p : placed(held, held.X_WB))
      radius = std::max(radius, glm::length(p.X_WP.apply(p.shape->centroid()) - X0.translation) +
                                    p.shape->radius());
    if (radius > 0.0)
      r = radius;
    const Vec3 c0 = X0.toTransform().apply(held.com_B);
    const scene::Body* target = nullptr;
    double best = std::numeric_limits<double>::infinity();
    Vec3 target_c(0.0);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const scene::Body& b = scene.bodies[i];
      if (static_cast<std::int32_t>(i) == scene.probe_body || !b.active)
        continue;
      for (const Placed& p : placed(b, b.X_WB)) {
        const Vec3 c = p.X_WP.apply(p.shape->centroid());
        const double d = glm::length(c - c0) - p.shape->radius();
        if (d < best) {
          best = d;
          target = &b;
          target_c = c;
        }
      }
    }
    if (target != nullptr && glm::length(target_c - c0) > 0.0) {
      dir = glm::normalize(target_c - c0);
      if (target->stiffness_n_per_m)
        stiffness = *target->stiffness_n_per_m;
      // march along dir until the held body touches the target (in steps of r/20)
      const double span = glm::length(target_c - c0) + r;
      const auto others = placed(*target, target->X_WB);
      contact = span;
      for (double s = 0.0; s <= span; s += r / 20.0) {
        Pose X = X0;
        X.translation += s * dir;
        if (distance(placed(held, X), others) <= 0.0) {
          contact = s;
          break;
        }
      }
    } else {
      contact = 2.0 * r;
    }
  } else if (any) {
    // a probe sphere from above the scene, straight down onto its highest point (touching at 2r)
    X0.translation = top + Vec3(0.0, 3.0 * r, 0.0);
    contact = 2.0 * r;
  }
  // about 4 N into the surface, at most a quarter of the held body's size
  const double depth = std::min(0.25 * r, 4.0 / stiffness);
  const Vec3 side = anyPerpendicular(dir);
  const double T = std::max(scale, 0.05);
  const Vec3 near_point = X0.translation + std::max(0.0, contact - 0.5 * r) * dir;
  const Vec3 pressed = X0.translation + (contact + depth) * dir;
  std::vector<proto::PoseStreamRow> rows;
  const double end = 6.5 * T;
  for (int i = 0;; ++i) {
    const double t = i * 0.01;  // rows at 100 Hz; the replay interpolates
    if (t > end + 1e-9)
      break;
    const double u = t / T;
    Vec3 p = X0.translation;
    double tilt = 0.0;
    if (u < 0.3) {
      p = X0.translation;
    } else if (u < 1.5) {
      p = glm::mix(X0.translation, near_point, smooth((u - 0.3) / 1.2));
    } else if (u < 2.5) {
      p = glm::mix(near_point, pressed, smooth(u - 1.5));
    } else if (u < 4.5) {
      p = pressed + 0.5 * r * std::sin(M_PI * (u - 2.5)) * side;
    } else if (u < 5.5) {
      p = pressed;
      tilt = 0.15 * std::sin(2.0 * M_PI * (u - 4.5));  // about 9 degrees each way
    } else {
      p = glm::mix(pressed, X0.translation, smooth(u - 5.5));
    }
    Pose X = X0;
    X.translation = p;
    X.rotation = glm::normalize(glm::angleAxis(tilt, side) * X0.rotation);
    rows.push_back({t, X, 0});
  }
  return rows;
}

std::string poseStreamCsv(const std::vector<proto::PoseStreamRow>& rows) {
  std::ostringstream out;
  out.precision(17);
  out << "t,px,py,pz,qx,qy,qz,qw,buttons\n";
  for (const auto& r : rows) {
    const auto& q = r.X_WD.rotation;
    out << r.t_s << ',' << r.X_WD.translation.x << ',' << r.X_WD.translation.y << ','
        << r.X_WD.translation.z << ',' << q.x << ',' << q.y << ',' << q.z << ',' << q.w << ','
        << r.buttons << '\n';
  }
  return out.str();
}

// --- the decision
// ---------------------------------------------------------------------------------

Recommendation recommend(const std::vector<const Summary*>& rows, double budget_ns) {
  Recommendation best, fastest;
  const auto better = [](const Summary* a, const Summary* b) {
    if (a->force_n.p99 != b->force_n.p99)
      return a->force_n.p99 < b->force_n.p99;
    if (a->force_n.mean != b->force_n.mean)
      return a->force_n.mean < b->force_n.mean;
    return a->time_ns.p999 < b->time_ns.p999;
  };
  for (const Summary* r : rows) {
    const auto k = knobsOf(r->setting);
    if (!k)
      continue;
    if (r->time_ns.p999 <= budget_ns && (best.row == nullptr || better(r, best.row)))
      best = {r, *k, true};
    if (fastest.row == nullptr || r->time_ns.p999 < fastest.row->time_ns.p999)
      fastest = {r, *k, false};
  }
  return best.row != nullptr ? best : fastest;
}

std::string configSnippet(const Knobs& knobs, const std::vector<std::string>& comment) {
  std::string s;
  for (const std::string& c : comment)
    s += "# " + c + "\n";
  s += "[response]\nmax_pairs_per_tick = " + std::to_string(knobs.max_pairs_per_tick) + "\n\n";
  s += "[scene]\ntessellation_tolerance = " + fmt(knobs.tessellation_tolerance, "%g") + "\n";
  return s;
}

}  // namespace hapticd::study
