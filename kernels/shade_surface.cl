/* Stage: hit resolution.
 * From: queue_in with the hit records of intersect_closest.
 * To:   misses add the environment's radiance and end. Hits add the surface's emission, resolve
 *       the material into the surface record (surface.h) and go to WP_QUEUE_SURFACE, unless the
 *       path has had max_depth scattering events already, in which case it ends here.
 * Emission and environment found here were found by BSDF sampling: they get the MIS weight
 * against the pdf with which NEE would have chosen the same point (mis.h). */
#include "stage.h"
#include "lights.h"
#include "mis.h"
#include "surface.h"

#if WP_AOV
/* Records the AOVs of the path in `slot` once (path_state.def): at the first surface whose BSDF is
 * not delta lobes alone, so that mirrors and smooth glass show what they reflect or let through,
 * as OIDN and OptiX want their albedo and normal inputs; or the background, for a path that leaves
 * the scene first. The depth (w) is set apart, by the camera ray. */
static inline void aov_record(Paths paths, uint slot, float3 albedo, float3 normal) {
  if (paths.aov_normal[slot].w != 0.0f) return;
  paths.aov_albedo[slot] = (float4)(albedo, paths.aov_albedo[slot].w);
  paths.aov_normal[slot] = (float4)(normal, 1.0f);
}
#endif

/* The hit of the path in `slot`: a miss adds the environment's radiance; a hit adds the surface's
 * emission and resolves the material into *s. True when the path goes on to scatter at *s (not
 * unlit, fewer than max_depth scattering events so far). Shared by this stage and the fused
 * shade.cl. */
WP_STAGE_FN bool shade_hit(const SceneView* scene, Paths paths, Launch launch, uint slot,
                           Surface* s) {
  const float4 hit = paths.hit[slot];
  float4 beta = paths.throughput[slot]; /* w: pdf of the BSDF sample (0: delta or camera) */
  const float3 ray_d = paths.ray_d[slot].xyz;
  if (!(hit.x < INFINITY)) {
    const float w = mis_weight_bsdf_hit(beta.w, environment_light_pdf(scene, ray_d));
    const float3 le = env_radiance(scene, ray_d);
    paths.radiance[slot].xyz += beta.xyz * le * w;
#if WP_AOV
    aov_record(paths, slot, clamp(le, 0.0f, 1.0f), (float3)(0.0f));
#endif
    return false;
  }
  const uint tri = as_uint(hit.w);
  const uint4 tv = scene->tri_vertices[tri];
  bool front;
  *s = resolve_surface(scene, tv, hit.y, hit.z, ray_d, &front);
#if WP_AOV
  if (paths.info[slot].y == 0u) /* from the camera, panes passed on the way included */
    paths.aov_albedo[slot].w = hit.x + as_float(paths.info[slot].w);
  if (!bsdf_only_delta(s)) aov_record(paths, slot, s->color, s->ns);
#endif
#if WP_FEATURE_VOLUME
  /* A ray that reaches the back of a volume travelled inside it: Beer-Lambert absorption with
   * transmittance attenuationColor^(distance / attenuationDistance) (KHR_materials_volume). */
  const float4 vol = scene->materials[tv.w].volume;
  if (!front && (s->flags & WP_SURF_VOLUME) && vol.w < INFINITY) {
    beta.xyz *= pow(vol.xyz, hit.x / vol.w);
    paths.throughput[slot] = beta;
  }
#endif
#if WP_FEATURE_EMISSION
  if (front || (scene->materials[tv.w].flags.x & WP_MAT_DOUBLE_SIDED)) {
    const float3 le = material_emission(scene, tv, hit.y, hit.z);
    if (max3(le) > 0.0f) {
      /* Seen from the vertex that sampled the ray: panes passed on the way add their distance. */
      const float dist = hit.x + as_float(paths.info[slot].w);
      const float p_light = triangle_light_pdf(scene, tri, dist, dot(s->ng, ray_d));
      paths.radiance[slot].xyz += beta.xyz * le * mis_weight_bsdf_hit(beta.w, p_light);
    }
  }
#endif
#if WP_FEATURE_UNLIT
  if (s->flags & WP_SURF_UNLIT) { /* shows its colour as emitted radiance; nothing scatters */
    paths.radiance[slot].xyz += beta.xyz * s->color;
    return false;
  }
#endif
  return paths.info[slot].y < launch.max_depth;
}

WP_GROUP_KERNEL void shade_surface(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  WP_GROUP_SCRATCH(scan);
  uint slot = 0u;
  bool scatters = false;
  if (queue_get(queues, launch.queue_in, get_global_id(0), &slot)) {
    Surface s;
    scatters = shade_hit(&scene, paths, launch, slot, &s);
    if (scatters) surface_store(paths, slot, &s);
  }
  queue_push_group(queues, WP_QUEUE_SURFACE, scatters, slot, scan);
}
