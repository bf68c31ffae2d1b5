// FNV-1a, 64-bit (Fowler, Noll and Vo): a fast, simple, non-cryptographic hash of bytes, for
// identities (the render key's scene and environment digests) and to detect corrupted files
// (.wpfilm data). Chainable: pass a previous result as `h` to hash a sequence of pieces.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace wp {

constexpr std::uint64_t kFnv1aOffset = 0xcbf29ce484222325ull;
constexpr std::uint64_t kFnv1aPrime = 0x100000001b3ull;

inline std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t h = kFnv1aOffset) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * kFnv1aPrime;
  return h;
}

// 16 lower-case hex digits.
inline std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace wp
