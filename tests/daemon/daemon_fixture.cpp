#include "tests/daemon/daemon_fixture.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

extern char** environ;

namespace hapticd::testing {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

nlohmann::json parseJsonOrEmpty(const std::string& text) {
  auto j = nlohmann::json::parse(text, nullptr, false);
  return j.is_discarded() ? nlohmann::json::object() : j;
}

std::string testName() {
  return ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

ScratchDir::ScratchDir(const std::string& prefix) {
  std::string name = testName();  // "Case/Param" for a parametrised test: one folder, no parent
  for (char& ch : name)
    if (ch == '/')
      ch = '_';
  path_ = fs::temp_directory_path() / (prefix + "_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(path_);
  fs::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

void blockDaemonSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  sigaddset(&set, SIGINT);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
}

bool pollUntil(const std::function<bool()>& pred, int polls, int ms) {
  for (int i = 0; i < polls; ++i) {
    if (pred())
      return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(ms));
  }
  return false;
}

nlohmann::json readStatus(const fs::path& file) {
  return parseJsonOrEmpty(slurp(file));
}

bool waitForStatus(const fs::path& file, const std::function<bool(const nlohmann::json&)>& pred) {
  return pollUntil([&] {
    const auto j = readStatus(file);
    return !j.empty() && pred(j);
  });
}

const proto::SceneUpdate::BodyPose* listedBody(const proto::State& s, std::uint32_t body) {
  for (const auto& b : s.bodies)
    if (b.body_index == body)
      return &b;
  return nullptr;
}

pid_t spawn(const std::vector<std::string>& args,
            const fs::path& out,
            const fs::path& err,
            const SpawnOptions& options) {
  std::vector<std::string> all(args);
  std::vector<char*> argv;
  for (auto& a : all)
    argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings(options.extra_env);
  for (char** e = environ; *e != nullptr; ++e)
    env_strings.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env_strings)
    envp.push_back(e.data());
  envp.push_back(nullptr);
  const std::string o = out.string(), e = err.string();
  const pid_t pid = fork();
  if (pid == 0) {
    const int fo = open(o.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int fe = open(e.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(fo, 1);
    dup2(fe, 2);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    if (options.prepare)
      options.prepare();
    execve(argv[0], argv.data(), envp.data());
    _exit(127);
  }
  return pid;
}

int waitExit(pid_t pid, double limit_s) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  int status = 0;
  while (std::chrono::steady_clock::now() < until) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid)
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (r < 0)
      return -1;  // reaped before (running() saw it end): nothing to wait for, nor to kill
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  return -1;
}

bool running(pid_t pid) {
  int status = 0;
  // 0: still running; the pid: it ended and is reaped now; -1 (ECHILD): reaped by an earlier
  // call, so not running either (it was counted as running, and a test that saw a daemon refused
  // then read the status of a process that no longer existed)
  return waitpid(pid, &status, WNOHANG) == 0;
}

bool receiveUntil(proto::Client& c,
                  const std::function<bool(const proto::State&)>& pred,
                  double limit_s,
                  proto::State* last) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  while (std::chrono::steady_clock::now() < end) {
    auto s = c.receiveState(100);
    if (!s)
      continue;
    if (last)
      *last = *s;
    if (pred(*s))
      return true;
  }
  return false;
}

StreamStop awaitStreamStop(proto::ShmClient& c, proto::ShmState& st, int polls) {
  StreamStop r;
  for (int i = 0; i < polls && !r.faulted; ++i) {
    c.beat(proto::monotonicNs());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (!c.readState(st))
      continue;
    if ((st.state_flags & proto::kStateRamping) != 0 && st.force_scale > 0.0 &&
        st.force_scale < 1.0)
      r.saw_ramp = true;
    r.faulted = (st.fault_bits & proto::kFaultStreamLost) != 0;
  }
  return r;
}

}  // namespace hapticd::testing
