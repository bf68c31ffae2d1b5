/* Tier-3 test kernels (tests/test_sampling.cpp): every sampling routine draws directions, and its
 * density is integrated over bins of the sphere, both on the device, so that the host can compare
 * the histogram with the expected counts (chi-square).
 *
 * A routine under test is chosen by `routine` (ST_*) and described by a few by-value arguments:
 *   ST_COSINE    sample_cosine_hemisphere / cosine_hemisphere_pdf; no parameters.
 *   ST_GGX       sample_ggx_visible_normal reflected about h / ggx_reflection_pdf; a = (v, alpha),
 *                v a unit local direction. Its density covers the whole sphere (l may go below).
 *   ST_BSDF      bsdf_sample / bsdf_eval; a.xyz = wo in the local frame, color = base colour,
 *                params = (metallic, roughness, ior, transmission), flags = Surface flags. The
 *                surface's normal is tilted_normal(), not an axis, so the BSDF's own frame is
 *                exercised; directions are reported in the frame make_basis(tilted_normal()).
 *                The layered extensions (each set only where the program has its feature):
 *                coat = (clearcoat, clearcoat roughness, tilt of the coat normal from ns and its
 *                azimuth from wo's, radians), sheen = (sheen colour, sheen roughness),
 *                specular = (specular colour, specular factor), aniso = (strength, rotation of
 *                aniso_t from wo's azimuth in radians, -, -), irid = (iridescence factor, film
 *                ior, film thickness in nm, -), dtrans = (diffuse transmission colour, factor),
 *                disp = (dispersion factor, the path's channel: 0 all three, 1 R, 2 G, 3 B).
 *   ST_TRIANGLE  sample_triangle (triangle 0 of the small scene in the buffers, light 0 with pmf
 *                1) / triangle_light_pdf times "the ray hits the emitting side"; a.xyz = the
 *                shading point. Frame: world.
 *
 * Bins (tests/sphere_bins.h) are uniform in (c, phi); `frame` says how they lie in the routine's
 * frame: BF_POLE_Y: (c, phi) -> (s cos phi, c, s sin phi), s = sqrt(1 - c^2), the pole on the
 * horizon; BF_POLE_Z: (c, phi) -> (s cos phi, s sin phi, c), the pole on the normal. */
#include "bsdf/bsdf.h"
#include "lights/lights.h"
#include "sampling/rng.h"

#define ST_COSINE 0u
#define ST_GGX 1u
#define ST_BSDF 2u
#define ST_TRIANGLE 3u

#define BF_POLE_Y 0u
#define BF_POLE_Z 1u

/* Sample kinds, in draw_samples' dir.w. */
#define SK_INVALID 0.0f
#define SK_SMOOTH 1.0f /* a direction with a density */
#define SK_DELTA 2.0f

typedef struct Config {
  uint routine, frame, flags;
  float4 a, color, params;
  float4 coat, sheen, specular, aniso, irid, dtrans, disp; /* ST_BSDF's extensions */
} Config;

inline float3 tilted_normal(void) {
  return normalize((float3)(0.3f, -0.5f, 0.8f));
}

inline float3 to_world(float3 l, float3 t, float3 b, float3 n) {
  return l.x * t + l.y * b + l.z * n;
}

/* The surface of an ST_BSDF configuration: every field not named here stays zero (Surface may
 * gain fields). */
inline Surface config_surface(const Config* c) {
  Surface s = {0};
  s.ng = s.ns = tilted_normal();
#if WP_FEATURE_GLOSSY
  s.specular = 1.0f; /* KHR_materials_specular's default */
#else
  s.specular = 0.0f; /* what the materials of a scene built without WP_FEATURE_GLOSSY have */
#endif
  s.color = c->color.xyz;
  s.metallic = c->params.x;
  s.roughness = c->params.y;
  s.ior = c->params.z;
  s.transmission = c->params.w;
  s.flags = c->flags;
  /* Azimuths are measured in the frame make_basis(ns), where wo has azimuth 0. */
  float3 t, b;
  make_basis(s.ns, &t, &b);
  (void)t, (void)b;
#if WP_FEATURE_SPECULAR
  s.specular_color = c->specular.xyz;
#endif
#if WP_FEATURE_GLOSSY
  s.specular = c->specular.w;
#endif
#if WP_FEATURE_CLEARCOAT
  s.clearcoat = c->coat.x;
  s.clearcoat_roughness = c->coat.y;
  s.nc =
      normalize(cos(c->coat.z) * s.ns + sin(c->coat.z) * (cos(c->coat.w) * t + sin(c->coat.w) * b));
#endif
#if WP_FEATURE_SHEEN
  s.sheen_color = c->sheen.xyz;
  s.sheen_roughness = c->sheen.w;
#endif
#if WP_FEATURE_ANISOTROPY
  s.anisotropy = c->aniso.x;
  s.aniso_t = normalize(cos(c->aniso.y) * t + sin(c->aniso.y) * b);
#endif
#if WP_FEATURE_IRIDESCENCE
  s.iridescence = c->irid.x;
  s.iridescence_ior = c->irid.y;
  s.iridescence_thickness = c->irid.z;
#endif
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  s.dt_color = c->dtrans.xyz;
  s.diffuse_transmission = c->dtrans.w;
#endif
#if WP_FEATURE_DISPERSION
  s.dispersion = c->disp.x;
  s.channel = (uint)c->disp.y;
#endif
  return s;
}

inline SceneView test_scene(__global const float4* positions, __global const uint4* tri_vertices,
                            __global const Material* materials, __global const uint* tri_light,
                            __global const LightAlias* light_alias, const SceneDesc* desc) {
  SceneView v = {0}; /* arrays the routines under test do not read stay null */
  v.positions = positions, v.tri_vertices = tri_vertices, v.materials = materials;
  v.tri_light = tri_light, v.light_alias = light_alias, v.desc = desc;
  return v;
}

/* Distance along unit d from p to triangle 0 (Moller-Trumbore), or 0 when the ray misses it. */
inline float triangle_hit(const SceneView* scene, float3 p, float3 d) {
  const uint4 tv = scene->tri_vertices[0];
  const float3 p0 = scene->positions[tv.x].xyz;
  const float3 e1 = scene->positions[tv.y].xyz - p0, e2 = scene->positions[tv.z].xyz - p0;
  const float3 q = cross(d, e2);
  const float det = dot(e1, q);
  if (det == 0.0f) return 0.0f;
  const float3 s = p - p0;
  const float u = dot(s, q) / det;
  const float3 r = cross(s, e1);
  const float v = dot(d, r) / det;
  const float t = dot(e2, r) / det;
  return (u >= 0.0f && v >= 0.0f && u + v <= 1.0f && t > 0.0f) ? t : 0.0f;
}

/* Density of the emitting triangle's sampling in direction d (world) from p; 0 off the triangle
 * or on a side that does not emit. */
inline float triangle_pdf(const SceneView* scene, float3 p, float3 d) {
  const float t = triangle_hit(scene, p, d);
  if (!(t > 0.0f)) return 0.0f;
  const uint4 tv = scene->tri_vertices[0];
  const float3 p0 = scene->positions[tv.x].xyz;
  const float3 n =
      normalize(cross(scene->positions[tv.y].xyz - p0, scene->positions[tv.z].xyz - p0));
  const float cos_light = -dot(n, d);
  const bool two_sided = scene->materials[tv.w].flags.x & WP_MAT_DOUBLE_SIDED;
  if (!(cos_light > 0.0f || (two_sided && cos_light < 0.0f))) return 0.0f;
  return triangle_light_pdf(scene, WP_NO_INSTANCE, 0u, t, cos_light);
}

/* The density the routine under test assigns to local direction l (the eval side). */
inline float config_pdf(const Config* c, const SceneView* scene, float3 l) {
  if (c->routine == ST_COSINE) return cosine_hemisphere_pdf(l.z);
  if (c->routine == ST_GGX) {
    const float3 v = c->a.xyz, h = normalize(v + l);
    return h.z > 0.0f ? ggx_reflection_pdf(v.z, h.z, h.x * h.x + h.y * h.y, c->a.w) : 0.0f;
  }
  if (c->routine == ST_BSDF) {
    const Surface s = config_surface(c);
    float3 t, b;
    make_basis(s.ns, &t, &b);
    return bsdf_eval(&s, to_world(c->a.xyz, t, b, s.ns), to_world(l, t, b, s.ns)).pdf;
  }
  return triangle_pdf(scene, c->a.xyz, l);
}

inline float rel_error(float x, float ref) {
  return x == ref ? 0.0f : fabs(x - ref) / fmax(fabs(ref), 1e-30f);
}
inline float rel_error3(float3 x, float3 ref) {
  return fmax(rel_error(x.x, ref.x), fmax(rel_error(x.y, ref.y), rel_error(x.z, ref.z)));
}

/* The index of refraction of s's volume on the path: with KHR_materials_dispersion, once the path
 * has a channel (1 R 630 nm, 2 G 532 nm, 3 B 465 nm), that wavelength's by the documented formula
 * n + (n - 1) (dispersion / 20) (523655 / lambda^2 - 1.5168) (docs/light-transport.md), where the
 * surface transmits into the volume; else the ior. */
inline float path_ior(const Surface* s) {
#if WP_FEATURE_DISPERSION
  if (s->channel != 0u && s->dispersion > 0.0f && (s->flags & WP_SURF_VOLUME) &&
      s->transmission > 0.0f && s->metallic < 1.0f) {
    const float lambda = s->channel == 1u ? 630.0f : s->channel == 2u ? 532.0f : 465.0f;
    return s->ior +
           (s->ior - 1.0f) * (s->dispersion / 20.0f) * (523655.0f / (lambda * lambda) - 1.5168f);
  }
#endif
  return s->ior;
}

/* The exact direction of a delta sample wi of surface s seen from wo: the mirror direction above
 * the surface; below it, straight through (thin-walled) or refracted with eta = n_from / n_to,
 * where a WP_SURF_VOLUME surface is entered from the front and left from the back (n: path_ior). */
inline float3 base_delta_direction(const Surface* s, float3 wo, float3 wi) {
  const float cos_o = dot(wo, s->ns);
  if (dot(wi, s->ns) >= 0.0f) return 2.0f * cos_o * s->ns - wo;
  if (!(s->flags & WP_SURF_VOLUME)) return -wo;
  const float ior = path_ior(s);
  const float eta = (s->flags & WP_SURF_FRONT) ? 1.0f / ior : ior;
  const float sin2_t = eta * eta * (1.0f - cos_o * cos_o);
  return -eta * wo + (eta * cos_o - sqrt(fmax(0.0f, 1.0f - sin2_t))) * s->ns;
}

/* Whether the smooth coat's delta reflection (mirror about nc) is a lobe of s. */
inline bool coat_delta(const Surface* s) {
#if WP_FEATURE_CLEARCOAT
  return s->clearcoat > 0.0f && s->clearcoat_roughness * s->clearcoat_roughness < WP_DELTA_ALPHA;
#else
  (void)s;
  return false;
#endif
}

/* Distance of delta sample wi from the nearest exact direction of s's delta lobes: the base's
 * (base_delta_direction) where the base is smooth, the mirror about the coat normal where the coat
 * is; 2 (as far as directions go) where s has no delta lobe. */
inline float delta_distance(const Surface* s, float3 wo, float3 wi) {
  float d = 2.0f;
  if (bsdf_has_delta(s)) d = length(wi - base_delta_direction(s, wo, wi));
#if WP_FEATURE_CLEARCOAT
  if (coat_delta(s)) d = fmin(d, length(wi - (2.0f * dot(wo, s->nc) * s->nc - wo)));
#endif
  return d;
}

/* One sample of an ST_BSDF configuration: dir = (local wi, kind); check = (pdf error against
 * bsdf_eval, weight error against f |cos| / pdf, distance from the exact delta direction, pdf). */
inline void draw_bsdf(const Config* c, float u_lobe, float2 u, float4* dir, float4* check) {
  const Surface s = config_surface(c);
  float3 t, b;
  make_basis(s.ns, &t, &b);
  const float3 wo = to_world(c->a.xyz, t, b, s.ns);
  const BsdfSample bs = bsdf_sample(&s, wo, u_lobe, u);
  const float3 l = (float3)(dot(bs.wi, t), dot(bs.wi, b), dot(bs.wi, s.ns));
  *check = (float4)(0.0f, 0.0f, 0.0f, bs.pdf);
  if (!bs.valid) {
    *dir = (float4)(l, SK_INVALID);
  } else if (bs.delta) {
    *dir = (float4)(l, SK_DELTA);
    check->z = delta_distance(&s, wo, bs.wi);
    /* No density to compare with: the weight (reflectance / selection probability) must at least
     * be a finite non-negative number. */
    const float3 w = bs.weight;
    check->y =
        isfinite(w.x) && isfinite(w.y) && isfinite(w.z) && w.x >= 0.0f && w.y >= 0.0f && w.z >= 0.0f
            ? 0.0f
            : 1.0f;
  } else {
    *dir = (float4)(l, SK_SMOOTH);
    const BsdfEval e = bsdf_eval(&s, wo, bs.wi);
    check->x = rel_error(bs.pdf, e.pdf);
    check->y = rel_error3(bs.weight, e.f * fabs(dot(s.ns, bs.wi)) / e.pdf);
  }
}

/* One sample of the other routines; check = (pdf error against config_pdf, 0, for triangles the
 * relative error of the reported distance, pdf). */
inline void draw_other(const Config* c, const SceneView* scene, float2 u, float4* dir,
                       float4* check) {
  float3 l;
  float pdf;
  if (c->routine == ST_COSINE) {
    l = sample_cosine_hemisphere(u.x, u.y);
    pdf = cosine_hemisphere_pdf(l.z);
  } else if (c->routine == ST_GGX) {
    const float3 v = c->a.xyz, h = sample_ggx_visible_normal(v, c->a.w, u.x, u.y);
    l = 2.0f * dot(v, h) * h - v;
    pdf = ggx_reflection_pdf(v.z, h.z, h.x * h.x + h.y * h.y, c->a.w);
  } else {
    const LightSample ls = sample_triangle(scene, WP_NO_INSTANCE, 0u, c->a.xyz, u);
    l = ls.wi;
    pdf = ls.pdf;
    check->z = pdf > 0.0f ? rel_error(ls.dist, triangle_hit(scene, c->a.xyz, l)) : 0.0f;
  }
  *dir = (float4)(l, pdf > 0.0f ? SK_SMOOTH : SK_INVALID);
  check->x = pdf > 0.0f ? rel_error(pdf, config_pdf(c, scene, l)) : 0.0f;
  check->w = pdf;
}

#define WP_CONFIG_PARAMS                                                                    \
  uint routine, uint frame, uint flags, float4 a, float4 color, float4 params, float4 coat, \
      float4 sheen, float4 specular, float4 aniso, float4 irid, float4 dtrans, float4 disp, \
      __global const float4 *positions, __global const uint4 *tri_vertices,                 \
      __global const Material *materials, __global const uint *tri_light,                   \
      __global const LightAlias *light_alias

#define WP_CONFIG_BIND                                                      \
  const Config cfg = {routine, frame,    flags, a,    color,  params, coat, \
                      sheen,   specular, aniso, irid, dtrans, disp};        \
  const SceneView scene =                                                   \
      test_scene(positions, tri_vertices, materials, tri_light, light_alias, (const SceneDesc*)0)

/* From: a configuration, a seed. To: `count` samples, dir = (local direction, SK_* kind) and
 * check (see draw_bsdf / draw_other). Sample i uses the hash stream of "pixel" i
 * (kernels/sampling/rng.h): each random number is a full-avalanche hash of (seed, dimension, i), so
 * numbers of different samples and dimensions are as independent as the hash makes them. */
__kernel void draw_samples(WP_CONFIG_PARAMS, uint seed, uint count, __global float4* dirs,
                           __global float4* checks) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_CONFIG_BIND;
  const Rng r = rng_make(i, 0u, seed, 0u);
  float4 dir, check = (float4)(0.0f);
  if (routine == ST_BSDF)
    draw_bsdf(&cfg, rng_get(r, WP_DIM_BSDF_LOBE), rng_get2(r, WP_DIM_BSDF_U), &dir, &check);
  else
    draw_other(&cfg, &scene, rng_get2(r, WP_DIM_BSDF_U), &dir, &check);
  dirs[i] = dir;
  checks[i] = check;
}

/* Midpoint rule with n x n points over rect = (c0, c1, phi0, phi1), in (theta, phi) with
 * c = cos(theta), d omega = sin(theta) d theta d phi: near the poles of the bins (c = +-1) points
 * uniform in theta come closer to the pole than points uniform in c, so features there (a support
 * boundary passing near the pole) are resolved sooner. */
inline float rect_midpoint(const Config* c, const SceneView* scene, float4 rect, uint n) {
  const float t0 = acos(clamp(rect.y, -1.0f, 1.0f)), t1 = acos(clamp(rect.x, -1.0f, 1.0f));
  const float dt = (t1 - t0) / (float)n, dp = (rect.w - rect.z) / (float)n;
  float total = 0.0f;
  for (uint i = 0; i < n; ++i) {
    const float theta = t0 + ((float)i + 0.5f) * dt, cc = cos(theta), sn = sin(theta);
    float row = 0.0f; /* rows first: at most 512 terms per float sum */
    for (uint j = 0; j < n; ++j) {
      const float phi = rect.z + ((float)j + 0.5f) * dp, x = sn * cos(phi), y = sn * sin(phi);
      row += config_pdf(c, scene, c->frame == BF_POLE_Z ? (float3)(x, y, cc) : (float3)(x, cc, y));
    }
    total += row * sn;
  }
  return total * dt * dp;
}

/* From: a configuration and `count` bins (rects). To: per bin (integral of the pdf over it, error
 * estimate). Starting at n0 x n0 points, the grid is doubled until the last two changes are both
 * at most max(rel_tol * result, abs_tol), or n0 * 2^max_level points per axis are reached; the
 * estimate is the larger of those two changes. On a smooth integrand the midpoint rule's error
 * falls 4x per doubling, so the result is well within it; where the bin cuts a discontinuity
 * (an edge of the triangle's image) the error falls only ~2x per doubling and erratically, hence
 * two changes, not one. */
__kernel void integrate_pdf(WP_CONFIG_PARAMS, __global const float4* rects, uint count, uint n0,
                            float rel_tol, float abs_tol, uint max_level, __global float2* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_CONFIG_BIND;
  uint n = n0;
  float fine = rect_midpoint(&cfg, &scene, rects[i], n), change = 0.0f, error = 0.0f;
  for (uint level = 1; level <= max_level; ++level) {
    n *= 2u;
    const float coarse = fine, previous = change;
    fine = rect_midpoint(&cfg, &scene, rects[i], n);
    change = fabs(fine - coarse);
    error = fmax(change, previous);
    if (level >= 2 && error <= fmax(rel_tol * fabs(fine), abs_tol)) break;
  }
  out[i] = (float2)(fine, error);
}

/* The lobe selection probabilities of an ST_BSDF configuration at its wo, and which lobes are
 * delta lobes: the delta fractions to expect above and below the surface. out = (specular,
 * transmission, diffuse, diffuse transmission, sheen, coat, 1 if the base's specular lobes are
 * delta lobes, 1 if the coat is a delta lobe whose mirror direction is valid (above ns and ng),
 * bsdf_only_delta). */
__kernel void lobe_selection(WP_CONFIG_PARAMS, __global float* out) {
  if (get_global_id(0) != 0) return;
  WP_CONFIG_BIND;
  (void)scene;
  const Surface s = config_surface(&cfg);
  float3 t, b;
  make_basis(s.ns, &t, &b);
  const float3 wo = to_world(cfg.a.xyz, t, b, s.ns);
  const Lobes l = bsdf_lobes(&s, wo, dot(wo, s.ns), relative_ior(&s));
  out[0] = l.spec, out[1] = l.trans, out[2] = l.diff;
  out[3] = l.dtrans, out[4] = l.sheen, out[5] = l.coat;
  out[6] = bsdf_has_delta(&s) ? 1.0f : 0.0f;
  bool coat_mirror = false;
#if WP_FEATURE_CLEARCOAT
  const float3 m = 2.0f * dot(wo, s.nc) * s.nc - wo;
  coat_mirror = coat_delta(&s) && dot(m, s.ns) > 0.0f && dot(m, s.ng) > 0.0f;
#endif
  out[7] = coat_mirror ? 1.0f : 0.0f;
  out[8] = bsdf_only_delta(&s) ? 1.0f : 0.0f;
}

/* KHR_materials_dispersion: one sample of an ST_BSDF configuration at a dispersive surface that a
 * path of all three channels reaches (disp.y = 0), where bsdf_sample chooses the channel. dir =
 * (local wi, SK_* kind) as draw_bsdf's; check = (1 when the reported pdf is not 0, else 0;
 * the weight's error against the documented one, 3 f_k |cos| / pdf_k on channel k and 0 on the
 * others, f_k and pdf_k bsdf_eval's for the surface with the sample's channel k (a delta sample:
 * 1 unless the weight is finite, >= 0 and 0 on the other channels); distance of a delta sample
 * from the exact direction of channel k's index (delta_distance); the sample's channel,
 * BsdfSample.channel, 0 in a program without the feature). */
__kernel void draw_channel_choice(WP_CONFIG_PARAMS, uint seed, uint count, __global float4* dirs,
                                  __global float4* checks) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_CONFIG_BIND;
  (void)scene;
  const Rng r = rng_make(i, 0u, seed, 0u);
  const Surface s = config_surface(&cfg);
  float3 t, b;
  make_basis(s.ns, &t, &b);
  const float3 wo = to_world(cfg.a.xyz, t, b, s.ns);
  const BsdfSample bs =
      bsdf_sample(&s, wo, rng_get(r, WP_DIM_BSDF_LOBE), rng_get2(r, WP_DIM_BSDF_U));
  uint k = 0u;
#if WP_FEATURE_DISPERSION
  k = bs.channel;
#endif
  Surface sk = s; /* the surface on a path of channel k */
#if WP_FEATURE_DISPERSION
  sk.channel = k;
#endif
  const float3 l = (float3)(dot(bs.wi, t), dot(bs.wi, b), dot(bs.wi, s.ns));
  float4 check = (float4)(bs.pdf != 0.0f ? 1.0f : 0.0f, 0.0f, 0.0f, (float)k);
  const float3 mask = (float3)(k == 1u ? 3.0f : 0.0f, k == 2u ? 3.0f : 0.0f, k == 3u ? 3.0f : 0.0f);
  const float3 w = bs.weight;
  if (!bs.valid) {
    dirs[i] = (float4)(l, SK_INVALID);
  } else if (bs.delta) {
    dirs[i] = (float4)(l, SK_DELTA);
    check.z = delta_distance(&sk, wo, bs.wi);
    const bool ok = isfinite(w.x) && isfinite(w.y) && isfinite(w.z) && w.x >= 0.0f && w.y >= 0.0f &&
                    w.z >= 0.0f && all(mask > 0.0f || w == 0.0f);
    check.y = ok ? 0.0f : 1.0f;
  } else {
    dirs[i] = (float4)(l, SK_SMOOTH);
    const BsdfEval e = bsdf_eval(&sk, wo, bs.wi);
    check.y = rel_error3(w, mask * e.f * fabs(dot(s.ns, bs.wi)) / e.pdf);
  }
  checks[i] = check;
}

/* The whole of one BSDF query for the known answer that dispersion 0 is the BSDF without
 * dispersion: per sample i, a bsdf_sample (numbers of stream i) and a bsdf_eval at a uniform
 * direction on the sphere, out[4 i .. 4 i + 3] = (wi, pdf), (weight, eta_scale), (f, pdf of the
 * eval), (valid, delta, bsdf_only_delta, 0), compared bit for bit by the host across programs. */
__kernel void bsdf_queries(WP_CONFIG_PARAMS, uint seed, uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_CONFIG_BIND;
  (void)scene;
  const Rng r = rng_make(i, 0u, seed, 0u);
  const Surface s = config_surface(&cfg);
  float3 t, b;
  make_basis(s.ns, &t, &b);
  const float3 wo = to_world(cfg.a.xyz, t, b, s.ns);
  const BsdfSample bs =
      bsdf_sample(&s, wo, rng_get(r, WP_DIM_BSDF_LOBE), rng_get2(r, WP_DIM_BSDF_U));
  const float2 u = rng_get2(r, WP_DIM_LIGHT_U);
  const float z = 1.0f - 2.0f * u.x, rho = sqrt(fmax(0.0f, 1.0f - z * z));
  const float phi = 2.0f * WP_PI * u.y;
  const BsdfEval e = bsdf_eval(&s, wo, rho * cos(phi) * t + rho * sin(phi) * b + z * s.ns);
  out[4 * i] = (float4)(bs.wi, bs.pdf);
  out[4 * i + 1] = (float4)(bs.weight, bs.eta_scale);
  out[4 * i + 2] = (float4)(e.f, e.pdf);
  out[4 * i + 3] = (float4)(bs.valid ? 1.0f : 0.0f, bs.delta ? 1.0f : 0.0f,
                            bsdf_only_delta(&s) ? 1.0f : 0.0f, 0.0f);
}

/* From: an alias table of `light_count` entries. To: `count` picks (index, reported pmf, what is
 * left of the number within the pick). */
__kernel void pick_lights(uint light_count, __global const LightAlias* light_alias, uint seed,
                          uint count, __global uint* chosen, __global float* pmfs,
                          __global float* rests) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  SceneDesc desc;
  desc.light_count = light_count;
  const SceneView scene = test_scene(0, 0, 0, 0, light_alias, &desc);
  float pmf, rest;
  chosen[i] =
      pick_light(&scene, rng_get(rng_make(i, 0u, seed, 0u), WP_DIM_LIGHT_PICK), &pmf, &rest);
  pmfs[i] = pmf;
  rests[i] = rest;
}
