// A test of a built binary (hapticctl, hapticd): each test gets a scratch directory of its own,
// runs command lines with their stdout and stderr kept there, and reads files back.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace hapticd::testing {

class CommandDirTest : public ::testing::Test {
 protected:
  /// `prefix` names the scratch directory: <tmp>/<prefix>_<pid>_<test name>
  explicit CommandDirTest(std::string prefix) : prefix_(std::move(prefix)) {}

  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (prefix_ + "_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string slurp(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  // runs a command line (arguments single-quoted); stdout and stderr kept in the directory
  int run(const std::string& program, const std::vector<std::string>& args) {
    std::string cmd = "'" + program + "'";
    for (const std::string& a : args)
      cmd += " '" + a + "'";
    cmd += " > '" + path("stdout") + "' 2> '" + path("stderr") + "'";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::string out() const { return slurp(path("stdout")); }
  std::string err() const { return slurp(path("stderr")); }

  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace hapticd::testing
