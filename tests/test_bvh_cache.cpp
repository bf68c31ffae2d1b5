// The BVH disk cache: a stored BVH comes back identical, anything the build depends on changes the
// key, and a damaged entry is a miss rather than an error.
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "bvh/bvh_cache.h"
#include "tests/bvh_test_util.h"

namespace {

using namespace wp::bvh;
using namespace wp::bvh::test;
namespace fs = std::filesystem;

class BvhCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / ("wp_bvh_cache_" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

TEST_F(BvhCache, StoredBvhComesBackIdentical) {
  const Mesh mesh = soup(3000, 5, 0.05f);
  for (int width : {2, 8}) {
    BuildOptions o;
    o.width = width;
    bool hit = true;
    const Bvh built = build_cached(mesh.input(), o, dir_, &hit);
    EXPECT_FALSE(hit);
    const Bvh loaded = build_cached(mesh.input(), o, dir_, &hit);
    EXPECT_TRUE(hit);
    EXPECT_EQ(loaded.width, width);
    EXPECT_TRUE(same_bytes(built.nodes, loaded.nodes));
    EXPECT_TRUE(same_bytes(built.triangles, loaded.triangles));
    EXPECT_TRUE(same_bytes(built.nodes8, loaded.nodes8));
    EXPECT_TRUE(same_bytes(built.blocks, loaded.blocks));
    EXPECT_EQ(built.stats.sah_cost, loaded.stats.sah_cost);
    EXPECT_EQ(check_invariants(loaded, mesh.triangles(), false), "");
  }
}

TEST_F(BvhCache, KeyDependsOnWhatTheBuildDependsOn) {
  Mesh mesh = soup(100, 6, 0.05f);
  BuildOptions o;
  const auto key = cache_key(mesh.input(), o);
  EXPECT_EQ(key, cache_key(mesh.input(), o));
  BuildOptions wide = o;
  wide.width = 8;
  EXPECT_NE(key, cache_key(mesh.input(), wide));
  BuildOptions splits = o;
  splits.spatial_splits = true;
  EXPECT_NE(key, cache_key(mesh.input(), splits));
  Mesh moved = mesh;
  moved.positions[7].x += 1e-6f;
  EXPECT_NE(key, cache_key(moved.input(), o));
  Mesh flagged = mesh;
  flagged.flags.assign(mesh.triangles(), 0u);
  EXPECT_EQ(key, cache_key(flagged.input(), o));  // all-zero flags are no flags
  flagged.flags[3] = WP_TRI_CULL_BACKFACE;
  EXPECT_NE(key, cache_key(flagged.input(), o));
}

TEST_F(BvhCache, DamagedEntryIsAMiss) {
  const Mesh mesh = soup(500, 7, 0.05f);
  BuildOptions o;
  build_cached(mesh.input(), o, dir_);
  ASSERT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
  const fs::path entry = fs::directory_iterator(dir_)->path();
  fs::resize_file(entry, fs::file_size(entry) / 2);  // truncated
  EXPECT_FALSE(cache_load(dir_, cache_key(mesh.input(), o)).has_value());
  bool hit = true;
  const Bvh rebuilt = build_cached(mesh.input(), o, dir_, &hit);
  EXPECT_FALSE(hit);
  EXPECT_EQ(check_invariants(rebuilt, mesh.triangles(), false), "");
  std::ofstream(entry, std::ios::binary) << "not a bvh";  // garbage
  EXPECT_FALSE(cache_load(dir_, cache_key(mesh.input(), o)).has_value());
  EXPECT_FALSE(cache_load("", 1).has_value());  // no cache folder: always a miss
}

}  // namespace
