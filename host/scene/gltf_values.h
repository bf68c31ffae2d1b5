// Checks of the numbers a glTF file gives, shared by the material and node readers: each throws
// wp::Error "WHERE: FIELD ..." naming the value's place, as the Khronos validator would reject it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "host/util/error.h"

namespace wp::gltf {

inline std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// A finite value as float32, saturated to +-FLT_MAX when beyond float32's range (a valid JSON
// number such as 1e39 would otherwise become infinite); the fields where that matters are clamped
// further, with a warning (at_most).
inline float finite(double value, const std::string& where, const char* field) {
  if (!std::isfinite(value)) throw Error(where + ": " + field + " is not a finite number");
  constexpr double kMax = std::numeric_limits<float>::max();
  return static_cast<float>(std::clamp(value, -kMax, kMax));
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

// `value` clamped to at most `limit` (scene.h: kMaxRadiance, kMaxIor), with a warning
// "WHERE: FIELD V clamped to LIMIT (WHY)" added to `warnings` when it was above.
inline double at_most(double value, double limit, const std::string& where, const char* field,
                      const char* why, std::vector<std::string>* warnings) {
  if (!(value > limit)) return value;
  if (warnings)
    warnings->push_back(where + ": " + field + " " + number_text(value) + " clamped to " +
                        number_text(limit) + " (" + why + ")");
  return limit;
}

}  // namespace wp::gltf
