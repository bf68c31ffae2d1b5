// Files: where the renderer's caches live and how it writes a file so that no reader ever sees half
// of it (the BVH cache, host/accel/bvh_cache.h, and the kernel program cache,
// host/device/program_cache.h); how the files a user names are read (only regular files) and
// where outputs can go (checked before rendering).
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace wp {

// The cache folder: $WAVEPATH_CACHE_DIR, else $XDG_CACHE_HOME/wavepath, else
// $HOME/.cache/wavepath; empty when none can be determined (then nothing is cached).
std::string cache_dir();

// Writes the file at `path` (creating its folder) through `write`, aside under a temporary name
// renamed into place, so that a reader never sees half a file; false (and nothing left behind) if
// `write` or any step fails.
bool write_file_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write);

// Input files the user names (scenes, their buffers and images, environment maps, films) must be
// regular files: a FIFO would block open() until a writer comes (forever), a device such as
// /dev/zero never ends, a folder has no bytes. Throws wp::Error "PATH: no such file" or
// "PATH: not a regular file (a FIFO)" (a folder, a character device, ...), without opening it.
void require_regular_file(const std::string& path);

// The whole of regular file `path` (require_regular_file, then opened with O_NONBLOCK and checked
// again on the open descriptor, so that nothing swapped in meanwhile can block). Throws wp::Error
// naming the path when it is not one, cannot be read, or holds more than `max_bytes`.
std::vector<unsigned char> read_regular_file(const std::string& path,
                                             std::uint64_t max_bytes = UINT64_MAX);

// Throws wp::Error "OUT: ..." unless a file can be created in the folder of output `out`: tried by
// creating (and removing) an empty temporary file there, which holds whatever the reason (no such
// folder, no permission, a read-only or pseudo file system such as /proc) and for root too.
void check_output_folder(const std::string& out);

}  // namespace wp
