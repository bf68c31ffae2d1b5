/* Test kernels of tests/test_sampling.cpp (LaneTwins.*): the eight-lane forms of common.h's
 * helpers and of the lane code of elementary.h and sampling/warps.h (util/lanes_begin.def), which
 * the packet kernels (integrator/shade_packet.h, traverse8_packet.h) use in place of the one-path
 * forms and so must match bit for bit, each beside the one-path form on the same inputs. Built with
 * WP_SHADE_PACKET=1 (the twins exist only there), with and without WP_PREFETCH=1 (the x86 builtins
 * of lane_bits8 and all8, or their generic forms). */
#include "util/common.h"
#include "sampling/warps.h"

/* Work-item g takes in[8g .. 8g + 8): a vector (xyz) and a number (w) per lane. Function `fn` of
 * each lane's input goes to lanes[8g + i] by the twin and to scalar[8g + i] by the original:
 * 0 length (x), 1 normalize, 2 dot with the vector's yzx (x), 3 cross with it, 4 make_basis of the
 * vector (t; 5: b), 6 cos_sin_turn of w (x, y), 7 sample_cosine_hemisphere at (x, y),
 * 8 offset_origin of the vector along its yzx by scale w, 9 the GGX visible normal from
 * ggx_view(x, y, w) at alpha ggx_alpha(w) for the numbers (x, y), 10 ggx_d, ggx_visibility and
 * ggx_reflection_pdf (x, y, z) of numbers made from (x, y, w). */
/* A direction to the viewer above the normal and a GGX alpha in [0.001, 1] from fractions. */
#define GGX_VIEW(x, y, w) V3((w)-0.5f, (x)-0.5f, 0.1f + (y))
#define GGX_ALPHA(w) (0.001f + 0.999f * (w))

__kernel void lane_twins(__global const float4* in, uint groups, uint fn, __global float4* lanes,
                         __global float4* scalar) {
  const uint g = get_global_id(0);
  if (g >= groups) return;
  float4 v[8];
  for (int i = 0; i < 8; ++i) v[i] = in[8u * g + (uint)i];
  float8 x, y, z, w;
  transpose4x8(v, &x, &y, &z, &w);
  const Float3x8 a = {x, y, z}, b = {y, z, x};
  Float3x8 r = {w, w, w};
  if (fn == 0u) {
    r.x = length3x8(a);
  } else if (fn == 1u) {
    r = normalize3x8(a);
  } else if (fn == 2u) {
    r.x = dot3x8(a, b);
  } else if (fn == 3u) {
    r = cross3x8(a, b);
  } else if (fn == 4u || fn == 5u) {
    Float3x8 t, bb;
    make_basis8(a, &t, &bb);
    r = fn == 4u ? t : bb;
  } else if (fn == 6u) {
    cos_sin_turn8(w, &r.x, &r.y);
  } else if (fn == 7u) {
    r = sample_cosine_hemisphere8(x, y);
  } else if (fn == 9u) {
#define V3(a, b, c) ((Float3x8){(a), (b), (c)})
    r = sample_ggx_visible_normal8(normalize3x8(GGX_VIEW(x, y, w)), GGX_ALPHA(w), x, y);
  } else if (fn == 10u) {
    r.x = ggx_d8(x, y, GGX_ALPHA(w));
    r.y = ggx_visibility8(x, y, GGX_ALPHA(w));
    r.z = ggx_reflection_pdf8(0.01f + x, y, 1.0f - y * y, GGX_ALPHA(w));
#undef V3
  } else {
    r = offset_origin8(a, b, w);
  }
  for (int i = 0; i < 8; ++i) {
    const float3 l = lane3(r, i), p = v[i].xyz, q = v[i].yzx;
    lanes[8u * g + (uint)i] = (float4)(l, 0.0f);
    float4 s = (float4)(v[i].w, v[i].w, v[i].w, 0.0f);
    if (fn == 0u) {
      s.x = length(p);
    } else if (fn == 1u) {
      s.xyz = normalize(p);
    } else if (fn == 2u) {
      s.x = dot(p, q);
    } else if (fn == 3u) {
      s.xyz = cross(p, q);
    } else if (fn == 4u || fn == 5u) {
      float3 t, bb;
      make_basis(p, &t, &bb);
      s.xyz = fn == 4u ? t : bb;
    } else if (fn == 6u) {
      float c, sn;
      cos_sin_turn(v[i].w, &c, &sn);
      s.xy = (float2)(c, sn);
    } else if (fn == 7u) {
      s.xyz = sample_cosine_hemisphere(p.x, p.y);
    } else if (fn == 9u) {
#define V3(a, b, c) ((float3)((a), (b), (c)))
      const float x = p.x, y = p.y, w = v[i].w;
      s.xyz = sample_ggx_visible_normal(normalize(GGX_VIEW(x, y, w)), GGX_ALPHA(w), x, y);
    } else if (fn == 10u) {
      const float x = p.x, y = p.y, w = v[i].w;
      s.x = ggx_d(x, y, GGX_ALPHA(w));
      s.y = ggx_visibility(x, y, GGX_ALPHA(w));
      s.z = ggx_reflection_pdf(0.01f + x, y, 1.0f - y * y, GGX_ALPHA(w));
#undef V3
    } else {
      s.xyz = offset_origin(p, q, v[i].w);
    }
    scalar[8u * g + (uint)i] = s;
  }
}
