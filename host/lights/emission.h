// A triangle's emission integrated over its area, for the light table (host/lights/light_table.h).
//
// An emissive texture makes a mesh's emission vary over it, and most of an emissive map is often
// black (DamagedHelmet: 15,452 emissive triangles, ~95% of their area black). Treating every
// triangle as a light of radiance emissiveFactor wastes NEE samples on black triangles and
// overestimates their power (543x on DamagedHelmet). Here each triangle's emission is integrated
// over the triangle, so that triangles that emit nothing anywhere are not lights at all and the
// rest are chosen in proportion to what they emit. Both are variance matters only: a triangle
// that is not in the light table still shows its emission to BSDF-sampled rays with MIS weight 1.
#pragma once

#include <cstddef>

#include <glm/vec3.hpp>

#include "host/scene/scene.h"

namespace wp {

struct TriangleEmission {
  glm::vec3 mean{0.0f};  // emitted radiance averaged over the triangle's area (linear RGB)
  float peak = 0.0f;     // the largest channel of emissiveFactor x any texel the filter can reach
  bool zero() const { return !(peak > 0.0f); }  // emits nothing at any point
};

// The emission of triangle `tri` of `scene`: emissiveFactor (x strength), times the emissive
// texture when there is one. `peak` is exact and conservative: it looks at every texel that the
// bilinear or nearest filter can reach from a point of the triangle (its texture-space bounding
// box grown by one texel, wrapped as the sampler wraps). `mean` is a midpoint rule over a
// stratified grid on the triangle (16 x 16 to 32 x 32 cells, more where the triangle covers more
// texels), with the same filter as the kernels (kernels/texture/textures.h).
TriangleEmission triangle_emission(const Scene& scene, std::size_t tri);

}  // namespace wp
