/* Sampling routines and their densities. Every routine here has a chi-square test against its pdf
 * (tests/test_sampling.cpp). Directions are in a local frame with the normal along +z. */
#ifndef WP_SAMPLING_H
#define WP_SAMPLING_H

#include "util/common.h"
#include "util/elementary.h"

/* The unit disk, the cosine-weighted hemisphere and GGX (lane code: util/lanes_begin.def). */
#define WP_LW 1
#include "sampling/warps.def"
#if WP_SHADE_PACKET
#define WP_LW 8
#include "sampling/warps.def"
#endif

/* sample_concentric_disk's point as a float2 (the lens, camera.h). */
static inline float2 sample_concentric_disk(float2 u) {
  float x, y;
  concentric_disk(u.x, u.y, &x, &y);
  return (float2)(x, y);
}

#endif /* WP_SAMPLING_H */
