/* The surface record that shade_surface leaves in the path state for the split stages after it
 * (the path_surf_* lanes of shared/path_state.def), and where rays leave a surface. */
#ifndef WP_SURFACE_H
#define WP_SURFACE_H

#include "bsdf/bsdf.h"
#include "integrator/path_state.h"

static inline void surface_store(Paths paths, uint slot, const Surface* s) {
  path_store_surf_p(paths, slot, s->p, s->p_scale);
  path_store_surf_ng(paths, slot, s->ng, s->specular);
#if WP_FEATURE_CLEARCOAT
  path_store_surf_ns(paths, slot, s->ns, s->clearcoat_roughness);
  path_store_surf_coat(paths, slot, s->nc, s->clearcoat);
#else
  path_set_surf_ns(paths, slot, s->ns);
#endif
  path_store_surf_color(paths, slot, s->color, s->metallic);
  path_store_surf_params(paths, slot, s->roughness, s->ior, s->transmission, s->flags);
#if WP_FEATURE_SPECULAR
  path_set_surf_specular_color(paths, slot, s->specular_color);
#endif
#if WP_FEATURE_DISPERSION
  path_set_surf_dispersion(paths, slot, s->dispersion);
#endif
#if WP_FEATURE_SHEEN
  path_store_surf_sheen(paths, slot, s->sheen_color, s->sheen_roughness);
#endif
#if WP_FEATURE_ANISOTROPY
  path_store_surf_aniso(paths, slot, s->aniso_t, s->anisotropy);
#endif
#if WP_FEATURE_IRIDESCENCE
  path_set_surf_iridescence(paths, slot, s->iridescence);
  path_set_surf_iridescence_ior(paths, slot, s->iridescence_ior);
  path_set_surf_iridescence_thickness(paths, slot, s->iridescence_thickness);
#endif
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  path_store_surf_dtrans(paths, slot, s->dt_color, s->diffuse_transmission);
#endif
}

static inline Surface surface_load(Paths paths, uint slot) {
  Surface s;
  s.p = path_surf_p(paths, slot);
  s.p_scale = path_surf_p_scale(paths, slot);
  s.ng = path_surf_ng(paths, slot);
  s.specular = path_surf_specular(paths, slot);
  s.ns = path_surf_ns(paths, slot);
  s.color = path_surf_color(paths, slot);
  s.metallic = path_surf_metallic(paths, slot);
  s.roughness = path_surf_roughness(paths, slot);
  s.ior = path_surf_ior(paths, slot);
  s.transmission = path_surf_transmission(paths, slot);
  s.flags = path_surf_flags(paths, slot);
#if WP_FEATURE_SPECULAR
  s.specular_color = path_surf_specular_color(paths, slot);
#endif
#if WP_FEATURE_DISPERSION
  s.dispersion = path_surf_dispersion(paths, slot);
  s.channel = (path_flags(paths, slot) & WP_PATH_CHANNEL_MASK) >> WP_PATH_CHANNEL_SHIFT;
#endif
#if WP_FEATURE_CLEARCOAT
  s.nc = path_surf_coat_normal(paths, slot);
  s.clearcoat = path_surf_clearcoat(paths, slot);
  s.clearcoat_roughness = path_surf_clearcoat_roughness(paths, slot);
#endif
#if WP_FEATURE_SHEEN
  s.sheen_color = path_surf_sheen_color(paths, slot);
  s.sheen_roughness = path_surf_sheen_roughness(paths, slot);
#endif
#if WP_FEATURE_ANISOTROPY
  s.aniso_t = path_surf_aniso_t(paths, slot);
  s.anisotropy = path_surf_anisotropy(paths, slot);
#endif
#if WP_FEATURE_IRIDESCENCE
  s.iridescence = path_surf_iridescence(paths, slot);
  s.iridescence_ior = path_surf_iridescence_ior(paths, slot);
  s.iridescence_thickness = path_surf_iridescence_thickness(paths, slot);
#endif
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  s.dt_color = path_surf_dt_color(paths, slot);
  s.diffuse_transmission = path_surf_diffuse_transmission(paths, slot);
#endif
  return s;
}

/* The origin of a ray leaving surface s in direction wi (a BSDF sample or a shadow ray), for a
 * path that arrived along unit d_in after travelling t_in. It is moved off s along the geometric
 * normal, to the side wi goes to (offset_origin). On the side the path came from, it is also pulled
 * back along d_in by as much (at most half the way to the previous vertex, which was free space):
 * a hit in a concave corner lies, within rounding, on the neighbouring surface too, and moving
 * along s's normal alone leaves it there; a ray from there into the neighbour starts on its plane,
 * finds t = 0 (or -1e-8) and passes through it, leaking light into closed rooms
 * (scenes/failure/closed_box). The pulled-back point is on the path's free side of every surface
 * the path did not cross. A refracted ray leaves on the far side, where there is no such point. */
static inline float3 surface_spawn(const Surface* s, float3 d_in, float t_in, float3 wi) {
  if (dot(wi, s->ng) > 0.0f) /* ng faces the incoming ray */
    return offset_origin(s->p - d_in * fmin(offset_distance(s->p_scale), 0.5f * t_in), s->ng,
                         s->p_scale);
  return offset_origin(s->p, -s->ng, s->p_scale);
}

#if WP_SHADE_PACKET
/* surface_spawn of eight lanes (common.h, Float3x8). */
WP_LANES_FN Float3x8 surface_spawn8(const Surface8* s, Float3x8 d_in, float8 t_in, Float3x8 wi) {
  const float8 back = fmin(offset_distance8(s->p_scale), 0.5f * t_in);
  const Float3x8 q = {s->p.x - d_in.x * back, s->p.y - d_in.y * back, s->p.z - d_in.z * back};
  return select3x8(offset_origin8(s->p, neg3x8(s->ng), s->p_scale),
                   offset_origin8(q, s->ng, s->p_scale), dot3x8(wi, s->ng) > 0.0f);
}
#endif

#endif /* WP_SURFACE_H */
