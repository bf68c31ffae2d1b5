// A disk cache of built BVHs, so rendering the same scene again (a convergence study, a second
// look) skips the build. Entries are keyed by a 64-bit hash of everything the build depends on:
// the triangles (positions by index, flags), the build options and the layout's format version.
// A missing, truncated, corrupted or mismatching entry is a miss, never an error (the caller then
// builds and overwrites it); a failed write is ignored.
//
// An entry is a CacheHeader, the four arrays of the Bvh in the order nodes, triangles, nodes8,
// blocks (their lengths in the header), then a 64-bit checksum of every byte before it, all in the
// host's byte order. A load trusts nothing in the file: the lengths must agree with the file's size
// and with the scene's triangle count before anything is allocated, the checksum must match, and
// the BVH must pass check_invariants (every node and triangle index in range) before it is used.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "bvh/bvh.h"

namespace wp::bvh {

struct CacheHeader {
  char magic[8];
  std::uint64_t key;
  std::int32_t width;
  std::int32_t max_depth;  // BuildStats::max_depth
  float lo[3], hi[3];      // scene bounds
  double build_seconds, sah_cost;
  std::uint64_t inner_nodes, leaves, triangle_refs;  // BuildStats
  std::uint64_t counts[4];                           // nodes, triangles, nodes8, blocks
};
static_assert(sizeof(CacheHeader) == 120, "CacheHeader has no implicit padding");

// The key of `input` built with `options`.
std::uint64_t cache_key(const BuildInput& input, const BuildOptions& options);

// The file of entry `key` in `dir`: <dir>/<key as 16 hex digits>.bvh.
std::string cache_entry_path(const std::string& dir, std::uint64_t key);

// The entry `key` for a scene of `triangle_count` triangles built with `options`, or nullopt when
// it is missing or fails any of the checks above.
std::optional<Bvh> cache_load(const std::string& dir, std::uint64_t key, std::size_t triangle_count,
                              const BuildOptions& options);
void cache_store(const std::string& dir, std::uint64_t key, const Bvh& bvh);

// bvh::build through the cache in `dir` (empty: no cache; a scene without triangles, which builds
// at once, is never cached). *hit tells whether it was loaded.
// `accept`, when given, sees a BVH just built before it is stored, and may throw to refuse it
// (then nothing is stored).
Bvh build_cached(const BuildInput& input, const BuildOptions& options, const std::string& dir,
                 bool* hit = nullptr, const std::function<void(const Bvh&)>& accept = {});

}  // namespace wp::bvh
