/* Basic definitions for every kernel: the shared types, constants and small vector helpers.
 *
 * Every function in kernels/ is `static inline`, never plain `inline`: OpenCL C takes C99's
 * rules, under which a plain inline definition emits no function, so a call the compiler chooses
 * not to inline (resolve_surface, bsdf_sample, leaf_test, ... for nvptx64 and amdgcn) is left
 * to an external symbol nothing defines and the program fails to link. PoCL inlines everything
 * and never shows it; tools/gpu_compile.py does. */
#ifndef WP_COMMON_H
#define WP_COMMON_H

#include "shared/types.h"
#include "features.h"

/* Bit i set where lane i of `m` is set (true: all bits of the lane). On PoCL's CPU devices with
 * AVX (WP_PREFETCH marks PoCL's CPU builds; clang defines __AVX__ for the target it compiles for)
 * one instruction takes each lane's sign bit: LLVM 15 turns the portable version into a
 * mask-and-or reduction of seven, and a node takes four such masks. The same bits either way
 * (a comparison's lanes are all ones or all zeros); measured in docs/performance.md, "Lane masks
 * in one instruction". any4: whether some lane of a four-lane mask is set, the same way. */
#if WP_PREFETCH && defined(__AVX__)
#define WP_SIGN_MASKS 1
#else
#define WP_SIGN_MASKS 0
#endif
static inline int lane_bits8(int8 m) {
#if WP_SIGN_MASKS
  return __builtin_ia32_movmskps256(as_float8(m));
#else
  const int8 b = m & (int8)(1, 2, 4, 8, 16, 32, 64, 128);
  const int4 b4 = b.lo | b.hi;
  const int2 b2 = b4.lo | b4.hi;
  return b2.x | b2.y;
#endif
}
static inline bool any4(int4 m) {
#if WP_SIGN_MASKS
  return __builtin_ia32_movmskps(as_float4(m)) != 0;
#else
  return any(m);
#endif
}

/* Whether some lane (all lanes) of a comparison's mask is set: the sign bits in one instruction,
 * as lane_bits8, where PoCL's any() and all() move the mask to a vector and test the lanes' signs
 * with shuffles and a branch per pair of lanes. */
static inline bool any8(int8 m) {
  return lane_bits8(m) != 0;
}
static inline bool all8(int8 m) {
  return lane_bits8(m) == 0xff;
}

/* The index of the lowest set bit of a lane mask (bits != 0): the BVH walks' next child, the
 * queue push's next entry. */
static inline int lowest_bit(int bits) {
  return 31 - clz(bits & -bits);
}

#define WP_PI 3.14159265358979323846f
#define WP_INV_PI 0.31830988618379067154f
#define WP_INF INFINITY

/* For the per-path bodies of the stages (integrator/<stage>.h), several called from their own
 * kernel and from the fused shade.cl: with two callers clang keeps them out of line, and the
 * surface they take by pointer then lives in a stack frame (local memory on GPUs, as ptxas shows
 * through tools/gpu_compile.py). */
#define WP_STAGE_FN static inline __attribute__((always_inline))

static inline float max3(float3 v) {
  return fmax(v.x, fmax(v.y, v.z));
}
static inline bool all_zero(float3 v) {
  return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f;
}

/* Always inlined: a float8 triple passed to a function kept out of line goes through memory. Not
 * where the host forces the packet kernels onto a device other than PoCL's CPU devices
 * (WP_PACKETS_FORCED, --force-packets: the Oclgrind tests), where speed does not matter:
 * Oclgrind cannot run what an always-inlined function returning a struct leaves behind
 * (stage.h). */
#if WP_PACKETS_FORCED
#define WP_LANES_FN static inline
#else
#define WP_LANES_FN static inline __attribute__((always_inline))
#endif
/* Out of line: a step of the packet called once per packet (shade_packet.h), whose float8 triples
 * go through memory once per eight paths. Inlined into the shade kernel with the rest, it made
 * the plain programs' PoCL build a quarter longer for no speed (docs/performance.md). */
#define WP_LANES_STEP static __attribute__((noinline))

/* Eight float4 as four float8 of their components, lane i from v[i] (shade, ray packets). */
WP_LANES_FN void transpose4x8(const float4* v, float8* x, float8* y, float8* z, float8* w) {
  const float8 a = (float8)(v[0], v[1]), b = (float8)(v[2], v[3]);
  const float8 c = (float8)(v[4], v[5]), d = (float8)(v[6], v[7]);
  *x = (float8)(shuffle2(a, b, (uint4)(0, 4, 8, 12)), shuffle2(c, d, (uint4)(0, 4, 8, 12)));
  *y = (float8)(shuffle2(a, b, (uint4)(1, 5, 9, 13)), shuffle2(c, d, (uint4)(1, 5, 9, 13)));
  *z = (float8)(shuffle2(a, b, (uint4)(2, 6, 10, 14)), shuffle2(c, d, (uint4)(2, 6, 10, 14)));
  *w = (float8)(shuffle2(a, b, (uint4)(3, 7, 11, 15)), shuffle2(c, d, (uint4)(3, 7, 11, 15)));
}

#if WP_SHADE_PACKET
/* Eight paths shaded at once (integrator/shade_packet.h), float8 lanes being paths. Each function
 * with a twin of eight lanes has it beside itself, written with the same expressions, so that the
 * twin rounds as it does lane by lane: the program is one translation unit in which traverse.h's
 * FP_CONTRACT OFF holds for all that follows it, so a header's fused multiply-adds depend on where
 * it is first included, and a twin in the same header shares them. */

typedef struct Float3x8 {
  float8 x, y, z;
} Float3x8;

WP_LANES_FN float lane_of(float8 v, int i) {
  float a[8];
  vstore8(v, 0, a);
  return a[i];
}
WP_LANES_FN bool lane_set(int8 mask, int i) {
  int a[8];
  vstore8(mask, 0, a);
  return a[i] != 0;
}
WP_LANES_FN float3 lane3(Float3x8 v, int i) {
  return (float3)(lane_of(v.x, i), lane_of(v.y, i), lane_of(v.z, i));
}
/* Element index[i] of array a in lane i, as three or four float8. */
WP_LANES_FN void gather4x8(__global const float4* a, const uint* index, float8* x, float8* y,
                           float8* z, float8* w) {
  float4 v[8];
#pragma unroll
  for (int i = 0; i < 8; ++i) v[i] = a[index[i]];
  transpose4x8(v, x, y, z, w);
}
WP_LANES_FN Float3x8 gather3x8(__global const float4* a, const uint* index) {
  Float3x8 r;
  float8 w;
  gather4x8(a, index, &r.x, &r.y, &r.z, &w);
  return r;
}

WP_LANES_FN Float3x8 load3x8(const float* x, const float* y, const float* z) {
  Float3x8 r = {vload8(0, x), vload8(0, y), vload8(0, z)};
  return r;
}
WP_LANES_FN Float3x8 neg3x8(Float3x8 a) {
  Float3x8 r = {-a.x, -a.y, -a.z};
  return r;
}
WP_LANES_FN Float3x8 sub3x8(Float3x8 a, Float3x8 b) {
  Float3x8 r = {a.x - b.x, a.y - b.y, a.z - b.z};
  return r;
}
WP_LANES_FN Float3x8 div3x8(Float3x8 a, float8 d) {
  Float3x8 r = {a.x / d, a.y / d, a.z / d};
  return r;
}
/* Lane by lane: b where take_b, else a. */
WP_LANES_FN Float3x8 select3x8(Float3x8 a, Float3x8 b, int8 take_b) {
  Float3x8 r = {select(a.x, b.x, take_b), select(a.y, b.y, take_b), select(a.z, b.z, take_b)};
  return r;
}
WP_LANES_FN float8 max3x8(Float3x8 a) {
  return fmax(a.x, fmax(a.y, a.z));
}
WP_LANES_FN int8 finite3x8(Float3x8 a) {
  return isfinite(a.x) & isfinite(a.y) & isfinite(a.z);
}

/* The builtins dot and cross: their products are not fused (checked against PoCL's). */
WP_LANES_FN float8 dot3x8(Float3x8 a, Float3x8 b) {
#pragma OPENCL FP_CONTRACT OFF
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
WP_LANES_FN Float3x8 cross3x8(Float3x8 a, Float3x8 b) {
#pragma OPENCL FP_CONTRACT OFF
  Float3x8 r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  return r;
}

/* The builtins length and normalize: sqrt(dot) and v * (1 / sqrt(dot)) where the squared length
 * is within (1e-30, 1e30), as checked against PoCL's; outside it they scale first, and the lanes
 * there take the builtin itself. */
WP_LANES_FN int8 plain_length(float8 dd) {
  return dd > 1e-30f && dd < 1e30f;
}
WP_LANES_FN float8 length3x8(Float3x8 a) {
  const float8 dd = dot3x8(a, a);
  float8 r = sqrt(dd);
  const int8 plain = plain_length(dd);
  if (!all8(plain)) {
    float l[8];
    vstore8(r, 0, l);
    for (int i = 0; i < 8; ++i)
      if (!lane_set(plain, i)) l[i] = length(lane3(a, i));
    r = vload8(0, l);
  }
  return r;
}
WP_LANES_FN Float3x8 normalize3x8(Float3x8 a) {
  const float8 dd = dot3x8(a, a);
  const float8 inv = 1.0f / sqrt(dd);
  Float3x8 r = {a.x * inv, a.y * inv, a.z * inv};
  const int8 plain = plain_length(dd);
  if (!all8(plain)) {
    float x[8], y[8], z[8];
    vstore8(r.x, 0, x), vstore8(r.y, 0, y), vstore8(r.z, 0, z);
    for (int i = 0; i < 8; ++i)
      if (!lane_set(plain, i)) {
        const float3 n = normalize(lane3(a, i));
        x[i] = n.x, y[i] = n.y, z[i] = n.z;
      }
    r = load3x8(x, y, z);
  }
  return r;
}
WP_LANES_FN Float3x8 add3x8(Float3x8 a, Float3x8 b) {
  Float3x8 r = {a.x + b.x, a.y + b.y, a.z + b.z};
  return r;
}
WP_LANES_FN Float3x8 mul3x8(Float3x8 a, Float3x8 b) {
  Float3x8 r = {a.x * b.x, a.y * b.y, a.z * b.z};
  return r;
}
WP_LANES_FN Float3x8 scale3x8(Float3x8 a, float8 k) {
  Float3x8 r = {a.x * k, a.y * k, a.z * k};
  return r;
}
/* The builtin mix, lane by lane and component by component. */
WP_LANES_FN Float3x8 mix3x8(Float3x8 a, Float3x8 b, float8 t) {
  Float3x8 r = {mix(a.x, b.x, t), mix(a.y, b.y, t), mix(a.z, b.z, t)};
  return r;
}
/* p[i] in each lane (lane code's gather, util/lanes_begin.def). */
WP_LANES_FN float8 gather_float8(__global const float* p, int8 i) {
  int k[8];
  float v[8];
  vstore8(i, 0, k);
#pragma unroll
  for (int j = 0; j < 8; ++j) v[j] = p[k[j]];
  return vload8(0, v);
}
/* p[i].xyz in each lane (gather3). */
WP_LANES_FN Float3x8 gather3_at8(__global const float4* p, int8 i) {
  int k[8];
  float4 v[8];
  vstore8(i, 0, k);
#pragma unroll
  for (int j = 0; j < 8; ++j) v[j] = p[k[j]];
  Float3x8 r;
  float8 w;
  transpose4x8(v, &r.x, &r.y, &r.z, &w);
  return r;
}
#endif

/* The arithmetic of Vec3 in one-path lane code (util/lanes_begin.def), as functions like the
 * eight-lane add3x8 ...: an operation that is a call at one width is a call at the other, so that
 * where FP_CONTRACT is on neither fuses a product across it into an addition. */
static inline float3 add3x1(float3 a, float3 b) {
  return a + b;
}
static inline float3 sub3x1(float3 a, float3 b) {
  return a - b;
}
static inline float3 mul3x1(float3 a, float3 b) {
  return a * b;
}
static inline float3 scale3x1(float3 a, float k) {
  return a * k;
}

/* luminance, sqr, pow5 and make_basis (lane code: util/lanes_begin.def). */
#define WP_LW 1
#include "util/arith.def"
#if WP_SHADE_PACKET
#define WP_LW 8
#include "util/arith.def"
#endif

/* A ray origin just off a surface point p, on the side of unit normal n, for rays that must not
 * hit the surface they leave. `scale` bounds the magnitudes that went into computing p and into
 * intersecting the surface again (the largest component of |b0 p0| + |b1 p1| + |b2 p2| for a point
 * interpolated from a triangle's vertices: pbrt's error-bound idea): float rounding in both is a
 * small multiple of 2^-24 scale, whatever the ray's angle, so moving the origin by 2^-16 scale
 * along n clears it with a wide margin, at any scene scale and distance from the origin. */
static inline float offset_distance(float scale) {
  return scale * (1.0f / 65536.0f);
}

static inline float3 offset_origin(float3 p, float3 n, float scale) {
  return p + n * offset_distance(scale);
}

#if WP_SHADE_PACKET
WP_LANES_FN float8 offset_distance8(float8 scale) {
  return scale * (1.0f / 65536.0f);
}
WP_LANES_FN Float3x8 offset_origin8(Float3x8 p, Float3x8 n, float8 scale) {
  Float3x8 r = {p.x + n.x * offset_distance8(scale), p.y + n.y * offset_distance8(scale),
                p.z + n.z * offset_distance8(scale)};
  return r;
}
#endif

#endif /* WP_COMMON_H */
