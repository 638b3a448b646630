// `hapticctl load FILE.gltf` with the real hapticd: the client bundles the buffers beside its file
// into the upload, so the daemon loads the client's geometry whatever its own [scene]
// allowed_uri_dir holds, even a file of the same name (issue "glTF as people export it": a
// client's ext2.gltf was once loaded with the daemon's external.bin). Waits are bounded; nothing
// is timed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/scene/glb.h"
#include "protocol/client.h"
#include "tests/core/scene/gltf_builder.h"
#include "tests/daemon/daemon_fixture.h"

namespace {

namespace fs = std::filesystem;
using hapticd::scene::testing::GltfBuilder;
using hapticd::scene::testing::json;
using hapticd::testing::slurp;
using hapticd::testing::spawn;
using hapticd::testing::waitExit;

class UploadBundleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hapticd_upload_bundle_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "client");
    fs::create_directories(dir_ / "daemon");
    // the client's scene: a floor and a 10 mm held cube whose mesh is in external.bin beside it
    GltfBuilder b;
    json floor = GltfBuilder::node("Floor", {0.0, -0.05, 0.0});
    GltfBuilder::physics(floor)["collider"] = GltfBuilder::shapeCollider(b.box({1.0, 0.1, 1.0}));
    b.addNode(floor);
    json probe = GltfBuilder::node("Probe", {0.0, 0.2, 0.0});
    probe["mesh"] = b.addMesh(hapticd::scene::testing::cubeMesh(0.005), "Probe");
    GltfBuilder::physics(probe)["motion"] = {{"isKinematic", true}};
    GltfBuilder::physics(probe)["collider"] = {{"geometry", {{"node", 1}}}};
    probe["extras"]["haptic"] = {{"probe", true}};
    b.addNode(probe);
    json d = b.doc;
    d["buffers"] = json::array({json{{"byteLength", b.bin.size()}, {"uri", "external.bin"}}});
    gltf_ = d.dump();
    std::ofstream(dir_ / "client" / "ext2.gltf") << gltf_;
    write(dir_ / "client" / "external.bin", b.bin);
    // the daemon's folder holds a file of the same name that no scene can be built from
    std::vector<std::uint8_t> poisoned = b.bin;
    for (std::size_t i = 0; i < 96; i += 4)
      poisoned[i + 3] = 0x7F, poisoned[i + 2] = 0xC0;  // NaN positions
    write(dir_ / "daemon" / "external.bin", poisoned);
  }
  void TearDown() override {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      EXPECT_EQ(waitExit(pid_, 60.0), 0) << slurp(dir_ / "d.err");
    }
    fs::remove_all(dir_);
  }
  static void write(const fs::path& p, const std::vector<std::uint8_t>& bytes) {
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }

  void startDaemon() {
    const std::string shm = "/hapticd-upload-bundle-" + std::to_string(getpid());
    std::ofstream(dir_ / "hapticd.toml")
        << "[servo]\nrealtime = \"off\"\n[scene]\npath = \"" << HAPTICD_SOURCE_DIR
        << "/scenes/peg_in_hole.glb\"\nallowed_uri_dir = \"" << (dir_ / "daemon").string()
        << "\"\n[network]\nshm = \"" << shm << "\"\n";
    pid_ = spawn({HAPTICD_BINARY, "--config", (dir_ / "hapticd.toml").string(), "--udp",
                  "127.0.0.1:0", "--status-file", (dir_ / "status.json").string()},
                 dir_ / "d.out", dir_ / "d.err");
    ASSERT_GT(pid_, 0);
    for (int i = 0; i < 6000 && port_ == 0; ++i) {
      auto j = nlohmann::json::parse(slurp(dir_ / "status.json"), nullptr, false);
      if (!j.is_discarded() && j.contains("network") && j.value("tick", 0) > 0) {
        const std::string a = j["network"]["udp"];
        port_ = std::stoi(a.substr(a.rfind(':') + 1));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_GT(port_, 0) << slurp(dir_ / "d.err");
  }

  int ctl(const std::vector<std::string>& args) {
    std::vector<std::string> all{HAPTICCTL_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    all.insert(all.end(), {"--port", std::to_string(port_)});
    return waitExit(spawn(all, dir_ / "c.out", dir_ / "c.err"), 120.0);
  }

  fs::path dir_;
  std::string gltf_;
  pid_t pid_ = -1;
  int port_ = 0;
};

TEST_F(UploadBundleTest, TheDaemonLoadsTheClientsGeometryWhateverItsFolderHolds) {
  startDaemon();
  // hapticctl sends the scene with the client's external.bin inside it: accepted
  EXPECT_EQ(ctl({"load", (dir_ / "client" / "ext2.gltf").string()}), 0) << slurp(dir_ / "c.err");
  ASSERT_EQ(ctl({"status", "--json"}), 0) << slurp(dir_ / "c.err");
  auto status = nlohmann::json::parse(slurp(dir_ / "c.out"), nullptr, false);
  EXPECT_EQ(status.value("scene", ""), "ext2.gltf") << slurp(dir_ / "c.out");

  // the same .gltf sent as it is (no bundle) is refused for naming a file, not resolved against
  // the daemon's folder: neither with the poisoned external.bin there nor with a valid one
  hapticd::proto::ClientConfig config;
  config.server = "127.0.0.1:" + std::to_string(port_);
  config.timeout_ms = 10000;
  auto client = hapticd::proto::Client::connect(config);
  ASSERT_TRUE(client) << client.error().message;
  const auto raw = std::vector<std::uint8_t>(gltf_.begin(), gltf_.end());
  auto refused = client.value()->load(raw, "raw.gltf");
  ASSERT_FALSE(refused);
  EXPECT_NE(
      refused.error().message.find("external URI 'external.bin' refused: no folder is allowed"),
      std::string::npos)
      << refused.error().message;
  fs::copy_file(dir_ / "client" / "external.bin", dir_ / "daemon" / "external.bin",
                fs::copy_options::overwrite_existing);
  refused = client.value()->load(raw, "raw.gltf");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("no folder is allowed"), std::string::npos)
      << refused.error().message;
  client.value()->bye();

  // with nothing of that name in the daemon's folder, the bundle still loads
  fs::remove(dir_ / "daemon" / "external.bin");
  EXPECT_EQ(ctl({"load", (dir_ / "client" / "ext2.gltf").string()}), 0) << slurp(dir_ / "c.err");
  // a buffer that escapes the client's folder is refused by hapticctl before anything is sent
  std::string escape = gltf_;
  escape.replace(escape.find("external.bin"), 12, "../daemon/external.bin");
  std::ofstream(dir_ / "client" / "escape.gltf") << escape;
  EXPECT_EQ(ctl({"load", (dir_ / "client" / "escape.gltf").string()}), 1);
  EXPECT_NE(slurp(dir_ / "c.err").find("traverses out of the allowed folder"), std::string::npos)
      << slurp(dir_ / "c.err");
}

}  // namespace
