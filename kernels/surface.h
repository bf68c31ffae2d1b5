/* The surface record that shade_surface leaves in the path state for the stages after it. */
#ifndef WP_SURFACE_H
#define WP_SURFACE_H

#include "bsdf.h"
#include "path_state.h"

static inline void surface_store(Paths paths, uint slot, const Surface* s) {
  paths.surf_p[slot] = (float4)(s->p, s->p_scale);
  paths.surf_ng[slot] = (float4)(s->ng, s->specular);
  paths.surf_ns[slot] = (float4)(s->ns, 0.0f);
  paths.surf_color[slot] = (float4)(s->color, s->metallic);
  paths.surf_params[slot] = (float4)(s->roughness, s->ior, s->transmission, as_float(s->flags));
}

static inline Surface surface_load(Paths paths, uint slot) {
  Surface s;
  const float4 p = paths.surf_p[slot];
  s.p = p.xyz;
  s.p_scale = p.w;
  const float4 ng = paths.surf_ng[slot];
  s.ng = ng.xyz;
  s.specular = ng.w;
  s.ns = paths.surf_ns[slot].xyz;
  const float4 c = paths.surf_color[slot];
  const float4 q = paths.surf_params[slot];
  s.color = c.xyz;
  s.metallic = c.w;
  s.roughness = q.x, s.ior = q.y, s.transmission = q.z;
  s.flags = as_uint(q.w);
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

#endif /* WP_SURFACE_H */
