// A float's bits and back, for tests that compare results bit for bit or plant exact values.
#pragma once

#include <cstdint>
#include <cstring>

namespace wp::test {

inline std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

inline float as_float(std::uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

}  // namespace wp::test
