/* The surface record that shade_surface leaves in the path state for the stages after it. */
#ifndef WP_SURFACE_H
#define WP_SURFACE_H

#include "bsdf.h"
#include "path_state.h"

inline void surface_store(Paths paths, uint slot, const Surface* s) {
  paths.surf_p[slot] = (float4)(s->p, s->p_scale);
  paths.surf_ng[slot] = (float4)(s->ng, s->specular);
  paths.surf_ns[slot] = (float4)(s->ns, 0.0f);
  paths.surf_color[slot] = (float4)(s->color, s->metallic);
  paths.surf_params[slot] = (float4)(s->roughness, s->ior, s->transmission, as_float(s->flags));
}

inline Surface surface_load(Paths paths, uint slot) {
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

#endif /* WP_SURFACE_H */
