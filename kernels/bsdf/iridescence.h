/* KHR_materials_iridescence: the Fresnel term of a thin dielectric film on the glTF base (the
 * extension's README, ratified; its model is Belcour & Barla 2017, "A Practical Extension to
 * Microfacet Theory for the Modeling of Varying Iridescence").
 *
 * Three media: outside (ior n1, 1 in glTF), the film (n2 = iridescenceIor, thickness d in nm) and
 * the base, known by its normal-incidence reflectance against air F0 per channel (a dielectric:
 * ((ior - 1) / (ior + 1))^2, times the specular factor; a metal: its base colour), whose ior is
 * n3 = (1 + sqrt F0) / (1 - sqrt F0) per channel, as the README derives it (a metal's extinction
 * is taken as 0). Light meets the film at cosine c1 (v.h, on the outside); it refracts to c2
 * (Snell). The Airy sum of the waves bounced inside the film, expanded as a Fourier series in the
 * phase 2 pi OPD / lambda with OPD = 2 n2 d c2, is integrated over the spectrum in closed form
 * against Gaussian fits of the CIE 1931 colour matching functions, then taken to linear Rec.709:
 *
 *   F = R12 + Rs + sum_{m=1,2} 2 Cm S(m OPD, m phi),   Rs = T121^2 R23 / (1 - R12 R23),
 *   Cm = (Rs - T121) (R12 R23)^(m/2),  T121 = 1 - R12,  phi = phi21 + phi23 (0 or pi each)
 *
 * R12 (outside -> film) and R23 (film -> base) are the interfaces' reflectances, phi21 and phi23
 * the phase shifts of the reflections inside the film; S(OPD, shift) is the colour of
 * cos(2 pi OPD / lambda + shift) (iridescence_sensitivity). Where this differs from the README's
 * sample code (non-normative), it does so on purpose; the numbers are from
 * tests/test_iridescence.cpp (a float64 spectral reference: the exact Airy reflectance, s and p,
 * against the CIE 1931 functions over 380-780 nm; largest error over 0-1200 nm):
 *
 *  - R12 is the exact unpolarised Fresnel reflectance of the dielectric interface n1 -> n2, not
 *    Schlick's: Schlick's never vanishes at oblique angles ((1 - c)^5 even for n2 = n1), so a
 *    film of the outside's index was 0.48 off at 71-80 degrees (0.02 now), and it cannot tend
 *    to the base as n2 -> n1. On the dielectric bases the error is lower in every angle band,
 *    or within 0.003 (film 1.3 on ior 1.5 at 71-80 degrees: 0.099 -> 0.042); on the metal-like
 *    one, where the base's own Schlick term dominates, within 0.03 either way. R23 stays Schlick's
 * (at c2, F0 = ((n3 - n2) / (n3 + n2))^2), as in the README: with n2 = n1 = 1 the result is then
 * the base's own glTF Fresnel term, and refraction keeps c2 away from grazing in any real film.
 *  - S is normalised per channel to 1 at OPD 0 (a flat spectrum is neutral in every term). The
 *    sample code adds the DC term R12 + Rs as a neutral colour but takes the oscillating terms
 *    through the equal-energy XYZ -> Rec.709 matrix, whose white is (1.205, 0.948, 0.910): one
 *    spectrum's two halves are coloured differently. Film 2.3 on ior 1.5 at 0-45 degrees:
 *    0.063 -> 0.024.
 *  - No lower clamp of R12 R23 (the code's 1e-5 left a ripple of 0.006 on a film that does not
 *    reflect on top) and no "+ 0.0001" on F0: the film -> base reflectance is formed from
 *    s = sqrt(F0) without n3, ((1 + s) - n2 (1 - s)) / ((1 + s) + n2 (1 - s)), finite for F0 = 1.
 *  - Thickness 0 is no film: F fades to the bare base's Schlick term over the first
 *    WP_IRID_FADE_NM nanometres (smoothstep). The README's formula at d = 0 is not the base
 *    (films of 1.3-2.3 on the test's bases: up to 0.13 off at 79 degrees; 0.42 for a film of
 *    index 1), though a film of thickness 0 is not there.
 *  - Phases follow the README's text: 0 where the reflecting medium's ior is higher than the
 *    incident one, pi otherwise (the code gives 0 also for equal iors; there the interface
 *    reflects little or nothing and the phase hardly matters).
 *  - The result is clamped to [0, 1]; the README clamps below 0 only, and its code exceeds 1
 *    (1.0015 at 84 degrees). Unclamped, this series went down to -6e-4 (film 1.3 on ior 1.5,
 *    345 nm, normal incidence: a saturated colour whose exact value is itself -4e-4, outside
 *    the Rec.709 gamut).
 *
 * Total internal reflection in the film (n1 > n2 beyond the critical angle; not with glTF's
 * n1 = 1 and n2 >= 1) reflects everything: F = 1, as in the README. */
#ifndef WP_IRIDESCENCE_H
#define WP_IRIDESCENCE_H

#include "util/common.h"
#include "util/elementary.h"

/* A film thinner than this fades into the bare base (smoothstep from 0 nm, no film, to here): its
 * optical path 2 n2 d is then at most 40 nm for n2 <= 2, a tenth of the shortest visible
 * wavelength. */
#define WP_IRID_FADE_NM 10.0f

/* The colour of the spectral modulation cos(2 pi opd / lambda) (opd in nm): the CIE 1931
 * matching functions' Gaussian fits in wavenumber (the README's evalSensitivity, from Belcour &
 * Barla's code: amplitude val sqrt(2 pi var) / 1.0685e-7, centre pos, variance var), Fourier
 * transformed to a(j) cos(k(j) opd) exp(-g(j) opd^2) with k = 2 pi 1e-9 pos and
 * g = (2 pi 1e-9)^2 var, taken to linear Rec.709 (the sRGB matrix) and divided per channel by its
 * value at opd 0, (1.20536875, 0.948319498, 0.91000965): 1 at opd 0, a flat spectrum's colour.
 * The phase shifts are 0 or pi (multiples of pi for the higher orders), so a shift is a sign the
 * caller applies. */
static inline float3 iridescence_sensitivity(float opd) {
  const float o2 = opd * opd;
  const float3 k = (float3)(0.0105620345f, 0.0112802026f, 0.0138757864f) * opd;
  const float3 g = -(float3)(1.70854696e-7f, 3.67330884e-7f, 2.61035245e-7f) * o2;
  const float3 xyz = (float3)(0.846590002f, 1.00022189f, 1.00112249f) *
                     (float3)(cos_poly(k.x), cos_poly(k.y), cos_poly(k.z)) *
                     (float3)(exp_poly(g.x), exp_poly(g.y), exp_poly(g.z));
  const float x =
      xyz.x + 0.153868307f * cos_poly(0.0140737068f * opd) * exp_poly(-1.78766171e-7f * o2);
  return (float3)(2.68835092f * x - 1.27524336f * xyz.y - 0.413592437f * xyz.z,
                  -1.02208802f * x + 1.97824763f * xyz.y + 0.0438206745f * xyz.z,
                  0.061145945f * x - 0.224201908f * xyz.y + 1.16177361f * xyz.z);
}

static inline float3 iridescence_schlick(float3 f0, float c) {
  return f0 + (1.0f - f0) * pow5(1.0f - c);
}

/* The film's reflectance per linear Rec.709 channel, in [0, 1].
 *   outside_ior  n1 >= 1: 1 in glTF (the README ignores a clearcoat's interface)
 *   film_ior     n2 >= 1: iridescenceIor
 *   base_f0      the base's reflectance at normal incidence against air, per channel, in [0, 1]
 *   thickness_nm d >= 0, nanometres (iridescence_thickness_nm); d <= 0 is no film
 *   cos1         cosine of the incident direction to the (micro)normal, on the outside (v.h),
 *                clamped to [0, 1]
 * With d = 0 or n2 = n1 the film is not there: the result is the bare base's Schlick term,
 * base_f0 + (1 - base_f0) (1 - cos1)^5 for n1 = 1 (the glTF Fresnel term; to a rounding). */
static inline float3 iridescent_fresnel(float outside_ior, float film_ior, float3 base_f0,
                                        float thickness_nm, float cos1) {
  const float c1 = clamp(cos1, 0.0f, 1.0f);
  const float3 f0 = clamp(base_f0, 0.0f, 1.0f);
  const float3 s = sqrt(f0);
  /* The bare base: for n1 = 1 its F0 is base_f0 itself. */
  float3 f0_base = f0;
  if (outside_ior != 1.0f) {
    const float3 r13 =
        (1.0f + s - outside_ior * (1.0f - s)) / (1.0f + s + outside_ior * (1.0f - s));
    f0_base = r13 * r13;
  }
  const float3 bare = iridescence_schlick(f0_base, c1);
  const float fade = smoothstep(0.0f, WP_IRID_FADE_NM, thickness_nm);
  if (!(fade > 0.0f)) return bare;

  /* Refraction into the film: c2^2 = 1 - eta^2 (1 - c1^2), written so that eta = 1 gives c1 to
   * a rounding at any angle (1 - eta^2 (1 - c1^2) lost c2 ~ c1 near grazing to cancellation):
   * a film of the outside's index then reflects nothing (R12 ~ 1e-14). */
  const float eta = outside_ior / film_ior;
  const float cos2_sq = (1.0f - eta) * (1.0f + eta) + eta * eta * c1 * c1;
  if (cos2_sq < 0.0f) /* total internal reflection */
    return fade < 1.0f ? mix(bare, (float3)(1.0f), fade) : (float3)(1.0f);
  const float c2 = sqrt(cos2_sq);

  /* First interface: exact Fresnel, the mean of s and p (both denominators vanish only for
   * c1 = c2 = 0, which needs n1 = n2: no interface). */
  const float ds = outside_ior * c1 + film_ior * c2, dp = film_ior * c1 + outside_ior * c2;
  const float rs = ds > 0.0f ? (outside_ior * c1 - film_ior * c2) / ds : 0.0f;
  const float rp = dp > 0.0f ? (film_ior * c1 - outside_ior * c2) / dp : 0.0f;
  const float r12 = 0.5f * (rs * rs + rp * rp);
  const float t121 = 1.0f - r12;

  /* Second interface: Schlick at c2 with the film -> base F0 from the base's ior per channel. */
  const float3 num = 1.0f + s - film_ior * (1.0f - s);
  const float3 r1 = num / (1.0f + s + film_ior * (1.0f - s));
  const float3 r23 = iridescence_schlick(r1 * r1, c2);

  /* Phases: phi21 = pi - phi12 with phi12 = 0 where n2 > n1 (else pi); phi23 = 0 where
   * n3 > n2 (num > 0), else pi. cos(x + phi) = sign * cos(x), sign = cos(phi) = +-1; the
   * second order's shift 2 phi is a multiple of 2 pi. */
  const float sign21 = film_ior > outside_ior ? -1.0f : 1.0f;
  const float3 sign =
      sign21 * select((float3)(-1.0f), (float3)(1.0f), isgreater(num, (float3)(0.0f)));

  /* Beyond 1e6 nm every order's Gaussian factor is 0 in float; the bound keeps an infinite
   * thickness from making cos(inf) = NaN. */
  const float opd = fmin(2.0f * film_ior * thickness_nm * c2, 1e6f);
  const float3 r123_sq = fmin(r12 * r23, 0.9999f);
  const float3 r123 = sqrt(r123_sq);
  const float3 rs_sum = t121 * t121 * r23 / (1.0f - r123_sq);
  float3 cm = (rs_sum - t121) * r123;
  float3 f = r12 + rs_sum + 2.0f * cm * sign * iridescence_sensitivity(opd);
  cm *= r123;
  f += 2.0f * cm * iridescence_sensitivity(2.0f * opd);
  f = clamp(f, 0.0f, 1.0f);
  return fade < 1.0f ? mix(bare, f, fade) : f;
}

/* The film's thickness: iridescenceThicknessMinimum and ...Maximum (nm) mixed by the thickness
 * texture's green channel (linear; 1 without a texture, so the maximum). Minimum > maximum is
 * allowed. */
static inline float iridescence_thickness_nm(float minimum_nm, float maximum_nm, float texture_g) {
  return mix(minimum_nm, maximum_nm, texture_g);
}

/* The README's mixing for the two bases. `strength` is iridescenceFactor times the intensity
 * texture's red channel; cos1 is v.h (wo on the outside: inside a volume the film is not seen
 * this way, and the plain Fresnel term applies). They take the place of the plain Fresnel terms
 * of bsdf.h:
 *   dielectric (ior, specular factor s): F = mix(s * Schlick(f0, c), film(s * f0), strength),
 *     f0 = ((ior - 1) / (ior + 1))^2 (KHR_materials_specular's variant of the README, which is
 *     the plain one for s = 1), weighting the specular lobe by F (rgb) and the layer below
 *     (diffuse, transmission) by 1 - max(F) (iridescence_base_weight: the README's rgb_mix, so
 *     that no channel gains energy);
 *   metal (base colour): F = mix(Schlick(base colour, c), film(base colour), strength). */
static inline float3 iridescence_dielectric_fresnel(float strength, float film_ior,
                                                    float thickness_nm, float ior, float specular,
                                                    float cos1) {
  const float f0 = sqr((ior - 1.0f) / (ior + 1.0f));
  const float c = clamp(cos1, 0.0f, 1.0f);
  const float plain = specular * (f0 + (1.0f - f0) * pow5(1.0f - c));
  if (!(strength > 0.0f)) return (float3)(plain);
  const float3 film = iridescent_fresnel(1.0f, film_ior, (float3)(specular * f0), thickness_nm, c);
  return mix((float3)(plain), film, strength);
}

static inline float3 iridescence_metal_fresnel(float strength, float film_ior, float thickness_nm,
                                               float3 base_color, float cos1) {
  const float c = clamp(cos1, 0.0f, 1.0f);
  const float3 plain = iridescence_schlick(base_color, c);
  if (!(strength > 0.0f)) return plain;
  return mix(plain, iridescent_fresnel(1.0f, film_ior, base_color, thickness_nm, c), strength);
}

/* The weight of the dielectric's layer below the specular one (diffuse, transmission) under
 * the colour-valued Fresnel term f of iridescence_dielectric_fresnel. */
static inline float iridescence_base_weight(float3 f) {
  return 1.0f - max3(f);
}

#endif /* WP_IRIDESCENCE_H */
