#include "tests/fuzz/fuzz_file.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace wp::fuzz {
namespace {

// Created on first use, removed at exit. Kept in a plain array: a std::string static would be
// destroyed before the atexit handler that needs it runs.
char g_folder[4096];

void remove_folder() {
  std::error_code ec;
  std::filesystem::remove_all(g_folder, ec);
}

std::string scratch_folder() {
  if (g_folder[0] == '\0') {
    // WP_FUZZ_SCRATCH (tools/fuzz.sh sets it, and removes it, so a crashed run leaves nothing).
    const char* base = std::getenv("WP_FUZZ_SCRATCH");
    if (!base) base = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
    const int n = std::snprintf(g_folder, sizeof g_folder, "%s/wavepath-fuzz-XXXXXX", base);
    if (n <= 0 || std::size_t(n) >= sizeof g_folder || !mkdtemp(g_folder)) {
      std::perror("wavepath fuzz: mkdtemp");
      std::abort();
    }
    std::atexit(remove_folder);
  }
  return g_folder;
}

}  // namespace

std::string write_input(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  const std::string folder = scratch_folder();
  // One name per extension, so a stale input of the other kind never lies beside this one.
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec))
    std::filesystem::remove(entry.path(), ec);
  const std::string path = folder + "/input" + extension;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror(("wavepath fuzz: writing " + path).c_str());
    std::abort();
  }
  return path;
}

void invariant_failed(const std::string& what) {
  std::fprintf(stderr, "wavepath fuzz: broken invariant: %s\n", what.c_str());
  std::abort();
}

}  // namespace wp::fuzz
