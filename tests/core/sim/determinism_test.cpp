// Determinism of the simulation state (core/sim/scene_state.h): each demo stream
// (tests/streams/*.csv on scenes/*.glb) replayed through sim::step twice in this process and
// once more in a second process (this binary run again, in a fresh address space) gives the
// same state hash at every tick; a state copied mid-stream steps on exactly as the original.
//
// Usage of the second process: determinism_test --write-hashes SCENE FILE (writes the hash of
// every tick of SCENE's replay to FILE, 8 bytes each, and exits 0).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/scene/loader.h"
#include "core/sim/model.h"
#include "core/sim/scene_state.h"
#include "protocol/pose_stream.h"
#include "tests/core/alloc_counter.h"
#include "tests/core/sim/demo_streams.h"

namespace hapticd::sim {
namespace {

// a demo scene compiled with the default options, and its pose stream
struct Replay {
  std::shared_ptr<const SimModel> model;
  std::vector<proto::PoseStreamRow> rows;
  double tick_s = 0.001;

  // ticks 0 .. n, n the stream's duration in ticks (as the replay device plays it)
  std::uint64_t ticks() const {
    return static_cast<std::uint64_t>(std::llround(rows.back().t_s / tick_s)) + 1;
  }
  TickInput input(std::uint64_t k, std::size_t& cursor) const {
    TickInput in;
    in.t_s = static_cast<double>(k) * tick_s;
    const proto::PoseStreamRow row = proto::samplePoseStream(rows, in.t_s, cursor);
    in.X_W_device = row.X_WD;
    in.buttons = row.buttons;
    return in;
  }
};

std::string sourceDir() {
  return HAPTICD_SOURCE_DIR;
}

Replay load(const std::string& name, std::string* error) {
  Replay r;
  auto report = scene::loadSceneFile(sourceDir() + "/scenes/" + name + ".glb");
  if (!report.ok()) {
    *error = report.message();
    return r;
  }
  const std::string stream = sourceDir() + "/tests/streams/" + name + ".csv";
  auto text = proto::readPoseStreamFile(stream);
  if (!text.ok()) {
    *error = stream + ": " + text.error().message;
    return r;
  }
  auto rows = proto::parsePoseStream(text.value(), stream, 1e-3, proto::PoseStreamDialect::kStrict);
  if (!rows.ok()) {
    *error = rows.error().message;
    return r;
  }
  r.rows = std::move(rows).value();
  const SimOptions options;
  r.tick_s = options.response.tick_s;
  auto model = SimModel::compile(
      std::make_shared<const scene::SceneModel>(std::move(*report.scene)), options);
  if (!model.ok()) {
    *error = model.error().message;
    return r;
  }
  r.model = std::move(model).value();
  return r;
}

// the state hash after every tick of the whole stream
std::vector<std::uint64_t> replayHashes(const Replay& r) {
  std::vector<std::uint64_t> out;
  auto state = makeState(*r.model);
  if (!state.ok())
    return out;
  SceneState& s = state.value();
  out.reserve(r.ticks());
  std::size_t cursor = 0;
  for (std::uint64_t k = 0; k < r.ticks(); ++k) {
    step(*r.model, s, r.input(k, cursor));
    out.push_back(stateHash(s));
  }
  return out;
}

// the first tick at which two runs differ, or -1
std::int64_t firstDifference(const std::vector<std::uint64_t>& a,
                             const std::vector<std::uint64_t>& b) {
  for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
    if (a[k] != b[k])
      return static_cast<std::int64_t>(k);
  }
  return a.size() == b.size() ? -1 : static_cast<std::int64_t>(std::min(a.size(), b.size()));
}

const char* g_self = nullptr;  // this executable (argv[0])

// this binary again, in a new process: --write-hashes NAME FILE
std::vector<std::uint64_t> hashesFromAnotherProcess(const std::string& name) {
  char path[] = "/tmp/hapticd_determinism_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0)
    return {};
  close(fd);
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/proc/self/exe", g_self, "--write-hashes", name.c_str(), path,
          static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  std::vector<std::uint64_t> out;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    std::ifstream in(path, std::ios::binary);
    std::uint64_t h = 0;
    while (in.read(reinterpret_cast<char*>(&h), sizeof h))
      out.push_back(h);
  }
  std::remove(path);
  return out;
}

class Determinism : public ::testing::TestWithParam<const char*> {};

TEST_P(Determinism, EveryTickHashesTheSameTwiceInOneProcessAndInAnother) {
  std::string error;
  const Replay r = load(GetParam(), &error);
  ASSERT_TRUE(r.model) << error;
  const std::vector<std::uint64_t> first = replayHashes(r);
  ASSERT_EQ(first.size(), r.ticks());
  // the state changes as the stream plays (the hash sees it)
  EXPECT_NE(first.front(), first.back());
  const std::vector<std::uint64_t> second = replayHashes(r);
  EXPECT_EQ(firstDifference(first, second), -1) << "the second run in this process differs";
  const std::vector<std::uint64_t> other = hashesFromAnotherProcess(GetParam());
  EXPECT_EQ(other.size(), first.size()) << "the other process failed or stopped early";
  EXPECT_EQ(firstDifference(first, other), -1) << "the run in another process differs";
  std::printf("  %s: %zu ticks, final state hash %016llx\n", GetParam(), first.size(),
              static_cast<unsigned long long>(first.back()));
}

TEST_P(Determinism, AStateCopiedMidStreamStepsOnAsTheOriginal) {
  std::string error;
  const Replay r = load(GetParam(), &error);
  ASSERT_TRUE(r.model) << error;
  auto made = makeState(*r.model);
  ASSERT_TRUE(made.ok()) << made.error().message;
  SceneState& original = made.value();
  const std::uint64_t n = r.ticks(), half = n / 2;
  std::size_t cursor = 0;
  for (std::uint64_t k = 0; k < half; ++k)
    step(*r.model, original, r.input(k, cursor));
  SceneState copy = original;
  EXPECT_TRUE(copy == original);
  ASSERT_EQ(stateHash(copy), stateHash(original));
  // the copy keeps every capacity: stepping it allocates nothing, and neither does the original
  std::uint64_t copy_allocations = 0, differing_ticks = 0, first_differing = 0;
  std::size_t copy_cursor = cursor;
  for (std::uint64_t k = half; k < n; ++k) {
    step(*r.model, original, r.input(k, cursor));
    const std::uint64_t before = testing_alloc::count();
    step(*r.model, copy, r.input(k, copy_cursor));
    copy_allocations += testing_alloc::count() - before;
    if (stateHash(copy) != stateHash(original) && differing_ticks++ == 0)
      first_differing = k;
  }
  EXPECT_EQ(differing_ticks, 0u) << "first at tick " << first_differing;
  EXPECT_TRUE(copy == original);
  EXPECT_EQ(copy_allocations, 0u);
  // and a state that has stepped differently compares unequal
  step(*r.model, copy, r.input(n, copy_cursor));
  EXPECT_FALSE(copy == original);
  EXPECT_NE(stateHash(copy), stateHash(original));
}

INSTANTIATE_TEST_SUITE_P(Scenes, Determinism, simtest::demoStreams(), simtest::demoStreamName);

}  // namespace
}  // namespace hapticd::sim

int main(int argc, char** argv) {
  using namespace hapticd::sim;  // NOLINT(google-build-using-namespace): the test's own helpers
  g_self = argv[0];
  if (argc == 4 && std::strcmp(argv[1], "--write-hashes") == 0) {
    std::string error;
    const Replay r = load(argv[2], &error);
    if (!r.model) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 1;
    }
    const std::vector<std::uint64_t> hashes = replayHashes(r);
    std::ofstream out(argv[3], std::ios::binary);
    out.write(reinterpret_cast<const char*>(hashes.data()),
              static_cast<std::streamsize>(hashes.size() * sizeof(std::uint64_t)));
    return out ? 0 : 1;
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
