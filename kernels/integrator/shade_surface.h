/* Hit resolution for one path: a miss adds the environment's radiance and ends the path; a hit
 * adds the surface's emission and resolves the material into a Surface (bsdf.h). Emission and
 * environment found here were found by BSDF sampling: they get the MIS weight against the pdf with
 * which NEE would have chosen the same point (mis.h). Used by shade_surface.cl and the fused
 * shade.cl. */
#ifndef WP_INTEGRATOR_SHADE_SURFACE_H
#define WP_INTEGRATOR_SHADE_SURFACE_H

#include "stage.h"
#include "util/elementary.h"
#include "lights/lights.h"
#include "lights/mis.h"
#include "geom/surface.h"

/* The fields shade_hit reads first, for the cache hints of the slot ahead. */
static inline void shade_prefetch(Paths paths, uint slot) {
  prefetch_path(paths, shadow_l, slot); /* the bounce count */
  prefetch_path(paths, hit, slot);
  prefetch_path(paths, ray_d, slot);
  prefetch_path(paths, throughput, slot);
  prefetch_path(paths, radiance, slot);
  prefetch_path(paths, ray_o, slot);
}

#if WP_AOV
/* Records the AOVs of the path in `slot` once: at the first surface whose BSDF is not delta lobes
 * alone, so that mirrors and smooth glass show what they reflect or let through, as OIDN and OptiX
 * want their albedo and normal inputs; or the background, for a path that leaves the scene first.
 * The depth is set apart, by the camera ray. */
static inline void aov_record(Paths paths, uint slot, float3 albedo, float3 normal) {
  if (path_aov_recorded(paths, slot) != 0.0f) return;
  path_set_aov_albedo(paths, slot, albedo);
  path_set_aov_normal(paths, slot, normal);
  path_set_aov_recorded(paths, slot, 1.0f);
}
#endif

#if WP_FEATURE_EMISSION
/* The emission of the surface the path in `slot` hit at distance t (triangle `tri`, vertices and
 * material tv, of instance `inst`; `front`: its front side; ng: its geometric normal on the ray's
 * side), seen through throughput beta along ray_d, sampled with pdf bsdf_pdf: the front side
 * emits, the back side too where the material is double-sided (lights.h). Also for
 * shade_packet.h. */
static inline void add_hit_emission(const SceneView* scene, Paths paths, uint slot, uint inst,
                                    uint tri, uint4 tv, float t, float3 beta, float bsdf_pdf,
                                    float3 ray_d, bool front, float3 ng, uint strategy) {
  if (!front && !(scene->materials[tv.w].flags.x & WP_MAT_DOUBLE_SIDED)) return;
  const float3 le = material_emission(scene, tv, path_hit_u(paths, slot), path_hit_v(paths, slot));
  if (!(max3(le) > 0.0f)) return;
  /* Seen from the vertex that sampled the ray: panes passed on the way add their distance. */
  const float dist = t + path_pane_distance(paths, slot);
  const float p_light = triangle_light_pdf(scene, inst, tri, dist, dot(ng, ray_d));
  path_set_radiance(
      paths, slot,
      path_radiance(paths, slot) + beta * le * mis_weight_bsdf_hit(bsdf_pdf, p_light, strategy));
}
#endif

/* The hit of the path in `slot`: a miss adds the environment's radiance; a hit adds the surface's
 * emission and resolves the material into *s. True when the path goes on to scatter at *s (not
 * unlit, fewer than max_depth scattering events so far). */
WP_STAGE_FN bool shade_hit(const SceneView* scene, Paths paths, Launch launch, uint slot,
                           Surface* s) {
  const float t = path_hit_t(paths, slot);
  float3 beta = path_throughput(paths, slot);
  const float bsdf_pdf = path_bsdf_pdf(paths, slot); /* 0: delta lobe or camera ray */
  const float3 ray_d = path_ray_dir(paths, slot);
  if (!(t < INFINITY)) {
    /* NEE's pdf of the direction only where MIS weighs it: not after a camera ray or a delta
     * lobe (bsdf_pdf 0), whose weight is 1 whatever it is. */
    float light_pdf;
    const float3 le = environment_hit(
        scene, ray_d, launch.strategy == WP_STRATEGY_MIS && bsdf_pdf > 0.0f, &light_pdf);
    const float w = mis_weight_bsdf_hit(bsdf_pdf, light_pdf, launch.strategy);
    path_set_radiance(paths, slot, path_radiance(paths, slot) + beta * le * w);
#if WP_AOV
    aov_record(paths, slot, clamp(le, 0.0f, 1.0f), (float3)(0.0f));
#endif
    return false;
  }
  const uint tri = path_hit_triangle(paths, slot), inst = path_hit_instance(paths, slot);
  const uint4 tv = scene->tri_vertices[tri]; /* the file's winding: emission reads it */
  (void)tv;
  bool front;
#if WP_FEATURE_TEXTURE_LOD
  /* The ray cone across the hit, and bent by the surface's curvature for the ray that leaves it
   * (ray_cone.h; sample_next_ray adds the lobe's spread). */
  const float2 cone = path_cone(paths, slot);
  const float width = cone_width_at(cone, t);
  *s = resolve_surface(scene, inst, tri, path_hit_u(paths, slot), path_hit_v(paths, slot), ray_d,
                       width, &front);
  path_set_cone(paths, slot, (float2)(width, cone_spread_curved(cone.y, s->curvature, width)));
#else
  *s = resolve_surface(scene, inst, tri, path_hit_u(paths, slot), path_hit_v(paths, slot), ray_d,
                       0.0f, &front);
#endif
#if WP_FEATURE_DISPERSION
  s->channel = (path_flags(paths, slot) & WP_PATH_CHANNEL_MASK) >> WP_PATH_CHANNEL_SHIFT;
#endif
#if WP_AOV
  if (path_bounce(paths, slot) == 0u) /* from the camera, panes passed on the way included */
    path_set_aov_depth(paths, slot, t + path_pane_distance(paths, slot));
  if (!bsdf_only_delta(s)) aov_record(paths, slot, s->color, s->ns);
#endif
#if WP_FEATURE_VOLUME
  /* A ray that reaches the back of a volume travelled inside it: Beer-Lambert absorption with
   * transmittance attenuationColor^(distance / attenuationDistance) (KHR_materials_volume). */
  const float4 vol = scene->materials[tv.w].volume;
  if (!front && (s->flags & WP_SURF_VOLUME) && vol.w < INFINITY) {
    const float e = t / vol.w; /* > 0: t > 0, attenuationDistance finite */
    beta *= (float3)(powr_poly(vol.x, e), powr_poly(vol.y, e), powr_poly(vol.z, e));
    path_set_throughput(paths, slot, beta);
  }
#endif
#if WP_FEATURE_EMISSION
  add_hit_emission(scene, paths, slot, inst, tri, tv, t, beta, bsdf_pdf, ray_d, front, s->ng,
                   launch.strategy);
#endif
#if WP_FEATURE_UNLIT
  if (s->flags & WP_SURF_UNLIT) { /* shows its colour as emitted radiance; nothing scatters */
    path_set_radiance(paths, slot, path_radiance(paths, slot) + beta * s->color);
    return false;
  }
#endif
  return path_bounce(paths, slot) < launch.max_depth;
}

#endif /* WP_INTEGRATOR_SHADE_SURFACE_H */
