#include "bvh_cache.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>

namespace wp::bvh {

namespace {

// Bump when the layout of a cached Bvh or of its arrays changes.
constexpr std::uint64_t kFormat = 2;  // 2: triangles stored as vertices (watertight test)
constexpr char kMagic[8] = {'w', 'p', 'b', 'v', 'h', '0', '0', '1'};

// A 64-bit multiply-xorshift hash over words, fed in order; not cryptographic, only collision
// resistant enough to tell scenes apart.
struct Hasher {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  void word(std::uint64_t w) {
    h ^= w + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 31;
  }
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
      std::uint64_t w;
      std::memcpy(&w, p + i, 8);
      word(w);
    }
    std::uint64_t tail = n;
    std::memcpy(&tail, p + i, n - i);
    word(tail);
  }
};

template <class T>
bool write_vector(std::FILE* f, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  return std::fwrite(&n, sizeof n, 1, f) == 1 &&
         (n == 0 || std::fwrite(v.data(), sizeof(T), v.size(), f) == v.size());
}

template <class T>
bool read_vector(std::FILE* f, std::vector<T>& v, std::uint64_t limit) {
  std::uint64_t n = 0;
  if (std::fread(&n, sizeof n, 1, f) != 1 || n > limit) return false;
  v.resize(static_cast<std::size_t>(n));
  return n == 0 || std::fread(v.data(), sizeof(T), v.size(), f) == v.size();
}

std::string entry_path(const std::string& dir, std::uint64_t key) {
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.bvh", static_cast<unsigned long long>(key));
  return dir + "/" + name;
}

}  // namespace

std::uint64_t cache_key(const BuildInput& input, const BuildOptions& options) {
  Hasher h;
  h.word(kFormat);
  h.word(static_cast<std::uint64_t>(options.width));
  h.word(options.spatial_splits ? 1u : 0u);
  h.word(static_cast<std::uint64_t>(options.max_leaf_size));
  float costs[2] = {options.traversal_cost, options.intersection_cost};
  h.bytes(costs, sizeof costs);
  h.word(input.triangle_count);
  // Positions by index, so the key does not depend on unused or reordered vertices.
  for (std::size_t t = 0; t < input.triangle_count; ++t) {
    float v[9];
    for (int k = 0; k < 3; ++k)
      std::memcpy(v + 3 * k, &input.positions[input.indices[3 * t + k]], 12);
    h.bytes(v, sizeof v);
    h.word(input.triangle_flags ? input.triangle_flags[t] : 0u);
  }
  return h.h;
}

std::string cache_dir() {
  if (const char* d = std::getenv("WAVEPATH_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/wavepath";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.cache/wavepath";
  return {};
}

std::optional<Bvh> cache_load(const std::string& dir, std::uint64_t key) {
  if (dir.empty()) return std::nullopt;
  std::FILE* f = std::fopen(entry_path(dir, key).c_str(), "rb");
  if (!f) return std::nullopt;
  Bvh b;
  char magic[8];
  std::uint64_t stored_key = 0;
  std::int32_t width = 0;
  constexpr std::uint64_t kLimit = std::uint64_t(1) << 32;
  bool ok = std::fread(magic, 1, 8, f) == 8 && std::memcmp(magic, kMagic, 8) == 0 &&
            std::fread(&stored_key, sizeof stored_key, 1, f) == 1 && stored_key == key &&
            std::fread(&width, sizeof width, 1, f) == 1 && (width == 2 || width == 8) &&
            std::fread(&b.lo, sizeof b.lo, 1, f) == 1 &&
            std::fread(&b.hi, sizeof b.hi, 1, f) == 1 &&
            std::fread(&b.stats, sizeof b.stats, 1, f) == 1 && read_vector(f, b.nodes, kLimit) &&
            read_vector(f, b.triangles, kLimit) && read_vector(f, b.nodes8, kLimit) &&
            read_vector(f, b.blocks, kLimit);
  std::fclose(f);
  if (!ok) return std::nullopt;
  b.width = width;
  const bool complete = width == 2 ? !b.nodes.empty() && !b.triangles.empty()
                                   : !b.nodes8.empty() && !b.blocks.empty();
  if (!complete) return std::nullopt;
  return b;
}

void cache_store(const std::string& dir, std::uint64_t key, const Bvh& b) {
  if (dir.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::string path = entry_path(dir, key);
  const std::string temp = path + ".tmp" + std::to_string(std::random_device{}());
  std::FILE* f = std::fopen(temp.c_str(), "wb");
  if (!f) return;
  const std::int32_t width = b.width;
  bool ok = std::fwrite(kMagic, 1, 8, f) == 8 && std::fwrite(&key, sizeof key, 1, f) == 1 &&
            std::fwrite(&width, sizeof width, 1, f) == 1 &&
            std::fwrite(&b.lo, sizeof b.lo, 1, f) == 1 &&
            std::fwrite(&b.hi, sizeof b.hi, 1, f) == 1 &&
            std::fwrite(&b.stats, sizeof b.stats, 1, f) == 1 && write_vector(f, b.nodes) &&
            write_vector(f, b.triangles) && write_vector(f, b.nodes8) && write_vector(f, b.blocks);
  ok &= std::fclose(f) == 0;
  if (ok) std::filesystem::rename(temp, path, ec);
  if (!ok || ec) std::filesystem::remove(temp, ec);
}

Bvh build_cached(const BuildInput& input, const BuildOptions& options, const std::string& dir,
                 bool* hit) {
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t key = dir.empty() ? 0 : cache_key(input, options);
  if (std::optional<Bvh> cached = cache_load(dir, key)) {
    if (hit) *hit = true;
    // The stats stay those of the build; its time becomes the time it took to find it.
    cached->stats.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return std::move(*cached);
  }
  if (hit) *hit = false;
  Bvh b = build(input, options);
  cache_store(dir, key, b);
  return b;
}

}  // namespace wp::bvh
