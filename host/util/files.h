// Files the renderer keeps for itself: where its caches live, and how a file is written so that
// no reader ever sees half of it. Used by the BVH cache (host/accel/bvh_cache.h) and the kernel
// program cache (host/device/program_cache.h).
#pragma once

#include <cstdio>
#include <functional>
#include <string>

namespace wp {

// The cache folder: $WAVEPATH_CACHE_DIR, else $XDG_CACHE_HOME/wavepath, else
// $HOME/.cache/wavepath; empty when none can be determined (then nothing is cached).
std::string cache_dir();

// Writes the file at `path` (creating its folder) through `write`, aside under a temporary name
// renamed into place, so that a reader never sees half a file; false (and nothing left behind) if
// `write` or any step fails.
bool write_file_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write);

}  // namespace wp
