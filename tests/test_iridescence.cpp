// KHR_materials_iridescence's thin-film Fresnel term (kernels/bsdf/iridescence.h) on the device,
// against a float64 reference computed here from physics, not from the model: the exact spectral
// reflectance of the film and its limits.
//
// The reference: a film of index n2 and thickness d between the outside (n1 = 1) and a base of
// index n3 (from F0: n3 = (1 + sqrt F0) / (1 - sqrt F0), per channel, as the extension derives
// it; a metal's extinction taken as 0). Its amplitude reflectance for one polarisation is Airy's
// sum of the waves bounced inside the film (Born & Wolf, Principles of Optics, 7.6.1):
//   r = (r12 + r23 z) / (1 + r12 r23 z),  z = exp(i delta),
//   delta = 2 pi 2 n2 d cos(theta2) / lambda,
// with the exact Fresnel amplitudes r_s = (na ca - nb cb) / (na ca + nb cb) and
// r_p = (nb ca - na cb) / (nb ca + na cb) of each interface (real: with n1 = 1 <= n2, n3 there
// is no total internal reflection), so that
//   R = (a^2 + b^2 + 2 a b cos delta) / (1 + a^2 b^2 + 2 a b cos delta),
// averaged over s and p (unpolarised light). It is integrated over 380-780 nm (trapezoid, 1 nm)
// against the CIE 1931 2-degree colour matching functions, in the multi-lobe piecewise-Gaussian
// fit of Wyman, Sloan & Shirley 2013 ("Simple Analytic Approximations to the CIE XYZ Color
// Matching Functions", JCGT 2(2), eq. 2), taken to linear Rec.709 with the sRGB matrix
// (IEC 61966-2-1) and normalised per channel so that a constant reflectance R gives (R, R, R),
// as the device's model does. The reference checks itself: at d = 0 it is the bare interface's
// Fresnel reflectance, and halving the wavelength step changes it by 1.3e-7 (bound: 1e-5).
//
// Tolerance. The model (iridescence.h's header) is an approximation: a Schlick base, phase
// shifts of 0 or pi, two Fourier orders, Gaussian fits of the matching functions in wavenumber.
// Its error against the reference was measured over thickness 0-1200 nm (5 nm steps), film
// indices 1.0, 1.3, 1.8, 2.3, bases of index 1.5 and 2.0 and the metal-like F0 (0.9, 0.6, 0.3),
// angles 0-89 degrees (1 degree steps); kRegimes below holds, per base kind and angle band, the
// largest measured maximum and mean (over thickness and angles, of the largest channel's
// absolute difference, for any one film), and the bounds set from them. Most of the error at
// oblique angles is Schlick's base term against the exact Fresnel reflectance of an index-n3
// dielectric (the metal-like base, whose real n3 of 3.4-38 has a Brewster dip that Schlick's
// curve lacks, differs by up to 0.48 with no film at all), so the bounds widen with the angle;
// below 45 degrees they are a few hundredths. A wrong model changes colours by far more; each of
// these fails the test, with the largest maximum and mean at 0-45 degrees (bounds 0.03 / 0.014
// dielectric, 0.06 / 0.021 metal-like), measured on a mutated copy of iridescence.h:
//   phase shift's sign flipped             0.56 / 0.18  (metal-like, film 2.3)
//   factor 2 of the Fourier orders dropped 0.18 / 0.046
//   cos(theta1) for cos(theta2) in the OPD 0.56 / 0.081
//   the film's index left out of the OPD   0.54 / 0.21
//   the second order left out              0.090 / 0.024
// (and the README's Schlick R12 fails on a film of index 1: 0.28 at 46-70 degrees, bound 0.15).
// Rounding in float32 is ~1e-6.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "tests/kernel_harness.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
// float32 evaluation: a few dozen roundings of relative size 6e-8 on values of order 1.
constexpr double kFloatRounding = 1e-6;

using Rgb = std::array<double, 3>;

// ---------------------------------------------------------------------------------------------
// The spectral reference.

// Wyman, Sloan & Shirley 2013, eq. 2: a lobe alpha * exp(-(l - mu)^2 / (2 sigma^2)), sigma1
// below mu and sigma2 above it.
double lobe(double l, double alpha, double mu, double sigma1, double sigma2) {
  const double t = (l - mu) / (l < mu ? sigma1 : sigma2);
  return alpha * std::exp(-0.5 * t * t);
}
std::array<double, 3> cie1931(double l) {
  return {lobe(l, 1.056, 599.8, 37.9, 31.0) + lobe(l, 0.362, 442.0, 16.0, 26.7) +
              lobe(l, -0.065, 501.1, 20.4, 26.2),
          lobe(l, 0.821, 568.8, 46.9, 40.5) + lobe(l, 0.286, 530.9, 16.3, 31.1),
          lobe(l, 1.217, 437.0, 11.8, 36.0) + lobe(l, 0.681, 459.0, 26.0, 13.8)};
}
// XYZ -> linear sRGB / Rec.709 (IEC 61966-2-1).
constexpr double kXyzToRgb[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                    {-0.9692660, 1.8760108, 0.0415560},
                                    {0.0556434, -0.2040259, 1.0572252}};

// Per wavelength: 1 / lambda and each channel's normalised quadrature weight.
struct Spectrum {
  std::vector<double> inv_lambda;
  std::vector<Rgb> weight;
};

Spectrum make_spectrum(double step_nm) {
  Spectrum s;
  const int n = int(std::lround(400.0 / step_nm));
  Rgb total = {0, 0, 0};
  for (int i = 0; i <= n; ++i) {
    const double l = 380.0 + i * step_nm, h = (i == 0 || i == n) ? 0.5 * step_nm : step_nm;
    const auto xyz = cie1931(l);
    Rgb w;
    for (int c = 0; c < 3; ++c) {
      w[c] = h * (kXyzToRgb[c][0] * xyz[0] + kXyzToRgb[c][1] * xyz[1] + kXyzToRgb[c][2] * xyz[2]);
      total[c] += w[c];
    }
    s.inv_lambda.push_back(1.0 / l);
    s.weight.push_back(w);
  }
  for (Rgb& w : s.weight)
    for (int c = 0; c < 3; ++c) w[c] /= total[c];
  return s;
}

double base_index(double f0) {
  const double s = std::sqrt(f0);
  return (1.0 + s) / (1.0 - s);
}

// Exact amplitudes (s, p) of the interface na -> nb, ca and cb the cosines on either side.
struct Amplitudes {
  double s, p;
};
Amplitudes fresnel_amplitudes(double na, double nb, double ca, double cb) {
  return {(na * ca - nb * cb) / (na * ca + nb * cb), (nb * ca - na * cb) / (nb * ca + na * cb)};
}
double refracted_cos(double n1, double n, double c1) {
  const double s2 = (n1 / n) * (n1 / n) * (1.0 - c1 * c1);
  return std::sqrt(1.0 - s2);
}

// A film n2 on the base F0 (per channel), seen from n1 = 1 at cosine c1: the RGB reflectance for
// the thicknesses 0, step, ..., (count - 1) step (nm). cos(delta) over the thicknesses comes from
// the recurrence cos((j + 1) t) = 2 cos(t) cos(j t) - cos((j - 1) t) (its rounding grows
// ~ j 1e-16 / sin t: below 1e-10 here).
std::vector<Rgb> exact_film(const Spectrum& sp, double n2, const Rgb& f0, double c1, double step,
                            int count) {
  const double n1 = 1.0;
  const double c2 = refracted_cos(n1, n2, c1);
  const Amplitudes r12 = fresnel_amplitudes(n1, n2, c1, c2);
  Amplitudes r23[3];
  for (int c = 0; c < 3; ++c) {
    const double n3 = base_index(f0[c]);
    r23[c] = fresnel_amplitudes(n2, n3, c2, refracted_cos(n1, n3, c1));
  }
  std::vector<Rgb> out(std::size_t(count), Rgb{0, 0, 0});
  for (std::size_t i = 0; i < sp.inv_lambda.size(); ++i) {
    const double t = 2.0 * kPi * 2.0 * n2 * step * c2 * sp.inv_lambda[i];  // delta per step
    const double ct = std::cos(t);
    double cd = 1.0, cd_prev = ct;  // cos(0 t), cos(-1 t)
    for (int j = 0; j < count; ++j) {
      double r = 0.0;
      for (int c = 0; c < 3; ++c) {
        if (c == 0 || f0[c] != f0[c - 1]) {  // the same base as the last channel: the same r
          r = 0.0;
          for (int pol = 0; pol < 2; ++pol) {
            const double a = pol ? r12.p : r12.s, b = pol ? r23[c].p : r23[c].s;
            const double ab2 = 2.0 * a * b * cd;
            r += 0.5 * (a * a + b * b + ab2) / (1.0 + a * a * b * b + ab2);
          }
        }
        out[std::size_t(j)][c] += sp.weight[i][c] * r;
      }
      const double next = 2.0 * ct * cd - cd_prev;
      cd_prev = cd;
      cd = next;
    }
  }
  return out;
}

// The unpolarised Fresnel reflectance of the bare interface 1 -> n3.
double exact_bare(double n3, double c1) {
  const Amplitudes r = fresnel_amplitudes(1.0, n3, c1, refracted_cos(1.0, n3, c1));
  return 0.5 * (r.s * r.s + r.p * r.p);
}

double schlick(double f0, double c) {
  return f0 + (1.0 - f0) * std::pow(1.0 - c, 5.0);
}

double f0_of_ior(double ior) {
  return std::pow((ior - 1.0) / (ior + 1.0), 2.0);
}

// ---------------------------------------------------------------------------------------------
// The device.

struct Query {
  float outside, film, thickness, cos1;
  Rgb f0;
};

class Iridescence : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { h_ = new wp::test::KernelHarness({"iridescence_kernels.cl"}); }
  static void TearDownTestSuite() {
    delete h_;
    h_ = nullptr;
  }

  // iridescent_fresnel at each query; a NaN or Inf component fails the test.
  static std::vector<Rgb> film(const std::vector<Query>& q) {
    std::vector<cl_float4> args, f0;
    for (const Query& x : q) {
      args.push_back({{x.outside, x.film, x.thickness, x.cos1}});
      f0.push_back({{float(x.f0[0]), float(x.f0[1]), float(x.f0[2]), 0.0f}});
    }
    cl::Buffer a = h_->buffer(args), b = h_->buffer(f0), out = h_->buffer<cl_float4>(q.size());
    h_->run("film", q.size(), a, b, std::uint32_t(q.size()), out);
    const auto v = h_->read<cl_float4>(out, q.size());
    std::vector<Rgb> r;
    for (std::size_t i = 0; i < v.size(); ++i) {
      EXPECT_EQ(v[i].s[3], 0.0f) << "NaN or Inf at outside " << q[i].outside << " film "
                                 << q[i].film << " d " << q[i].thickness << " cos " << q[i].cos1;
      r.push_back({v[i].s[0], v[i].s[1], v[i].s[2]});
    }
    return r;
  }

  static wp::test::KernelHarness* h_;
};
wp::test::KernelHarness* Iridescence::h_ = nullptr;

double max_abs_diff(const Rgb& a, const Rgb& b) {
  return std::max({std::fabs(a[0] - b[0]), std::fabs(a[1] - b[1]), std::fabs(a[2] - b[2])});
}

// ---------------------------------------------------------------------------------------------
// The reference against itself.

TEST(IridescenceReference, ThicknessZeroIsTheBareInterface) {
  // Airy's sum at delta = 0 is (r12 + r23) / (1 + r12 r23) = r13 for s and p (Stokes): the film
  // is not there. A constant spectrum integrates to itself.
  const Spectrum sp = make_spectrum(1.0);
  for (double n2 : {1.0, 1.3, 1.8, 2.3})
    for (double f0 : {0.04, 0.3, 0.9})
      for (double deg : {0.0, 30.0, 60.0, 85.0, 89.0}) {
        const double c1 = std::cos(deg * kPi / 180.0);
        const Rgb r = exact_film(sp, n2, {f0, f0, f0}, c1, 1.0, 1)[0];
        const double bare = exact_bare(base_index(f0), c1);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(r[c], bare, 1e-12) << n2 << " " << f0 << " " << deg;
      }
}

TEST(IridescenceReference, WavelengthStepConverged) {
  // Spectra up to the most oscillatory (the thickest film of the highest index, at normal
  // incidence) with 1 nm and 0.5 nm steps.
  const Spectrum coarse = make_spectrum(1.0), fine = make_spectrum(0.5);
  double worst = 0.0;
  for (double n2 : {1.3, 2.3})
    for (double deg : {0.0, 60.0}) {
      const double c1 = std::cos(deg * kPi / 180.0);
      const auto a = exact_film(coarse, n2, {0.9, 0.6, 0.3}, c1, 100.0, 13);  // 0-1200 nm
      const auto b = exact_film(fine, n2, {0.9, 0.6, 0.3}, c1, 100.0, 13);
      for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, max_abs_diff(a[i], b[i]));
    }
  std::printf("reference: 1 nm against 0.5 nm steps: largest difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-5);
}

// ---------------------------------------------------------------------------------------------
// Accuracy against the spectral reference.

struct Regime {
  const char* base;  // "dielectric" (index 1.5 and 2.0) or "metal-like"
  double max_degrees;
  double measured_max, measured_mean;  // the largest over the films (see the header comment)
  double bound_max, bound_mean;
};

// Angle bands: (previous band's max, max_degrees]. The bounds are the measured numbers with
// about a quarter more, rounded up. Nothing here is random, so the margin is not for noise: it is
// far above the differences between OpenCL implementations' cos and exp (~1e-6), and keeps the
// bounds from being fitted to one device's last digits.
constexpr Regime kRegimes[] = {
    {"dielectric", 45, 0.0238, 0.0109, 0.030, 0.014},
    {"dielectric", 70, 0.1139, 0.0236, 0.15, 0.030},
    {"dielectric", 80, 0.1870, 0.0604, 0.24, 0.076},
    {"dielectric", 89, 0.1940, 0.0638, 0.25, 0.080},
    {"metal-like", 45, 0.0478, 0.0167, 0.060, 0.021},
    {"metal-like", 70, 0.2024, 0.0584, 0.26, 0.073},
    {"metal-like", 80, 0.3781, 0.2042, 0.48, 0.26},
    {"metal-like", 89, 0.4758, 0.3799, 0.60, 0.48},
};

TEST_F(Iridescence, MatchesTheExactSpectralReflectance) {
  const Spectrum sp = make_spectrum(1.0);
  struct Base {
    const char* kind;
    const char* name;
    Rgb f0;
  };
  const Base bases[] = {{"dielectric", "ior 1.5", {0.04, 0.04, 0.04}},
                        {"dielectric", "ior 2.0", {1.0 / 9.0, 1.0 / 9.0, 1.0 / 9.0}},
                        {"metal-like", "F0 .9 .6 .3", {0.9, 0.6, 0.3}}};
  const double films[] = {1.0, 1.3, 1.8, 2.3};
  const double step = 5.0;
  const int count = 241;  // 0-1200 nm
  std::vector<int> degrees;
  for (int a = 0; a <= 89; ++a) degrees.push_back(a);

  // Device queries and reference values, in one order.
  std::vector<Query> q;
  std::vector<Rgb> ref;
  for (const Base& b : bases)
    for (double n2 : films)
      for (int deg : degrees) {
        const float c1 = float(std::cos(deg * kPi / 180.0));
        const auto r = exact_film(sp, n2, b.f0, c1, step, count);
        for (int i = 0; i < count; ++i) {
          q.push_back({1.0f, float(n2), float(i * step), c1, b.f0});
          ref.push_back(r[i]);
        }
      }
  const auto dev = film(q);

  // The reference itself leaves [0, 1] where the spectrum's colour is outside the Rec.709 gamut
  // (slightly); the device's values never do.
  std::size_t outside = 0;
  double lowest = 0.0, highest = 1.0;
  for (std::size_t i = 0; i < ref.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      outside += ref[i][c] < 0.0 || ref[i][c] > 1.0;
      lowest = std::min(lowest, ref[i][c]);
      highest = std::max(highest, ref[i][c]);
      ASSERT_TRUE(dev[i][c] >= 0.0 && dev[i][c] <= 1.0)
          << dev[i][c] << " at film " << q[i].film << " F0 " << q[i].f0[c] << " d "
          << q[i].thickness << " cos " << q[i].cos1;
    }
  std::printf("reference values outside [0, 1]: %zu of %zu, in [%.4f, %.4f]\n", outside,
              3 * ref.size(), lowest, highest);

  // Per base, film and band: the largest and the mean difference.
  std::size_t k = 0;
  std::printf("%-12s %-5s %-7s %9s %9s\n", "base", "film", "degrees", "max", "mean");
  for (const Base& b : bases)
    for (double n2 : films) {
      struct Acc {
        double max = 0, sum = 0;
        std::size_t n = 0;
      } acc[4];
      for (int deg : degrees)
        for (int i = 0; i < count; ++i, ++k) {
          const double e = max_abs_diff(dev[k], ref[k]);
          int band = 0;
          while (deg > kRegimes[band].max_degrees) ++band;
          acc[band].max = std::max(acc[band].max, e);
          acc[band].sum += e;
          acc[band].n++;
        }
      for (int band = 0; band < 4; ++band) {
        const Regime& reg = kRegimes[(b.kind[0] == 'm' ? 4 : 0) + band];
        const double mean = acc[band].sum / double(acc[band].n);
        const int lo = band == 0 ? 0 : int(kRegimes[band - 1].max_degrees) + 1;
        std::printf("%-12s %-5.1f %2d-%-4d %9.4f %9.4f\n", b.name, n2, lo, int(reg.max_degrees),
                    acc[band].max, mean);
        EXPECT_LE(acc[band].max, reg.bound_max)
            << b.name << " film " << n2 << " at " << lo << "-" << reg.max_degrees << " degrees";
        EXPECT_LE(mean, reg.bound_mean)
            << b.name << " film " << n2 << " at " << lo << "-" << reg.max_degrees << " degrees";
      }
    }
}

// ---------------------------------------------------------------------------------------------
// Limits.

// The bases of the limit tests: F0 per channel (0 and 1 included).
const Rgb kLimitBases[] = {{0.04, 0.04, 0.04}, {0.9, 0.6, 0.3}, {0.0, 1e-6, 1.0}, {1.0, 0.5, 0.0}};

double degrees_cos(double deg) {
  return double(float(std::cos(deg * kPi / 180.0)));
}

TEST_F(Iridescence, ThicknessZeroIsTheBaseFresnel) {
  // No film: the glTF Fresnel term of the base, F0 + (1 - F0) (1 - c)^5, within float rounding,
  // at every angle to grazing (and a negative thickness is none either).
  std::vector<Query> q;
  for (const Rgb& f0 : kLimitBases)
    for (float n2 : {1.0f, 1.3f, 1.8f, 2.3f, 3.0f})
      for (float d : {0.0f, -5.0f})
        for (int deg = 0; deg <= 90; ++deg) q.push_back({1.0f, n2, d, float(degrees_cos(deg)), f0});
  const auto f = film(q);
  double worst = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double e = std::fabs(f[i][c] - schlick(q[i].f0[c], q[i].cos1));
      worst = std::max(worst, e);
      ASSERT_LE(e, kFloatRounding) << "film " << q[i].film << " cos " << q[i].cos1;
    }
  std::printf("thickness 0: largest difference from the base's Schlick term %.2e\n", worst);
}

TEST_F(Iridescence, ThinFilmFadesContinuouslyIntoTheBase) {
  // Over the first WP_IRID_FADE_NM = 10 nm the film fades in: nothing at 0, continuous (the
  // largest step between thicknesses 0.01 nm apart is small), the whole film from 10 nm on.
  std::vector<Query> q;
  for (const Rgb& f0 : kLimitBases)
    for (float n2 : {1.3f, 2.3f})
      for (int deg : {0, 60, 85})
        for (int k = 0; k <= 1500; ++k)
          q.push_back({1.0f, n2, 0.01f * float(k), float(degrees_cos(deg)), f0});
  const auto f = film(q);
  double step = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i)
    if (q[i].thickness > 0.0f) step = std::max(step, max_abs_diff(f[i], f[i - 1]));
  std::printf("fade: largest change over 0.01 nm %.2e\n", step);
  // A bound on the change over 0.01 nm without a jump: the optical path moves by at most
  // 2 n2 0.01 nm = 0.046 nm, S's phase by at most 0.0141 rad per nm of it (the fastest lobe;
  // twice the path for the second order) and |S| <= 1.48, so the orders' 2 Cm S (|Cm| <= 1) by
  // at most 2 (1.48 0.0141) (0.046 + 0.092) = 5.8e-3; the fade adds smoothstep's slope (1.5 per
  // 10 nm) times 0.01 nm times |film - base| <= 1: 1.5e-3. Without the fade the step at 0 nm
  // would be the formula's difference from the base there, up to 0.09.
  EXPECT_LT(step, 7.3e-3);
}

TEST_F(Iridescence, FilmOfTheOutsideIndexIsTheBase) {
  // n2 = n1: no interface on top, and the film is not there at any thickness (the base's
  // Schlick term); as n2 -> n1 the result tends to it continuously, the change ~ (n2 - n1).
  const float films[] = {1.0f, 1.0001f, 1.001f, 1.01f};
  double worst[4] = {0, 0, 0, 0};
  for (int fi = 0; fi < 4; ++fi) {
    std::vector<Query> q;
    for (const Rgb& f0 : kLimitBases)
      for (float d : {10.0f, 100.0f, 250.0f, 400.0f, 700.0f, 1200.0f})
        for (int deg = 0; deg <= 80; deg += 2)
          q.push_back({1.0f, films[fi], d, float(degrees_cos(deg)), f0});
    const auto f = film(q);
    for (std::size_t i = 0; i < q.size(); ++i)
      for (int c = 0; c < 3; ++c)
        worst[fi] = std::max(worst[fi], std::fabs(f[i][c] - schlick(q[i].f0[c], q[i].cos1)));
  }
  std::printf(
      "film index 1 + e, 0-80 degrees: largest difference from the base: e = 0 %.2e, "
      "1e-4 %.2e, 1e-3 %.2e, 1e-2 %.2e\n",
      worst[0], worst[1], worst[2], worst[3]);
  EXPECT_LE(worst[0], kFloatRounding);
  // For small e = n2 - n1 the top interface's amplitude is |r12| <= e / (2 c1^2) (the s wave's;
  // p's is smaller), and the film's change to the base is led by the first order, 2 Cm S with
  // |Cm| <= sqrt(R12) and |S| <= 1.48 (the red channel's largest, from the Rec.709 matrix's
  // negative lobes): |F - base| <= 1.48 e / c1^2 + O(R12), linear in e, largest at the
  // widest angle (80 degrees; it grows without bound toward grazing, as the physics does).
  const double c2_min = std::pow(std::cos(80.0 * kPi / 180.0), 2.0);
  for (int fi = 1; fi <= 2; ++fi) {
    const double e = double(films[fi]) - 1.0, r = e / (2.0 * c2_min);
    EXPECT_LT(worst[fi], 1.48 * e / c2_min + 2.0 * r * r) << "e = " << e;
  }
  EXPECT_LT(worst[1], worst[2]);
  EXPECT_LT(worst[2], worst[3]);
}

TEST_F(Iridescence, TotalInternalReflectionInTheFilm) {
  // From a denser outside (1.5) onto a film of 1.3: beyond the critical angle (60.07 degrees)
  // everything is reflected; approaching it the reflectance rises continuously to 1.
  const double critical = std::asin(1.3 / 1.5) * 180.0 / kPi;
  std::vector<Query> q;
  for (const Rgb& f0 : kLimitBases)
    for (float d : {10.0f, 300.0f, 1200.0f}) {
      for (double deg = critical + 0.01; deg <= 90.0; deg += 0.5)
        q.push_back({1.5f, 1.3f, d, float(std::cos(deg * kPi / 180.0)), f0});
      q.push_back({1.5f, 1.3f, d, 0.0f, f0});
    }
  const std::size_t beyond = q.size();
  std::vector<double> below = {1e-1, 1e-2, 1e-3, 1e-4};
  for (const Rgb& f0 : kLimitBases)
    for (float d : {10.0f, 300.0f, 1200.0f})
      for (double delta : below)
        q.push_back({1.5f, 1.3f, d, float(std::cos((critical - delta) * kPi / 180.0)), f0});
  const auto f = film(q);
  for (std::size_t i = 0; i < beyond; ++i)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(f[i][c], 1.0) << "cos " << q[i].cos1;
  double lowest[4] = {1, 1, 1, 1};
  for (std::size_t i = beyond; i < q.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      double& l = lowest[(i - beyond) % 4];
      l = std::min(l, f[i][c]);
    }
  std::printf(
      "below the critical angle by 0.1, 0.01, 0.001, 0.0001 degrees: lowest %.4f %.4f "
      "%.4f %.4f\n",
      lowest[0], lowest[1], lowest[2], lowest[3]);
  for (int k = 1; k < 4; ++k) EXPECT_GT(lowest[k], lowest[k - 1]);
  EXPECT_GT(lowest[3], 0.95);
}

TEST_F(Iridescence, SensitivityIsOneAtZeroPathAndFadesOut) {
  // Normalised per channel: a flat spectrum (opd 0) has the colour (1, 1, 1); the fits'
  // Gaussians make every channel vanish for paths much longer than the coherence of the
  // visible band.
  const std::vector<float> opd = {0.0f, 20000.0f, 1e6f};
  cl::Buffer in = h_->buffer(opd), out = h_->buffer<cl_float4>(opd.size());
  h_->run("sensitivity", opd.size(), in, std::uint32_t(opd.size()), out);
  const auto v = h_->read<cl_float4>(out, opd.size());
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(v[0].s[c], 1.0, kFloatRounding);
    EXPECT_NEAR(v[1].s[c], 0.0, 1e-6);
    EXPECT_EQ(v[2].s[c], 0.0f);
  }
}

TEST_F(Iridescence, FiniteAndWithinZeroOneEverywhere) {
  // A dense sweep over every argument, degenerate ones included (F0 0 and 1, n2 = n1, n2 below
  // n1, grazing and out-of-range cosines, thickness 0, tiny, huge and infinite): every value is
  // finite and in [0, 1] (the model's series can leave [0, 1] by a little; it is clamped).
  std::vector<Query> q;
  const float inf = std::numeric_limits<float>::infinity();
  for (float n1 : {1.0f, 1.5f})
    for (float n2 : {1.0f, 1.0000001f, 1.2f, 1.5f, 1.8f, 2.3f, 3.0f, 5.0f})
      for (const Rgb& f0 :
           {Rgb{0, 0, 0}, Rgb{1, 1, 1}, Rgb{0.04, 0.5, 0.9999}, Rgb{1e-7, 0.2, 0.7}})
        for (float d : {0.0f, 1e-6f, 0.5f, 5.0f, 9.999f, 10.0f, 37.0f, 150.0f, 333.0f, 555.5f,
                        800.0f, 1200.0f, 3000.0f, 1e5f, 1e30f, inf})
          for (float c :
               {-0.1f, 0.0f, 1e-7f, 1e-4f, 0.01f, 0.1f, 0.3f, 0.5f, 0.7f, 0.9f, 0.999f, 1.0f, 1.1f})
            q.push_back({n1, n2, d, c, f0});
  for (int i = 0; i < 20000; ++i) {  // and a grid in (thickness, cos) for a few films
    const float n2 = 1.0f + 0.1f * float(i % 16);
    q.push_back({1.0f, n2, 0.1f * float(i % 12007), float((i * 7919) % 10007) / 10006.0f,
                 Rgb{0.04, 0.6, 0.95}});
  }
  const auto f = film(q);  // a NaN or Inf fails there
  for (std::size_t i = 0; i < q.size(); ++i)
    for (int c = 0; c < 3; ++c)
      ASSERT_TRUE(f[i][c] >= 0.0 && f[i][c] <= 1.0)
          << f[i][c] << " at outside " << q[i].outside << " film " << q[i].film << " d "
          << q[i].thickness << " cos " << q[i].cos1;
}

// ---------------------------------------------------------------------------------------------
// The README's mixing into the glTF BSDF.

TEST_F(Iridescence, MixesIntoTheDielectricAndMetalFresnel) {
  struct Case {
    float strength, film, thickness, cos1, ior, specular, texture_g;
    Rgb colour;
  };
  std::vector<Case> cases;
  for (float strength : {0.0f, 0.3f, 1.0f})
    for (float d : {0.0f, 250.0f, 700.0f})
      for (float c : {1.0f, 0.6f, 0.1f})
        for (float specular : {1.0f, 0.5f})
          cases.push_back({strength, 1.8f, d, c, 1.5f, specular, 0.25f, Rgb{0.9, 0.6, 0.3}});
  std::vector<cl_float4> args, extra, colour;
  std::vector<Query> film_q;  // the film alone, for the expected mixes
  for (const Case& k : cases) {
    args.push_back({{k.strength, k.film, k.thickness, k.cos1}});
    extra.push_back({{k.ior, k.specular, k.texture_g, 0.0f}});
    colour.push_back({{float(k.colour[0]), float(k.colour[1]), float(k.colour[2]), 0.0f}});
    const double f0 = double(k.specular) * f0_of_ior(k.ior);
    film_q.push_back({1.0f, k.film, k.thickness, k.cos1, Rgb{f0, f0, f0}});
    film_q.push_back({1.0f, k.film, k.thickness, k.cos1, k.colour});
  }
  const auto films = film(film_q);
  cl::Buffer a = h_->buffer(args), e = h_->buffer(extra), col = h_->buffer(colour);
  cl::Buffer od = h_->buffer<cl_float4>(cases.size()), om = h_->buffer<cl_float4>(cases.size());
  h_->run("mixes", cases.size(), a, e, col, std::uint32_t(cases.size()), od, om);
  const auto vd = h_->read<cl_float4>(od, cases.size()), vm = h_->read<cl_float4>(om, cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& k = cases[i];
    const double s = k.strength, f0 = f0_of_ior(k.ior);
    double fmax = 0.0;
    for (int c = 0; c < 3; ++c) {
      // Dielectric: mix(specular * Schlick(f0, c), film(specular * f0), strength).
      const double plain_d = k.specular * schlick(f0, k.cos1);
      const double want_d = (1.0 - s) * plain_d + s * films[2 * i][c];
      EXPECT_NEAR(vd[i].s[c], want_d, 1e-5) << "dielectric, case " << i;
      fmax = std::max(fmax, double(vd[i].s[c]));
      // Metal: mix(Schlick(colour, c), film(colour), strength).
      const double want_m = (1.0 - s) * schlick(k.colour[c], k.cos1) + s * films[2 * i + 1][c];
      EXPECT_NEAR(vm[i].s[c], want_m, 1e-5) << "metal, case " << i;
    }
    EXPECT_NEAR(vd[i].s[3], 1.0 - fmax, 1e-6) << "base weight, case " << i;
    EXPECT_NEAR(vm[i].s[3], 100.0 + 300.0 * k.texture_g, 1e-4) << "thickness";
  }
}

}  // namespace
