// The BVH disk cache: a stored BVH comes back identical, anything the build depends on changes the
// key, and a damaged entry (truncated, a flipped byte, a huge length, an index out of range) is a
// miss rather than an error, a crash or a huge allocation.
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <new>
#include <stdexcept>

#include <gtest/gtest.h>

#include "host/accel/bvh_cache.h"
#include "tests/bvh_test_util.h"

// Every allocation of this test program goes through here, so that a test can tell the largest
// one a load asked for; one of a GiB or more is refused (bad_alloc), never attempted, so a load
// that trusts a huge length fails the test instead of exhausting the machine.
namespace {
std::atomic<std::size_t> largest_allocation{0};
constexpr std::size_t kRefusedAllocation = std::size_t(1) << 30;
void note_allocation(std::size_t n) {
  std::size_t seen = largest_allocation.load();
  while (n > seen && !largest_allocation.compare_exchange_weak(seen, n)) {
  }
  if (n >= kRefusedAllocation) throw std::bad_alloc();
}
}  // namespace

// None of them is inlined: GCC checks that what frees a pointer matches what allocated it
// (-Wmismatched-new-delete), and an inlined one shows it malloc or free instead. Under the
// sanitizers (tools/sanitize.sh) it inlined the deletes into gtest's `new TestClass` and warned
// of operator new's pointer given to free(); with only the deletes out of line, it warned at -O3
// of malloc's pointer given to operator delete.
[[gnu::noinline]] void* operator new(std::size_t n) {
  note_allocation(n);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new(std::size_t n, std::align_val_t a) {
  note_allocation(n);
  void* p = nullptr;
  const std::size_t align = std::max(static_cast<std::size_t>(a), sizeof(void*));
  if (posix_memalign(&p, align, n ? n : 1) == 0) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

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
  // Builds `mesh` with `o` through the cache and returns the path of the one entry it stored.
  fs::path store(const Mesh& mesh, const BuildOptions& o) {
    build_cached(mesh.input(), o, dir_);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
    return fs::directory_iterator(dir_)->path();
  }
  // An empty cache, then `mesh` stored with `o`: the entry's path, key and bytes.
  struct Entry {
    fs::path path;
    std::uint64_t key;
    std::vector<char> bytes;
  };
  Entry fresh_entry(const Mesh& mesh, const BuildOptions& o);
  std::string dir_;
};

std::vector<char> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

BvhCache::Entry BvhCache::fresh_entry(const Mesh& mesh, const BuildOptions& o) {
  fs::remove_all(dir_);
  Entry e;
  e.path = store(mesh, o);
  e.key = cache_key(mesh.input(), o);
  e.bytes = read_bytes(e.path);
  return e;
}

// Replaces the file with the first n bytes. Removed first: truncating a file in place makes some
// file systems (ext4's auto_da_alloc) flush it to disk on close, milliseconds each time.
void write_bytes(const fs::path& path, const std::vector<char>& bytes, std::size_t n) {
  fs::remove(path);
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(n));
}

BuildOptions options(int width, bool splits = false) {
  BuildOptions o;
  o.width = width;
  o.spatial_splits = splits;
  return o;
}

// Empty vectors (a layout's unused arrays) may have null data(), which memcmp must not be given
// even for zero bytes.
template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
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

// What (d) of the corruption tests rests on: a sound entry loads, for both layouts with and
// without spatial splits (whose extra references the length checks must allow), and equals the
// build it came from.
TEST_F(BvhCache, SoundEntryLoadsAsBuilt) {
  const Mesh mesh = soup(800, 11, 0.2f);  // large triangles: spatial splits do happen
  for (int width : {2, 8}) {
    for (bool splits : {false, true}) {
      fs::remove_all(dir_);
      const BuildOptions o = options(width, splits);
      const Bvh built = build(mesh.input(), o);
      const std::uint64_t key = cache_key(mesh.input(), o);
      cache_store(dir_, key, built);
      const std::optional<Bvh> loaded = cache_load(dir_, key, mesh.triangles(), o);
      ASSERT_TRUE(loaded.has_value()) << "width " << width << " splits " << splits;
      EXPECT_EQ(loaded->width, width);
      EXPECT_TRUE(same_bytes(built.nodes, loaded->nodes));
      EXPECT_TRUE(same_bytes(built.triangles, loaded->triangles));
      EXPECT_TRUE(same_bytes(built.nodes8, loaded->nodes8));
      EXPECT_TRUE(same_bytes(built.blocks, loaded->blocks));
      EXPECT_EQ(built.lo, loaded->lo);
      EXPECT_EQ(built.hi, loaded->hi);
      EXPECT_EQ(built.stats.sah_cost, loaded->stats.sah_cost);
      EXPECT_EQ(built.stats.triangle_refs, loaded->stats.triangle_refs);
      EXPECT_EQ(built.stats.max_depth, loaded->stats.max_depth);
      if (splits) {
        EXPECT_GT(built.stats.triangle_refs, mesh.triangles());
      }
      // The same entry for another triangle count or layout is not this scene's.
      EXPECT_FALSE(cache_load(dir_, key, mesh.triangles() + 1, o).has_value());
      EXPECT_FALSE(cache_load(dir_, key, mesh.triangles() - 1, o).has_value());
      EXPECT_FALSE(
          cache_load(dir_, key, mesh.triangles(), options(10 - width, splits)).has_value());
    }
  }
}

// (a) One changed byte anywhere in the node payload (and, more sparsely, anywhere else) makes
// the entry a miss: a flipped low bit of a box coordinate may still pass the structural checks,
// a flipped index byte would send the kernels out of bounds.
TEST_F(BvhCache, FlippedByteIsAMiss) {
  const Mesh mesh = soup(500, 7, 0.05f);
  for (int width : {2, 8}) {
    const BuildOptions o = options(width);
    const auto [entry, key, good] = fresh_entry(mesh, o);
    const Bvh built = build(mesh.input(), o);
    const std::size_t node_bytes = width == 2 ? built.nodes.size() * sizeof(built.nodes[0])
                                              : built.nodes8.size() * sizeof(built.nodes8[0]);
    const std::size_t nodes_begin = sizeof(CacheHeader);
    ASSERT_GT(good.size(), nodes_begin + node_bytes);
    std::vector<std::size_t> at;
    const std::size_t first_node =
        width == 2 ? sizeof(wp::dev::BvhNode) : sizeof(wp::dev::BvhNode8);
    for (std::size_t i = 0; i < first_node; ++i) at.push_back(nodes_begin + i);  // the root
    for (std::size_t i = 0; i < 64; ++i) at.push_back(nodes_begin + i * node_bytes / 64);
    for (std::size_t i = 0; i < 64; ++i) at.push_back(i * good.size() / 64);  // the whole entry
    at.push_back(good.size() - 1);                                            // the checksum
    for (std::size_t pos : at) {
      for (int mask : {0x01, 0x80}) {
        std::vector<char> bad = good;
        bad[pos] = static_cast<char>(bad[pos] ^ mask);
        write_bytes(entry, bad, bad.size());
        EXPECT_FALSE(cache_load(dir_, key, mesh.triangles(), o).has_value())
            << "width " << width << ", byte " << pos << " ^ " << mask;
      }
    }
    // A miss is rebuilt and the entry overwritten: the next look-up hits.
    bool hit = true;
    const Bvh rebuilt = build_cached(mesh.input(), o, dir_, &hit);
    EXPECT_FALSE(hit);
    EXPECT_EQ(check_invariants(rebuilt, mesh.triangles(), false), "");
    build_cached(mesh.input(), o, dir_, &hit);
    EXPECT_TRUE(hit);
  }
}

// (b) A huge length (or any large value written over any header field) is a miss, and the load
// allocates nothing near what the length claims.
TEST_F(BvhCache, HugeLengthIsAMissWithoutABigAllocation) {
  const Mesh mesh = soup(500, 7, 0.05f);
  for (int width : {2, 8}) {
    const BuildOptions o = options(width);
    const auto [entry, key, good] = fresh_entry(mesh, o);
    const std::uint64_t huge[] = {std::uint64_t(1) << 31,       std::uint64_t(1) << 32,
                                  (std::uint64_t(1) << 32) - 1, std::uint64_t(1) << 40,
                                  ~std::uint64_t(0) >> 1,       ~std::uint64_t(0)};
    // Every byte offset of the header, so that no field is left out whatever the layout.
    for (std::size_t pos = 0; pos + 8 <= sizeof(CacheHeader) + 8; ++pos) {
      for (std::uint64_t value : huge) {
        std::vector<char> bad = good;
        std::memcpy(bad.data() + pos, &value, 8);
        if (bad == good) continue;
        write_bytes(entry, bad, bad.size());
        largest_allocation = 0;
        std::optional<Bvh> loaded;
        EXPECT_NO_THROW(loaded = cache_load(dir_, key, mesh.triangles(), o))
            << "width " << width << ", " << value << " at byte " << pos;
        EXPECT_FALSE(loaded.has_value()) << "width " << width << ", " << value << " at " << pos;
        EXPECT_LT(largest_allocation.load(), std::size_t(1) << 20)
            << "width " << width << ", " << value << " at byte " << pos;
      }
    }
  }
}

// (c) An entry cut short anywhere is a miss.
TEST_F(BvhCache, TruncatedEntryIsAMiss) {
  const Mesh mesh = soup(500, 7, 0.05f);
  for (int width : {2, 8}) {
    const BuildOptions o = options(width);
    const auto [entry, key, good] = fresh_entry(mesh, o);
    std::vector<std::size_t> lengths;
    for (std::size_t n = 0; n <= sizeof(CacheHeader) + 16; ++n) lengths.push_back(n);
    for (std::size_t n = sizeof(CacheHeader); n < good.size(); n += 97) lengths.push_back(n);
    for (std::size_t n = good.size() - 16; n < good.size(); ++n) lengths.push_back(n);
    for (std::size_t n : lengths) {
      write_bytes(entry, good, n);
      EXPECT_FALSE(cache_load(dir_, key, mesh.triangles(), o).has_value())
          << "width " << width << ", " << n << " of " << good.size() << " bytes";
    }
    write_bytes(entry, good, good.size());
    EXPECT_TRUE(cache_load(dir_, key, mesh.triangles(), o).has_value());
  }
}

// build_cached's `accept` sees each fresh build before it is stored; one it refuses (render's
// packed-size check, host/device/device_scene.h) leaves nothing in the cache.
TEST_F(BvhCache, RefusedBuildIsNotStored) {
  const Mesh mesh = soup(200, 9, 0.05f);
  const BuildOptions o;
  const auto refuse = [](const Bvh&) { throw std::runtime_error("too large"); };
  EXPECT_THROW(build_cached(mesh.input(), o, dir_, nullptr, refuse), std::runtime_error);
  EXPECT_TRUE(!fs::exists(dir_) || fs::is_empty(dir_));
  int calls = 0;
  const auto count = [&calls](const Bvh& b) { calls += b.nodes.empty() ? 0 : 1; };
  bool hit = true;
  build_cached(mesh.input(), o, dir_, &hit, count);
  EXPECT_FALSE(hit);
  EXPECT_EQ(calls, 1);
  build_cached(mesh.input(), o, dir_, &hit, count);
  EXPECT_TRUE(hit);
  EXPECT_EQ(calls, 1);  // a cached BVH was accepted when it was stored
}

// An entry whose checksum holds (it was written that way) but whose indices do not: the loaded
// BVH would send the kernels out of bounds, so the structural checks make it a miss.
TEST_F(BvhCache, OutOfRangeIndexIsAMiss) {
  const Mesh mesh = soup(500, 7, 0.05f);
  for (int width : {2, 8}) {
    const BuildOptions o = options(width);
    const std::uint64_t key = cache_key(mesh.input(), o);
    Bvh bad = build(mesh.input(), o);
    if (width == 2)
      bad.nodes[0].link.x = 1 << 30;  // an inner child far past the end
    else
      bad.blocks[0].prim.x = static_cast<std::uint32_t>(mesh.triangles());  // no such triangle
    cache_store(dir_, key, bad);
    EXPECT_FALSE(cache_load(dir_, key, mesh.triangles(), o).has_value()) << "width " << width;
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
  const fs::path entry = store(mesh, o);
  fs::resize_file(entry, fs::file_size(entry) / 2);  // truncated
  EXPECT_FALSE(cache_load(dir_, cache_key(mesh.input(), o), mesh.triangles(), o).has_value());
  bool hit = true;
  const Bvh rebuilt = build_cached(mesh.input(), o, dir_, &hit);
  EXPECT_FALSE(hit);
  EXPECT_EQ(check_invariants(rebuilt, mesh.triangles(), false), "");
  std::ofstream(entry, std::ios::binary) << "not a bvh";  // garbage
  EXPECT_FALSE(cache_load(dir_, cache_key(mesh.input(), o), mesh.triangles(), o).has_value());
  EXPECT_FALSE(
      cache_load("", 1, mesh.triangles(), o).has_value());  // no cache folder: always a miss
}

}  // namespace
