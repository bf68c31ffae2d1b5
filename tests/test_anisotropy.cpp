// sampling tier: anisotropic GGX (kernels/bsdf/ggx_aniso.h, KHR_materials_anisotropy) on the OpenCL
// device, against its own densities and a float64 model written here from the formulas of the
// header's comment (not its code).
//
// - Chi-square (AnisotropicGgx.VisibleNormalReflection): per configuration (ax, ay, view, turn
//   of the tangent frame) tests/kernels/anisotropy_kernels.cl draws kSamples directions
//   wi = reflect(wo, h), h from sample_ggx_aniso_visible_normal, and integrates
//   ggx_aniso_reflection_pdf over bins of the sphere (tests/sphere_bins.h); the histogram must
//   fit the integrals (tests/chi2.h, p > 1e-4), the integral over the sphere must be 1 (every
//   sample valid: the density covers the whole sphere, below-horizon reflections included), and
//   each sample's pdf (from the sampled h) must equal the eval side's at its wi (from
//   h = normalize(wo + wi)). As test_sampling.cpp does for the isotropic GGX, whose method,
//   binning, quadrature and tolerances this follows.
// - Normalisation (AnisotropicGgx.Normalisation): in float64 on the host, by quadrature,
//   integral of D(h) (n.h) = 1 and integral of G1(wo) max(0, wo.h) D(h) / wo.z = 1 (the visible
//   normals' density) over the hemisphere.
// - Float64 references (AnisotropicGgx.MatchesFloat64Model): the device's D, Lambda, G1,
//   visibility and pdf at random points, relative tolerances from float32 rounding (below).
// - Isotropic limit (AnisotropicGgx.ReducesToIsotropic): ax == ay against sampling/warps.h's ggx_d,
//   ggx_g1, ggx_visibility, ggx_reflection_pdf and sample_ggx_visible_normal.
// - Robustness (AnisotropicGgx.FiniteEverywhere): no NaN or Inf over a sweep of alphas (0, under
//   the floor, 1e-3 .. 1), views to exactly grazing, and random numbers at their ends.
// - The material's alphas (AnisotropicGgx.AlphasFromMaterial): ggx_aniso_alphas against the
//   extension's mix(roughness^2, 1, strength^2).
//
// False alarms: a correct routine fails one configuration's chi-square with probability 1e-4
// (the 5-sigma mass check adds ~1e-6); over the 16 configurations that is at most 1.6e-3 (union
// bound) for a random choice of seeds. Seeds are fixed, so a build on a device passes or fails
// reproducibly. Every other check is deterministic, with tolerances from rounding bounds.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kernels/shared/types.h"
#include "tests/chi2.h"
#include "tests/kernel_harness.h"
#include "tests/sphere_bins.h"

namespace {

using wp::dev::float4;
using wp::test::BinRect;
using wp::test::SphereBins;

constexpr double kPi = SphereBins::kPi;
constexpr double kAlphaMin = 1e-3;  // WP_GGX_ANISO_ALPHA_MIN (ggx_aniso.h)

// ---------------------------------------------------------------------------------------------
// The model in float64 (ggx_aniso.h's header formulas).

struct V3 {
  double x, y, z;
};
double dot(V3 a, V3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
V3 unit(V3 a) {
  const double l = std::sqrt(dot(a, a));
  return {a.x / l, a.y / l, a.z / l};
}
V3 v3(const float4& f) {
  return {f.x, f.y, f.z};
}

double ref_d(V3 h, double ax, double ay) {
  const double q = h.x * h.x / (ax * ax) + h.y * h.y / (ay * ay) + h.z * h.z;
  return 1.0 / (kPi * ax * ay * q * q);
}
// (sqrt(1 + t2) - 1) / 2 as expm1(log1p(t2) / 2) / 2: no cancellation where t2 is small.
double ref_lambda(V3 w, double ax, double ay) {
  const double t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / (w.z * w.z);
  return 0.5 * std::expm1(0.5 * std::log1p(t2));
}
double ref_g1(V3 w, double ax, double ay) {
  return 1.0 / (1.0 + ref_lambda(w, ax, ay));
}
double ref_visibility(V3 wo, V3 wi, double ax, double ay) {
  const double g2 = 1.0 / (1.0 + ref_lambda(wo, ax, ay) + ref_lambda(wi, ax, ay));
  return g2 / (4.0 * std::fabs(wo.z) * std::fabs(wi.z));
}
// The density of wi = reflect(wo, h): D_wo(h) / (4 wo.h), D_wo(h) = G1(wo) max(0, wo.h) D / wo.z.
double ref_visible_normal_pdf(V3 wo, V3 h, double ax, double ay) {
  if (h.z <= 0.0) return 0.0;
  return ref_g1(wo, ax, ay) * std::max(0.0, dot(wo, h)) * ref_d(h, ax, ay) / wo.z;
}
double ref_reflection_pdf(V3 wo, V3 h, double ax, double ay) {
  const double o_h = dot(wo, h);
  return o_h > 0.0 ? ref_visible_normal_pdf(wo, h, ax, ay) / (4.0 * o_h) : 0.0;
}

// ---------------------------------------------------------------------------------------------
// The device.

constexpr std::uint32_t kSamples = 1u << 19;

// Binning and the pdf's integration over bins as test_sampling.cpp (its comments give the
// reasons): a 32 x 64 base grid, bins expected to hold more than kTargetPerBin samples split into
// up to kMaxSplit^2 parts; per bin the midpoint rule from 2 x 2 points doubled until two changes
// are within 1e-3 relative or 1e-8 absolute, up to 256 x 256.
constexpr int kBaseC = 32, kBasePhi = 64, kMaxSplit = 24;
constexpr double kTargetPerBin = 2000.0;
constexpr std::uint32_t kN0 = 2, kMaxLevel = 7;
constexpr float kIntegralRelTol = 1e-3f, kIntegralAbsTol = 1e-8f;

struct Config {
  std::string name;
  double ax, ay, view_cos, turn_deg;
  float4 v() const {
    return {static_cast<float>(std::sqrt(1.0 - view_cos * view_cos)), 0.0f,
            static_cast<float>(view_cos), 0.0f};
  }
  float4 p() const {
    const double t = turn_deg * kPi / 180.0;
    return {static_cast<float>(ax), static_cast<float>(ay), static_cast<float>(std::cos(t)),
            static_cast<float>(std::sin(t))};
  }
};

std::uint32_t seed_of(const std::string& name) {  // FNV-1a: a fixed stream per configuration
  std::uint32_t h = 2166136261u;
  for (unsigned char ch : name) h = (h ^ ch) * 16777619u;
  return h;
}

struct Integrals {
  explicit Integrals(std::size_t n) : value(n, 0.0), error(n, 0.0) {}
  std::vector<double> value, error;  // per bin
};

// Outputs of the `evaluate` kernel per item (anisotropy_kernels.cl lists them).
struct Eval {
  float4 o[8];
};

class Device {
 public:
  static Device& get() {
    static Device d;
    return d;
  }

  void draw(const Config& c, std::vector<float4>& dirs, std::vector<float4>& checks) {
    h_.run("draw_aniso", kSamples, c.v(), c.p(), seed_of(c.name), kSamples, dirs_, checks_);
    dirs = h_.read<float4>(dirs_, kSamples);
    checks = h_.read<float4>(checks_, kSamples);
  }

  // Integrals of c's pdf over `rects`, stored at out[at[k]] for rect k.
  void integrate(const Config& c, const std::vector<BinRect>& rects,
                 const std::vector<std::size_t>& at, Integrals& out) {
    if (rects.empty()) return;
    std::vector<float4> r;
    for (const BinRect& b : rects)
      r.push_back({static_cast<float>(b.c0), static_cast<float>(b.c1), static_cast<float>(b.phi0),
                   static_cast<float>(b.phi1)});
    const auto count = static_cast<std::uint32_t>(r.size());
    cl::Buffer in = h_.buffer(r), result = h_.buffer<cl_float2>(count);
    h_.run("integrate_aniso_pdf", count, c.v(), c.p(), in, count, kN0, kIntegralRelTol,
           kIntegralAbsTol, kMaxLevel, result);
    const auto v = h_.read<cl_float2>(result, count);
    for (std::size_t k = 0; k < count; ++k) {
      out.value[at[k]] = v[k].s[0];
      out.error[at[k]] = v[k].s[1];
    }
  }

  // a[i] = (wo, ax), b[i] = (w, ay), u[i]: the `evaluate` kernel.
  std::vector<Eval> evaluate(const std::vector<float4>& a, const std::vector<float4>& b,
                             const std::vector<cl_float2>& u) {
    const auto count = static_cast<std::uint32_t>(a.size());
    cl::Buffer out = h_.buffer<float4>(std::size_t{8} * count);
    h_.run("evaluate", count, h_.buffer(a), h_.buffer(b), h_.buffer(u), count, out);
    const auto flat = h_.read<float4>(out, std::size_t{8} * count);
    std::vector<Eval> e(count);
    std::memcpy(e.data(), flat.data(), flat.size() * sizeof(float4));
    return e;
  }

 private:
  Device() : h_({"anisotropy_kernels.cl"}) {
    dirs_ = h_.buffer<float4>(std::size_t{kSamples});
    checks_ = h_.buffer<float4>(std::size_t{kSamples});
  }
  wp::test::KernelHarness h_;
  cl::Buffer dirs_, checks_;
};

std::vector<std::size_t> iota(std::size_t n) {
  std::vector<std::size_t> v(n);
  std::iota(v.begin(), v.end(), std::size_t{0});
  return v;
}

// Bins chosen from the pdf, never from the samples (as test_sampling.cpp's make_bins).
Integrals make_bins(const Config& c, SphereBins& bins) {
  const auto base_count = static_cast<std::size_t>(bins.base_count());
  Integrals base(base_count);
  Device::get().integrate(c, bins.rects(), iota(base_count), base);
  std::vector<int> split(base_count);
  for (std::size_t b = 0; b < base_count; ++b) {
    const double parts = std::ceil(std::sqrt(kSamples * base.value[b] / kTargetPerBin));
    split[b] = static_cast<int>(std::clamp(parts, 1.0, double{kMaxSplit}));
  }
  bins.refine(split);
  const std::vector<BinRect> rects = bins.rects();
  Integrals in(bins.size());
  std::vector<BinRect> parts;
  std::vector<std::size_t> at;
  for (std::size_t b = 0; b < base_count; ++b) {
    const std::size_t first = bins.first_of(b), m = static_cast<std::size_t>(split[b]);
    if (m == 1) {
      in.value[first] = base.value[b], in.error[first] = base.error[b];
      continue;
    }
    for (std::size_t k = first; k < first + m * m; ++k) parts.push_back(rects[k]), at.push_back(k);
  }
  Device::get().integrate(c, parts, at, in);
  return in;
}

void check_config(const Config& c) {
  SCOPED_TRACE(c.name);
  std::vector<float4> dirs, checks;
  Device::get().draw(c, dirs, checks);
  SphereBins bins(kBaseC, kBasePhi);
  const Integrals in = make_bins(c, bins);
  std::vector<double> observed(bins.size(), 0.0), expected(bins.size(), 0.0);
  std::size_t valid = 0;
  double pdf_error = 0.0, unit_error = 0.0, min_hz = 1.0;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const float4 d = dirs[i], k = checks[i];
    pdf_error = std::max(pdf_error, static_cast<double>(k.x));
    unit_error = std::max(unit_error, static_cast<double>(k.y));
    min_hz = std::min(min_hz, static_cast<double>(k.z));
    if (d.w != 1.0f) continue;
    ++valid;
    observed[bins.bin_of(d.x, d.z, d.y)] += 1.0;  // the pole on the normal (sphere_bins.h)
  }
  const double total = std::accumulate(in.value.begin(), in.value.end(), 0.0);
  const double total_error = std::accumulate(in.error.begin(), in.error.end(), 0.0);
  for (std::size_t b = 0; b < bins.size(); ++b)
    expected[b] = in.value[b] * static_cast<double>(valid) / total;
  const wp::test::Chi2Result chi2 = wp::test::chi2_test(observed, expected);
  // Integration error as test_sampling.cpp: 3x the bins' estimates, 1e-5 for the device's float
  // sums, and the pdf's own rounding: D's relative error ~4 * 6e-8 / alpha^2 where 1 - (n.h)^2 is
  // ~alpha^2 (the narrower direction's alpha decides).
  const double alpha = std::min(c.ax, c.ay);
  const double tol = 3.0 * total_error + 1e-5 + 2.4e-7 / (alpha * alpha);
  EXPECT_EQ(valid, std::size_t{kSamples}) << "samples with pdf 0";
  EXPECT_NEAR(total, 1.0, tol) << "pdf mass";
  EXPECT_GT(chi2.p_value, 1e-4) << chi2.detail;
  // The eval side rebuilds h from wi; where wo + wi is short that loses a few bits, and D of a
  // small alpha is steep (as test_sampling.cpp's GGX check).
  EXPECT_LE(pdf_error, 1e-2) << "sampled pdf vs eval pdf";
  EXPECT_LE(unit_error, 1e-6) << "| |h| - 1 |";
  EXPECT_GT(min_hz, 0.0) << "h below the surface";
  std::printf("%-40s int %.6f +- %.1e | pdf err %.1e | %s\n", c.name.c_str(), total, tol, pdf_error,
              chi2.detail.c_str());
  std::fflush(stdout);
}

// Views whose cosines are multiples of 1/16 (0, 46.6 and 79.2 degrees: the 0/45/80 of the
// brief, moved onto bin edges): the pdf's support ends where h reaches the horizon, at
// wi.z = -wo.z, a jump that then lies on an edge of the bins (c = -1 + k/16), as in
// test_sampling.cpp. A turn of the tangent frame puts the view out of the (t, n) plane.
TEST(AnisotropicGgx, VisibleNormalReflection) {
  struct Pair {
    double ax, ay;
  };
  const Pair pairs[] = {{0.05, 0.8}, {1.0, 0.1}, {0.3, 0.33}, {0.5, 0.2}};
  std::vector<Config> configs;
  auto add = [&](Pair p, int k, double turn) {
    char name[96];
    std::snprintf(name, sizeof name, "aniso (%.2f, %.2f) v.z %d/16 turn %.0f", p.ax, p.ay, k, turn);
    configs.push_back({name, p.ax, p.ay, k / 16.0, turn});
  };
  for (const Pair& p : pairs)
    for (int k : {16, 11, 3}) add(p, k, 0.0);
  for (const Pair& p : {pairs[0], pairs[1]})
    for (int k : {11, 3}) add(p, k, 30.0);
  for (const Config& c : configs) check_config(c);
}

// ---------------------------------------------------------------------------------------------
// Normalisation by quadrature in float64.
//
// The integrals are taken over the stretched hemisphere: h = M w' / |M w'|, M = diag(ax, ay, 1),
// w' = (sin t cos p, sin t sin p, cos t) on the unit upper hemisphere, d omega_h =
// ax ay / |M w'|^3 d omega' (the Jacobian of a linear map on the sphere). D's peak, however
// narrow and elongated, is spread over the whole of w's hemisphere, so a uniform grid in (t, p)
// resolves every alpha alike. The midpoint rule with n x 2n and n/2 x n points, extrapolated
// (Richardson: the midpoint rule's error is c n^-2 + O(n^-4) on smooth integrands); its error
// estimate is the change from the same extrapolation one level coarser (n/2 and n/4), an
// overestimate where the extrapolation converges (the visible normals' integrand has a kink,
// max(0, wo.h), along a great circle of the stretched hemisphere, which the n^-2 law describes
// only on average: there the estimate is what keeps the test honest).
struct Quad {
  double value, change;
};

template <class F>
Quad hemisphere(double ax, double ay, int n, F f) {
  auto at = [&](int nt) {
    const int np = 2 * nt;
    const double dt = 0.5 * kPi / nt, dp = 2.0 * kPi / np;
    double total = 0.0;
    for (int i = 0; i < nt; ++i) {
      const double t = (i + 0.5) * dt, st = std::sin(t), ct = std::cos(t);
      double row = 0.0;
      for (int j = 0; j < np; ++j) {
        const double p = (j + 0.5) * dp;
        const V3 m = {ax * st * std::cos(p), ay * st * std::sin(p), ct};
        const double len = std::sqrt(dot(m, m));
        const V3 h = {m.x / len, m.y / len, m.z / len};
        row += f(h) * ax * ay / (len * len * len);
      }
      total += row * st;
    }
    return total * dt * dp;
  };
  const double fine = at(n), mid = at(n / 2), coarse = at(n / 4);
  const double extrapolated = (4.0 * fine - mid) / 3.0, previous = (4.0 * mid - coarse) / 3.0;
  return {extrapolated, std::fabs(extrapolated - previous)};
}

// Tolerance per integral: 1e-6 + 2x its error estimate (float64's own rounding over 10^5 terms is
// ~1e-12). The estimates must stay below kMaxEstimate, so that the quadrature can tell: an error
// in the model moves these integrals by far more (Lambda with ax and ay swapped: by 0.4% for
// (0.3, 0.33) at 45 degrees, 64% for (0.05, 0.8) at 80; Lambda of the isotropic alpha
// sqrt(ax ay): 0.2% and 19%).
TEST(AnisotropicGgx, Normalisation) {
  constexpr int kN = 256;
  constexpr double kMaxEstimate = 2e-5;
  auto tol = [](const Quad& q) { return 1e-6 + 2.0 * q.change; };
  struct Pair {
    double ax, ay;
  };
  const Pair pairs[] = {{0.05, 0.8}, {1.0, 0.1}, {0.3, 0.33}, {1e-3, 0.5}, {0.01, 0.01}, {1, 1}};
  struct View {
    double deg, azimuth_deg;
  };
  const View views[] = {{0, 0}, {45, 0}, {45, 60}, {80, 0}, {80, 60}, {89, 30}};
  double worst_change = 0.0, worst_error = 0.0;
  for (const Pair& p : pairs) {
    // The grid itself: the area of the hemisphere. (For alpha << 1 the Jacobian peaks at the
    // stretched horizon, which this grid does not resolve; D's integrands carry no such peak.)
    if (std::min(p.ax, p.ay) >= 0.05) {
      const Quad area = hemisphere(p.ax, p.ay, kN, [](V3) { return 1.0; });
      EXPECT_NEAR(area.value / (2.0 * kPi), 1.0, tol(area)) << "the grid itself, " << p.ax;
    }
    const Quad nd = hemisphere(p.ax, p.ay, kN, [&](V3 h) { return ref_d(h, p.ax, p.ay) * h.z; });
    EXPECT_NEAR(nd.value, 1.0, tol(nd)) << "D (n.h), alphas " << p.ax << ", " << p.ay;
    std::printf("alphas (%.3f, %.3f): D n.h %.9f (%.0e)", p.ax, p.ay, nd.value, nd.change);
    worst_change = std::max(worst_change, nd.change);
    worst_error = std::max(worst_error, std::fabs(nd.value - 1.0));
    for (const View& v : views) {
      const double th = v.deg * kPi / 180.0, ph = v.azimuth_deg * kPi / 180.0;
      const V3 wo = {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
      const Quad vn = hemisphere(p.ax, p.ay, kN,
                                 [&](V3 h) { return ref_visible_normal_pdf(wo, h, p.ax, p.ay); });
      EXPECT_NEAR(vn.value, 1.0, tol(vn)) << "visible normals, alphas " << p.ax << ", " << p.ay
                                          << ", view " << v.deg << ", azimuth " << v.azimuth_deg;
      std::printf(" | v%.0f/%.0f %.9f (%.0e)", v.deg, v.azimuth_deg, vn.value, vn.change);
      worst_change = std::max(worst_change, vn.change);
      worst_error = std::max(worst_error, std::fabs(vn.value - 1.0));
    }
    std::printf("\n");
  }
  std::printf("largest |integral - 1| %.2e, largest error estimate %.2e\n", worst_error,
              worst_change);
  EXPECT_LE(worst_change, kMaxEstimate) << "the quadrature is too coarse to judge by";
}

// ---------------------------------------------------------------------------------------------
// Pointwise: the device against the float64 model, and against sampling/warps.h's isotropic GGX.

// Random unit directions (a fixed stream) with |z| spread over [1e-5, 1] (half log-uniform, half
// uniform in z), so that grazing directions are common; z < 0 with probability `below`.
struct Points {
  std::vector<float4> a, b;
  std::vector<cl_float2> u;
};

Points random_points(std::size_t n, bool isotropic) {
  std::uint64_t s = 0x9e3779b97f4a7c15ull;
  auto next = [&]() {  // splitmix64, to a double in (0, 1)
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (static_cast<double>(z >> 11) + 0.5) / 9007199254740992.0;
  };
  auto direction = [&](double below) {
    double z = next() < 0.5 ? std::pow(10.0, -5.0 * next()) : next();
    if (next() < below) z = -z;
    const double phi = 2.0 * kPi * next(), r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return V3{r * std::cos(phi), r * std::sin(phi), z};
  };
  auto alpha = [&]() { return std::pow(10.0, -3.0 * next()); };  // log-uniform in [1e-3, 1]
  Points p;
  for (std::size_t i = 0; i < n; ++i) {
    const V3 wo = direction(0.0), w = direction(0.25);
    const double ax = alpha(), ay = isotropic ? ax : alpha();
    p.a.push_back({static_cast<float>(wo.x), static_cast<float>(wo.y), static_cast<float>(wo.z),
                   std::max(static_cast<float>(ax), 1e-3f)});
    p.b.push_back({static_cast<float>(w.x), static_cast<float>(w.y), static_cast<float>(w.z),
                   isotropic ? p.a.back().w : std::max(static_cast<float>(ay), 1e-3f)});
    p.u.push_back({{static_cast<float>(next()), static_cast<float>(next())}});
  }
  return p;
}

// Relative error bounds of the device's float32 evaluation, in units of u = 2^-24 (half an ulp
// of 1): +, -, x correctly rounded (1 u relative each), / within 2.5 ulp and sqrt within 3 ulp
// (OpenCL 1.2's limits: 5 u and 6 u), pi's float 0.5 u. Every sum in ggx_aniso.h adds positive
// terms, so relative errors add up along each formula (to first order):
//   D:   ax ay 1u; ax ay hz^2 3u; (ay / ax) hx^2 7u (same for y); the sum 9u; pi k 10.5u; pi k^2
//        20.5u; the quotient 26.5u.
//   Lambda: (ax wx)^2 3u; + (ay wy)^2 4u; / wz^2 10u = e; 1 + e 11u; sqrt 11.5u; 1 + sqrt 12.5u;
//        the quotient 27.5u.
//   G1:  |(ax wx, ay wy, wz)|: squares 3u, sums 5u, sqrt 8.5u; wz + it 9.5u; the quotient 14.5u.
//   V:   products with |wz| 9.5u; their sum 10.5u; the quotient 15.5u.
//   pdf: D 26.5u; wo.z + |...| 9.5u; the quotient 41u.
// The inputs are floats, taken exactly by the model, so only the device's rounding counts.
constexpr double kU = 1.0 / 16777216.0;
constexpr double kTolD = 27 * kU, kTolLambda = 28 * kU, kTolG1 = 15 * kU, kTolV = 16 * kU,
                 kTolPdf = 41 * kU;

double rel(double x, double ref) {
  return x == ref ? 0.0 : std::fabs(x - ref) / std::fabs(ref);
}

TEST(AnisotropicGgx, MatchesFloat64Model) {
  constexpr std::size_t kPoints = 1u << 16;
  const Points p = random_points(kPoints, false);
  const std::vector<Eval> e = Device::get().evaluate(p.a, p.b, p.u);
  double worst[6] = {0, 0, 0, 0, 0, 0};  // D, Lambda(wo), G1(wo), V, pdf, Lambda/G1(w)
  std::size_t pdfs = 0;
  for (std::size_t i = 0; i < kPoints; ++i) {
    const V3 wo = v3(p.a[i]), w = v3(p.b[i]);
    const double ax = p.a[i].w, ay = p.b[i].w;
    const float4 o0 = e[i].o[0], o1 = e[i].o[1];
    const double err[5] = {
        rel(o0.x, ref_d(w, ax, ay)), rel(o0.y, ref_lambda(wo, ax, ay)),
        rel(o0.z, ref_g1(wo, ax, ay)), rel(o0.w, ref_visibility(wo, w, ax, ay)),
        std::max(rel(o1.y, ref_lambda(w, ax, ay)), rel(o1.z, ref_g1(w, ax, ay)))};
    for (int k = 0; k < 4; ++k) worst[k] = std::max(worst[k], err[k]);
    worst[5] = std::max(worst[5], err[4]);
    // The pdf is 0 unless h.z > 0 and wo.h > 0: where wo.h is within float rounding of 0 the
    // device may decide either way; not compared there.
    if (std::fabs(dot(wo, w)) > 1e-6) {
      worst[4] = std::max(worst[4], rel(o1.x, ref_reflection_pdf(wo, w, ax, ay)));
      pdfs += o1.x > 0.0f;
    }
  }
  std::printf(
      "worst relative errors in u = 2^-24: D %.1f, Lambda %.1f, G1 %.1f, V %.1f, pdf %.1f, "
      "Lambda/G1 below %.1f (%zu positive pdfs)\n",
      worst[0] / kU, worst[1] / kU, worst[2] / kU, worst[3] / kU, worst[4] / kU, worst[5] / kU,
      pdfs);
  EXPECT_LE(worst[0], kTolD) << "D";
  EXPECT_LE(worst[1], kTolLambda) << "Lambda";
  EXPECT_LE(worst[2], kTolG1) << "G1";
  EXPECT_LE(worst[3], kTolV) << "visibility";
  EXPECT_LE(worst[4], kTolPdf) << "reflection pdf";
  EXPECT_LE(worst[5], std::max(kTolLambda, kTolG1)) << "Lambda, G1 of directions below";
  EXPECT_GT(pdfs, kPoints / 4) << "too few points where the pdf is compared";
}

// ax == ay: the isotropic functions of sampling/warps.h, up to both sides' rounding. Their bounds
// (in u, counted as above): ggx_d 16.5u (a^2 cos^2 3u, + sin^2 4u, pi k^2 10.5u, quotient 16.5u);
// ggx_g1 15u (the radicand a^2 + (1 - a^2) c^2 within 6u: its terms are positive up to 1 - a^2's
// rounding, 1u of the radicand; sqrt 9u; c + sqrt 10u; quotient 15u); ggx_visibility 16u
// likewise; ggx_reflection_pdf 37.5u (g1 15u, d 16.5u, x 1u, / 4c 5u). Their formulas assume
// |w| = 1 (the radicand takes 1 - c^2 for wx^2 + wy^2), and a float-rounded unit vector has
// |w|^2 = 1 within 2u: 1u more for G1, V and the pdf. The sampler is the same sequence of
// operations and D the same up to factors of exactly 1: both agree bit for bit on PoCL, and the
// sampler on NVIDIA's OpenCL too (there D is fused into FMAs differently: within 11u). The
// sampler is held to 8 ulp of 1 in case a compiler contracts the two differently.
TEST(AnisotropicGgx, ReducesToIsotropic) {
  constexpr std::size_t kPoints = 1u << 16;
  const Points p = random_points(kPoints, true);
  const std::vector<Eval> e = Device::get().evaluate(p.a, p.b, p.u);
  double worst[5] = {0, 0, 0, 0, 0};  // D, G1, V, pdf, sample
  std::size_t same_d = 0, compared_d = 0, same_h = 0, pdfs = 0;
  for (std::size_t i = 0; i < kPoints; ++i) {
    const V3 wo = v3(p.a[i]), w = v3(p.b[i]);
    const float4 o0 = e[i].o[0], o1 = e[i].o[1], iso = e[i].o[2], h = e[i].o[3], hi = e[i].o[4];
    if (w.z > 0.0) {  // the isotropic D takes n.h >= 0
      worst[0] = std::max(worst[0], rel(o0.x, iso.x));
      same_d += o0.x == iso.x;
      ++compared_d;
    }
    worst[1] = std::max(worst[1], rel(o0.z, iso.y));
    if (w.z > 0.0) worst[2] = std::max(worst[2], rel(o0.w, iso.z));  // ggx_visibility: n.l >= 0
    if (w.z > 0.0 && dot(wo, w) > 1e-6) {
      worst[3] = std::max(worst[3], rel(o1.x, iso.w));
      ++pdfs;
    }
    const double dh =
        std::max({std::fabs(h.x - hi.x), std::fabs(h.y - hi.y), std::fabs(h.z - hi.z)});
    worst[4] = std::max(worst[4], dh);
    same_h += dh == 0.0;
  }
  std::printf(
      "ax == ay vs sampling/warps.h, worst relative differences in u: D %.1f (%zu of %zu bit for "
      "bit), G1 %.1f, V %.1f, pdf %.1f (%zu); sample %.1e (%zu of %zu bit for bit)\n",
      worst[0] / kU, same_d, compared_d, worst[1] / kU, worst[2] / kU, worst[3] / kU, pdfs,
      worst[4], same_h, kPoints);
  EXPECT_LE(worst[0], (26.5 + 16.5) * kU) << "ggx_d";
  EXPECT_LE(worst[1], (14.5 + 15 + 1) * kU) << "ggx_g1";
  EXPECT_LE(worst[2], (15.5 + 16 + 1) * kU) << "ggx_visibility";
  EXPECT_LE(worst[3], (41 + 37.5 + 1) * kU) << "ggx_reflection_pdf";
  EXPECT_LE(worst[4], 16 * kU) << "sample_ggx_visible_normal";
}

// No NaN or Inf anywhere: alphas 0 and 1e-5 (under the floor), 1e-3 .. 1 in every pairing; views
// from the normal to exactly grazing; random numbers at 0, the ends of the generator's range
// (2^-24, 1 - 2^-24) and 1; second directions on the normal, grazing and below. Each item
// evaluates D, Lambda, G1, the visibility and the pdf, samples h and reflects wo about it.
TEST(AnisotropicGgx, FiniteEverywhere) {
  const float alphas[] = {0.0f, 1e-5f, 1e-3f, 2e-3f, 0.01f, 0.05f, 0.2f, 0.5f, 0.8f, 1.0f};
  const double zs[] = {0.0, 1e-7, 1e-5, 1e-3, 0.05, 0.3, 0.7, 0.99, 1.0};
  const double azimuths[] = {0.0, 0.5, kPi / 2, 2.4, kPi, 4.0};
  const float us[] = {0.0f, 0x1p-24f, 0.25f, 0.5f, 0.75f, 1.0f - 0x1p-24f, 1.0f};
  const V3 others[] = {{0, 0, 1},          {1, 0, 0},      {0, 1, 0},
                       {0.6, 0.8, 0},      {0, 0.6, -0.8}, {0.3, -0.4, 0.866},
                       {-0.7, 0.1, 0.707}, {0, 0, -1},     {0.8, 0, 1e-6}};
  Points p;
  std::vector<double> view_z;
  std::size_t k = 0;
  for (float ax : alphas)
    for (float ay : alphas)
      for (double z : zs)
        for (double az : azimuths)
          for (float u0 : us)
            for (float u1 : us) {
              const double r = std::sqrt(1.0 - z * z);
              const V3 o = unit(others[k++ % (sizeof others / sizeof others[0])]);
              p.a.push_back({static_cast<float>(r * std::cos(az)),
                             static_cast<float>(r * std::sin(az)), static_cast<float>(z), ax});
              p.b.push_back(
                  {static_cast<float>(o.x), static_cast<float>(o.y), static_cast<float>(o.z), ay});
              p.u.push_back({{u0, u1}});
              view_z.push_back(z);
            }
  const std::vector<Eval> e = Device::get().evaluate(p.a, p.b, p.u);
  auto finite = [](const float4& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
  };
  std::size_t bad = 0, zero_pdf = 0, zero_pdf_inner = 0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    const float4 o0 = e[i].o[0], o1 = e[i].o[1], h = e[i].o[3], wi = e[i].o[5], d = e[i].o[6];
    const double hl = std::sqrt(double{h.x} * h.x + double{h.y} * h.y + double{h.z} * h.z);
    const bool ok = finite(o0) && finite(o1) && finite(h) && finite(wi) && finite(d) &&
                    o0.x > 0.0f && o0.y >= 0.0f && o0.z >= 0.0f && o0.z <= 1.0f && o0.w >= 0.0f &&
                    o1.x >= 0.0f && o1.y >= 0.0f && o1.z >= 0.0f && o1.z <= 1.0f && h.z > 0.0f &&
                    std::fabs(hl - 1.0) < 1e-6 && h.w >= 0.0f && wi.w >= 0.0f && d.x > 0.0f &&
                    d.y >= 0.0f;
    if (!ok && bad++ < 10)
      ADD_FAILURE() << "item " << i << ": wo (" << p.a[i].x << ", " << p.a[i].y << ", " << p.a[i].z
                    << ") ax " << p.a[i].w << " ay " << p.b[i].w << " u (" << p.u[i].s[0] << ", "
                    << p.u[i].s[1] << "): D " << o0.x << " Lambda " << o0.y << " G1 " << o0.z
                    << " V " << o0.w << " pdf " << o1.x << " h (" << h.x << ", " << h.y << ", "
                    << h.z << ") pdf " << h.w << " V(wi) " << wi.w;
    // A sampled h has pdf 0 only where wo.h rounds to <= 0: h on the rim of the visible
    // hemisphere, reached at u.x = 1 (r = 1) or for a view at the horizon.
    if (h.w == 0.0f) {
      ++zero_pdf;
      zero_pdf_inner += p.u[i].s[0] < 1.0f && view_z[i] > 0.0;
    }
  }
  std::printf(
      "%zu items: %zu not finite or out of range; sampled pdf 0 at %zu (%zu with u.x < 1 "
      "and wo.z > 0)\n",
      e.size(), bad, zero_pdf, zero_pdf_inner);
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(zero_pdf_inner, 0u);
}

// KHR_materials_anisotropy's alphas: ax = mix(roughness^2, 1, strength^2), ay = roughness^2;
// strength 0 gives the isotropic alpha exactly, strength 1 gives ax = 1 exactly. Elsewhere within
// 5u of ax: five roundings (r^2, s^2, 1 - s^2, the product, the sum), each at most u times a
// value no larger than ax (ax >= alpha, s^2 and alpha (1 - s^2); s^2's rounding enters through
// 1 - s^2 multiplied by alpha <= ax).
TEST(AnisotropicGgx, AlphasFromMaterial) {
  const float roughness[] = {0.0f, 0.03f, 0.1f, 0.5f, 0.77f, 1.0f};
  const float strength[] = {0.0f, 0.2f, 0.6f, 0.95f, 1.0f};
  Points p;
  for (float r : roughness)
    for (float st : strength) {
      p.a.push_back({0, 0, 1, r});
      p.b.push_back({0, 0, 1, st});
      p.u.push_back({{0.5f, 0.5f}});
    }
  const std::vector<Eval> e = Device::get().evaluate(p.a, p.b, p.u);
  for (std::size_t i = 0; i < e.size(); ++i) {
    const double r = p.a[i].w, st = p.b[i].w, alpha = r * r, s2 = st * st;
    const float4 o = e[i].o[7];
    SCOPED_TRACE("roughness " + std::to_string(r) + " strength " + std::to_string(st));
    EXPECT_EQ(o.y, p.a[i].w * p.a[i].w) << "ay = roughness^2";
    if (st == 0.0) {
      EXPECT_EQ(o.x, o.y) << "strength 0: isotropic";
    } else if (st == 1.0) {
      EXPECT_EQ(o.x, 1.0f) << "strength 1: ax = 1";
    } else {
      EXPECT_NEAR(o.x, alpha * (1.0 - s2) + s2, 5 * kU * (alpha * (1.0 - s2) + s2)) << "ax";
    }
  }
}

}  // namespace
