/* The environment: radiance of escaped rays, and its importance sampling for NEE.
 *
 * Without a map (env_width == 0, or a program built with WP_FEATURE_ENVIRONMENT=0) the
 * environment is the constant background radiance, sampled uniformly over the sphere.
 *
 * With a map of W x H = env_width x env_height texels (equirectangular; host/lights/environment.h
 * states the convention), a world direction d is first turned into the map's frame by the inverse
 * of the rotation R about +Y (env_params.y, .z = cos R, sin R): m = (cos R d.x - sin R d.z, d.y,
 * sin R d.x + cos R d.z), then u = (atan2(m.x, -m.z) + pi) / (2 pi), v = theta / pi with theta =
 * atan2(|m.xz|, m.y), and the radiance is env_params.x times the lookup (--env-filter):
 *   nearest (WP_ENV_BILINEAR=0): texel (floor(u W), floor(v H)), piecewise constant over (u, v).
 *   bilinear (WP_ENV_BILINEAR=1): the texel centres sit at ((x + 0.5) / W, (y + 0.5) / H);
 *     with fx = u W - 0.5, fy = v H - 0.5 the four texels (x0, y0), (x0 + 1, y0), (x0, y0 + 1),
 *     (x0 + 1, y0 + 1) around (fx, fy), x0 = floor(fx), y0 = floor(fy), are blended with weights
 *     (1 - tx, tx) x (1 - ty, ty), tx = fx - x0, ty = fy - y0. Columns wrap across the u seam
 *     (x = -1 is W - 1, x = W is 0). Rows clamp at the poles (y = -1 is 0, y = H is H - 1): within
 *     half a texel of a pole the map is interpolated along u only, so the pole value depends on
 *     the direction of approach as it does with nearest lookup (the pole is a null set).
 * The two atan2 are atan2_poly's (elementary.h), which PoCL inlines.
 *
 * Sampling tables (host/lights/environment.cpp fills them), float CDFs, built for the filter:
 *   env_marginal[0..H]: over rows; [0] = 0, [H] = 1, row y has probability
 *     P(y) = env_marginal[y+1] - env_marginal[y], proportional to the sum over the row of
 *     f(x, y) x sin(theta at the row's centre), i.e. to f x solid angle.
 *     All zero for a black map: nothing to sample (env_sample then returns pdf 0, env_pdf is 0).
 *   env_conditional[y (W+1) + 0..W]: over the columns of row y, [0] = 0, [W] = 1, column x has
 *     P(x | y) = c[x+1] - c[x], proportional to f (uniform in a black row, never chosen).
 * f(x, y) is the texel's luminance for nearest lookup, and for bilinear lookup the largest
 * luminance of the 3 x 3 texels around it (columns wrapped, rows clamped as in the lookup).
 * env_sample picks a row with u.x and a column with u.y (binary search) and a point uniform in the
 * texel's (u, v) rectangle from the remainders of u.x and u.y within the chosen intervals. Its
 * density over (u, v) is P(y) P(x | y) W H, computed from the very float differences the search
 * used, so it is the exact density of the sampling (a texel whose interval rounded to nothing has
 * density 0 and is left to BSDF sampling). Over solid angle it is divided by the Jacobian
 * |d omega / du dv| = 2 pi^2 sin(theta); at the poles (sin(theta) = 0, a null set) the pdf is 0.
 * The sample's radiance is the lookup at the sampled direction, and env_pdf evaluates that same
 * piecewise-constant density for BSDF-sampled escaped rays (MIS), whatever the filter.
 *
 * Why bilinear lookup with a piecewise-constant density stays unbiased: an estimator L / pdf of
 * the integral of L needs pdf > 0 wherever L > 0. Over texel (x, y)'s rectangle,
 * fx lies in [x - 0.5, x + 0.5) and fy in [y - 0.5, y + 0.5), so the bilinear radiance there is a
 * convex combination of texels within one column (wrapped) and one row (clamped) of (x, y): the
 * 3 x 3 block. Luminance is linear with positive weights and texels are >= 0, so the luminance of
 * the blend is at most f(x, y), and L > 0 at a point (some channel > 0) means some texel of the
 * block with positive weight has luminance > 0, hence f(x, y) > 0 and (up to the float rounding
 * above, as for nearest) P(x, y) > 0. A black texel next to a bright one thus keeps the bright
 * one's weight. Since L <= f on each texel, L / pdf is bounded by the constant the nearest tables
 * give a map whose texels are f: the blurred table costs variance, never bias. */
#ifndef WP_ENVIRONMENT_H
#define WP_ENVIRONMENT_H

#include "geom/scene.h"
#include "sampling/warps.h"

#if WP_FEATURE_ENVIRONMENT

#define WP_ENV_BELOW_ONE 0x1.fffffep-1f /* the largest float below 1 */

/* World direction to the map's frame (inverse rotation); env_from_map turns it back. */
static inline float3 env_to_map(const SceneDesc* d, float3 w) {
  const float c = d->env_params.y, s = d->env_params.z;
  return (float3)(c * w.x - s * w.z, w.y, s * w.x + c * w.z);
}

/* env_from_map, env_texel_pdf, env_find_interval, env_bilinear and env_map_sample (lane code:
 * util/lanes_begin.def). */
#define WP_LW 1
#include "lights/env_map.def"
#if WP_SHADE_PACKET
#define WP_LW 8
#include "lights/env_map.def"
#endif

/* The map coordinates (u, v) of map-frame direction m (any length), with r_xz = |m.xz|; theta by
 * atan2, well conditioned at the poles, unlike acos. */
static inline float2 env_map_uv(float3 m, float r_xz) {
  return (float2)(fmax(0.0f, atan2_poly(m.x, -m.z) + WP_PI) * (0.5f * WP_INV_PI),
                  atan2_poly(r_xz, m.y) * WP_INV_PI);
}

/* The map coordinates of world direction dir (any length); *sin_theta gets its sin(theta). */
static inline float2 env_dir_uv(const SceneDesc* d, float3 dir, float* sin_theta) {
  const float3 m = env_to_map(d, dir);
  const float r_xz = sqrt(m.x * m.x + m.z * m.z);
  *sin_theta = r_xz / length(m);
  return env_map_uv(m, r_xz);
}

/* The texel (x, y) holding map coordinates uv. */
static inline uint2 env_texel_at(const SceneDesc* d, float2 uv) {
  return (uint2)(min((uint)(uv.x * (float)d->env_width), d->env_width - 1u),
                 min((uint)(uv.y * (float)d->env_height), d->env_height - 1u));
}

/* The map's radiance at map coordinates uv: the filter's lookup, scaled. */
static inline float3 env_map_radiance_uv(const SceneView* scene, float2 uv) {
#if WP_ENV_BILINEAR
  return env_bilinear(scene, uv.x, uv.y) * scene->desc->env_params.x;
#else
  const SceneDesc* d = scene->desc;
  const uint2 t = env_texel_at(d, uv);
  return scene->env_texels[t.y * d->env_width + t.x].xyz * d->env_params.x;
#endif
}

/* The density env_map_sample gives the direction at map coordinates uv, where sin(theta) is
 * sin_theta: its texel's (env_texel_at). */
static inline float env_map_pdf_uv(const SceneView* scene, float2 uv, float sin_theta) {
  const SceneDesc* d = scene->desc;
  const uint w = d->env_width;
  const uint2 t = env_texel_at(d, uv);
  __global const float* row = scene->env_conditional + t.y * (w + 1u);
  const float p =
      (scene->env_marginal[t.y + 1u] - scene->env_marginal[t.y]) * (row[t.x + 1u] - row[t.x]);
  return env_texel_pdf(p, w, d->env_height, sin_theta);
}

#endif /* WP_FEATURE_ENVIRONMENT */

/* The radiance arriving along dir and, where want_pdf holds, in *pdf the solid-angle density with
 * which env_sample produces dir (else 0): env_radiance and env_pdf, the map's coordinates worked
 * out once for both (an escaped ray needs both; a camera ray or one after a delta lobe only its
 * radiance). The same values, bit for bit. */
static inline float3 env_radiance_pdf(const SceneView* scene, float3 dir, bool want_pdf,
                                      float* pdf) {
#if WP_FEATURE_ENVIRONMENT
  if (scene->desc->env_width > 0u) {
    float sin_theta;
    const float2 uv = env_dir_uv(scene->desc, dir, &sin_theta);
    *pdf = want_pdf ? env_map_pdf_uv(scene, uv, sin_theta) : 0.0f;
    return env_map_radiance_uv(scene, uv);
  }
#endif
  (void)dir;
  *pdf = want_pdf ? 1.0f / (4.0f * WP_PI) : 0.0f;
  return scene->desc->background.xyz;
}

static inline float3 env_radiance(const SceneView* scene, float3 dir) {
  float no_pdf;
  return env_radiance_pdf(scene, dir, false, &no_pdf);
}

/* env_sample_uniform (lane code: util/lanes_begin.def). */
#define WP_LW 1
#include "lights/env_uniform.def"
#if WP_SHADE_PACKET
#define WP_LW 8
#include "lights/env_uniform.def"
#endif

/* Samples a direction toward the environment; returns its radiance, *pdf is the solid-angle
 * density (0 if nothing can be sampled). */
static inline float3 env_sample(const SceneView* scene, float2 u, float3* dir, float* pdf) {
#if WP_FEATURE_ENVIRONMENT
  if (scene->desc->env_width > 0u) return env_map_sample(scene, u.x, u.y, dir, pdf);
#endif
  *dir = env_sample_uniform(u.x, u.y);
  *pdf = 1.0f / (4.0f * WP_PI);
  return scene->desc->background.xyz;
}

/* The solid-angle density with which env_sample produces dir. */
static inline float env_pdf(const SceneView* scene, float3 dir) {
  float pdf;
  (void)env_radiance_pdf(scene, dir, true, &pdf);
  return pdf;
}

#endif /* WP_ENVIRONMENT_H */
