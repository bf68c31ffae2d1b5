// A disk cache of built BVHs, so rendering the same scene again (a convergence study, a second
// look) skips the build. Entries are keyed by a 64-bit hash of everything the build depends on:
// the triangles (positions by index, flags), the build options and the layout's format version.
// A missing, truncated or mismatching entry is a miss, never an error; a failed write is ignored.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "bvh.h"

namespace wp::bvh {

// The key of `input` built with `options`.
std::uint64_t cache_key(const BuildInput& input, const BuildOptions& options);

// Where entries live: $WAVEPATH_CACHE_DIR, else $XDG_CACHE_HOME/wavepath, else
// $HOME/.cache/wavepath; empty when none can be determined (then nothing is cached).
std::string cache_dir();

std::optional<Bvh> cache_load(const std::string& dir, std::uint64_t key);
void cache_store(const std::string& dir, std::uint64_t key, const Bvh& bvh);

// bvh::build through the cache in `dir` (empty: no cache). *hit tells whether it was loaded.
Bvh build_cached(const BuildInput& input, const BuildOptions& options, const std::string& dir,
                 bool* hit = nullptr);

}  // namespace wp::bvh
