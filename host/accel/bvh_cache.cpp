#include "host/accel/bvh_cache.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <new>

#include "host/util/files.h"

namespace wp::bvh {

namespace {

// Bump when the layout of an entry, of a cached Bvh or of its arrays changes.
// 2: triangles stored as vertices (watertight test); 3: lengths in the header, checksum at the end.
constexpr std::uint64_t kFormat = 3;
constexpr char kMagic[8] = {'w', 'p', 'b', 'v', 'h', '0', '0', '3'};

// Embree holds at most 2 references per triangle with spatial splits (kSplitCapacityFactor in
// embree_tree.cpp); a little room beyond that costs nothing, since it only bounds what a load
// allocates, check_invariants decides.
constexpr std::uint64_t kMaxRefsPerTriangle = 4;

// A 64-bit multiply-xorshift hash over words, fed in order; not cryptographic, only collision
// resistant enough to tell scenes apart. As the entries' checksum it always catches one changed
// word (for a given state each step is a bijection of the word), other damage all but surely.
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
    if (n > i) std::memcpy(&tail, p + i, n - i);
    word(tail);
  }
};

template <class T>
bool write_array(std::FILE* f, const std::vector<T>& v, Hasher& sum) {
  sum.bytes(v.data(), v.size() * sizeof(T));
  return v.empty() || std::fwrite(v.data(), sizeof(T), v.size(), f) == v.size();
}

// Reads n elements (n already checked against the file's size) and feeds them to `sum`.
template <class T>
bool read_array(std::FILE* f, std::vector<T>& v, std::uint64_t n, Hasher& sum) {
  v.resize(static_cast<std::size_t>(n));
  if (n && std::fread(v.data(), sizeof(T), v.size(), f) != v.size()) return false;
  sum.bytes(v.data(), v.size() * sizeof(T));
  return true;
}

constexpr std::uint64_t kElementSize[4] = {sizeof(dev::BvhNode), sizeof(dev::IsectTri),
                                           sizeof(dev::BvhNode8), sizeof(dev::TriBlock4)};

// Whether the header's lengths are those of a width-`options.width` BVH over `triangles` scene
// triangles (bounds from check_invariants' contract: every triangle referenced, once without
// spatial splits; leaves of at least one triangle (width 2) or block (width 8); wide inner nodes
// of at least 2 children) and account for exactly `file_size` bytes.
bool lengths_fit(const CacheHeader& h, std::uint64_t triangles, const BuildOptions& options,
                 std::uint64_t file_size) {
  const std::uint64_t* n = h.counts;
  const std::uint64_t refs = options.spatial_splits ? kMaxRefsPerTriangle * triangles : triangles;
  if (h.width != options.width || triangles == 0) return false;
  if (h.width == 2) {
    if (n[2] != 0 || n[3] != 0 || n[1] < triangles || n[1] > refs) return false;
    if (n[0] < 1 || n[0] > n[1]) return false;
  } else if (h.width == WP_BVH8_WIDTH) {
    if (n[0] != 0 || n[1] != 0 || n[3] < (triangles + 3) / 4 || n[3] > refs) return false;
    if (n[2] < 1 || n[2] > n[3]) return false;
  } else {
    return false;
  }
  std::uint64_t size = sizeof(CacheHeader) + sizeof(std::uint64_t);  // header, checksum
  for (int i = 0; i < 4; ++i) size += n[i] * kElementSize[i];        // no overflow: n <= 4 refs
  return size == file_size;
}

// The size of the open file `f`, or 0 when it cannot be told; leaves it at its start.
std::uint64_t file_size(std::FILE* f) {
  if (fseeko(f, 0, SEEK_END) != 0) return 0;
  const off_t end = ftello(f);
  if (end < 0 || fseeko(f, 0, SEEK_SET) != 0) return 0;
  return static_cast<std::uint64_t>(end);
}

std::optional<Bvh> read_entry(std::FILE* f, std::uint64_t key, std::size_t triangle_count,
                              const BuildOptions& options) {
  const std::uint64_t size = file_size(f);
  CacheHeader h{};
  if (std::fread(&h, sizeof h, 1, f) != 1 || std::memcmp(h.magic, kMagic, 8) != 0 || h.key != key ||
      !lengths_fit(h, triangle_count, options, size))
    return std::nullopt;
  Hasher sum;
  sum.bytes(&h, sizeof h);
  Bvh b;
  std::uint64_t stored_sum = 0;
  if (!read_array(f, b.nodes, h.counts[0], sum) || !read_array(f, b.triangles, h.counts[1], sum) ||
      !read_array(f, b.nodes8, h.counts[2], sum) || !read_array(f, b.blocks, h.counts[3], sum) ||
      std::fread(&stored_sum, sizeof stored_sum, 1, f) != 1 || stored_sum != sum.h)
    return std::nullopt;
  b.width = h.width;
  b.lo = {h.lo[0], h.lo[1], h.lo[2]};
  b.hi = {h.hi[0], h.hi[1], h.hi[2]};
  b.stats = {h.build_seconds,
             h.sah_cost,
             static_cast<std::size_t>(h.inner_nodes),
             static_cast<std::size_t>(h.leaves),
             static_cast<std::size_t>(h.triangle_refs),
             h.max_depth};
  // The kernels index with what the file says: out-of-range indices would read out of bounds.
  if (!check_invariants(b, triangle_count, options.spatial_splits).empty()) return std::nullopt;
  return b;
}

}  // namespace

std::string cache_entry_path(const std::string& dir, std::uint64_t key) {
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.bvh", static_cast<unsigned long long>(key));
  return dir + "/" + name;
}

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

std::optional<Bvh> cache_load(const std::string& dir, std::uint64_t key, std::size_t triangle_count,
                              const BuildOptions& options) {
  if (dir.empty()) return std::nullopt;
  std::FILE* f = std::fopen(cache_entry_path(dir, key).c_str(), "rb");
  if (!f) return std::nullopt;
  std::optional<Bvh> b;
  try {
    b = read_entry(f, key, triangle_count, options);
  } catch (const std::bad_alloc&) {
    // Lengths that fit the file and the scene but not the memory: the build would not fit either,
    // and says so itself.
  }
  std::fclose(f);
  return b;
}

void cache_store(const std::string& dir, std::uint64_t key, const Bvh& b) {
  if (dir.empty()) return;
  CacheHeader h{};
  std::memcpy(h.magic, kMagic, 8);
  h.key = key;
  h.width = b.width;
  h.max_depth = b.stats.max_depth;
  for (int k = 0; k < 3; ++k) h.lo[k] = b.lo[k], h.hi[k] = b.hi[k];
  h.build_seconds = b.stats.build_seconds;
  h.sah_cost = b.stats.sah_cost;
  h.inner_nodes = b.stats.inner_nodes;
  h.leaves = b.stats.leaves;
  h.triangle_refs = b.stats.triangle_refs;
  h.counts[0] = b.nodes.size();
  h.counts[1] = b.triangles.size();
  h.counts[2] = b.nodes8.size();
  h.counts[3] = b.blocks.size();
  write_file_atomically(cache_entry_path(dir, key), [&](std::FILE* f) {
    Hasher sum;
    sum.bytes(&h, sizeof h);
    return std::fwrite(&h, sizeof h, 1, f) == 1 && write_array(f, b.nodes, sum) &&
           write_array(f, b.triangles, sum) && write_array(f, b.nodes8, sum) &&
           write_array(f, b.blocks, sum) && std::fwrite(&sum.h, sizeof sum.h, 1, f) == 1;
  });
}

Bvh build_cached(const BuildInput& input, const BuildOptions& options, const std::string& dir,
                 bool* hit, const std::function<void(const Bvh&)>& accept) {
  const auto start = std::chrono::steady_clock::now();
  // A scene without triangles builds at once (no Embree): nothing to save by caching it.
  if (input.triangle_count == 0) {
    if (hit) *hit = false;
    Bvh b = build(input, options);
    if (accept) accept(b);
    return b;
  }
  const std::uint64_t key = dir.empty() ? 0 : cache_key(input, options);
  if (std::optional<Bvh> cached = cache_load(dir, key, input.triangle_count, options)) {
    if (hit) *hit = true;
    // The stats stay those of the build; its time becomes the time it took to find it.
    cached->stats.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return std::move(*cached);
  }
  if (hit) *hit = false;
  Bvh b = build(input, options);
  if (accept) accept(b);
  cache_store(dir, key, b);
  return b;
}

}  // namespace wp::bvh
