/* Test kernels of tests/test_sampling.cpp (LaneTwins.*): the eight-lane twins of common.h,
 * elementary.h and sampling/warps.h, which the packet kernels (integrator/shade_packet.h,
 * traverse8_packet.h) use in place of their scalar originals and so must match bit for bit, each
 * beside its original on the same inputs. Built with WP_SHADE_PACKET=1 (the twins exist only
 * there), with and without WP_PREFETCH=1 (the x86 builtins of lane_bits8 and all8, or their
 * generic forms). */
#include "util/common.h"
#include "sampling/warps.h"

/* Work-item g takes in[8g .. 8g + 8): a vector (xyz) and a number (w) per lane. Function `fn` of
 * each lane's input goes to lanes[8g + i] by the twin and to scalar[8g + i] by the original:
 * 0 length (x), 1 normalize, 2 dot with the vector's yzx (x), 3 cross with it, 4 make_basis of the
 * vector (t; 5: b), 6 cos_sin_turn of w (x, y), 7 sample_cosine_hemisphere at (x, y),
 * 8 offset_origin of the vector along its yzx by scale w. */
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
      s.xy = cos_sin_turn(v[i].w);
    } else if (fn == 7u) {
      s.xyz = sample_cosine_hemisphere(p.xy);
    } else {
      s.xyz = offset_origin(p, q, v[i].w);
    }
    scalar[8u * g + (uint)i] = s;
  }
}
