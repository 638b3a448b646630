#include "client/query.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/collision/pair_query.h"
#include "protocol/wire.h"  // nameOf

namespace hapticd::client {
namespace {

using json = nlohmann::ordered_json;
using geom::Pose;
using geom::Vec3;

// The most pair queries one line may ask for (repeat x poses_b): about 1 to 10 s of work.
constexpr long long kMaxQueriesPerLine = 10'000'000;

// A bad line: the message names the field.
struct BadLine : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double number(const json& j, const std::string& where) {
  if (!j.is_number())
    throw BadLine(where + ": expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v))
    throw BadLine(where + ": not a finite number");
  return v;
}

Vec3 vec3(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3)
    throw BadLine(where + ": expected [x, y, z]");
  return {number(j[0], where + "[0]"), number(j[1], where + "[1]"), number(j[2], where + "[2]")};
}

Pose pose(const json& obj, const char* key) {
  if (!obj.contains(key))
    return Pose{};
  const json& j = obj.at(key);
  const std::string where = key;
  if (!j.is_object())
    throw BadLine(where + ": expected an object with translation and rotation");
  Vec3 t{0.0};
  if (j.contains("translation"))
    t = vec3(j.at("translation"), where + ".translation");
  if (!j.contains("rotation"))
    return Pose{t, geom::Quat{1, 0, 0, 0}};
  const json& r = j.at("rotation");
  if (!r.is_array() || r.size() != 4)
    throw BadLine(where + ".rotation: expected [qx, qy, qz, qw]");
  const double q[4] = {number(r[0], where + ".rotation[0]"), number(r[1], where + ".rotation[1]"),
                       number(r[2], where + ".rotation[2]"), number(r[3], where + ".rotation[3]")};
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(norm > 1e-12))
    throw BadLine(where + ".rotation: zero quaternion");
  return Pose::fromXyzw(t, q[0], q[1], q[2], q[3]);
}

Pose poseOf(const json& j, const std::string& where) {
  json wrapper;
  wrapper[where] = j;
  return pose(wrapper, where.c_str());
}

geom::Polytope polytope(const json& obj, const char* key) {
  const std::string where = key;
  if (!obj.contains(key) || !obj.at(key).is_object() || !obj.at(key).contains("vertices")) {
    throw BadLine(where + ".vertices: missing");
  }
  const json& v = obj.at(key).at("vertices");
  if (!v.is_array())
    throw BadLine(where + ".vertices: expected an array of [x, y, z]");
  std::vector<Vec3> pts;
  pts.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    pts.push_back(vec3(v[i], where + ".vertices[" + std::to_string(i) + "]"));
  }
  auto r = geom::Polytope::fromPoints(pts);
  if (!r.ok())
    throw BadLine(where + ": " + r.error().message);
  return std::move(r).value();
}

json toJson(const Vec3& v) {
  return json::array({v.x, v.y, v.z});
}

// in collision::ContactStatus order
constexpr const char* kStatusNames[] = {"separated", "touching", "penetrating"};
static_assert(std::size(kStatusNames) ==
              static_cast<std::size_t>(collision::ContactStatus::kPenetrating) + 1);

// One answer in scene coordinates (results of queryPair are in A's frame); `id` first when given.
json answer(const collision::PairResult& r, const geom::Transform& X_WA, const json* id = nullptr) {
  json contacts = json::array();
  for (std::size_t i = 0; i < r.manifold.count; ++i) {
    const auto& c = r.manifold.points[i];
    contacts.push_back({{"point", toJson(X_WA.apply(c.point))},
                        {"normal", toJson(X_WA.rotate(c.normal))},
                        {"depth", c.depth}});
  }
  json out = json::object();
  if (id != nullptr)
    out["id"] = *id;
  out["status"] = proto::nameOf(r.status, kStatusNames, "?");
  out["distance"] = r.distance;
  out["normal"] = toJson(X_WA.rotate(r.normal));
  out["point_a"] = toJson(X_WA.apply(r.point_a));
  out["point_b"] = toJson(X_WA.apply(r.point_b));
  out["contacts"] = contacts;
  out["features"] = json::array({r.fa.name(), r.fb.name()});
  return out;
}

json answerLine(const json& q) {
  if (!q.is_object())
    throw BadLine("expected a JSON object");
  const geom::Polytope a = polytope(q, "a");
  const geom::Polytope b = polytope(q, "b");
  const Pose X_WA = pose(q, "pose_a");
  const geom::Transform T_WA = X_WA.toTransform();
  json out;
  out["id"] = q.contains("id") ? q.at("id") : json(nullptr);  // first, as in the format
  if (q.contains("poses_b")) {
    if (q.contains("pose_b"))
      throw BadLine("give pose_b or poses_b, not both");
    const json& seq = q.at("poses_b");
    if (!seq.is_array() || seq.empty())
      throw BadLine("poses_b: expected a non-empty array of poses");
    long long repeat = 1;
    if (q.contains("repeat")) {
      if (!q.at("repeat").is_number_integer())
        throw BadLine("repeat: expected an integer");
      repeat = q.at("repeat").get<long long>();
      if (repeat < 1 || repeat > 1000000)
        throw BadLine("repeat: must be 1 to 1000000");
    }
    // a bound on the work of one line, so that a line cannot run for hours in silence
    if (static_cast<double>(repeat) * static_cast<double>(seq.size()) > kMaxQueriesPerLine)
      throw BadLine("repeat x poses_b: " + std::to_string(repeat) + " x " +
                    std::to_string(seq.size()) + " pair queries, over the limit of " +
                    std::to_string(kMaxQueriesPerLine) + " per line: lower repeat");
    std::vector<geom::Transform> steps;
    steps.reserve(seq.size());
    for (std::size_t i = 0; i < seq.size(); ++i) {
      steps.push_back(
          geom::relativeTransform(X_WA, poseOf(seq[i], "poses_b[" + std::to_string(i) + "]")));
    }
    std::vector<collision::PairResult> first(steps.size());
    std::vector<double> ns_per_step;
    for (long long k = 0; k < repeat; ++k) {
      collision::PairCache cache;
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < steps.size(); ++i)
        first[i] = collision::queryPair(a, b, steps[i], cache);
      const auto t1 = std::chrono::steady_clock::now();
      ns_per_step.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() /
                            static_cast<double>(steps.size()));
    }
    std::sort(ns_per_step.begin(), ns_per_step.end());
    const std::size_t n = ns_per_step.size();
    const double median =
        n % 2 ? ns_per_step[n / 2] : 0.5 * (ns_per_step[n / 2 - 1] + ns_per_step[n / 2]);
    json results = json::array();
    for (const auto& r : first)
      results.push_back(answer(r, T_WA));
    out["results"] = results;
    out["ns_per_step_median"] = median;
    return out;
  }
  if (!q.contains("pose_b"))
    throw BadLine("pose_b (or poses_b): missing");
  collision::PairCache cache;
  const auto r =
      collision::queryPair(a, b, geom::relativeTransform(X_WA, pose(q, "pose_b")), cache);
  return answer(r, T_WA, &out["id"]);
}

}  // namespace

int runQuery(std::istream& in, std::ostream& out) {
  int status = 0;
  std::string line;
  std::size_t number_of_line = 0;
  while (std::getline(in, line)) {
    ++number_of_line;
    if (line.find_first_not_of(" \t\r") == std::string::npos)
      continue;
    json id = nullptr;
    try {
      const json q = json::parse(line);
      if (q.is_object() && q.contains("id"))
        id = q.at("id");
      out << answerLine(q).dump() << '\n';
    } catch (const nlohmann::json::parse_error& e) {
      out << json{{"id", id},
                  {"error",
                   "line " + std::to_string(number_of_line) + ": invalid JSON: " + e.what()}}
                 .dump()
          << '\n';
      status = 1;
    } catch (const std::exception& e) {
      out << json{{"id", id}, {"error", "line " + std::to_string(number_of_line) + ": " + e.what()}}
                 .dump()
          << '\n';
      status = 1;
    }
  }
  out.flush();
  return status;
}

}  // namespace hapticd::client
