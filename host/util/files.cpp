#include "host/util/files.h"

#include <cstdlib>
#include <filesystem>
#include <random>

namespace wp {

std::string cache_dir() {
  if (const char* d = std::getenv("WAVEPATH_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/wavepath";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.cache/wavepath";
  return {};
}

bool write_file_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write) {
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  const std::string temp = path + ".tmp" + std::to_string(std::random_device{}());
  std::FILE* f = std::fopen(temp.c_str(), "wb");
  if (!f) return false;
  bool ok = write(f);
  ok &= std::fclose(f) == 0;
  if (ok) std::filesystem::rename(temp, path, ec);
  if (!ok || ec) std::filesystem::remove(temp, ec);
  return ok && !ec;
}

}  // namespace wp
