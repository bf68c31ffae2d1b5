/* The fused shading stage for eight paths per work-item, float8 lanes being paths, in programs
 * whose every scattering surface is untextured, with Lambert's BSDF or glTF's metallic-roughness
 * one without extensions (WP_BSDF_PLAIN) (WP_SHADE_PACKET: the host's choice on PoCL's CPU
 * devices, which run a kernel's work-items one after another, so SIMD across paths has to be
 * written out). Each path gets exactly what shade.cl's single-path body gives it: a miss,
 * emission, a punctual light (and a triangle light in textured or alpha programs), and a surface
 * with a delta lobe go through the same functions lane by lane; the BSDF through its lane code
 * (util/lanes_begin.def: one source for one path and eight); the surface, a triangle light's
 * sample and the next ray through their twins of eight lanes, each beside its original (common.h
 * says why) and computing the same expressions. */
#ifndef WP_INTEGRATOR_SHADE_PACKET_H
#define WP_INTEGRATOR_SHADE_PACKET_H

#include "integrator/roulette_compact.h"
#include "integrator/sample_bsdf.h"
#include "integrator/sample_lights.h"
#include "integrator/shade_surface.h"

#if WP_SHADE_PACKET
#if (WP_FEATURE_GLOSSY && !WP_BSDF_PLAIN) || WP_FEATURE_TRANSMISSION || WP_FEATURE_VOLUME || \
    WP_BSDF_EXTENSIONS || WP_FEATURE_DISPERSION || WP_BVH_INSTANCES || WP_AOV
#error "WP_SHADE_PACKET: programs of Lambert's or WP_BSDF_PLAIN's BSDF without instances or AOVs"
#endif

/* Programs whose surfaces the lanes cannot resolve (textures, ray cones, normal maps, vertex
 * colours, unlit materials; alpha, whose emission reads textures): there each hit is shade_hit's,
 * lane by lane, emission and all, and the surfaces it gives are put in lanes (surface8_of) for
 * the light sample and the BSDF's. Elsewhere resolve_surface8 does it in the lanes. */
#define WP_SHADE_HITS_BY_LANE                                                 \
  (WP_FEATURE_TEXTURES || WP_FEATURE_TEXTURE_LOD || WP_FEATURE_NORMAL_MAPS || \
   WP_FEATURE_VERTEX_COLORS || WP_FEATURE_ALPHA || WP_FEATURE_UNLIT)

#define WP_SHADE_LANES 8

/* Whether a miss adds nothing: a black background without a map, where shade_hit adds beta * 0
 * to the radiance, leaving it as it is bit for bit (beta is finite; no AOVs in these programs). */
static inline bool background_dark(const SceneView* scene) {
#if WP_FEATURE_ENVIRONMENT
  if (scene->desc->env_width != 0u) return false;
#endif
  return !(max3(scene->desc->background.xyz) > 0.0f);
}

/* The one-path code the packet calls lane by lane for what its lanes do not do is kept out of
 * line, compiled once: inlined at each call it made the program's build up to twice as long, and
 * most of these lanes are rare ones (a miss, a delta lobe, a punctual light). */
#define WP_LANE_BY_LANE static __attribute__((noinline))

/* shade_hit for the path in `slot` (a miss, or a hit the lanes do not resolve). */
WP_LANE_BY_LANE bool hit_lane(const SceneView* scene, Paths paths, Launch launch, uint slot,
                              Surface* s) {
  return shade_hit(scene, paths, launch, slot, s);
}

/* sample_light_ray for the path in `slot` at surface one, hit at distance t along ray_d, with the
 * light pick's number and the light point's. */
WP_LANE_BY_LANE bool light_lane(const SceneView* scene, Paths paths, Queues queues, uint slot,
                                const Surface* one, float3 ray_d, float t, float light_pick,
                                float2 light_uv, uint strategy) {
  const BsdfView v = bsdf_view(one, -ray_d);
  BounceRandom u; /* what sample_light_ray reads of it */
  u.light_pick = light_pick;
  u.light_uv = light_uv;
  return sample_light_ray(scene, paths, queues, slot, one, &v, t, &u, strategy);
}

#if WP_FEATURE_GLOSSY
/* What shade.cl's body does after shade_hit for the path in `slot`, lane i of the packet (surface
 * one, hit at distance t along ray_d, the bounce's numbers u), by the one-path functions: bits i
 * of *shadow and *survives set where it has a shadow ray and a next ray. */
WP_LANE_BY_LANE void shade_lane(const SceneView* scene, Paths paths, Queues queues, Launch launch,
                                uint slot, const Surface* one, int i, float3 ray_d, float t,
                                const BounceRandom* u, uint* shadow, uint* survives) {
  const BsdfView v = bsdf_view(one, -ray_d);
  if (launch.strategy != WP_STRATEGY_BSDF &&
      sample_light_ray(scene, paths, queues, slot, one, &v, t, u, launch.strategy))
    *shadow |= 1u << i;
  sample_next_ray(paths, queues, slot, one, &v, t, u);
  if (roulette(paths, queues, launch, slot, u->roulette)) *survives |= 1u << i;
}
#endif

#if WP_SHADE_HITS_BY_LANE
/* Eight surfaces in lanes (closure.h, Surface8). */
WP_LANES_FN Surface8 surface8_of(const Surface* one) {
  Surface8 s;
  float4 v[8];
  float8 w, unused;
  for (int i = 0; i < 8; ++i) v[i] = (float4)(one[i].p, one[i].p_scale);
  transpose4x8(v, &s.p.x, &s.p.y, &s.p.z, &s.p_scale);
  for (int i = 0; i < 8; ++i)
    v[i] = (float4)(one[i].ng, (one[i].flags & WP_SURF_FRONT) ? 1.0f : 0.0f);
  transpose4x8(v, &s.ng.x, &s.ng.y, &s.ng.z, &w);
  s.front = w != 0.0f;
#if WP_FEATURE_GLOSSY
  for (int i = 0; i < 8; ++i) v[i] = (float4)(one[i].ns, one[i].metallic);
  transpose4x8(v, &s.ns.x, &s.ns.y, &s.ns.z, &s.metallic);
  for (int i = 0; i < 8; ++i) v[i] = (float4)(one[i].color, one[i].roughness);
  transpose4x8(v, &s.color.x, &s.color.y, &s.color.z, &s.roughness);
  for (int i = 0; i < 8; ++i) v[i] = (float4)(one[i].ior, one[i].specular, 0.0f, 0.0f);
  transpose4x8(v, &s.ior, &s.specular, &unused, &w);
#else
  for (int i = 0; i < 8; ++i) v[i] = (float4)(one[i].ns, 0.0f);
  transpose4x8(v, &s.ns.x, &s.ns.y, &s.ns.z, &unused);
  for (int i = 0; i < 8; ++i) v[i] = (float4)(one[i].color, 0.0f);
  transpose4x8(v, &s.color.x, &s.color.y, &s.color.z, &unused);
#endif
  return s;
}
#endif

/* The shading of the paths in entries [first, first + WP_SHADE_LANES) of launch.queue_in, as
 * shade.cl's body shades each: their slots, and in bit i of *shadow and *survives whether path i
 * has a shadow ray and a next ray. Lanes without a path to scatter compute with another lane's
 * numbers, and their results are dropped. */
WP_STAGE_FN void shade_packet(const SceneView* scene, Paths paths, Queues queues, Launch launch,
                              uint first, uint* slots, uint* shadow, uint* survives) {
  *shadow = 0u, *survives = 0u;
  for (uint i = 0u; i < WP_SHADE_LANES; ++i) {
    uint ahead;
    if (prefetch_slot(queues, launch.queue_in, first + i, &ahead)) shade_prefetch(paths, ahead);
  }
  const int n = queue_get_run(queues, launch.queue_in, first, WP_SHADE_LANES, slots);
  if (n == 0) return;
  /* The hits; a miss is shade_hit's alone, where it adds something. */
  const bool dark = background_dark(scene);
  uint hits = 0u, first_hit = 0u;
  for (int i = n - 1; i >= 0; --i) {
    if (path_hit_t(paths, slots[i]) < INFINITY) {
      hits |= 1u << i, first_hit = (uint)i;
    } else if (!dark) {
      Surface unused;
      (void)hit_lane(scene, paths, launch, slots[i], &unused);
    }
  }
  if (hits == 0u) return;
  /* From here on every lane holds a hit: its own, or the first one's. */
  uint sl[WP_SHADE_LANES];
  float4 h[WP_SHADE_LANES], d[WP_SHADE_LANES], b[WP_SHADE_LANES];
#pragma unroll
  for (int i = 0; i < WP_SHADE_LANES; ++i) {
    sl[i] = slots[(hits >> i) & 1u ? i : (int)first_hit];
    h[i] = path_load_hit(paths, sl[i]), d[i] = path_load_ray_d(paths, sl[i]);
    b[i] = path_load_throughput(paths, sl[i]);
  }
  float8 t, hu, hv, tri_bits, no_panes, bsdf_pdf; /* no transmission: no pane distances */
  transpose4x8(h, &t, &hu, &hv, &tri_bits);
  Float3x8 ray_d, beta;
  transpose4x8(d, &ray_d.x, &ray_d.y, &ray_d.z, &no_panes);
  transpose4x8(b, &beta.x, &beta.y, &beta.z, &bsdf_pdf);
  /* The bounce's numbers (bounce_random), by their use: light pick, light point, direction,
   * roulette. */
  float8 u[7];
  uint bo[WP_SHADE_LANES];
  for (int i = 0; i < WP_SHADE_LANES; ++i) bo[i] = path_bounce(paths, sl[i]);
  const uint8 bounce = vload8(0, bo);
#if WP_SAMPLER != WP_SAMPLER_INDEPENDENT
  {
    uint px[WP_SHADE_LANES], sa[WP_SHADE_LANES];
    for (int i = 0; i < WP_SHADE_LANES; ++i)
      px[i] = path_pixel(launch, sl[i]), sa[i] = path_sample(launch, sl[i]);
    const RngLanes r = {vload8(0, px), vload8(0, sa), bounce, launch.seed};
    /* The light pick's own number only past WP_LIGHT_PICK_REUSE_MAX lights (sample_light),
     * roulette's only at its depth (roulette). */
    rng_bounce_lanes(r, u, scene->desc->light_count > WP_LIGHT_PICK_REUSE_MAX,
                     any8(bounce + 1u >= (uint8)(launch.rr_depth)), WP_FEATURE_GLOSSY);
  }
#else
  {
    float4 lo[WP_SHADE_LANES], hi[WP_SHADE_LANES];
#pragma nounroll
    for (int i = 0; i < WP_SHADE_LANES; ++i) {
      const float8 v = rng_bounce(path_rng(paths, sl[i], launch));
      lo[i] = v.lo, hi[i] = v.hi;
    }
    float8 unused;
    transpose4x8(lo, &u[0], &u[1], &u[6], &u[3]);
    transpose4x8(hi, &u[5], &u[2], &u[4], &unused);
  }
#endif
  const float8 light_pick = u[0], light_u = u[1], light_v = u[2], bsdf_u = u[3], bsdf_v = u[4],
               roulette_u = u[5], lobe_u = u[6];
  uint tri[WP_SHADE_LANES];
  vstore8(as_uint8(tri_bits), 0, tri);
#if WP_SHADE_HITS_BY_LANE
  /* Each hit by shade_hit, emission and all; the paths that scatter, whose surfaces go to the
   * lanes (the others' lanes take the first one's). */
  (void)hu, (void)hv;
  Surface one[WP_SHADE_LANES];
  uint go = 0u;
  for (int i = 0; i < n; ++i)
    if (((hits >> i) & 1u) && hit_lane(scene, paths, launch, slots[i], &one[i])) go |= 1u << i;
  if (go == 0u) return;
  for (int i = 0; i < WP_SHADE_LANES; ++i)
    if (!((go >> i) & 1u)) one[i] = one[lowest_bit((int)go)];
  const Surface8 s = surface8_of(one);
#else
  uint4 tv[WP_SHADE_LANES];
  const Surface8 s = resolve_surface8(scene, tri, hu, hv, ray_d, tv);
#if WP_FEATURE_EMISSION
  /* Emission (shade_hit), by add_hit_emission for the lanes whose material emits (it returns at
   * once for the others: no textures here). */
  for (int i = 0; i < n; ++i) {
    if (!((hits >> i) & 1u) || !(max3(scene->materials[tv[i].w].emission.xyz) > 0.0f)) continue;
    add_hit_emission(scene, paths, slots[i], WP_NO_INSTANCE, tri[i], tv[i], lane_of(t, i),
                     lane3(beta, i), lane_of(bsdf_pdf, i), lane3(ray_d, i), lane_set(s.front, i),
                     lane3(s.ng, i), launch.strategy);
  }
#endif
  /* The paths that scatter: fewer than max_depth events so far. */
  uint go = hits & (uint)lane_bits8(bounce < (uint8)(launch.max_depth));
#endif
#if WP_FEATURE_GLOSSY
  /* Those at a surface with a delta lobe, one at a time (lane code has no delta lobes). */
  for (uint delta = go & (uint)lane_bits8(glossy_delta8(&s)); delta != 0u; delta &= delta - 1u) {
    const int i = lowest_bit((int)delta);
    BounceRandom one_u;
    one_u.light_pick = lane_of(light_pick, i), one_u.lobe = lane_of(lobe_u, i);
    one_u.roulette = lane_of(roulette_u, i);
    one_u.light_uv = (float2)(lane_of(light_u, i), lane_of(light_v, i));
    one_u.bsdf_uv = (float2)(lane_of(bsdf_u, i), lane_of(bsdf_v, i));
#if WP_SHADE_HITS_BY_LANE
    const Surface lane_surface = one[i];
#else
    const Surface lane_surface = surface_lane(scene, &s, tv[i], i);
#endif
    shade_lane(scene, paths, queues, launch, slots[i], &lane_surface, i, lane3(ray_d, i),
               lane_of(t, i), &one_u, shadow, survives);
    go &= ~(1u << i);
  }
#else
  (void)lobe_u;
#endif
  if (go == 0u) return;
  const BsdfView8 v8 = bsdf_view8(&s, neg3x8(ray_d));
  if (launch.strategy != WP_STRATEGY_BSDF && scene->desc->light_count != 0u) {
    /* The light each path picks (sample_light): a triangle's point (in untextured programs
     * without alpha) and the environment's, with or without a map, in the lanes; any other
     * light by sample_light_ray itself. */
    uint ltri[WP_SHADE_LANES], picked[WP_SHADE_LANES], lanes = 0u, env = 0u;
    const bool reuse = scene->desc->light_count <= WP_LIGHT_PICK_REUSE_MAX;
    float8 pmf, rest;
    vstore8(pick_light8(scene, reuse ? light_u : light_pick, &pmf, &rest), 0, picked);
    const float8 lu = reuse ? rest : light_u;
    for (int i = 0; i < WP_SHADE_LANES; ++i) {
      const uint4 meta = scene->lights[picked[i]].meta;
#if WP_FEATURE_TEXTURES || WP_FEATURE_ALPHA /* which sample_triangle8 knows nothing of */
      const bool triangle = false;
#else
      const bool triangle = meta.x == WP_LIGHT_TRIANGLE;
#endif
      ltri[i] = triangle ? meta.y : tri[i];
      if (!((go >> i) & 1u)) continue;
      if (triangle) {
        lanes |= 1u << i;
      } else if (meta.x == WP_LIGHT_ENVIRONMENT) {
        lanes |= 1u << i, env |= 1u << i;
      } else {
#if WP_SHADE_HITS_BY_LANE
        const Surface lane_surface = one[i];
#else
        const Surface lane_surface = surface_lane(scene, &s, tv[i], i);
#endif
        if (light_lane(scene, paths, queues, slots[i], &lane_surface, lane3(ray_d, i),
                       lane_of(t, i), lane_of(light_pick, i),
                       (float2)(lane_of(light_u, i), lane_of(light_v, i)), launch.strategy))
          *shadow |= 1u << i;
      }
    }
    if (lanes != 0u)
      *shadow |= sample_light_ray8(scene, paths, queues, slots, lanes, env, &s, &v8, ray_d, t, beta,
                                   ltri, pmf, lu, light_v, launch.strategy);
  }
  *survives |= sample_next_ray8(paths, queues, launch, slots, go, &s, &v8, ray_d, t, beta, bounce,
                                lobe_u, bsdf_u, bsdf_v, roulette_u);
}
#endif

#endif /* WP_INTEGRATOR_SHADE_PACKET_H */
