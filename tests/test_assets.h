// Where the shared real-world assets are, for tests that use them. When the folder is absent (a
// fresh clone elsewhere), such tests skip rather than fail.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace wp::test {

inline std::string assets_dir() {
  if (const char* env = std::getenv("WAVEPATH_ASSETS"); env && *env) return env;
  return WP_ASSETS_DIR;
}

// Path of a model file under assets/models, e.g. model_path("Box/Box.glb"); empty if missing.
inline std::string model_path(const std::string& relative) {
  const std::filesystem::path p = std::filesystem::path(assets_dir()) / "models" / relative;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

inline std::string source_path(const std::string& relative) {
  return std::string(WP_SOURCE_DIR) + "/" + relative;
}

}  // namespace wp::test

// Skips the current test when the asset is absent; otherwise declares `var` holding its path.
#define WP_REQUIRE_MODEL(var, relative)                     \
  const std::string var = ::wp::test::model_path(relative); \
  if (var.empty())                                          \
  GTEST_SKIP() << "asset not found: " << (relative) << " (under " << ::wp::test::assets_dir() << ")"
