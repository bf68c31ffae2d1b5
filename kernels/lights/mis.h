/* Multiple importance sampling of direct light (the second level; the first is the choice of a
 * light, lights.h). Two strategies can produce the same light path: NEE (a light sample, pdf
 * p_light in solid angle, the light-choice probability included) and BSDF sampling (pdf p_bsdf).
 * Each contribution is weighted by w = h(p_own, p_other), with h the balance heuristic
 * p / (p + q) or the power heuristic p^2 / (p^2 + q^2). A delta light or a delta lobe can only be
 * found by one strategy: its weight is 1 (callers pass q = 0).
 *
 * The strategy (WP_STRATEGY_*, Launch.strategy) selects what is counted: MIS (both, weighted),
 * NEE (light samples with weight 1;
 * emission found by BSDF sampling only where NEE cannot reach it: after a delta lobe or from the
 * camera) or BSDF (no NEE; all emission found by BSDF sampling, weight 1; punctual lights then
 * contribute nothing, which is the expected answer for that strategy). */
#ifndef WP_MIS_H
#define WP_MIS_H

#include "util/common.h"

/* Written with the ratio r = p_other / p_own: p^2 / (p^2 + q^2) overflows to inf / inf = NaN for
 * pdfs above ~1.8e19 (a near-delta lobe or a tiny light seen edge-on reaches that), while
 * 1 / (1 + r^2) only ever rounds to 1 or 0. */
static inline float mis_weight(float p_own, float p_other) {
  if (!(p_other > 0.0f)) return 1.0f;
  if (isinf(p_own)) return isinf(p_other) ? 0.5f : 1.0f;
  const float r = p_other / p_own;
#if WP_MIS_POWER
  return 1.0f / (1.0f + r * r);
#else
  return 1.0f / (1.0f + r);
#endif
}

/* Weight of emission that a BSDF-sampled ray found, given the pdf of that sample (0 after a
 * delta lobe or for a camera ray) and the pdf with which NEE would have produced it. */
static inline float mis_weight_bsdf_hit(float p_bsdf, float p_light, uint strategy) {
  if (strategy == WP_STRATEGY_BSDF || !(p_bsdf > 0.0f)) return 1.0f;
  return strategy == WP_STRATEGY_MIS ? mis_weight(p_bsdf, p_light) : 0.0f;
}

/* Weight of a light sample with pdf p_light (0 < p_light; `delta` for a delta light) against the
 * BSDF's pdf p_bsdf of the same direction (only MIS weighs; NEE counts it whole, BSDF takes
 * none). */
static inline float mis_weight_light(float p_light, float p_bsdf, bool delta, uint strategy) {
  return strategy == WP_STRATEGY_MIS && !delta ? mis_weight(p_light, p_bsdf) : 1.0f;
}

#if WP_SHADE_PACKET
/* mis_weight_light of eight lanes (common.h) for lights that are not delta lights. */
WP_LANES_FN float8 mis_weight_light8(float8 p_light, float8 p_bsdf, uint strategy) {
  if (strategy != WP_STRATEGY_MIS) return (float8)(1.0f);
  const float8 r = p_bsdf / p_light;
#if WP_MIS_POWER
  const float8 w = 1.0f / (1.0f + r * r);
#else
  const float8 w = 1.0f / (1.0f + r);
#endif
  const float8 inf_own = select((float8)(1.0f), (float8)(0.5f), isinf(p_bsdf));
  return select(select(w, inf_own, isinf(p_light)), (float8)(1.0f), !(p_bsdf > 0.0f));
}
#endif

#endif /* WP_MIS_H */
