#pragma once
/// \file
/// Test helpers for running the real hapticd and hapticctl binaries as subprocesses: spawn with
/// stdout and stderr to files, wait with a bound (a hang fails), read a file whole. Header-only,
/// test code.

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace hapticd::testing {

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs `args` (args[0] the binary) with stdout and stderr to files; returns the pid.
inline pid_t spawn(const std::vector<std::string>& args,
                   const std::filesystem::path& out,
                   const std::filesystem::path& err) {
  std::vector<std::string> all(args);
  std::vector<char*> argv;
  for (auto& a : all)
    argv.push_back(a.data());
  argv.push_back(nullptr);
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
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

/// The exit code, or -1 after killing a child that did not end within limit_s.
inline int waitFor(pid_t pid, double limit_s) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  int status = 0;
  while (std::chrono::steady_clock::now() < until) {
    if (waitpid(pid, &status, WNOHANG) == pid)
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  return -1;
}

}  // namespace hapticd::testing
