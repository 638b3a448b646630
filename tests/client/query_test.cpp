// hapticctl query: the JSON-lines format of docs/architecture.md, answers in scene coordinates.
#include "client/query.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

namespace hapticd::client {
namespace {

using nlohmann::json;

const char* kCube = "[[-1,-1,-1],[1,-1,-1],[-1,1,-1],[1,1,-1],[-1,-1,1],[1,-1,1],[-1,1,1],[1,1,1]]";

std::string pairLine(const std::string& id, const std::string& pose_a, const std::string& pose_b) {
  return std::string("{\"id\":\"") + id + "\",\"a\":{\"vertices\":" + kCube +
         "},\"b\":{\"vertices\":" + kCube + "},\"pose_a\":" + pose_a + ",\"pose_b\":" + pose_b +
         "}";
}

std::vector<json> run(const std::string& input, int& status) {
  std::istringstream in(input);
  std::ostringstream out;
  status = runQuery(in, out);
  std::vector<json> lines;
  std::istringstream res(out.str());
  std::string line;
  while (std::getline(res, line))
    lines.push_back(json::parse(line));
  return lines;
}

TEST(Query, SeparatedTouchingPenetratingInSceneCoordinates) {
  // A turned 90 degrees about z and moved: answers must come back in scene coordinates
  const std::string pose_a =
      "{\"translation\":[10,20,30],\"rotation\":[0,0,0.7071067811865476,0.7071067811865476]}";
  const std::string input =
      pairLine("gap", pose_a, "{\"translation\":[10,22.5,30],\"rotation\":[0,0,0,1]}") + "\n" +
      pairLine("touch", pose_a, "{\"translation\":[10,22,30.5],\"rotation\":[0,0,0,1]}") + "\n" +
      pairLine("deep", pose_a, "{\"translation\":[10,21.75,30],\"rotation\":[0,0,0,1]}") + "\n";
  int status = -1;
  const auto out = run(input, status);
  EXPECT_EQ(status, 0);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0]["id"], "gap");
  EXPECT_EQ(out[0]["status"], "separated");
  EXPECT_NEAR(out[0]["distance"].get<double>(), 0.5, 1e-12);
  EXPECT_NEAR(out[0]["normal"][1].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(out[0]["point_a"][1].get<double>(), 21.0, 1e-12);
  EXPECT_NEAR(out[0]["point_b"][1].get<double>(), 21.5, 1e-12);
  EXPECT_EQ(out[0]["contacts"].size(), 4u);
  EXPECT_EQ(out[0]["features"].size(), 2u);
  EXPECT_EQ(out[1]["status"], "touching");
  EXPECT_NEAR(out[1]["distance"].get<double>(), 0.0, 1e-12);
  EXPECT_EQ(out[2]["status"], "penetrating");
  EXPECT_NEAR(out[2]["distance"].get<double>(), -0.25, 1e-12);
  EXPECT_NEAR(out[2]["normal"][1].get<double>(), 1.0, 1e-12);
  for (const auto& c : out[2]["contacts"])
    EXPECT_NEAR(c["depth"].get<double>(), 0.25, 1e-12);
}

TEST(Query, CoherentSequenceIsTimed) {
  std::string poses = "[";
  for (int k = 0; k < 50; ++k) {
    poses += std::string(k ? "," : "") + "{\"translation\":[" + std::to_string(3.0 - 0.03 * k) +
             ",0.1,0],\"rotation\":[0,0,0,1]}";
  }
  poses += "]";
  const std::string line = std::string("{\"id\":7,\"a\":{\"vertices\":") + kCube +
                           "},\"b\":{\"vertices\":" + kCube + "},\"poses_b\":" + poses +
                           ",\"repeat\":3}";
  int status = -1;
  const auto out = run(line + "\n", status);
  EXPECT_EQ(status, 0);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0]["id"], 7);
  ASSERT_EQ(out[0]["results"].size(), 50u);
  EXPECT_GT(out[0]["ns_per_step_median"].get<double>(), 0.0);
  EXPECT_NEAR(out[0]["results"][0]["distance"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(out[0]["results"][49]["distance"].get<double>(), -0.47, 1e-9);
  EXPECT_EQ(out[0]["results"][49]["status"], "penetrating");
}

TEST(Query, ALineAskingForTooManyQueriesIsRefusedAtOnce) {
  // repeat x poses_b over 10^7: refused before any query runs (at 10^8 queries it would run for
  // minutes with no output); at the limit it is accepted (a small sequence, quickly)
  auto line = [](int poses, long long repeat) {
    std::string p = "[";
    for (int k = 0; k < poses; ++k)
      p += std::string(k ? "," : "") + "{\"translation\":[3,0,0]}";
    return std::string("{\"id\":1,\"a\":{\"vertices\":") + kCube +
           "},\"b\":{\"vertices\":" + kCube + "},\"poses_b\":" + p +
           "],\"repeat\":" + std::to_string(repeat) + "}";
  };
  int status = -1;
  auto out = run(line(200, 1000000) + "\n", status);
  EXPECT_EQ(status, 1);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0]["error"],
            "line 1: repeat x poses_b: 1000000 x 200 pair queries, over the limit of 10000000 per "
            "line: lower repeat");
  out = run(line(11, 1000000) + "\n", status);
  EXPECT_EQ(status, 1);
  EXPECT_TRUE(out[0].contains("error"));
  out = run(line(2, 10) + "\n", status);
  EXPECT_EQ(status, 0);
  EXPECT_EQ(out[0]["results"].size(), 2u);
}

// The shapes of the near-contact check (issue 18): hulls of other families than the benchmarks'
// (a round one, a box, a plate and a needle of aspect 100 and 50, a prism, a cone, a tetrahedron),
// unit size, scaled by the test.
std::vector<std::vector<double>> familyShape(int which) {
  std::vector<std::vector<double>> v;
  const double pi = 3.14159265358979323846;
  const auto box = [&](double a, double b, double c) {
    for (int k = 0; k < 8; ++k)
      v.push_back({k & 1 ? a : -a, k & 2 ? b : -b, k & 4 ? c : -c});
  };
  switch (which) {
    case 0:  // 48 points on a sphere (a golden-angle spiral)
      for (int k = 0; k < 48; ++k) {
        const double z = 1.0 - (2.0 * k + 1.0) / 48.0, r = std::sqrt(1.0 - z * z);
        const double t = 2.399963229728653 * k;
        v.push_back({r * std::cos(t), r * std::sin(t), z});
      }
      break;
    case 1:
      box(1, 1, 1);
      break;
    case 2:
      box(1, 1, 0.01);
      break;
    case 3:
      box(0.02, 0.02, 1);
      break;
    case 4:
      for (int k = 0; k < 32; ++k) {
        for (double z : {-0.3, 0.3})
          v.push_back({std::cos(2 * pi * k / 32), std::sin(2 * pi * k / 32), z});
      }
      break;
    case 5:
      for (int k = 0; k < 24; ++k)
        v.push_back({std::cos(2 * pi * k / 24), std::sin(2 * pi * k / 24), -1.0});
      v.push_back({0.0, 0.0, 1.0});
      break;
    default:
      v = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
      break;
  }
  return v;
}

TEST(Query, CoherentSequencesGiveTheColdAnswerOnEveryShapeFamilyAndScale) {
  // B approaches A from a seeded direction, through near contact into overlap and out again,
  // turning 0.1 degree a step: the warm-started sequence (the servo loop's way: tracked features,
  // the depth proven from last step's structure) must give, step by step, the answer of a cold
  // query of that pose alone, and the same answer relative to the size in mm, m and km
  constexpr int kShapes = 7;
  constexpr std::size_t kSteps = 120;
  int penetrating = 0, near = 0;
  for (int ia = 0; ia < kShapes; ++ia) {
    for (int ib = 0; ib < kShapes; ++ib) {
      std::vector<double> relative;  // the distances / scale at the first scale
      for (const double s : {1e-3, 1.0, 1e3}) {
        json a, b;
        for (const auto& p : familyShape(ia))
          a["vertices"].push_back({p[0] * s, p[1] * s, p[2] * s});
        for (const auto& p : familyShape(ib))
          b["vertices"].push_back({p[0] * s, p[1] * s, p[2] * s});
        const double phi = 0.7 + 0.9 * ia + 0.37 * ib, theta = 0.4 + 0.31 * ia + 0.53 * ib;
        const double d[3] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                             std::cos(theta)};
        const double axis[3] = {0.48, -0.6, 0.64};  // unit
        json poses = json::array();
        for (std::size_t k = 0; k < kSteps; ++k) {
          // centre distance 2.25 +- 0.55 of the unit shapes: apart, near, overlapping
          const double c = (2.25 + 0.55 * std::cos(4.0 * 3.14159265358979323846 *
                                                   static_cast<double>(k) / kSteps)) *
                           s;
          const double half = 0.5 * (0.3 + 0.1 * ia + 0.001745329251994 * static_cast<double>(k));
          const double sh = std::sin(half);
          poses.push_back(
              {{"translation", {d[0] * c, d[1] * c, d[2] * c}},
               {"rotation", {axis[0] * sh, axis[1] * sh, axis[2] * sh, std::cos(half)}}});
        }
        std::string input =
            json{{"id", "seq"}, {"a", a}, {"b", b}, {"poses_b", poses}}.dump() + "\n";
        for (std::size_t k = 0; k < kSteps; ++k)
          input += json{{"id", k}, {"a", a}, {"b", b}, {"pose_b", poses[k]}}.dump() + "\n";
        int status = -1;
        const auto out = run(input, status);
        ASSERT_EQ(status, 0);
        ASSERT_EQ(out.size(), kSteps + 1);
        const json& seq = out[0]["results"];
        ASSERT_EQ(seq.size(), kSteps);
        const bool first_scale = relative.empty();
        for (std::size_t k = 0; k < kSteps; ++k) {
          const json& w = seq[k];
          const json& c = out[k + 1];
          const std::string where = std::to_string(ia) + "/" + std::to_string(ib) + " at " +
                                    std::to_string(s) + ", step " + std::to_string(k);
          ASSERT_EQ(w["status"], c["status"]) << where;
          const double dw = w["distance"].get<double>(), dc = c["distance"].get<double>();
          ASSERT_TRUE(std::isfinite(dw)) << where;
          EXPECT_NEAR(dw / s, dc / s, 1e-9) << where;
          if (std::abs(dc) > 1e-6 * s) {
            double dot = 0.0;
            for (std::size_t q = 0; q < 3; ++q)
              dot += w["normal"][q].get<double>() * c["normal"][q].get<double>();
            EXPECT_GT(dot, 1.0 - 1e-9) << where;
          }
          if (first_scale) {
            relative.push_back(dw / s);
            penetrating += w["status"] == "penetrating" ? 1 : 0;
            near += (dw > 0.0 && dw < 0.1 * s) ? 1 : 0;
          } else {
            EXPECT_NEAR(dw / s, relative[k], 1e-9) << where;
          }
        }
      }
    }
  }
  // the paths do what they are for: a good share overlaps, some steps are near contact (apart by
  // less than a tenth of the size; 286 of the 5 880 steps when written)
  const int total = kShapes * kShapes * static_cast<int>(kSteps);
  EXPECT_GT(penetrating, total / 10);
  EXPECT_GT(near, total / 30);
}

TEST(Query, BadLinesGetTheirErrorAndTheRestIsAnswered) {
  const std::string good = pairLine("ok", "{}", "{\"translation\":[3,0,0]}");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"{not json", "invalid JSON"},
      {"[1,2,3]", "expected a JSON object"},
      {"{\"id\":1}", "a.vertices: missing"},
      {"{\"id\":2,\"a\":{\"vertices\":[[0,0,0],[1,0,0],[0,1,0]]},\"b\":{\"vertices\":[]},\"pose_"
       "b\":{}}",
       "at least 4"},
      {"{\"id\":3,\"a\":{\"vertices\":[[0,0,0],[1,0,0],[0,1,0],[0,0,\"x\"]]}}",
       "a.vertices[3][2]: expected a number"},
      {"{\"id\":4,\"a\":{\"vertices\":[[0,0,0],[1,0,0],[0,1,0],[0,0,1e999]]}}", "number"},
      {pairLine("5", "{}", "{\"rotation\":[0,0,0,0]}"), "zero quaternion"},
      {pairLine("6", "{}", "{\"rotation\":[0,0,1]}"), "expected [qx, qy, qz, qw]"},
      {std::string("{\"id\":8,\"a\":{\"vertices\":") + kCube + "},\"b\":{\"vertices\":" + kCube +
           "}}",
       "pose_b"},
      {std::string("{\"id\":9,\"a\":{\"vertices\":") + kCube + "},\"b\":{\"vertices\":" + kCube +
           "},\"poses_b\":[{}],\"repeat\":0}",
       "repeat"},
  };
  for (const auto& [line, expect] : bad) {
    int status = -1;
    const auto out = run(line + "\n\n" + good + "\n", status);
    EXPECT_EQ(status, 1) << line;
    ASSERT_EQ(out.size(), 2u) << line;
    ASSERT_TRUE(out[0].contains("error")) << line;
    EXPECT_NE(out[0]["error"].get<std::string>().find(expect), std::string::npos)
        << line << " -> " << out[0]["error"];
    EXPECT_EQ(out[1]["id"], "ok");
    EXPECT_EQ(out[1]["status"], "separated");
  }
}

}  // namespace
}  // namespace hapticd::client
