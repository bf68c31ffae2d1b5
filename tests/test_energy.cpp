// Energy over the whole material space: the directional albedo of the glTF BSDF (bsdf.h), as the
// renderer estimates it on the device (tests/kernels/energy_kernels.cl: BSDF sampling alone, and
// BSDF sampling with a uniform-sphere light sample under MIS, as in a white furnace), against the
// albedo that this file computes independently in float64 from the model's formulas (bsdf.h's
// header) by quadrature. The sweep covers metallic x roughness (densely around the smooth/rough
// threshold and the float32 cancellation band 0.0101-0.0135 that once gave D = inf) x view
// angle, dielectric specular, transmission thin-walled and with a volume, entering and leaving,
// with ior 1, 1.0001, 1.5 and 2.4, smooth and rough.
//
// Tolerance: the estimate is a mean of N = 2^19 independent samples; its standard error s is
// computed from the samples. Over ~1000 comparisons a 5 s bound has a false-alarm probability
// ~6e-4 (Gaussian tails; N is large enough for the CLT even for the heavy-tailed BSDF-only
// estimate of near-delta lobes, whose variance is bounded: weights are at most 1 / eta^2 <= 2.25
// for these materials). The quadrature's error is bounded by twice the change from n/2 to n
// points per axis: where the midpoint rule converges at least linearly (ratio <= 1/2, across the
// integrand's jumps), the remaining error is at most one change; the second allows for the
// erratic convergence at the jumps (the worst case seen, metal roughness 0.035 at 60 degrees,
// needed 1.1 changes). It is added. A NaN or Inf anywhere on the way fails the test.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "tests/kernel_harness.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint32_t kSamples = 1u << 19;
// Each sample's weight is computed in float32, a few roundings of relative size 6e-8 each; where
// the variance is 0 (a smooth white metal: every weight is 1 up to rounding) the mean can differ
// from the exact value by that much and no more.
constexpr double kFloatRounding = 1e-6;

struct Material {
  double grey = 1.0;  // base colour, every channel
  double metallic = 0.0, roughness = 0.5, ior = 1.5, transmission = 0.0;
  bool volume = false, front = true;  // KHR_materials_volume; wo on the front side
};

// ---------------------------------------------------------------------------------------------
// The model in float64, from bsdf.h's documentation (not its code).

struct V3 {
  double x, y, z;
};
V3 operator+(V3 a, V3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
V3 operator*(double s, V3 a) {
  return {s * a.x, s * a.y, s * a.z};
}
double dot(V3 a, V3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

double pow5(double x) {
  return x * x * x * x * x;
}

// eta = index beyond the interface / index on wo's side.
double relative_eta(const Material& m) {
  return m.volume && !m.front ? 1.0 / m.ior : m.ior;
}

// The dielectric Fresnel term (Schlick) at cosine c on wo's side: from the denser side the
// refracted cosine is used, and beyond the critical angle it is 1.
double fresnel(double c, double eta) {
  const double f0 = std::pow((eta - 1.0) / (eta + 1.0), 2.0);
  if (eta < 1.0) {
    const double sin2_t = (1.0 - c * c) / (eta * eta);
    if (sin2_t >= 1.0) return 1.0;
    c = std::sqrt(1.0 - sin2_t);
  }
  return f0 + (1.0 - f0) * pow5(1.0 - c);
}

double lambda(double cos_theta, double alpha) {
  const double c2 = cos_theta * cos_theta, tan2 = (1.0 - c2) / c2;
  return 0.5 * (std::sqrt(1.0 + alpha * alpha * tan2) - 1.0);
}

// Reflectance and transmittance weights of a microfacet (or the smooth surface) at cosine c.
double reflectance(const Material& m, double c, double eta) {
  return (1.0 - m.metallic) * fresnel(c, eta) +
         m.metallic * (m.grey + (1.0 - m.grey) * pow5(1.0 - c));
}
double transmittance(const Material& m, double c, double eta) {
  return (1.0 - m.metallic) * (1.0 - fresnel(c, eta)) * m.transmission * m.grey;
}

bool smooth(const Material& m) {
  return m.roughness * m.roughness < 1e-3;  // WP_DELTA_ALPHA
}
bool straight_through(const Material& m, double eta) {
  return !m.volume || std::fabs(eta - 1.0) < 1e-3;  // WP_ETA_STRAIGHT
}

// Midpoint rule over [0,1)^2 with n x n points of f(row(x), column(y)): what depends on one
// coordinate only is computed once per row or column (the values, and so the sums, are those of
// evaluating everything at every point; this is ~10% of the test's time instead of ~30%).
template <class Row, class Column, class F>
double midpoint2(int n, const Row& row, const Column& column, const F& f) {
  std::vector<decltype(column(0.0))> columns;
  for (int j = 0; j < n; ++j) columns.push_back(column((j + 0.5) / n));
  double total = 0.0;
  for (int i = 0; i < n; ++i) {
    const auto r = row((i + 0.5) / n);
    double sum = 0.0;
    for (int j = 0; j < n; ++j) sum += f(r, columns[std::size_t(j)]);
    total += sum;
  }
  return total / (double(n) * n);
}

struct Quad {
  double value, error;
};
template <class Row, class Column, class F>
Quad converge(int n, const Row& row, const Column& column, const F& f) {
  const double fine = midpoint2(n, row, column, f), coarse = midpoint2(n / 2, row, column, f);
  return {fine, 2.0 * std::fabs(fine - coarse)};
}

// The azimuth phi = 2 pi p's cosine and sine, the column of both integrals below.
struct Azimuth {
  double c, s;
};
Azimuth azimuth(double p) {
  const double phi = 2.0 * kPi * p;
  return {std::cos(phi), std::sin(phi)};
}

// The diffuse lobe: (1-m)(1-t) base / pi (1 - F(wo.h)) over the upper hemisphere, in
// (sin^2 theta_i, phi / 2 pi), where cos_i d omega / pi = d(sin^2) d(phi / 2 pi).
Quad diffuse_albedo(const Material& m, V3 wo, double eta, int n) {
  const double k = (1.0 - m.metallic) * (1.0 - m.transmission) * m.grey;
  if (k == 0.0) return {0.0, 0.0};
  struct Row {
    double sn, cos_i;
  };
  return converge(
      n,
      [](double s2) {
        return Row{std::sqrt(s2), std::sqrt(1.0 - s2)};
      },
      azimuth,
      [&](const Row& r, const Azimuth& a) {
        const V3 wi = {r.sn * a.c, r.sn * a.s, r.cos_i};
        const V3 sum = wo + wi;
        const V3 h = (1.0 / std::sqrt(dot(sum, sum))) * sum;
        return k * (1.0 - fresnel(std::max(dot(wo, h), 0.0), eta));
      });
}

// The microfacet lobes over the microfacet normal h, in (w, phi / 2 pi) with
// tan^2 theta_h = alpha^2 w / (1 - w): then D(h) cos theta_h d omega_h = dw d phi / 2 pi, and
// f |cos_i| d omega_i = X D G2 (wo.h) / cos_o d omega_h for reflection and thin-walled
// transmission (X = F or the transmittance), X D G2 (wo.h) / (cos_o eta^2) d omega_h for
// refraction into a volume (Walter et al. 2007). `cos_h` and `sin_h` are theta_h's.
double microfacet_integrand(const Material& m, V3 wo, double eta, double cos_h, double sin_h,
                            const Azimuth& a) {
  const double alpha = m.roughness * m.roughness, cos_o = wo.z;
  const bool straight = m.volume && straight_through(m, eta);
  const V3 h = {sin_h * a.c, sin_h * a.s, cos_h};
  const double o_h = dot(wo, h);
  if (o_h <= 0.0) return 0.0;
  const double measure = o_h / (cos_o * cos_h);  // times D cos_h d omega_h
  double total = 0.0;
  const V3 wr = 2.0 * o_h * h + (-1.0) * wo;
  if (wr.z > 0.0) {
    const double g2 = 1.0 / (1.0 + lambda(cos_o, alpha) + lambda(wr.z, alpha));
    total += reflectance(m, o_h, eta) * g2 * measure;
    if (!m.volume) total += transmittance(m, o_h, eta) * g2 * measure;  // mirrored below
  }
  if (!m.volume || m.transmission == 0.0) return total;
  if (straight) {  // delta through an index-matched interface: the eta -> 1 limit
    // Sampled with D_v = G1 D (wo.h) / cos_o, weight T G2 / G1 / eta^2 with G2 at wi = -wo.
    const double g2 = 1.0 / (1.0 + 2.0 * lambda(cos_o, alpha));
    return total + transmittance(m, o_h, eta) * g2 * measure / (eta * eta);
  }
  const double sin2_t = (1.0 - o_h * o_h) / (eta * eta);
  if (sin2_t >= 1.0) return total;  // total internal reflection at this microfacet
  const V3 wt = (-1.0 / eta) * wo + (o_h / eta - std::sqrt(1.0 - sin2_t)) * h;
  if (wt.z >= 0.0) return total;
  const double g2 = 1.0 / (1.0 + lambda(cos_o, alpha) + lambda(-wt.z, alpha));
  return total + transmittance(m, o_h, eta) * g2 * measure / (eta * eta);
}

Quad microfacet_albedo(const Material& m, V3 wo, double eta, int n) {
  // w = 1 - (1 - x)^4: the GGX tail (tan^2 theta_h > T has probability alpha^2 / (alpha^2 + T),
  // all of it in w > T / (alpha^2 + T)) is resolved down to 1 - w ~ 1e-13, not cut at 1 / n.
  struct Row {
    double dw_dx, cos_h, sin_h;
  };
  const double alpha = m.roughness * m.roughness;
  return converge(
      n,
      [&](double x) {
        const double w = 1.0 - std::pow(1.0 - x, 4.0), dw_dx = 4.0 * std::pow(1.0 - x, 3.0);
        const double tan_h = alpha * std::sqrt(w / (1.0 - w));
        const double cos_h = 1.0 / std::sqrt(1.0 + tan_h * tan_h);
        return Row{dw_dx, cos_h, tan_h * cos_h};
      },
      azimuth,
      [&](const Row& r, const Azimuth& a) {
        return r.dw_dx * microfacet_integrand(m, wo, eta, r.cos_h, r.sin_h, a);
      });
}

// Directional albedo for wo at cosine cos_o (x-z plane: the kernel's wo lies in that plane of
// its own frame; the albedo does not depend on the azimuth).
Quad directional_albedo(const Material& m, double cos_o, int n = 1024) {
  const V3 wo = {std::sqrt(1.0 - cos_o * cos_o), 0.0, cos_o};
  const double eta = relative_eta(m);
  Quad q = diffuse_albedo(m, wo, eta, n);
  if (smooth(m)) {  // delta lobes: the reflectance and transmittance at the macro normal
    q.value += reflectance(m, cos_o, eta);
    if (m.transmission > 0.0)
      q.value += transmittance(m, cos_o, eta) / (m.volume ? eta * eta : 1.0);
    return q;
  }
  const Quad s = microfacet_albedo(m, wo, eta, n);
  return {q.value + s.value, q.error + s.error};
}

// ---------------------------------------------------------------------------------------------

struct Estimate {
  double mean[2] = {0, 0}, se[2] = {0, 0};
  std::uint64_t nonfinite = 0;
};

class Energy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { h_ = new wp::test::KernelHarness({"energy_kernels.cl"}); }
  static void TearDownTestSuite() {
    delete h_;
    h_ = nullptr;
  }

  static Estimate estimate(const Material& m, double cos_o) {
    cl::Buffer out = h_->buffer<cl_float4>(kSamples);
    const cl_float4 color = {{float(m.grey), float(m.grey), float(m.grey), 0.0f}};
    const cl_float4 params = {
        {float(m.metallic), float(m.roughness), float(m.ior), float(m.transmission)}};
    const std::uint32_t flags = (m.volume ? 2u : 0u) | (m.front ? 4u : 0u);  // WP_SURF_*
    h_->run("albedo_estimates", kSamples, color, params, flags, float(cos_o), 7u, kSamples, out);
    const auto v = h_->read<cl_float4>(out, kSamples);
    Estimate e;
    double sum[2] = {0, 0}, sq[2] = {0, 0};
    for (const cl_float4& s : v) {
      for (int k = 0; k < 2; ++k) sum[k] += s.s[k], sq[k] += double(s.s[k]) * s.s[k];
      e.nonfinite += s.s[2] != 0.0f;
    }
    for (int k = 0; k < 2; ++k) {
      e.mean[k] = sum[k] / kSamples;
      const double var = std::max(0.0, sq[k] / kSamples - e.mean[k] * e.mean[k]);
      e.se[k] = std::sqrt(var / (kSamples - 1.0));
    }
    return e;
  }

  // The estimates for m at the view angles, against the quadrature.
  static void check(const char* name, const Material& m,
                    std::initializer_list<double> view_degrees = {0, 30, 60, 80, 89}) {
    for (double deg : view_degrees) {
      const double cos_o = std::cos(deg * kPi / 180.0);
      // The kernel's wo is the float32 direction at this cosine; use the same cosine.
      const double c = double(float(cos_o));
      const Quad ref = directional_albedo(m, c);
      const Estimate e = estimate(m, c);
      char what[160];
      std::snprintf(
          what, sizeof what,
          "%s (m %.2f r %.4f ior %.4f t %.1f %s%s) at %.0f deg: reference %.6f +- %.1e", name,
          m.metallic, m.roughness, m.ior, m.transmission, m.volume ? "volume" : "thin",
          m.volume ? (m.front ? " entering" : " leaving") : "", deg, ref.value, ref.error);
      EXPECT_EQ(e.nonfinite, 0u) << what;
      const char* method[2] = {"BSDF sampling", "MIS with a light sample"};
      for (int k = 0; k < 2; ++k)
        EXPECT_NEAR(e.mean[k], ref.value, 5.0 * e.se[k] + ref.error + kFloatRounding * ref.value)
            << what << ", " << method[k] << " (se " << e.se[k] << ")";
    }
  }

  static wp::test::KernelHarness* h_;
};
wp::test::KernelHarness* Energy::h_ = nullptr;

// The quadrature itself, where the answer is known: a white metal's single-scattering albedo at
// normal incidence tends to 1 as roughness goes to 0; a Lambertian (F = 0: specular factor is not
// modelled here, so use metallic 0, transmission 0 and ior 1, where Schlick's f0 = 0) is grey x
// (1 - a small Fresnel loss). Checks of the reference's plumbing, not of the renderer.
TEST(EnergyReference, KnownLimits) {
  Material metal;
  metal.metallic = 1.0, metal.roughness = 0.04;
  EXPECT_NEAR(directional_albedo(metal, 1.0).value, 1.0, 2e-3);
  Material smooth_glass;
  smooth_glass.roughness = 0.0, smooth_glass.transmission = 1.0;
  // Thin-walled smooth glass, white: F + (1 - F) = 1 exactly.
  EXPECT_NEAR(directional_albedo(smooth_glass, 0.5).value, 1.0, 1e-12);
}

TEST_F(Energy, MetallicRoughness) {
  for (double metallic : {0.0, 0.5, 1.0})
    for (double roughness : {0.0, 0.005, 0.01, 0.0101, 0.011, 0.012, 0.0135, 0.015, 0.02, 0.03,
                             0.0316, 0.032, 0.035, 0.05, 0.1, 0.3, 0.6, 1.0}) {
      Material m;
      m.metallic = metallic, m.roughness = roughness, m.grey = metallic == 1.0 ? 1.0 : 0.8;
      check("metallic-roughness", m);
    }
}

// A grey (0.5) metal: Schlick's colour-dependent Fresnel.
TEST_F(Energy, GreyMetal) {
  for (double roughness : {0.0, 0.012, 0.2, 0.7}) {
    Material m;
    m.metallic = 1.0, m.roughness = roughness, m.grey = 0.5;
    check("grey metal", m);
  }
}

TEST_F(Energy, Transmission) {
  for (bool volume : {false, true})
    for (bool front : {true, false}) {
      if (!volume && !front) continue;  // thin-walled has no inside
      for (double ior : {1.0, 1.0001, 1.5, 2.4})
        for (double roughness : {0.0, 0.012, 0.05, 0.3, 0.8}) {
          Material m;
          m.roughness = roughness, m.ior = ior, m.transmission = 1.0, m.grey = 1.0;
          m.volume = volume, m.front = front;
          check("transmission", m);
        }
    }
}

// Partial transmission with every lobe at once.
TEST_F(Energy, MixedLobes) {
  Material m;
  m.metallic = 0.3, m.roughness = 0.4, m.transmission = 0.5, m.grey = 0.7, m.volume = true;
  check("mixed", m);
  m.front = false;
  check("mixed", m);
}

// The power heuristic in the ratio form: no NaN where p^2 overflows float32, 1 or 0 at the
// extremes, p^2 / (p^2 + q^2) in between (to float rounding).
TEST_F(Energy, MisWeightWithoutOverflow) {
  const std::vector<cl_float2> pairs = {{{1e20f, 1.0f}},    {{1.0f, 1e20f}}, {{3e38f, 2e38f}},
                                        {{1e-30f, 1e-30f}}, {{2.0f, 1.0f}},  {{INFINITY, 1.0f}},
                                        {{1.0f, 0.0f}}};
  cl::Buffer in = h_->buffer(pairs), out = h_->buffer<float>(pairs.size());
  h_->run("mis_weights", pairs.size(), in, std::uint32_t(pairs.size()), out);
  const auto w = h_->read<float>(out, pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const double p = pairs[i].s[0], q = pairs[i].s[1];
    ASSERT_TRUE(std::isfinite(w[i])) << p << " vs " << q;
    // Either heuristic (the harness builds with the default): p^b / (p^b + q^b), b = 1 or 2.
    const double r = q / p, balance = 1.0 / (1.0 + r), power = 1.0 / (1.0 + r * r);
    EXPECT_TRUE(std::fabs(w[i] - balance) < 1e-6 || std::fabs(w[i] - power) < 1e-6)
        << p << " vs " << q << ": " << w[i];
  }
}

}  // namespace
