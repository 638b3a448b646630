// The configuration: the shipped file equals the built-in defaults and documents every key with
// its default; bad values, wrong types and unknown keys are refused with the key and the line.
#include "daemon/config.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <regex>
#include <set>
#include <sstream>

#include "daemon/command_line.h"
#include "daemon/config_keys.h"

namespace hapticd::daemon {
namespace {

const std::string kFile = std::string(HAPTICD_SOURCE_DIR) + "/config/hapticd.toml";

TEST(Config, ShippedFileEqualsTheBuiltInDefaults) {
  auto parsed = loadConfigFile(kFile);
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_TRUE(parsed.value().config == Config{});
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Config, ShippedFileIsTheOneTheTableMakes) {
  // regenerate with: build/release/bin/hapticd --print-config > config/hapticd.toml
  EXPECT_EQ(slurp(kFile), toToml(Config{}));
}

TEST(Config, ShippedFileSetsEveryKeyOnceWithItsDefaultInTheCommentAbove) {
  auto parsed = loadConfigFile(kFile);
  ASSERT_TRUE(parsed) << parsed.error().message;
  const auto known = knownConfigKeys();
  EXPECT_EQ(parsed.value().keys_set, known);  // every key, in the reader's order
  EXPECT_EQ(std::set<std::string>(known.begin(), known.end()).size(), known.size());

  std::ifstream in(kFile);
  std::string line, comments;
  const std::regex key_line(R"(^([a-z0-9_]+) = (.*)$)");
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

TEST(Config, DefaultsAreThoseOfTheSimulationAndDeviceOptions) {
  const Config c;
  const sim::SimOptions a = toSimOptions(c);
  const sim::SimOptions b;
  const sim::ResponseOptions& r = a.response;
  const sim::ResponseOptions& e = b.response;
  EXPECT_EQ(r.stiffness_n_per_m, e.stiffness_n_per_m);
  EXPECT_EQ(r.tick_s, e.tick_s);  // 0 follows 1 kHz: 1 ms
  EXPECT_EQ(r.max_force_n, e.max_force_n);
  EXPECT_EQ(r.max_torque_nm, e.max_torque_nm);
  EXPECT_EQ(r.max_force_step_n, e.max_force_step_n);
  EXPECT_EQ(r.max_torque_step_nm, e.max_torque_step_nm);
  EXPECT_EQ(r.ramp_s, e.ramp_s);
  EXPECT_EQ(r.max_speed_m_per_s, e.max_speed_m_per_s);
  EXPECT_EQ(r.speed_decay_s, e.speed_decay_s);
  EXPECT_EQ(r.min_predictive_fraction, e.min_predictive_fraction);
  EXPECT_EQ(r.proxy_stiffness_ratio, e.proxy_stiffness_ratio);
  EXPECT_EQ(r.coupling_damping_factor, e.coupling_damping_factor);
  EXPECT_EQ(r.rot_stiffness_nm_per_rad, e.rot_stiffness_nm_per_rad);
  EXPECT_EQ(r.penetration_allowance_m, e.penetration_allowance_m);
  EXPECT_EQ(r.crease_angle_deg, e.crease_angle_deg);
  EXPECT_EQ(r.attach_button_mask, e.attach_button_mask);
  EXPECT_EQ(r.attach_distance_m, e.attach_distance_m);
  EXPECT_EQ(r.hinge_attach, e.hinge_attach);
  EXPECT_EQ(r.centre_radius_fraction, e.centre_radius_fraction);
  EXPECT_EQ(r.grab_weight, e.grab_weight);
  EXPECT_EQ(r.grab_inertia, e.grab_inertia);
  EXPECT_EQ(r.grab_inertia_filter_s, e.grab_inertia_filter_s);
  EXPECT_EQ(r.dynamic_backstop_fraction, e.dynamic_backstop_fraction);
  EXPECT_EQ(a.dynamics_impulse_window_s, b.dynamics_impulse_window_s);
  EXPECT_EQ(a.dynamics_sleep_time_s, b.dynamics_sleep_time_s);
  EXPECT_EQ(a.dynamics_velocity_iterations, b.dynamics_velocity_iterations);
  EXPECT_EQ(a.dynamics_position_iterations, b.dynamics_position_iterations);
  EXPECT_EQ(a.max_pairs_per_tick, b.max_pairs_per_tick);
  EXPECT_EQ(a.probe_sphere_radius_m, b.probe_sphere_radius_m);

  const device::DeviceOptions& d = c.device.options;
  const device::DeviceOptions f;
  EXPECT_EQ(d.limits.max_force_n, f.limits.max_force_n);
  EXPECT_EQ(d.limits.max_torque_nm, f.limits.max_torque_nm);
  EXPECT_EQ(d.sim_hand_mass_kg, f.sim_hand_mass_kg);
  EXPECT_EQ(d.sim_hand_stiffness_n_per_m, f.sim_hand_stiffness_n_per_m);
  EXPECT_EQ(d.sim_hand_damping_n_s_per_m, f.sim_hand_damping_n_s_per_m);
  EXPECT_EQ(d.sim_idle_motion_after_s, f.sim_idle_motion_after_s);
  EXPECT_EQ(d.sim_home.translation, f.sim_home.translation);
  EXPECT_EQ(d.sim_home.rotation, f.sim_home.rotation);
  EXPECT_EQ(d.sim_hand_inertia_kg_m2, f.sim_hand_inertia_kg_m2);
  EXPECT_EQ(d.sim_hand_rot_stiffness_nm_per_rad, f.sim_hand_rot_stiffness_nm_per_rad);
  EXPECT_EQ(d.sim_hand_rot_damping_nm_s_per_rad, f.sim_hand_rot_damping_nm_s_per_rad);
  EXPECT_EQ(d.sim_idle_amplitude_m, f.sim_idle_amplitude_m);
  EXPECT_EQ(d.sim_idle_angle_rad, f.sim_idle_angle_rad);
  EXPECT_EQ(d.sim_max_step_s, f.sim_max_step_s);
  EXPECT_EQ(d.replay_quat_tolerance, f.replay_quat_tolerance);
  EXPECT_EQ(d.hid_spacemouse_speed_m_per_s, f.hid_spacemouse_speed_m_per_s);
  EXPECT_EQ(d.hid_spacemouse_angular_speed_rad_per_s, f.hid_spacemouse_angular_speed_rad_per_s);
  EXPECT_EQ(d.hid_spacemouse_full_scale, f.hid_spacemouse_full_scale);
  EXPECT_EQ(d.hid_spacemouse_deadband, f.hid_spacemouse_deadband);
  EXPECT_EQ(d.hid_spacemouse_workspace_m, f.hid_spacemouse_workspace_m);
  EXPECT_EQ(d.usb_silence_lost_s, f.usb_silence_lost_s);
  EXPECT_EQ(d.usb_falcon_max_motor_command, f.usb_falcon_max_motor_command);
  EXPECT_EQ(d.usb_falcon_firmware, f.usb_falcon_firmware);
  EXPECT_EQ(d.forcedimension_library, f.forcedimension_library);
  EXPECT_EQ(d.openhaptics_library, f.openhaptics_library);
  EXPECT_EQ(d.haply_silence_lost_s, f.haply_silence_lost_s);
  EXPECT_EQ(d.haply_connect_timeout_s, f.haply_connect_timeout_s);

  const scene::LoadOptions l = toLoadOptions(c);
  const scene::SceneLimits g;
  EXPECT_EQ(l.limits.max_file_bytes, g.max_file_bytes);
  EXPECT_EQ(l.limits.max_nodes, g.max_nodes);
  EXPECT_EQ(l.limits.max_bodies, g.max_bodies);
  EXPECT_EQ(l.limits.max_primitives, g.max_primitives);
  EXPECT_EQ(l.limits.max_hull_input_points, g.max_hull_input_points);
  EXPECT_EQ(l.limits.max_hull_vertices, g.max_hull_vertices);
  EXPECT_EQ(l.limits.tessellation_tolerance, g.tessellation_tolerance);
  EXPECT_FALSE(l.allowed_uri_dir.has_value());
  const scene::DecompositionOptions dd;
  EXPECT_EQ(l.decomposition.concavity, dd.concavity);
  EXPECT_EQ(l.decomposition.max_pieces, dd.max_pieces);
  EXPECT_EQ(l.decomposition.time_limit_s, dd.time_limit_s);
  EXPECT_EQ(c.scene.cache_dir, "auto");
}

// [scene] concavity, max_pieces, decompose_time_limit_s, cache_dir and cache_max_mb reach the
// loader's options
TEST(Config, DecompositionKeysReachTheLoader) {
  auto parsed = parseConfig(R"([scene]
concavity = 0.05
max_pieces = 12
decompose_time_limit_s = 30
cache_dir = "/srv/hapticd-cache"
cache_max_mb = 64
)",
                            "t.toml");
  ASSERT_TRUE(parsed) << parsed.error().message;
  const scene::LoadOptions l = toLoadOptions(parsed.value().config);
  EXPECT_EQ(l.decomposition.concavity, 0.05);
  EXPECT_EQ(l.decomposition.max_pieces, 12u);
  EXPECT_EQ(l.decomposition.time_limit_s, 30.0);
  EXPECT_EQ(l.decomposition.cache_dir, std::filesystem::path("/srv/hapticd-cache"));
  EXPECT_EQ(l.decomposition.cache_max_bytes, std::uint64_t{64} << 20);
  EXPECT_EQ(toLoadOptions(Config{}).decomposition.cache_max_bytes,
            scene::DecompositionOptions{}.cache_max_bytes);
  // "" turns the cache off; "auto" is the environment's folder
  auto off = parseConfig("[scene]\ncache_dir = \"\"\n", "t.toml");
  ASSERT_TRUE(off) << off.error().message;
  EXPECT_TRUE(toLoadOptions(off.value().config).decomposition.cache_dir.empty());
  EXPECT_EQ(toLoadOptions(Config{}).decomposition.cache_dir, scene::decompositionCacheDir("auto"));
}

TEST(Config, PrintedConfigParsesBackToTheSame) {
  Config c;
  c.servo.rate_hz = 4000.0;
  c.device.spec = "replay:a \"quoted\" name.csv";
  c.device.workspace.scale = 0.1;
  c.response.sim.response.hinge_attach = sim::ResponseOptions::HingeAttach::kRim;
  c.response.sim.response.grab_weight = false;
  c.response.sim.response.grab_inertia_filter_s = 0.03;
  c.response.sim.dynamics_impulse_window_s = 0.01;
  c.response.sim.dynamics_sleep_time_s = 0.0;
  c.response.sim.dynamics_velocity_iterations = 40;
  c.response.sim.dynamics_position_iterations = 0;
  c.network.shm = "/hapticd-printed";
  auto parsed = parseConfig(toToml(c), "printed.toml");
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_TRUE(parsed.value().config == c);
  auto defaults = parseConfig(toToml(Config{}), "printed.toml");
  ASSERT_TRUE(defaults);
  EXPECT_TRUE(defaults.value().config == Config{});
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
grab_weight = false
grab_inertia_filter_s = 0.02
impulse_window_s = 0.04
dynamics_velocity_iterations = 30
dynamics_position_iterations = 0
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
  EXPECT_EQ(c.device.workspace.scale, 2.5);
  EXPECT_EQ(c.response.sim.response.stiffness_n_per_m, 1200.0);
  EXPECT_FALSE(toSimOptions(c).response.grab_weight);
  EXPECT_TRUE(toSimOptions(c).response.grab_inertia);
  EXPECT_EQ(toSimOptions(c).response.grab_inertia_filter_s, 0.02);
  EXPECT_EQ(toSimOptions(c).dynamics_impulse_window_s, 0.04);
  EXPECT_EQ(toSimOptions(c).dynamics_velocity_iterations, 30u);
  EXPECT_EQ(toSimOptions(c).dynamics_position_iterations, 0u);
  EXPECT_EQ(c.scene.path, "a.glb");
  EXPECT_EQ(c.network.udp, "0.0.0.0:5000");
  EXPECT_EQ(c.log.level, LogLevel::kDebug);
  EXPECT_DOUBLE_EQ(toSimOptions(c).response.tick_s, 1.0 / 4000.0);  // tick follows the rate
}

struct BadCase {
  const char* text;
  const char* expect;  // substring of the error: file:line: [section] key: what
};

// stable, readable test names (ctest lists them): the expected message, non-alphanumerics as '_'
void PrintTo(const BadCase& c, std::ostream* os) {
  for (const char* p = c.expect; *p != '\0'; ++p)
    *os << (std::isalnum(static_cast<unsigned char>(*p)) ? *p : '_');
}

class ConfigRefuses : public ::testing::TestWithParam<BadCase> {};

TEST_P(ConfigRefuses, NamingFileLineAndKey) {
  auto parsed = parseConfig(GetParam().text, "bad.toml");
  ASSERT_FALSE(parsed) << GetParam().text;
  EXPECT_NE(parsed.error().message.find(GetParam().expect), std::string::npos)
      << "error was: " << parsed.error().message;
}

INSTANTIATE_TEST_SUITE_P(
    Config,
    ConfigRefuses,
    ::testing::Values(
        BadCase{"[servo]\nrate_hz = 0\n", "bad.toml:2: [servo] rate_hz: must be in [1, 20000]"},
        BadCase{"[servo]\n\nrate_hz = \"fast\"\n", "bad.toml:3: [servo] rate_hz: must be a number"},
        BadCase{"[servo]\nrate_hz = nan\n", "bad.toml:2: [servo] rate_hz"},
        BadCase{"[servo]\nrealtime = \"always\"\n",
                "bad.toml:2: [servo] realtime: realtime: \"always\""},
        BadCase{"[servo]\npriority = 100\n", "bad.toml:2: [servo] priority: must be in [1, 99]"},
        BadCase{"[servo]\nrate_hs = 1000\n", "bad.toml:2: [servo] rate_hs: unknown key"},
        BadCase{"[srevo]\nrate_hz = 1000\n", "bad.toml:1: srevo: unknown section"},
        BadCase{"[device]\nmax_force_n = -1\n", "bad.toml:2: [device] max_force_n"},
        BadCase{"[device]\nmax_force_n = 0\n", "bad.toml:2: [device] max_force_n: must be > 0"},
        BadCase{"[device]\nworkspace_rotation = [0, 0, 0, 2]\n",
                "bad.toml:2: [device] workspace_rotation"},
        BadCase{"[device]\nworkspace_rotation = [0, 0, 0.5, 0.5]\n", "unit quaternion"},
        BadCase{"[device]\nsim_home_translation_m = [0, 0]\n", "must be an array of 3 numbers"},
        BadCase{"[device]\nspec = \"\"\n", "bad.toml:2: [device] spec: must not be empty"},
        BadCase{"[response]\nmax_pairs_per_tick = 1.5\n",
                "[response] max_pairs_per_tick: must be an integer"},
        BadCase{"[network]\nudp = \"127.0.0.1\"\n", "bad.toml:2: [network] udp"},
        BadCase{"[network]\nudp = \"127.0.0.1:70000\"\n", "port must be 0..65535"},
        BadCase{"[log]\nlevel = \"loud\"\n", "bad.toml:2: [log] level"},
        BadCase{"servo = 3\n", "bad.toml:1: servo: must be a table"},
        BadCase{"[servo\nrate_hz = 1\n", "bad.toml:1:"},
        BadCase{"[scene]\nmax_nodes = -4\n", "bad.toml:2: [scene] max_nodes"},
        BadCase{"[scene]\nconcavity = 0\n", "bad.toml:2: [scene] concavity: must be > 0"},
        BadCase{"[scene]\nconcavity = 1.0\n", "bad.toml:2: [scene] concavity: must be in (0, 1)"},
        BadCase{"[scene]\nmax_pieces = 0\n",
                "bad.toml:2: [scene] max_pieces: must be in [1, 10000]"},
        BadCase{"[scene]\ndecompose_time_limit_s = -1\n",
                "bad.toml:2: [scene] decompose_time_limit_s: must be in [0, 86400]"},
        BadCase{"[scene]\ncache_dir = \"cache\"\n",
                "bad.toml:2: [scene] cache_dir: must be \"auto\", \"\" (no cache) or an absolute "
                "folder (got \"cache\")"},
        BadCase{"[response]\ndynamics_velocity_iterations = 0\n",
                "bad.toml:2: [response] dynamics_velocity_iterations: must be in [1, 1000]"},
        BadCase{"[response]\ndynamics_velocity_iterations = 1001\n",
                "bad.toml:2: [response] dynamics_velocity_iterations: must be in [1, 1000]"},
        BadCase{"[response]\ndynamics_velocity_iterations = 2.5\n",
                "bad.toml:2: [response] dynamics_velocity_iterations: must be an integer"},
        BadCase{"[response]\ndynamics_velocity_iterations_max = 1001\n",
                "bad.toml:2: [response] dynamics_velocity_iterations_max: must be in [0, 1000]"},
        BadCase{"[response]\ndynamics_position_iterations_max = -1\n",
                "bad.toml:2: [response] dynamics_position_iterations_max: must be in [0, 1000]"},
        BadCase{"[response]\ndynamics_position_iterations = \"many\"\n",
                "bad.toml:2: [response] dynamics_position_iterations: must be an integer"},
        BadCase{"[response]\ndynamics_position_iterations = -1\n",
                "bad.toml:2: [response] dynamics_position_iterations: must be in [0, 1000]"},
        BadCase{"[response]\ndynamics_position_iterations = 5000\n",
                "bad.toml:2: [response] dynamics_position_iterations: must be in [0, 1000]"},
        BadCase{"[response]\nhinge_attach = \"side\"\n",
                "bad.toml:2: [response] hinge_attach: \"side\""},
        BadCase{"[device]\nusb_falcon_max_motor_command = 40000\n",
                "[device] usb_falcon_max_motor_command: must be in [1, 32767]"}));

TEST(Config, EveryProblemOfAFileIsListed) {
  auto parsed = parseConfig("[servo]\nrate_hz = 0\npriority = 0\n[log]\nlevel = 3\n", "f.toml");
  ASSERT_FALSE(parsed);
  const std::string& m = parsed.error().message;
  EXPECT_NE(m.find("f.toml:2:"), std::string::npos);
  EXPECT_NE(m.find("f.toml:3:"), std::string::npos);
  EXPECT_NE(m.find("f.toml:5:"), std::string::npos);
}

// every key: a value past its range is refused, and the message names the key as the file does
TEST(Config, EveryRangeIsCheckedAndNamesItsKey) {
  for (const ConfigKey& k : configKeys()) {
    if (!std::holds_alternative<double*>(k.in(Config{})))
      continue;
    for (const double v : {k.range.hi * 2.0 + 1.0, k.range.lo - 1.0}) {
      Config c;
      *std::get<double*>(k.in(c)) = v;
      auto r = validateConfig(c);
      ASSERT_FALSE(r) << k.label() << " = " << v;
      EXPECT_EQ(r.error().message.rfind(k.label() + ": must be", 0), 0u) << r.error().message;
      // the same through a file, with the line
      auto parsed = parseConfig(
          "[" + std::string(k.section) + "]\n" + std::string(k.name) + " = " + tomlFloat(v) + "\n",
          "r.toml");
      ASSERT_FALSE(parsed) << k.label();
      EXPECT_NE(parsed.error().message.find("r.toml:2: " + k.label() + ": must be"),
                std::string::npos)
          << parsed.error().message;
    }
  }
}

// the cases the simulation refused after the config had passed them (issue 14)
TEST(Config, RangesAreTheSimulationsAndTheLoaders) {
  const std::pair<const char*, const char*> refused[] = {
      {"[response]\ndynamic_backstop_fraction = 2.0\n",
       "[response] dynamic_backstop_fraction: must be in [0, 1]"},
      {"[response]\ncrease_angle_deg = 90.0\n", "[response] crease_angle_deg: must be in [0, 90)"},
      {"[response]\ncrease_angle_deg = 120\n", "[response] crease_angle_deg: must be in [0, 90)"},
      {"[response]\nproxy_stiffness_ratio = 1.0\n",
       "[response] proxy_stiffness_ratio: must be > 1"},
      {"[response]\nmin_predictive_fraction = 0\n",
       "[response] min_predictive_fraction: must be > 0"},
      {"[scene]\ntessellation_tolerance = 0.5\n",
       "[scene] tessellation_tolerance: must be in (0, 0.5)"},
  };
  for (const auto& [text, expect] : refused) {
    auto parsed = parseConfig(text, "s.toml");
    ASSERT_FALSE(parsed) << text;
    EXPECT_NE(parsed.error().message.find(expect), std::string::npos) << parsed.error().message;
  }
  auto ok = parseConfig("[response]\ndynamic_backstop_fraction = 1.0\ncrease_angle_deg = 89.5\n",
                        "s.toml");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok.value().config.response.sim.response.crease_angle_deg, 89.5);
}

TEST(Config, ADeprecatedKeyIsReadIntoItsNewKeyWithAWarning) {
  const DeprecatedKey renamed[] = {{"response", "k_s", "response", "stiffness_n_per_m"},
                                   {"device", "old_scale", "device", "workspace_scale"}};
  // `text` taken: 700 N/m set as the new key, with the one warning `warning`
  auto expectTaken = [&](const char* text, const char* warning) {
    auto parsed = parseConfig(text, "d.toml", renamed);
    ASSERT_TRUE(parsed) << parsed.error().message;
    EXPECT_EQ(parsed.value().config.response.sim.response.stiffness_n_per_m, 700.0);
    ASSERT_EQ(parsed.value().warnings.size(), 1u);
    EXPECT_EQ(parsed.value().warnings[0], warning);
    EXPECT_EQ(parsed.value().keys_set, std::vector<std::string>{"response.stiffness_n_per_m"});
  };
  // the message `text` is refused with ("" and a failure when taken)
  auto refusal = [&](const char* text) -> std::string {
    auto parsed = parseConfig(text, "d.toml", renamed);
    EXPECT_FALSE(parsed) << text;
    return parsed ? std::string() : parsed.error().message;
  };
  expectTaken("[response]\nk_s = 700\n",
              "d.toml:2: [response] k_s is deprecated: use [response] stiffness_n_per_m (the value "
              "is taken for it)");
  // its value is held to the new key's range, and the message names both
  const std::string bad = refusal("[device]\nold_scale = -1\n");
  EXPECT_NE(bad.find("d.toml:2: [device] old_scale: must be > 0"), std::string::npos) << bad;
  // both names at once, different values: refused, naming both (in either order)
  const std::string both = refusal("[response]\nk_s = 700\nstiffness_n_per_m = 800\n");
  EXPECT_NE(both.find("[response] k_s and [response] stiffness_n_per_m are both set, to different "
                      "values"),
            std::string::npos)
      << both;
  EXPECT_NE(both.find("keep only [response] stiffness_n_per_m"), std::string::npos);
  const std::string both_new_first = refusal("[device]\nworkspace_scale = 2\nold_scale = 3\n");
  EXPECT_NE(
      both_new_first.find(
          "[device] old_scale and [device] workspace_scale are both set, to different values"),
      std::string::npos)
      << both_new_first;
  // both names at once, the same value: taken, with a warning naming both
  expectTaken("[response]\nstiffness_n_per_m = 700\nk_s = 700.0\n",
              "d.toml:3: [response] k_s is deprecated: use [response] stiffness_n_per_m (both are "
              "set, to the same value: remove [response] k_s)");
  // without the list it is an unknown key
  EXPECT_FALSE(parseConfig("[response]\nk_s = 700\n", "d.toml", {}));
}

// The output limits were set twice, in [device] and [response]: the old [response] keys are
// read into the one set with a warning naming the new key; old and new together must agree.
TEST(Config, TheOldResponseOutputKeysMapToTheOneSetWithAWarning) {
  const struct {
    const char* old_key;
    const char* section;  // of the new key
    const char* name;
    double value;
    double (*sim)(const sim::ResponseOptions&);  // what the simulation gets
  } moved[] = {
      {"max_force_n", "device", "max_force_n", 7.5,
       [](const sim::ResponseOptions& r) { return r.max_force_n; }},
      {"max_torque_nm", "device", "max_torque_nm", 0.75,
       [](const sim::ResponseOptions& r) { return r.max_torque_nm; }},
      {"max_force_step_n", "device", "max_force_step_n", 0.25,
       [](const sim::ResponseOptions& r) { return r.max_force_step_n; }},
      {"max_torque_step_nm", "device", "max_torque_step_nm", 0.025,
       [](const sim::ResponseOptions& r) { return r.max_torque_step_nm; }},
      {"ramp_s", "servo", "ramp_in_s", 0.125,
       [](const sim::ResponseOptions& r) { return r.ramp_s; }},
  };
  for (const auto& m : moved) {
    SCOPED_TRACE(m.old_key);
    const std::string new_label = "[" + std::string(m.section) + "] " + m.name;
    const std::string old_text =
        "[response]\n" + std::string(m.old_key) + " = " + shortestNumber(m.value) + "\n";
    auto parsed = parseConfig(old_text, "old.toml");
    ASSERT_TRUE(parsed) << parsed.error().message;
    EXPECT_EQ(m.sim(toSimOptions(parsed.value().config).response), m.value);
    ASSERT_EQ(parsed.value().warnings.size(), 1u);
    EXPECT_EQ(parsed.value().warnings[0], "old.toml:2: [response] " + std::string(m.old_key) +
                                              " is deprecated: use " + new_label +
                                              " (the value is taken for it)");
    EXPECT_EQ(parsed.value().keys_set,
              std::vector<std::string>{std::string(m.section) + "." + m.name});
    // the new key beside it with another value: refused, naming both
    const std::string conflict =
        old_text + "[" + m.section + "]\n" + m.name + " = " + shortestNumber(2.0 * m.value) + "\n";
    auto refused = parseConfig(conflict, "old.toml");
    ASSERT_FALSE(refused) << conflict;
    EXPECT_NE(refused.error().message.find("[response] " + std::string(m.old_key) + " and " +
                                           new_label + " are both set, to different values"),
              std::string::npos)
        << refused.error().message;
    // the same value: taken, with one warning
    const std::string agree =
        old_text + "[" + m.section + "]\n" + m.name + " = " + shortestNumber(m.value) + "\n";
    auto taken = parseConfig(agree, "old.toml");
    ASSERT_TRUE(taken) << taken.error().message;
    EXPECT_EQ(m.sim(toSimOptions(taken.value().config).response), m.value);
    EXPECT_EQ(taken.value().warnings.size(), 1u);
  }
  // the [device] limits reach both stages: the simulation's and the servo loop's guard
  auto parsed = parseConfig("[device]\nmax_force_n = 7.5\nmax_force_step_n = 0.25\n", "new.toml");
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_EQ(toSimOptions(parsed.value().config).response.max_force_n, 7.5);
  EXPECT_EQ(toSimOptions(parsed.value().config).response.max_force_step_n, 0.25);
  device::DeviceInfo wide;
  wide.limits.max_force_n = wide.limits.max_torque_nm = 1e9;
  const ServoOptions o = toServoOptions(parsed.value().config, wide);
  EXPECT_EQ(o.limits.max_force_n, 7.5);
  EXPECT_EQ(o.max_force_step_n, 0.25);
  // an old [response] key is no longer a key of the table
  for (const auto& m : moved)
    EXPECT_EQ(findConfigKey("response", m.old_key), nullptr) << m.old_key;
}

TEST(Config, ChangedKeysNamesWhatDiffers) {
  Config a, b;
  b.device.options.sim_hand_mass_kg = 0.7;
  b.response.sim.response.stiffness_n_per_m = 700.0;
  EXPECT_EQ(changedKeys(a, b),
            (std::vector<std::string>{"device.sim_hand_mass_kg", "response.stiffness_n_per_m"}));
  const std::string_view restart_only[] = {"servo", "device", "network"};
  EXPECT_EQ(changedKeys(a, b, restart_only), std::vector<std::string>{"device.sim_hand_mass_kg"});
  EXPECT_FALSE(a == b);
  EXPECT_TRUE(a == Config{});
}

TEST(Config, MissingFileIsAClearError) {
  auto parsed = loadConfigFile("/nonexistent/hapticd.toml");
  ASSERT_FALSE(parsed);
  EXPECT_NE(parsed.error().message.find("/nonexistent/hapticd.toml"), std::string::npos);
}

}  // namespace
}  // namespace hapticd::daemon
