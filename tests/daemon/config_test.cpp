// The configuration: the shipped file equals the built-in defaults and documents every key with
// its default; bad values, wrong types and unknown keys are refused with the key and the line.
#include "daemon/config.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

namespace hapticd::daemon {
namespace {

const std::string kFile = std::string(HAPTICD_SOURCE_DIR) + "/config/hapticd.toml";

TEST(Config, ShippedFileEqualsTheBuiltInDefaults) {
  auto parsed = loadConfigFile(kFile);
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_TRUE(parsed.value().config == Config{});
}

TEST(Config, ShippedFileSetsEveryKeyOnceWithItsDefaultInTheCommentAbove) {
  auto parsed = loadConfigFile(kFile);
  ASSERT_TRUE(parsed) << parsed.error().message;
  const auto known = knownConfigKeys();
  EXPECT_EQ(parsed.value().keys_set, known);  // every key, in the reader's order
  EXPECT_EQ(std::set<std::string>(known.begin(), known.end()).size(), known.size());

  std::ifstream in(kFile);
  std::string line, comments;
  const std::regex key_line(R"(^([a-z_]+) = (.*)$)");
  int keys = 0;
  while (std::getline(in, line)) {
    std::smatch m;
    if (line.rfind('#', 0) == 0) {
      comments += line + "\n";
    } else if (std::regex_match(line, m, key_line)) {
      ++keys;
      // the comment block right above the key ends with "(default: VALUE)", VALUE as set
      const std::string expect = "(default: " + m[2].str() + ")";
      EXPECT_NE(comments.find(expect), std::string::npos) << "key line: " << line;
      comments.clear();
    } else {
      comments.clear();
    }
  }
  EXPECT_EQ(static_cast<std::size_t>(keys), known.size());
}

TEST(Config, EmptyTextGivesTheDefaults) {
  auto parsed = parseConfig("", "empty.toml");
  ASSERT_TRUE(parsed);
  EXPECT_TRUE(parsed.value().config == Config{});
}

TEST(Config, ValuesAreRead) {
  auto parsed = parseConfig(R"([servo]
rate_hz = 4000
realtime = "require"
cpu = 1
[device]
spec = "replay:x.csv"
workspace_scale = 2.5
workspace_rotation = [0.0, 0.0, 1.0, 0.0]
[response]
stiffness_n_per_m = 1200.0
[scene]
path = "a.glb"
[network]
udp = "0.0.0.0:5000"
[log]
level = "debug"
)",
                            "t.toml");
  ASSERT_TRUE(parsed) << parsed.error().message;
  const Config& c = parsed.value().config;
  EXPECT_EQ(c.servo.rate_hz, 4000.0);
  EXPECT_EQ(c.servo.realtime, RealtimePolicy::kRequire);
  EXPECT_EQ(c.servo.cpu, 1);
  EXPECT_EQ(c.device.spec, "replay:x.csv");
  EXPECT_EQ(c.device.workspace_scale, 2.5);
  EXPECT_EQ(c.response.stiffness_n_per_m, 1200.0);
  EXPECT_EQ(c.scene.path, "a.glb");
  EXPECT_EQ(c.network.udp, "0.0.0.0:5000");
  EXPECT_EQ(c.log.level, LogLevel::kDebug);
  EXPECT_DOUBLE_EQ(toSimOptions(c).response.tick_s, 1.0 / 4000.0);  // tick follows the rate
}

struct BadCase {
  const char* text;
  const char* expect;  // substring of the error: file:line: [section] key: what
};

class ConfigRefuses : public ::testing::TestWithParam<BadCase> {};

TEST_P(ConfigRefuses, NamingFileLineAndKey) {
  auto parsed = parseConfig(GetParam().text, "bad.toml");
  ASSERT_FALSE(parsed) << GetParam().text;
  EXPECT_NE(parsed.error().message.find(GetParam().expect), std::string::npos)
      << "error was: " << parsed.error().message;
}

INSTANTIATE_TEST_SUITE_P(
    Config, ConfigRefuses,
    ::testing::Values(
        BadCase{"[servo]\nrate_hz = 0\n", "bad.toml:2: [servo] rate_hz: must be in [1, 20000]"},
        BadCase{"[servo]\n\nrate_hz = \"fast\"\n", "bad.toml:3: [servo] rate_hz: must be a number"},
        BadCase{"[servo]\nrate_hz = nan\n", "bad.toml:2: [servo] rate_hz"},
        BadCase{"[servo]\nrealtime = \"always\"\n", "bad.toml:2: [servo] realtime: realtime: \"always\""},
        BadCase{"[servo]\npriority = 100\n", "bad.toml:2: [servo] priority: must be in [1, 99]"},
        BadCase{"[servo]\nrate_hs = 1000\n", "bad.toml:2: [servo] rate_hs: unknown key"},
        BadCase{"[srevo]\nrate_hz = 1000\n", "bad.toml:1: srevo: unknown section"},
        BadCase{"[device]\nmax_force_n = -1\n", "bad.toml:2: [device] max_force_n"},
        BadCase{"[device]\nmax_force_n = 0\n", "bad.toml:2: [device] max_force_n: must be > 0"},
        BadCase{"[device]\nworkspace_rotation = [0, 0, 0, 2]\n", "bad.toml:2: [device] workspace_rotation"},
        BadCase{"[device]\nworkspace_rotation = [0, 0, 0.5, 0.5]\n", "unit quaternion"},
        BadCase{"[device]\nsim_home_translation_m = [0, 0]\n", "must be an array of 3 numbers"},
        BadCase{"[device]\nspec = \"\"\n", "bad.toml:2: [device] spec: must not be empty"},
        BadCase{"[response]\nmax_pairs_per_tick = 1.5\n", "[response] max_pairs_per_tick: must be an integer"},
        BadCase{"[network]\nudp = \"127.0.0.1\"\n", "bad.toml:2: [network] udp"},
        BadCase{"[network]\nudp = \"127.0.0.1:70000\"\n", "port must be 1..65535"},
        BadCase{"[log]\nlevel = \"loud\"\n", "bad.toml:2: [log] level"},
        BadCase{"servo = 3\n", "bad.toml:1: servo: must be a table"},
        BadCase{"[servo\nrate_hz = 1\n", "bad.toml:1:"},
        BadCase{"[scene]\nmax_nodes = -4\n", "bad.toml:2: [scene] max_nodes"}));

TEST(Config, EveryProblemOfAFileIsListed) {
  auto parsed = parseConfig("[servo]\nrate_hz = 0\npriority = 0\n[log]\nlevel = 3\n", "f.toml");
  ASSERT_FALSE(parsed);
  const std::string& m = parsed.error().message;
  EXPECT_NE(m.find("f.toml:2:"), std::string::npos);
  EXPECT_NE(m.find("f.toml:3:"), std::string::npos);
  EXPECT_NE(m.find("f.toml:5:"), std::string::npos);
}

TEST(Config, MissingFileIsAClearError) {
  auto parsed = loadConfigFile("/nonexistent/hapticd.toml");
  ASSERT_FALSE(parsed);
  EXPECT_NE(parsed.error().message.find("/nonexistent/hapticd.toml"), std::string::npos);
}

}  // namespace
}  // namespace hapticd::daemon
