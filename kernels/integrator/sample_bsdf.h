/* BSDF sampling for one path: the next ray from the surface, throughput *= f cos / pdf, the
 * sample's pdf (0 for a delta lobe) and WP_PATH_DELTA kept for MIS at the next hit, and a
 * refraction into another medium multiplying the eta scale by eta^2. A path with no valid
 * direction gets throughput 0, which roulette ends, as it does a path whose throughput or pdf would
 * be NaN/Inf (counted, queues.h). Through a smooth thin-walled transmitter the previous sample's
 * pdf, flags and distance are carried on (below). Used by sample_bsdf.cl and the fused shade.cl. */
#ifndef WP_INTEGRATOR_SAMPLE_BSDF_H
#define WP_INTEGRATOR_SAMPLE_BSDF_H

#include "stage.h"
#include "integrator/roulette_compact.h"
#include "texture/ray_cone.h"
#include "geom/surface.h"

/* The next ray of the path in `slot` from surface s, seen as v (bsdf_view at -ray_d), hit at
 * distance t, with the bounce's random numbers u (its lobe choice and direction). */
WP_STAGE_FN void sample_next_ray(Paths paths, Queues queues, uint slot, const Surface* s,
                                 const BsdfView* v, float t, const BounceRandom* u) {
  const float3 ray_d = path_ray_dir(paths, slot);
  const BsdfSample bs = bsdf_sample_view(s, v, -ray_d, u->lobe, u->bsdf_uv);
  const float3 next = path_throughput(paths, slot) * bs.weight;
  const bool finite = all(isfinite(next)) && isfinite(bs.pdf);
  if (bs.valid && !finite) count_nonfinite(queues);
  if (!bs.valid || !finite) {
    path_store_throughput(paths, slot, (float3)(0.0f), 0.0f);
    return;
  }
  path_set_eta_scale(paths, slot, path_eta_scale(paths, slot) * bs.eta_scale);
  float pdf = bs.pdf, pane_distance = 0.0f;
#if WP_FEATURE_TRANSMISSION
  /* Straight through a smooth thin-walled transmitter, which shadow rays pass too (trace_shadow):
   * the path goes on along the direction the previous vertex sampled, so it keeps that sample's
   * pdf and flags for MIS at the next hit, and counts the distance to that vertex for the light's
   * pdf there. */
  if (bs.delta && !bsdf_volume(s) && dot(bs.wi, s->ng) < 0.0f) {
    pdf = path_bsdf_pdf(paths, slot);
    pane_distance = path_pane_distance(paths, slot) + t;
  } else
#endif
  {
#if WP_FEATURE_DISPERSION
    const uint flags = (bs.delta ? WP_PATH_DELTA : 0u) | (bs.channel << WP_PATH_CHANNEL_SHIFT);
#else
    const uint flags = bs.delta ? WP_PATH_DELTA : 0u;
#endif
#if WP_FEATURE_TEXTURE_LOD
    /* The flags, and the ray cone widened by the lobe the sample came from (ray_cone.h). */
    path_set_flags_word(paths, slot,
                        with_high_bf16(flags, path_cone(paths, slot).y + lobe_spread(bs.pdf)));
#else
    path_set_flags(paths, slot, flags);
#endif
  }
  path_store_throughput(paths, slot, next, pdf);
  /* Leave on the side the new direction goes to (below for transmission). */
  path_store_ray_o(paths, slot, surface_spawn(s, ray_d, t, bs.wi), 0.0f);
  path_store_ray_d(paths, slot, bs.wi, pane_distance);
}

#if WP_SHADE_PACKET
/* sample_next_ray and then roulette of eight lanes (common.h, shade_packet.h) for the paths in
 * slots[i] whose bit is set in `lanes`, at surfaces without a delta lobe: surface s seen as v,
 * hit at distance t along ray_d, throughput beta, at `bounce`, u_lobe the lobe's number, (ux, uy)
 * the direction's and u_rr roulette's. Returns the lanes that survive roulette. */
WP_LANES_STEP uint sample_next_ray8(Paths paths, Queues queues, Launch launch, const uint* slots,
                                    uint lanes, const Surface8* s, const BsdfView8* v,
                                    Float3x8 ray_d, float8 t, Float3x8 beta, uint8 bounce,
                                    float8 u_lobe, float8 ux, float8 uy, float8 u_rr) {
  float8 pdf;
  int8 valid;
  Float3x8 weight;
  const Float3x8 wi = bsdf_sample8(s, v, neg3x8(ray_d), u_lobe, ux, uy, &weight, &pdf, &valid);
  const Float3x8 next = mul3x8(beta, weight);
  const int8 finite = finite3x8(next) && isfinite(pdf);
  const Float3x8 o = surface_spawn8(s, ray_d, t, wi);
  float eta[8];
  uint bo[8];
  vstore8(bounce + 1u, 0, bo);
#pragma unroll
  for (int i = 0; i < 8; ++i) {
    eta[i] = 1.0f;
    if (!((lanes >> i) & 1u)) continue;
    const uint slot = slots[i];
    eta[i] = path_eta_scale(paths, slot);
    path_set_bounce(paths, slot, bo[i]);
    if (lane_set(valid, i) && !lane_set(finite, i)) count_nonfinite(queues);
  }
  const int8 ok = valid && finite;
  const Float3x8 zero = {(float8)(0.0f), (float8)(0.0f), (float8)(0.0f)};
  Float3x8 kept;
  const uint survives =
      lanes & (uint)lane_bits8(roulette8(launch, bounce, select3x8(zero, next, ok), vload8(0, eta),
                                         u_rr, &kept));
#pragma unroll
  for (int i = 0; i < 8; ++i) {
    if (!((lanes >> i) & 1u)) continue;
    const uint slot = slots[i];
    if (!lane_set(ok, i)) {
      path_store_throughput(paths, slot, (float3)(0.0f), 0.0f);
      continue;
    }
    /* no delta lobe, no refraction: no flags, the eta scale as it was */
#if WP_FEATURE_TEXTURE_LOD /* and the ray cone widened by the lobe (ray_cone.h) */
    path_set_flags_word(
        paths, slot, with_high_bf16(0u, path_cone(paths, slot).y + lobe_spread(lane_of(pdf, i))));
#else
    path_set_flags(paths, slot, 0u);
#endif
    path_store_throughput(paths, slot, lane3(kept, i), lane_of(pdf, i));
    path_store_ray_o(paths, slot, lane3(o, i), 0.0f);
    path_store_ray_d(paths, slot, lane3(wi, i), 0.0f);
  }
  return survives;
}
#endif

#endif /* WP_INTEGRATOR_SAMPLE_BSDF_H */
