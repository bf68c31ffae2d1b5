// Internal to bvh/: what the structural checks of both layouts (bvh_check.cpp: binary and the
// public entry point, bvh_check_wide.cpp: 8-wide) share.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "bvh.h"

namespace wp::bvh::detail {

struct ChildBox {
  float lo[3], hi[3];
};

inline ChildBox scene_box(const Bvh& bvh) {
  return ChildBox{{bvh.lo.x, bvh.lo.y, bvh.lo.z}, {bvh.hi.x, bvh.hi.y, bvh.hi.z}};
}

// `c` is a non-empty box inside `p`.
inline bool inside(const ChildBox& c, const ChildBox& p) {
  for (int k = 0; k < 3; ++k)
    if (!(c.lo[k] >= p.lo[k] && c.hi[k] <= p.hi[k] && c.lo[k] <= c.hi[k])) return false;
  return true;
}

// Whether a stored triangle (its vertices) fits the leaf box `box`: without spatial splits the
// whole triangle lies in it; with them its bounds must at least overlap it (the box holds a
// clipped piece, whose bounds are rounded outwards by a few ulps of the scene's coordinates, which
// `tolerance` absorbs).
inline bool triangle_fits(const float v0[3], const float v1[3], const float v2[3],
                          const ChildBox& box, bool splits, float tolerance) {
  for (int k = 0; k < 3; ++k) {
    const float lo = std::min({v0[k], v1[k], v2[k]});
    const float hi = std::max({v0[k], v1[k], v2[k]});
    const bool ok = splits ? hi >= box.lo[k] - tolerance && lo <= box.hi[k] + tolerance
                           : lo >= box.lo[k] - tolerance && hi <= box.hi[k] + tolerance;
    if (!ok) return false;
  }
  return true;
}

inline float fit_tolerance(const Bvh& bvh) {
  const float extent = std::max({std::fabs(bvh.lo.x), std::fabs(bvh.lo.y), std::fabs(bvh.lo.z),
                                 std::fabs(bvh.hi.x), std::fabs(bvh.hi.y), std::fabs(bvh.hi.z)});
  return 1e-6f * extent + 1e-30f;
}

// Counts the references to each scene triangle.
class RefCounts {
 public:
  explicit RefCounts(std::size_t triangle_count) : refs_(triangle_count, 0) {}
  bool add(std::uint32_t index) {
    if (index >= refs_.size()) return false;
    refs_[index]++;
    return true;
  }
  // Empty if every triangle is referenced (exactly once without spatial splits), else a message.
  std::string check(bool splits) const {
    for (std::size_t i = 0; i < refs_.size(); ++i)
      if (refs_[i] == 0 || (!splits && refs_[i] != 1))
        return "triangle " + std::to_string(i) + " referenced " + std::to_string(refs_[i]) +
               " times";
    return {};
  }

 private:
  std::vector<std::uint32_t> refs_;
};

// Empty if every flag is set, else "<what> <index of the first unset one> <why>".
inline std::string first_unset(const std::vector<bool>& flags, const std::string& what,
                               const std::string& why) {
  const auto it = std::find(flags.begin(), flags.end(), false);
  if (it == flags.end()) return {};
  return what + " " + std::to_string(it - flags.begin()) + " " + why;
}

// The width-8 checks (bvh_check_wide.cpp); the contract is that of check_invariants.
std::string check_invariants_wide(const Bvh& bvh, std::size_t triangle_count, bool spatial_splits);

}  // namespace wp::bvh::detail
