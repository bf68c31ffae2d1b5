/* Elementary functions without the library's calls. PoCL compiles OpenCL's transcendental
 * builtins (exp, log, pow, cbrt, atan2, cos, ...) into calls to out-of-line routines (with argument
 * reductions for any input and special-case handling), and with them in the shading kernel a
 * render spent 12-20% of its time in those calls (docs/performance.md, "Environment lookups without
 * library calls", "Sheen without library calls"). No kernel calls them now
 * (tests/test_kernel_tree.cpp, KernelSources.NoTranscendentalLibraryCalls); these are inlined
 * polynomials for the arguments the kernels pass, each with its error bound, checked against double
 * precision by tests/test_sampling.cpp (Elementary.*, Sampling.Atan2Poly, Sampling.CosSinTurn;
 * u = 2^-24, float's unit roundoff, is half an ulp relative):
 *
 *   exp_poly(x)      e^x, within 3 u where it is a normal float (subnormal results round once
 *                    more, as the library's may), 0 below x = -103.97, +inf from 88.73 on, NaN
 *                    for NaN
 *   log_poly(x)      ln x, within 4 u; -inf at 0, +inf at +inf, NaN below 0 and for NaN
 *   log1p_poly(y)    ln(1 + y) for -1/2 < y < 1/2, within 4 u (the kernels' sheen takes it on
 *                    (-1/2, 0]); log_poly(1 + y) elsewhere
 *   powr_poly(x, c)  x^c for x >= 0 as e^(c ln x): within (3 + 5 |c ln x|) u, 0 at x = 0 for c > 0
 *   cbrt_poly(x)     the cube root for x >= 0, as e^(ln(x) / 3): within (3 + 6 |ln x| / 3) u
 *   log2_poly(x)     log2 x, as log_poly(x) / ln 2, within 5 u
 *   cos_sin_turn(u)  (cos 2 pi u, sin 2 pi u) for u in [0, 1], within 4e-7 absolute
 *   cos_poly(x)      cos x for finite x, within 4e-7 + 1.2e-7 |x| absolute
 *   atan2_poly(y, x) atan2, within 4.8e-7 absolute
 *
 * The ranges of exp and log are reduced with Cody and Waite's split of ln 2: ln2_hi has 15
 * significant bits, so n ln2_hi is exact for |n| < 512 and x - n ln2_hi exact where it is small
 * (Sterbenz); ln2_lo = ln 2 - ln2_hi. */
#ifndef WP_ELEMENTARY_H
#define WP_ELEMENTARY_H

#include "common.h"

#define WP_LN2_HI 0.693145751953125f
#define WP_LN2_LO 1.428606765330187e-06f
#define WP_LOG2_E 1.44269504f /* 1 / ln 2 */

/* e^x = 2^n e^r with n the integer nearest x / ln 2 and |r| <= ln 2 / 2 (a little more where the
 * product rounds), e^r by its Taylor polynomial to r^7 (remainder below 1.1e-8 relative), 2^n as
 * two powers of two, each a normal float for n from -150 to 128, so that no exponent field
 * overflows and a subnormal result is rounded once, by the last product. */
static inline float exp_poly(float x) {
  if (!(x < 88.7228317f)) return x != x ? x : INFINITY; /* ln FLT_MAX = 88.72284 */
  if (x < -103.972084f) return 0.0f;                    /* ln 2^-150: below half the least */
  const float n = floor(x * WP_LOG2_E + 0.5f);
  const float r = (x - n * WP_LN2_HI) - n * WP_LN2_LO;
  const float p =
      1.0f + r * (1.0f + r * (0.5f + r * (1.0f / 6.0f +
                                          r * (1.0f / 24.0f +
                                               r * (1.0f / 120.0f +
                                                    r * (1.0f / 720.0f + r * (1.0f / 5040.0f)))))));
  const int k = (int)n, k1 = k / 2;
  return p * as_float((k1 + 127) << 23) * as_float((k - k1 + 127) << 23);
}

/* ln x = e ln 2 + ln m with x = m 2^e, m in [sqrt(1/2), sqrt(2)]; ln m = 2 atanh(s), s = (m - 1) /
 * (m + 1) in [-0.172, 0.172], by its series to s^11 (remainder below 3e-11 relative); m - 1 is
 * exact. Subnormal x is scaled by 2^24 first. */
static inline float log_poly(float x) {
  if (!(x > 0.0f)) return x == 0.0f ? -INFINITY : NAN;
  if (x == INFINITY) return x;
  int e = 0;
  if (x < FLT_MIN) x *= 16777216.0f, e = -24;
  const uint b = as_uint(x);
  e += (int)(b >> 23) - 127;
  float m = as_float((b & 0x007fffffu) | 0x3f800000u); /* [1, 2) */
  if (m > 1.41421354f) m *= 0.5f, ++e;
  const float f = m - 1.0f;
  const float s = f / (2.0f + f), z = s * s;
  const float q =
      z * (1.0f / 3.0f +
           z * (1.0f / 5.0f + z * (1.0f / 7.0f + z * (1.0f / 9.0f + z * (1.0f / 11.0f)))));
  const float ln_m = 2.0f * s + 2.0f * s * q;
  const float fe = (float)e;
  return fe * WP_LN2_HI + (fe * WP_LN2_LO + ln_m);
}

/* ln(1 + y): for |y| < 1/2 as 2 atanh(s), s = y / (2 + y) in (-1/3, 1/5), by its series to s^17
 * (remainder below 1e-10 relative), which keeps y's relative precision where 1 + y would round it
 * away; elsewhere log_poly(1 + y). */
static inline float log1p_poly(float y) {
  if (!(fabs(y) < 0.5f)) return log_poly(1.0f + y);
  const float s = y / (2.0f + y), z = s * s;
  const float q =
      z * (1.0f / 3.0f +
           z * (1.0f / 5.0f +
                z * (1.0f / 7.0f +
                     z * (1.0f / 9.0f +
                          z * (1.0f / 11.0f +
                               z * (1.0f / 13.0f + z * (1.0f / 15.0f + z * (1.0f / 17.0f))))))));
  return 2.0f * s + 2.0f * s * q;
}

/* x^c for x >= 0 (OpenCL's powr). */
static inline float powr_poly(float x, float c) {
  return exp_poly(c * log_poly(x));
}

/* The cube root of x >= 0. */
static inline float cbrt_poly(float x) {
  return exp_poly(log_poly(x) * (1.0f / 3.0f));
}

/* log2 x, as log_poly(x) / ln 2: within 5 u (log_poly's 4 u and the product's u). */
static inline float log2_poly(float x) {
  return log_poly(x) * WP_LOG2_E;
}

/* cos_sin_quarter and cos_sin_turn (lane code: util/lanes_begin.def). */
#define WP_LW 1
#include "util/cos_sin.def"
#if WP_SHADE_PACKET
#define WP_LW 8
#include "util/cos_sin.def"
#endif

/* cos x for finite x: x in turns less its whole turns (exact), then cos_sin_turn. The turns are off
 * by 2 u of themselves (the float 1 / (2 pi) and the product), 2 u |x| in the angle, so the error
 * grows with |x|: within 4e-7 + 1.2e-7 |x|. */
static inline float cos_poly(float x) {
  const float t = x * (0.5f * WP_INV_PI);
  float c, s;
  cos_sin_turn(t - floor(t), &c, &s);
  return c;
}

/* atan2(y, x) in [-pi, pi] (an environment map's lookup at every escaped ray took 12% of a render
 * of an environment-lit model in PoCL's atan2). The angle of the smaller coordinate over the
 * larger, a = min(|x|, |y|) / max(|x|, |y|) in [0, 1], from a P(a^2), P of degree 8 fitted to atan
 * on [0, 1] (tools/generators/gen_atan_poly.py: 5.8e-9 at worst, 1.1e-7 with float coefficients and
 * Horner in float), moved to its octant: pi/2 - r where |y| > |x|, pi - r where x's sign bit is set
 * (x = -0 too, as IEEE's atan2), then the sign of y. (0, 0) gives 0 or pi with y's sign; x and y
 * finite. */
static inline float atan2_poly(float y, float x) {
  const float ax = fabs(x), ay = fabs(y);
  const bool steep = ay > ax;
  const float hi = steep ? ay : ax, lo = steep ? ax : ay;
  const float a = hi > 0.0f ? lo / hi : 0.0f;
  const float s = a * a;
  const float p = 9.999998808e-01f +
                  s * (-3.333259821e-01f +
                       s * (1.998590678e-01f +
                            s * (-1.416122913e-01f +
                                 s * (1.049894616e-01f +
                                      s * (-7.234857976e-02f +
                                           s * (3.978122771e-02f + s * (-1.440135855e-02f +
                                                                        s * 2.456724877e-03f)))))));
  float r = a * p;
  r = steep ? 0.5f * WP_PI - r : r;
  r = signbit(x) ? WP_PI - r : r;
  return copysign(r, y);
}

#endif /* WP_ELEMENTARY_H */
