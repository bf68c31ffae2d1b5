// Checks of the numbers a glTF file gives, shared by the material and node readers: each throws
// wp::Error "WHERE: FIELD ..." naming the value's place, as the Khronos validator would reject it.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "host/util/error.h"

namespace wp::gltf {

inline std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

inline float finite(double value, const std::string& where, const char* field) {
  if (!std::isfinite(value)) throw Error(where + ": " + field + " is not a finite number");
  return static_cast<float>(value);
}

// A finite value within [lo, hi] (glTF's ranges: factors in [0, 1], intensities >= 0, ...).
inline float in_range(double value, double lo, double hi, const std::string& where,
                      const char* field) {
  const float v = finite(value, where, field);
  if (value < lo || value > hi)
    throw Error(where + ": " + field + " " + number_text(value) + " is outside [" +
                number_text(lo) + ", " + number_text(hi) + "]");
  return v;
}

// Throws "WHERE: FIELD must be RULE (got VALUE)" unless `ok`: a rule of glTF's schema (or of an
// extension's) that a finite number breaks, e.g. a camera's znear must be > 0.
inline void require(bool ok, const std::string& where, const char* field, const char* rule,
                    double value) {
  if (!ok)
    throw Error(where + ": " + field + " must be " + rule + " (got " + number_text(value) + ")");
}

}  // namespace wp::gltf
