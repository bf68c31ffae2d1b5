// A fuzz input as a file: the loaders under test take a path, so each input is written to a
// per-process scratch folder (under $WP_FUZZ_SCRATCH, else /dev/shm when there is one, so no disk
// I/O) and read back by the loader. The folder is removed at a normal exit (not after a crash).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace wp::fuzz {

// Writes data[0..size) to <scratch folder>/input<extension> (replacing the last input) and returns
// the path. Aborts when the file cannot be written: that is a broken harness, not a finding.
std::string write_input(const std::uint8_t* data, std::size_t size, const std::string& extension);

// Aborts with a message naming the broken invariant: a finding, as a crash would be.
[[noreturn]] void invariant_failed(const std::string& what);

}  // namespace wp::fuzz
