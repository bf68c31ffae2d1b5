/* Test kernels for kernels/lights/environment.h (tests/test_environment.cpp). Each takes a
 * SceneDesc by value (env_width/env_height/env_params/background set, offsets unused) and the three
 * environment arrays as separate buffers, and builds the part of a SceneView they read. */
#include "lights/environment.h"
#include "sampling/rng.h"

inline SceneView env_view(const SceneDesc* d, __global const float4* texels,
                          __global const float* marginal, __global const float* conditional) {
  SceneView s = {0};
  s.env_texels = texels;
  s.env_marginal = marginal;
  s.env_conditional = conditional;
  s.desc = d;
  return s;
}

#define ENV_ARGS                                                                 \
  SceneDesc desc, __global const float4 *texels, __global const float *marginal, \
      __global const float *conditional
#define ENV_BIND const SceneView scene = env_view(&desc, texels, marginal, conditional)

/* out[2 i] = (env_radiance(dirs[i]).rgb, env_pdf(dirs[i])) (env_radiance_pdf with want_pdf);
 * out[2 i + 1] the same from env_radiance_pdf without it, as shade_hit asks for a camera ray. */
__kernel void env_eval(ENV_ARGS, __global const float4* dirs, uint count, __global float4* out) {
  ENV_BIND;
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float3 d = dirs[i].xyz;
  out[2 * i] = (float4)(env_radiance(&scene, d), env_pdf(&scene, d));
  float pdf = -1.0f;
  const float3 l = env_radiance_pdf(&scene, d, false, &pdf);
  out[2 * i + 1] = (float4)(l, pdf);
}

/* Sample i uses u = the project's hash of (i, seed). dir_pdf[i] = (direction, pdf returned by
 * env_sample); radiance_pdf[i] = (radiance returned, env_pdf of the direction). */
__kernel void env_draw(ENV_ARGS, uint count, uint seed, __global float4* dir_pdf,
                       __global float4* radiance_pdf) {
  ENV_BIND;
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float2 u = rng_get2(rng_make(i, 0u, seed, 0u), 0u);
  float3 dir;
  float pdf;
  const float3 l = env_sample(&scene, u, &dir, &pdf);
  dir_pdf[i] = (float4)(dir, pdf);
  radiance_pdf[i] = (float4)(l, env_pdf(&scene, dir));
}

/* Kahan-compensated running sum. */
inline void kahan_add(float* sum, float* comp, float x) {
  const float y = x - *comp;
  const float t = *sum + y;
  *comp = (t - *sum) - y;
  *sum = t;
}

/* The integral of env_pdf over the world-space bins uniform in z = cos(theta) (bins_z of them,
 * from +Y down) and phi = atan2(x, -z) (bins_phi, from -pi), one work-item per bin.
 *
 * With a map, env_pdf x sin(theta) is constant on each texel in (theta, phi) coordinates, and
 * rotation about +Y only shifts phi (texel column edges lie where (phi + R + pi) W / (2 pi) is an
 * integer). So each bin is cut along texel row and column edges into pieces, and a piece's
 * integral is env_pdf(centre) sin(theta_centre) dtheta dphi: the midpoint rule on texel-aligned
 * sub-cells, exact for the piecewise-constant integrand up to float rounding. Maps only. */
__kernel void env_integrate_bins(ENV_ARGS, uint bins_z, uint bins_phi, __global float* out) {
  ENV_BIND;
  const uint b = get_global_id(0);
  if (b >= bins_z * bins_phi) return;
  const uint iz = b / bins_phi, ip = b % bins_phi;
  const float t0 = acos(1.0f - 2.0f * (float)iz / (float)bins_z);
  const float t1 = acos(1.0f - 2.0f * (float)(iz + 1u) / (float)bins_z);
  const float p0 = 2.0f * WP_PI * (float)ip / (float)bins_phi - WP_PI;
  const float p1 = 2.0f * WP_PI * (float)(ip + 1u) / (float)bins_phi - WP_PI;
  const float rot = atan2(desc.env_params.z, desc.env_params.y);
  const float h = (float)desc.env_height, w = (float)desc.env_width;
  const float row_edge = WP_PI / h, col_edge = 2.0f * WP_PI / w;
  const int j0 = (int)floor(t0 / row_edge), j1 = (int)ceil(t1 / row_edge);
  const int k0 = (int)floor((p0 + rot + WP_PI) / col_edge);
  const int k1 = (int)ceil((p1 + rot + WP_PI) / col_edge);
  float sum = 0.0f, comp = 0.0f;
  for (int j = j0; j < j1; ++j) {
    const float ta = fmax(t0, (float)j * row_edge), tb = fmin(t1, (float)(j + 1) * row_edge);
    if (!(tb > ta)) continue;
    const float tc = 0.5f * (ta + tb), st = sin(tc), ct = cos(tc);
    for (int k = k0; k < k1; ++k) {
      const float pa = fmax(p0, (float)k * col_edge - rot - WP_PI);
      const float pb = fmin(p1, (float)(k + 1) * col_edge - rot - WP_PI);
      if (!(pb > pa)) continue;
      const float pc = 0.5f * (pa + pb);
      const float3 d = (float3)(st * sin(pc), ct, -st * cos(pc));
      kahan_add(&sum, &comp, env_pdf(&scene, d) * st * (tb - ta) * (pb - pa));
    }
  }
  out[b] = sum;
}
