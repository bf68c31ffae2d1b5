// Runs the wavepath binary (WP_WAVEPATH_BIN, set by tests/CMakeLists.txt) as a user does, for the
// command-line tests.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

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

}  // namespace wp::test
