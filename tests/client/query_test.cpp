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
