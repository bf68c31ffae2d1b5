// Runs the wavepath binary (WP_WAVEPATH_BIN, set by tests/CMakeLists.txt) as a user does, for the
// command-line tests.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace wp::test {

struct CliRun {
  int status = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs `wavepath args` in folder `dir` with extra environment `env` (assignments, or a command
// prefix); stdout and stderr are captured through out.txt and err.txt there, then removed.
inline CliRun run_wavepath(const std::filesystem::path& dir, const std::string& args,
                           const std::string& env = "") {
  const std::string cmd = "cd '" + dir.string() + "' && " + env + " '" WP_WAVEPATH_BIN "' " + args +
                          " >out.txt 2>err.txt";
  CliRun r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(dir / "out.txt");
  r.err = slurp(dir / "err.txt");
  std::filesystem::remove(dir / "out.txt");
  std::filesystem::remove(dir / "err.txt");
  return r;
}

// A fixture whose every test has a fresh folder of its own, dir_ (named after the process and the
// test), removed afterwards.
class FolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("wavepath_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name() + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::filesystem::path dir_;
};

// The number after "key": in the JSON line `json` (wavepath's --json output), or NaN when absent.
inline double json_number(const std::string& json, const std::string& key) {
  const std::string tag = "\"" + key + "\":";
  const std::size_t at = json.find(tag);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + tag.size(), nullptr);
}

}  // namespace wp::test
