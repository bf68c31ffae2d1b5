// A disk cache of built OpenCL programs (the device's binaries), so that a render of a scene whose
// kernel variant was built before starts without compiling, or even preprocessing, the kernels:
// PoCL, which caches compiled kernels itself, still preprocesses the whole source with clang to
// find them, most of a small render's start-up; from a binary it does not (docs/performance.md).
//
// An entry is keyed by a 64-bit hash of everything the binary depends on: the source, the build
// options, and the device (platform name, device name and version, driver version). A missing,
// truncated or corrupted entry (its size against the file's, checked before anything is
// allocated, and a checksum of the binary) is a miss, never an error; so is a binary the
// implementation refuses (ClRuntime::build then builds from source and overwrites it); a failed
// write is ignored. Entries live beside the BVH cache's (bvh::cache_dir()).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace wp {

struct DeviceEntry;

std::uint64_t program_cache_key(const DeviceEntry& device, const std::string& driver_version,
                                const std::string& source, const std::string& options);

// The entry's path in `dir` (for tests and messages).
std::string program_cache_path(const std::string& dir, std::uint64_t key);

std::optional<std::vector<unsigned char>> program_cache_load(const std::string& dir,
                                                             std::uint64_t key);
void program_cache_store(const std::string& dir, std::uint64_t key,
                         const std::vector<unsigned char>& binary);

}  // namespace wp
