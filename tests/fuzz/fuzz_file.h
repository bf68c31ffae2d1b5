// A fuzz input as a file: the loaders under test take a path, so each input is written to a
// per-process scratch folder (under $WP_FUZZ_SCRATCH, else /dev/shm when there is one, so no disk
// I/O) and read back by the loader. The folder is removed at a normal exit (not after a crash).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "host/scene/gltf_loader.h"
#include "host/util/error.h"

namespace wp::fuzz {

// The load options of every target: as wavepath loads (render and info refuse a scene whose
// counts cannot fit in memory before loading it: render.h, check_scene_counts), with the limit
// the fuzzer's own, 2^20 stored triangles (Draco's decoder and the scene arrays take about 200
// bytes a triangle: 0.2 GB, within libFuzzer's 2 GB -rss_limit_mb).
inline LoadOptions load_options() {
  LoadOptions o;
  o.check_counts = [](const LoadCounts& c) {
    if ((c.instanced ? c.mesh_max_triangles : c.max_triangles) > (std::uint64_t(1) << 20))
      throw Error("more triangles than the fuzzer's memory holds");
  };
  return o;
}

// Writes data[0..size) to <scratch folder>/input<extension> (replacing the last input) and returns
// the path. Aborts when the file cannot be written: that is a broken harness, not a finding.
std::string write_input(const std::uint8_t* data, std::size_t size, const std::string& extension);

// Aborts with a message naming the broken invariant: a finding, as a crash would be.
[[noreturn]] void invariant_failed(const std::string& what);

}  // namespace wp::fuzz
