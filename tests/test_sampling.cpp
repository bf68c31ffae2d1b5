// sampling tier: every sampling routine against its own density, on the OpenCL device (PoCL in CI).
//
// Per configuration, tests/kernels/sampling_kernels.cl draws kSamples directions (fewer for the
// layered extensions: Config::samples, kLayeredSamples, with the power that leaves) and integrates
// the density that the routine's eval side gives (cosine_hemisphere_pdf, ggx_reflection_pdf,
// bsdf_eval, triangle_light_pdf) over bins of the sphere (tests/sphere_bins.h). Checks:
// - chi-square (tests/chi2.h): the histogram of non-delta samples against the integrals, scaled
//   to the number of such samples (so it tests the shape; the mass is the next check); p > 1e-4;
// - mass: the integral of the pdf over the sphere equals the observed fraction of non-delta
//   samples (1 - invalid - delta) within 5 binomial sigma plus the integration's own error;
//   where every sample must be valid and none delta, the integral is 1 and nothing is invalid;
// - pointwise: each sample's pdf equals the eval side's at its direction (relative 1e-4; 1e-5 for
//   the BSDF) and a BSDF weight equals f |cos| / pdf (relative 1e-5); delta samples lie on the
//   exact direction of one of the surface's delta lobes (mirror about ns or the coat normal,
//   refraction) and have a finite weight >= 0.
// KHR_materials_dispersion (Dispersion*): where a path of all channels chooses one, the channels'
// frequencies (chi-square against 1/3) and, per chosen channel, the directions against that
// channel's BSDF (the checks above on the samples that chose it); with the channel chosen earlier,
// the checks above; and dispersion 0 bit for bit the program without the feature.
//
// False alarms: a correct routine fails one configuration's chi-square with probability 1e-4 (the
// 5-sigma checks add ~1e-6); over the ~250 chi-squares here (228 configurations, 22 of
// dispersion's) that is at most 2.5% (union bound) for a random choice of seeds. Seeds are fixed,
// so a given build on a given device passes or fails reproducibly; a change of the random stream
// (new code, another device's rounding) draws anew from that 2.5%.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "host/lights/light_table.h"
#include "kernels/shared/types.h"
#include "tests/chi2.h"
#include "tests/float_bits.h"
#include "tests/kernel_harness.h"
#include "tests/sphere_bins.h"

namespace {

using wp::dev::float4;
using wp::test::BinRect;
using wp::test::SphereBins;

constexpr std::uint32_t kSamples = 1u << 20;
constexpr double kPi = SphereBins::kPi;
constexpr std::uint32_t kVolume = 2u, kFront = 4u;  // WP_SURF_VOLUME, WP_SURF_FRONT (bsdf.h)

// Binning: a 32 x 64 base grid; base bins expected to hold more than kTargetPerBin samples are
// split into up to kMaxSplit^2 parts of about that many, so that narrow lobes (roughness 0.1:
// GGX alpha 0.01, a lobe ~0.02 rad wide) still spread over several bins.
constexpr int kBaseC = 32, kBasePhi = 64, kMaxSplit = 24;
constexpr double kTargetPerBin = 2000.0;

// Integration per bin (integrate_pdf): from n0 x n0 points, doubled up to max_level times until
// the last two changes are within 1e-3 relative (the error is then far smaller on smooth
// integrands: a bias of at most ~(1e-3)^2 N = 1 in a chi-square with >1000 degrees of freedom) or
// 1e-8 absolute (0.01 samples).
struct Quadrature {
  std::uint32_t n0, max_level;
};
constexpr Quadrature kSmooth = {2, 7};  // 2 .. 256 points per axis
// The triangle's pdf jumps at its edges, which cut bins anywhere: start finer, so that a thin
// part of a bin on one side of an edge is not missed by three coarse levels alike.
constexpr Quadrature kEdges = {8, 5};  // 8 .. 256
// Bins whose integral came out 0 but which hold samples are integrated again with many more
// points: there the points missed a sliver of the support. Expected counts stay functions of the
// pdf alone, computed more carefully where it matters; a sample outside the support is caught by
// the pointwise pdf check. More than kMaxRescued such bins means samples outside the support,
// not slivers: the chi-square fails on them without the (slow) second look.
constexpr Quadrature kRescue = {128, 2};  // 128 .. 512
constexpr std::size_t kMaxRescued = 64;
constexpr float kIntegralRelTol = 1e-3f, kIntegralAbsTol = 1e-8f;

enum Routine : std::uint32_t { kCosine = 0, kGgx = 1, kBsdf = 2, kTriangle = 3 };  // ST_* (.cl)
// How the bins lie (BF_* in the .cl, the mapping in sphere_bins.h): the pole on the horizon keeps
// lobes of the plane of incidence away from the poles and the horizon on bin edges; the pole on
// the normal puts each circle of constant z - the GGX reflection's support ends at z = -v.z - on
// bin edges when z is a multiple of 1/16.
enum Frame : std::uint32_t { kPoleOnHorizon = 0, kPoleOnNormal = 1 };

// One configuration of a routine; the fields' meaning per routine is in sampling_kernels.cl.
struct Config {
  std::string name;
  std::uint32_t routine = kCosine, frame = kPoleOnHorizon, flags = 0;
  float4 a{}, color{}, params{};
  // kBsdf's layered extensions (sampling_kernels.cl, ST_BSDF); the defaults leave each out, with
  // KHR_materials_specular's default colour and factor 1. Set by the with_* functions below.
  float4 coat{}, sheen{}, specular{1, 1, 1, 1}, aniso{}, irid{}, dtrans{};
  float4 disp{};  // KHR_materials_dispersion: (dispersion factor, the path's channel 0-3)
  std::uint32_t samples = kSamples;  // at most kSamples
  // ST_TRIANGLE: counter-clockwise seen from the origin, so its front faces the shading point;
  // the vertices lie off the bins' grid lines (a vertex on one makes a sliver that only rounding
  // reaches).
  std::vector<float4> triangle = {{-1.1f, -0.9f, 1, 1}, {0.1f, 1.05f, 1, 1}, {0.95f, -1.05f, 1, 1}};
  bool double_sided = false;
  bool all_valid = false;      // every sample valid and non-delta: the pdf integrates to 1
  bool lambert_build = false;  // run on the Lambert-only build (Device::get)
  Quadrature quadrature = kSmooth;
};

float4 direction(double cos_theta) {  // in the x-z plane
  return {static_cast<float>(std::sqrt(1.0 - cos_theta * cos_theta)), 0.0f,
          static_cast<float>(cos_theta), 0.0f};
}
double cos_deg(double deg) {
  return std::cos(deg * kPi / 180.0);
}

std::uint32_t seed_of(const std::string& name) {  // FNV-1a: a fixed stream per configuration
  std::uint32_t h = 2166136261u;
  for (unsigned char ch : name) h = (h ^ ch) * 16777619u;
  return h;
}

struct Draw {
  std::vector<float4> dirs, checks;  // see draw_samples in sampling_kernels.cl
  std::size_t smooth = 0, delta = 0, invalid = 0;
  std::size_t below = 0, delta_below = 0;  // valid samples below the surface (local z < 0)
  double pdf_error = 0, weight_error = 0, third_error = 0;  // maxima of checks' x, y, z
};

struct Integrals {
  explicit Integrals(std::size_t n) : value(n, 0.0), error(n, 0.0) {}
  std::vector<double> value, error;  // per bin
};

// The counts and maxima of d from its dirs and checks.
void tally(Draw& d) {
  for (std::size_t i = 0; i < d.dirs.size(); ++i) {
    const float4 v = d.dirs[i], k = d.checks[i];
    if (v.w == 0.0f) {
      ++d.invalid;
      continue;
    }
    (v.w == 1.0f ? d.smooth : d.delta) += 1;
    d.below += v.z < 0.0f;
    d.delta_below += v.z < 0.0f && v.w == 2.0f;
    d.pdf_error = std::max(d.pdf_error, static_cast<double>(k.x));
    d.weight_error = std::max(d.weight_error, static_cast<double>(k.y));
    d.third_error = std::max(d.third_error, static_cast<double>(k.z));
  }
}

// The test kernels, built once per process, and the sample buffers every draw reuses.
class Device {
 public:
  // The program with every feature, or the Lambert-only build of a scene without a specular
  // layer (WP_FEATURE_GLOSSY 0: kernels/bsdf/bsdf.h). Each is built on first use.
  static Device& get(bool lambert_build) {
    if (lambert_build) {
      static Device lambert("-D WP_FEATURE_GLOSSY=0 -D WP_FEATURE_TRANSMISSION=0");
      return lambert;
    }
    static Device general("");
    return general;
  }
  // The program without KHR_materials_dispersion's code (WP_FEATURE_DISPERSION 0), for the known
  // answer that dispersion 0 is the BSDF without it.
  static Device& without_dispersion() {
    static Device none("-D WP_FEATURE_DISPERSION=0");
    return none;
  }

  // `kernel`: draw_samples, or draw_channel_choice (its checks differ: sampling_kernels.cl).
  Draw draw(const Config& c, const char* kernel = "draw_samples") {
    const std::uint32_t n = std::min(c.samples, kSamples);
    run(c, kernel, n, seed_of(c.name), n, dirs_, checks_);
    Draw d;
    d.dirs = h_.read<float4>(dirs_, n);
    d.checks = h_.read<float4>(checks_, n);
    tally(d);
    return d;
  }

  // Integrals of c's pdf over `rects` (value, error estimate), stored at out[at[k]] for rect k.
  void integrate(const Config& c, const std::vector<BinRect>& rects, Quadrature q,
                 const std::vector<std::size_t>& at, Integrals& out) {
    if (rects.empty()) return;
    std::vector<float4> r;
    for (const BinRect& b : rects)
      r.push_back({static_cast<float>(b.c0), static_cast<float>(b.c1), static_cast<float>(b.phi0),
                   static_cast<float>(b.phi1)});
    const auto count = static_cast<std::uint32_t>(r.size());
    cl::Buffer in = h_.buffer(r), result = h_.buffer<cl_float2>(count);
    run(c, "integrate_pdf", count, in, count, q.n0, kIntegralRelTol, kIntegralAbsTol, q.max_level,
        result);
    const auto v = h_.read<cl_float2>(result, count);
    for (std::size_t k = 0; k < count; ++k) {
      out.value[at[k]] = v[k].s[0];
      out.error[at[k]] = v[k].s[1];
    }
  }

  // bsdf_lobes at the configuration's wo and the delta lobes (lobe_selection in the .cl).
  struct Lobes {
    double spec, trans, diff, dtrans, sheen, coat;
    bool base_delta, coat_delta, only_delta;
  };
  Lobes lobes(const Config& c) {
    cl::Buffer out = h_.buffer<float>(9);
    run(c, "lobe_selection", 1, out);
    const std::vector<float> v = h_.read<float>(out, 9);
    return {v[0], v[1], v[2], v[3], v[4], v[5], v[6] > 0.5f, v[7] > 0.5f, v[8] > 0.5f};
  }

  wp::test::KernelHarness& harness() { return h_; }

  // Runs `kernel` with c's arguments, then `rest` (bsdf_queries).
  template <class... Rest>
  void run_config(const Config& c, const char* kernel, std::size_t items, Rest&&... rest) {
    run(c, kernel, items, std::forward<Rest>(rest)...);
  }

 private:
  explicit Device(const std::string& options) : h_({"sampling_kernels.cl"}, options) {
    dirs_ = h_.buffer<float4>(std::size_t{kSamples});
    checks_ = h_.buffer<float4>(std::size_t{kSamples});
  }

  // Runs `kernel` with the configuration's arguments (WP_CONFIG_PARAMS) followed by `rest`; the
  // one-triangle scene (light 0, pmf 1, emission 1) is rebuilt from the configuration each time.
  template <class... Rest>
  void run(const Config& c, const char* kernel, std::size_t items, Rest&&... rest) {
    wp::dev::Material m{};
    m.emission = {1, 1, 1, 0};
    m.flags.x = c.double_sided ? WP_MAT_DOUBLE_SIDED : 0u;
    m.textures0 = m.textures1 = {-1, -1, -1, -1};
    const std::vector<wp::dev::uint4> tri_vertices = {{0, 1, 2, 0}};
    const std::vector<wp::dev::LightAlias> alias = {{1.0f, 0u, 1.0f, 0u}};
    h_.run(kernel, items, c.routine, c.frame, c.flags, c.a, c.color, c.params, c.coat, c.sheen,
           c.specular, c.aniso, c.irid, c.dtrans, c.disp, h_.buffer(c.triangle),
           h_.buffer(tri_vertices), h_.buffer(std::vector<wp::dev::Material>{m}),
           h_.buffer(std::vector<std::uint32_t>{0u}), h_.buffer(alias),
           std::forward<Rest>(rest)...);
  }

  wp::test::KernelHarness h_;
  cl::Buffer dirs_, checks_;
};

std::vector<std::size_t> iota(std::size_t n) {
  std::vector<std::size_t> v(n);
  std::iota(v.begin(), v.end(), std::size_t{0});
  return v;
}

// Bins for configuration c, chosen from its pdf, never from the samples: the base grid, each bin
// split where its integral says the density is high. Returns the integrals over the final bins.
Integrals make_bins(const Config& c, SphereBins& bins) {
  const auto base_count = static_cast<std::size_t>(bins.base_count());
  Integrals base(base_count);
  Device::get(c.lambert_build).integrate(c, bins.rects(), c.quadrature, iota(base_count), base);
  std::vector<int> split(base_count);
  for (std::size_t b = 0; b < base_count; ++b) {
    const double parts = std::ceil(std::sqrt(c.samples * base.value[b] / kTargetPerBin));
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
  Device::get(c.lambert_build).integrate(c, parts, c.quadrature, at, in);
  return in;
}

struct Fit {
  double total = 0.0, total_error = 0.0;  // of the pdf's integrals over the bins
  wp::test::Chi2Result chi2;
};

// The chi-square of the non-delta samples' histogram against c's pdf integrated over its bins.
Fit fit(const Config& c, const Draw& d) {
  SphereBins bins(kBaseC, kBasePhi);
  Integrals in = make_bins(c, bins);
  const std::vector<BinRect> rects = bins.rects();
  std::vector<double> observed(bins.size(), 0.0), expected(bins.size(), 0.0);
  for (const float4& v : d.dirs) {
    if (v.w != 1.0f) continue;
    const bool pole_z = c.frame == kPoleOnNormal;  // see sphere_bins.h for the mapping
    observed[pole_z ? bins.bin_of(v.x, v.z, v.y) : bins.bin_of(v.x, v.y, v.z)] += 1.0;
  }
  std::vector<BinRect> again;
  std::vector<std::size_t> again_at;
  for (std::size_t b = 0; b < bins.size(); ++b)
    if (in.value[b] <= 0.0 && observed[b] > 0.0) again.push_back(rects[b]), again_at.push_back(b);
  if (again.size() <= kMaxRescued)
    Device::get(c.lambert_build).integrate(c, again, kRescue, again_at, in);
  Fit f;
  f.total = std::accumulate(in.value.begin(), in.value.end(), 0.0);
  f.total_error = std::accumulate(in.error.begin(), in.error.end(), 0.0);
  const double scale = f.total > 0.0 ? static_cast<double>(d.smooth) / f.total : 0.0;
  for (std::size_t b = 0; b < bins.size(); ++b) expected[b] = in.value[b] * scale;
  f.chi2 = wp::test::chi2_test(observed, expected);
  return f;
}

double binomial_sigma(double p, double n) {
  return std::sqrt(std::max(p * (1.0 - p), 1.0 / n) / n);
}

// Rounding in the pdf itself: GGX's D(h) depends on 1 - (n.h)^2, ~alpha^2 at the lobe's peak, and
// n.h (from dot products and a normalisation) carries ~6e-8 of rounding, so D's relative error
// there is ~4 * 6e-8 / alpha^2: 2.4e-3 for roughness 0.1 (alpha 0.01) with a tilted normal. A
// BSDF's narrowest GGX lobe counts: the base's (across the anisotropy direction: alpha), the
// coat's.
double pdf_rounding(const Config& c) {
  double alpha = 0.0;
  const auto narrowest = [&alpha](double a) {
    if (a > 1e-4) alpha = alpha > 0.0 ? std::min(alpha, a) : a;
  };
  if (c.routine == kGgx) narrowest(c.a.w);
  if (c.routine == kBsdf) {
    narrowest(c.params.y * c.params.y);
    if (c.coat.x > 0.0f) narrowest(c.coat.y * c.coat.y);
  }
  return alpha > 0.0 ? 2.4e-7 / (alpha * alpha) : 0.0;
}

// The distribution checks of draw d of configuration c (c.samples samples): the mass, the
// chi-square, and all_valid's.
void check_distribution(const Config& c, const Draw& d) {
  const Fit f = fit(c, d);
  const double n = c.samples, smooth = static_cast<double>(d.smooth) / n;
  // Integration error: 3x the sum of the per-bin estimates (on smooth integrands each is many
  // times its bin's error; where a bin cuts an edge of the triangle the error can be a few times
  // the last change), 1e-5 for float rounding in the device's sums, and the pdf's own rounding.
  const double tol = 3.0 * f.total_error + 1e-5 + pdf_rounding(c);
  EXPECT_NEAR(f.total, smooth, 5.0 * binomial_sigma(smooth, n) + tol) << "pdf mass vs samples";
  if (c.all_valid) {
    EXPECT_EQ(d.invalid + d.delta, 0u);
    EXPECT_NEAR(f.total, 1.0, tol);
  }
  if (d.smooth > 0) {
    EXPECT_GT(f.chi2.p_value, 1e-4) << f.chi2.detail;
  }
  std::printf("%-48s smooth %.4f delta %.4f invalid %.4f | int %.5f +- %.1e | %s\n", c.name.c_str(),
              smooth, static_cast<double>(d.delta) / n, static_cast<double>(d.invalid) / n, f.total,
              tol, d.smooth > 0 ? f.chi2.detail.c_str() : "no density to test");
  std::fflush(stdout);
}

// Draws configuration c and applies the checks listed at the top of the file. Returns the draw
// for further checks by the caller.
Draw check_config(const Config& c) {
  SCOPED_TRACE(c.name);
  const Draw d = Device::get(c.lambert_build).draw(c);
  check_distribution(c, d);
  // GGX: the eval side rebuilds h from l = reflect(v, h); where v + l is short (grazing v) that
  // loses a few bits, and D(h) of a small alpha is steep. The BSDF's sample reports bsdf_eval's
  // pdf and f at the very direction it returns, so the two sides agree to rounding (1e-5 leaves
  // room for a compiler contracting the weight's product and quotient differently).
  const double pdf_tol = c.routine == kGgx ? 1e-2 : c.routine == kBsdf ? 1e-5 : 1e-4;
  EXPECT_LE(d.pdf_error, pdf_tol) << "sampled pdf vs eval pdf";
  EXPECT_LE(d.weight_error, c.routine == kBsdf ? 1e-5 : 1e-4)
      << "weight vs f |cos| / pdf (a delta sample: a finite weight >= 0)";
  EXPECT_LE(d.third_error, c.routine == kTriangle ? 1e-4 : 1e-5)
      << (c.routine == kTriangle ? "distance vs ray hit" : "delta direction");
  return d;
}

Config bsdf_config(float metallic, float roughness, float4 color, double view_deg,
                   float transmission = 0.0f, std::uint32_t flags = kFront) {
  char name[96];
  std::snprintf(name, sizeof name, "bsdf m%.1f r%.1f c(%.1f,%.1f,%.2f) t%.1f f%u v%.0f", metallic,
                roughness, color.x, color.y, color.z, transmission, flags, view_deg);
  Config c{name, kBsdf, kPoleOnHorizon, flags};
  c.a = direction(cos_deg(view_deg));
  c.color = color;
  c.params = {metallic, roughness, 1.5f, transmission};
  return c;
}

// A BSDF configuration's lobe choice in its draw d of c.samples samples (check_bsdf: after
// check_config). A smooth surface (roughness 0; with anisotropy, alpha along the anisotropy
// direction below WP_DELTA_ALPHA) has delta lobes for specular reflection and transmission, and a
// smooth coat (clearcoat roughness 0) a delta reflection about the coat normal, each chosen with
// bsdf_lobes' probabilities, so the fractions of delta samples above and below the surface must
// match them (the coat's mirror direction is lost, not a sample, where it falls below the surface);
// without delta lobes there are no delta samples. Nothing goes below a surface that transmits
// neither specularly nor diffusely, nor below a smooth one past the critical angle without diffuse
// transmission. A BSDF that bsdf_only_delta says is all delta lobes (light sampling then skips it)
// has no sample with a density.
void check_lobe_fractions(const Config& c, const Draw& d) {
  SCOPED_TRACE(c.name);
  const Device::Lobes l = Device::get(c.lambert_build).lobes(c);
  const double n = c.samples;
  const double above = (l.base_delta ? l.spec : 0.0) + (l.coat_delta ? l.coat : 0.0);
  const double below = l.base_delta ? l.trans : 0.0;
  if (l.base_delta || l.coat_delta) {
    EXPECT_NEAR(static_cast<double>(d.delta - d.delta_below) / n, above,
                5.0 * binomial_sigma(above, n))
        << "delta reflections (base and coat)";
    EXPECT_NEAR(static_cast<double>(d.delta_below) / n, below, 5.0 * binomial_sigma(below, n))
        << "delta transmission";
  } else {
    EXPECT_EQ(d.delta, 0u);
  }
  if (l.only_delta) {
    EXPECT_EQ(d.smooth, 0u) << "bsdf_only_delta, yet a sample with a density";
  }
  // A rough surface chooses transmission per microfacet: past the macro critical angle (trans =
  // 0 at the macro normal) microfacets tilted toward wo still transmit.
  const bool transmits = c.params.w > 0.0f && c.params.x < 1.0f;
  if ((!transmits || (l.base_delta && l.trans == 0.0)) && l.dtrans == 0.0) {
    EXPECT_EQ(d.below, 0u);
  } else if (l.trans + l.dtrans > 0.01) {
    EXPECT_GT(d.below, 0u);
  }
}

void check_bsdf(const Config& c) {
  check_lobe_fractions(c, check_config(c));
}

// The layered extensions on a bsdf_config (sampling_kernels.cl, ST_BSDF), each named in the
// configuration's name (its random stream). Angles in degrees; azimuths from wo's.
Config with_coat(Config c, float clearcoat, float roughness, double tilt = 0, double azimuth = 0) {
  char s[64];
  std::snprintf(s, sizeof s, " coat %.1f r%.2f", clearcoat, roughness);
  c.name += s;
  if (tilt != 0.0) {
    std::snprintf(s, sizeof s, " nc %.0f@%.0f", tilt, azimuth);
    c.name += s;
  }
  c.coat = {clearcoat, roughness, static_cast<float>(tilt * kPi / 180.0),
            static_cast<float>(azimuth * kPi / 180.0)};
  return c;
}
Config with_sheen(Config c, float4 color, float roughness) {
  char s[64];
  std::snprintf(s, sizeof s, " sheen (%.1f,%.1f,%.1f) r%.2f", color.x, color.y, color.z, roughness);
  c.name += s;
  c.sheen = {color.x, color.y, color.z, roughness};
  return c;
}
Config with_specular(Config c, float4 color, float factor = 1.0f) {
  char s[64];
  std::snprintf(s, sizeof s, " spec (%.1f,%.1f,%.1f)x%.1f", color.x, color.y, color.z, factor);
  c.name += s;
  c.specular = {color.x, color.y, color.z, factor};
  return c;
}
Config with_aniso(Config c, float strength, double rotation) {
  char s[64];
  std::snprintf(s, sizeof s, " aniso %.1f@%.0f", strength, rotation);
  c.name += s;
  c.aniso = {strength, static_cast<float>(rotation * kPi / 180.0), 0, 0};
  return c;
}
Config with_iridescence(Config c, float factor, float ior = 1.3f, float thickness = 400.0f) {
  char s[64];
  std::snprintf(s, sizeof s, " irid %.1f ior %.2f %.0fnm", factor, ior, thickness);
  c.name += s;
  c.irid = {factor, ior, thickness, 0};
  return c;
}
Config with_diffuse_transmission(Config c, float factor, float4 color) {
  char s[64];
  std::snprintf(s, sizeof s, " dt %.1f (%.1f,%.1f,%.1f)", factor, color.x, color.y, color.z);
  c.name += s;
  c.dtrans = {color.x, color.y, color.z, factor};
  return c;
}
// KHR_materials_dispersion: the dispersion factor and the path's channel (0: all three, 1 R, 2 G,
// 3 B: a path that chose it earlier).
Config with_dispersion(Config c, float dispersion, int channel) {
  char s[64];
  std::snprintf(s, sizeof s, " disp %.1f ch %d", dispersion, channel);
  c.name += s;
  c.disp = {dispersion, static_cast<float>(channel), 0, 0};
  return c;
}
Config with_samples(Config c, std::uint32_t samples) {
  c.samples = samples;
  return c;
}

const float4 kWhite = {1, 1, 1, 0}, kSaturated = {0.9f, 0.1f, 0.02f, 0};

// The eight-lane forms of common.h's helpers and of the lane code of elementary.h and
// sampling/warps.h (tests/kernels/lanes_kernels.cl) against their one-path forms on the same
// inputs, bit for bit,
// as the packet kernels need (integrator/shade_packet.h: the same images with and without packets):
// vectors whose squared length is zero, subnormal, just inside and outside (1e-30, 1e30) (where
// length3x8 and normalize3x8 hand the lane to the builtin) or huge, mixed in one packet with
// ordinary ones, and signed zeros; fractions of a turn and unit-square points at their boundaries
// (which also make the GGX functions' views, alphas and numbers).
// NaN results (the zero vector's normal) must be NaN on both sides. Built with and without
// WP_PREFETCH (lane_bits8's x86 builtin or its generic form).
TEST(LaneTwins, MatchTheirScalarFunctions) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), exponent(-25.0f, 25.0f);
  std::vector<cl_float4> vectors;
  const float edges[] = {0.0f,   -0.0f,   1e-20f, 1e-15f, 3e-16f, 1e15f,  3e15f, 1e20f,
                         1e-40f, -2e-40f, 1.0f,   -1.0f,  0.5f,   1e-38f, 3e19f, -7e14f};
  for (float a : edges)
    for (float b : edges) {
      vectors.push_back({{a, b, 0.0f, 0.0f}});
      vectors.push_back({{b, 0.0f, a, 0.0f}});
      vectors.push_back({{a, a, b, 0.0f}});
    }
  for (float base : {1e-15f, 1e15f})  // squared lengths at the plain range's ends
    for (int k = -4; k <= 4; ++k) {
      float x = base;
      for (int step = 0; step < (k < 0 ? -k : k); ++step)
        x = std::nextafter(x, k < 0 ? 0.0f : 1e30f);
      vectors.push_back({{x, 0.0f, 0.0f, 0.0f}});
      vectors.push_back({{0.0f, -x, 0.0f, 0.0f}});
    }
  for (int i = 0; i < 4096; ++i) {  // ordinary vectors, and magnitudes from 1e-25 to 1e25
    cl_float4 v = {{unit(rng), unit(rng), unit(rng), 0.0f}};
    if (i % 2)
      for (int c = 0; c < 3; ++c) v.s[c] *= std::pow(10.0f, exponent(rng));
    vectors.push_back(v);
  }
  std::shuffle(vectors.begin(), vectors.end(), rng);  // unusual lanes beside ordinary ones
  for (std::size_t i = 0; i < vectors.size(); ++i) vectors[i].s[3] = unit(rng);  // offset scale
  std::vector<cl_float4> fractions;  // (x, y) in the unit square, w a fraction of a turn
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  const float ends[] = {0.0f,
                        0.25f,
                        0.5f,
                        0.75f,
                        std::nextafter(1.0f, 0.0f),
                        1.0f,
                        std::nextafter(0.125f, 0.0f),
                        0.125f,
                        std::nextafter(0.125f, 1.0f)};
  for (float a : ends)
    for (float b : ends)
      fractions.push_back({{a, std::min(b, std::nextafter(1.0f, 0.0f)), 0.0f, a}});
  for (int i = 0; i < 4096; ++i) fractions.push_back({{u01(rng), u01(rng), 0.0f, u01(rng)}});
  for (auto* set : {&vectors, &fractions})
    while (set->size() % 8) set->push_back({{1.0f, 2.0f, 3.0f, 0.5f}});

  const auto same = [](float a, float b) {
    return wp::test::bits(a) == wp::test::bits(b) || (std::isnan(a) && std::isnan(b));
  };
  const char* names[] = {"length",       "normalize",         "dot",
                         "cross",        "make_basis t",      "make_basis b",
                         "cos_sin_turn", "cosine hemisphere", "offset_origin",
                         "GGX visible normal", "GGX D, V, pdf"};
  for (const char* options : {"-D WP_SHADE_PACKET=1", "-D WP_SHADE_PACKET=1 -D WP_PREFETCH=1"}) {
    wp::test::KernelHarness h({"lanes_kernels.cl"}, options);
    for (cl_uint fn = 0; fn < 11; ++fn) {
      const std::vector<cl_float4>& in = fn == 6 || fn == 7 || fn >= 9 ? fractions : vectors;
      const auto groups = static_cast<cl_uint>(in.size() / 8);
      cl::Buffer b_in = h.buffer(in), lanes = h.buffer<cl_float4>(in.size()),
                 scalar = h.buffer<cl_float4>(in.size());
      h.run("lane_twins", groups, b_in, groups, fn, lanes, scalar);
      const auto l = h.read<cl_float4>(lanes, in.size()), s = h.read<cl_float4>(scalar, in.size());
      std::size_t differ = 0;
      for (std::size_t i = 0; i < in.size(); ++i)
        for (int c = 0; c < 3; ++c)
          if (!same(l[i].s[c], s[i].s[c]) && differ++ < 3)
            ADD_FAILURE() << options << ", " << names[fn] << " of (" << in[i].s[0] << ", "
                          << in[i].s[1] << ", " << in[i].s[2] << ", " << in[i].s[3]
                          << "), component " << c << ": lanes " << l[i].s[c] << ", scalar "
                          << s[i].s[c];
      EXPECT_EQ(differ, 0u) << options << ", " << names[fn];
    }
  }
}

// cos_sin_turn (kernels/sampling/warps.h), the (cos, sin) of 2 pi u that the GGX visible-normal
// samplers and the uniform sphere use instead of the library's cos and sin: against double
// precision at u (the float itself), on a dense grid and at every quarter turn's boundary and its
// neighbours. The bound: t = (4u - q) pi/2 with 4u - q exact and |t| <= pi/4 rounds by at most
// 2^-24 pi/4 and pi/2's own rounding adds 2^-25 pi/4 (both < 5e-8 in the angle); the Taylor
// remainders are below 2e-9; Horner's five float steps round by at most 5 x 2^-24 (3e-7) of values
// <= 1: 4e-7 in all. Quarter turns are exact (cos 2 pi u is exactly 1, 0, -1, 0 at u = 0, 1/4, 1/2,
// 3/4).
TEST(Sampling, CosSinTurn) {
  wp::test::KernelHarness h({"trig_kernels.cl"});
  std::vector<float> u;
  constexpr int kGrid = 1 << 20;
  for (int i = 0; i <= kGrid; ++i) u.push_back(static_cast<float>(i) / kGrid);
  for (int k = 0; k <= 8; ++k) {  // quarter turns and the rounding boundaries between them
    float x = static_cast<float>(k) / 8.0f;
    for (int step = 0; step < 4; ++step) x = std::nextafter(x, -1.0f);
    for (int step = 0; step < 9; ++step, x = std::nextafter(x, 2.0f))
      if (x >= 0.0f && x <= 1.0f) u.push_back(x);
  }
  const auto count = static_cast<std::uint32_t>(u.size());
  cl::Buffer in = h.buffer(u), out = h.buffer<cl_float2>(count);
  h.run("cos_sin_turn_at", count, in, count, out);
  const auto v = h.read<cl_float2>(out, count);
  double worst = 0.0;
  for (std::uint32_t i = 0; i < count; ++i) {
    const double a = 2.0 * 3.14159265358979323846 * static_cast<double>(u[i]);
    worst =
        std::max({worst, std::fabs(v[i].s[0] - std::cos(a)), std::fabs(v[i].s[1] - std::sin(a))});
  }
  std::cout << "  cos_sin_turn: largest error " << worst << " over " << count << " points\n";
  EXPECT_LE(worst, 4e-7);
  const float quarters[][3] = {{0.0f, 1.0f, 0.0f},
                               {0.25f, 0.0f, 1.0f},
                               {0.5f, -1.0f, 0.0f},
                               {0.75f, 0.0f, -1.0f},
                               {1.0f, 1.0f, 0.0f}};
  for (const auto& q : quarters) {
    const auto i = static_cast<std::size_t>(q[0] * kGrid);
    EXPECT_EQ(v[i].s[0], q[1]) << "u " << q[0];
    EXPECT_EQ(v[i].s[1], q[2]) << "u " << q[0];
  }
}

// atan2_poly (kernels/util/elementary.h), the atan2 of the environment map's lookup: against double
// precision atan2 of the same floats, at 2^20 angles around the circle (each at radii from 1e-30
// to 1e30, where the quotient min/max must not lose its precision), densely near the octant
// boundaries |x| = |y| where the reflection pi/2 - r takes over, and on the axes with both signed
// zeros. The bound, summed over the steps: the quotient a = min/max, correctly rounded on PoCL
// (Elementary's comment below says more), rounds by at most 2^-24 a
// (6e-8 in the angle, as atan' <= 1); the polynomial with float coefficients, evaluated by Horner
// in float, is within 1.1e-7 of atan on [0, 1] (tools/generators/gen_atan_poly.py, at 4 million
// points); pi/2 - r and pi - r round by at most half an ulp of results below 2 and 4 (6e-8, 1.2e-7)
// with the float constants pi/2 and pi off by 4.4e-8 and 8.8e-8: 4.8e-7 in all. Exact where the
// octant's angle is: 0, +-pi/2 and +-pi on the axes (float pi/2 and pi, as the library gives),
// with atan2's signs of zero.
TEST(Sampling, Atan2Poly) {
  wp::test::KernelHarness h({"trig_kernels.cl"});
  std::vector<cl_float2> yx;  // (y, x)
  constexpr int kAngles = 1 << 20;
  const double two_pi = 2.0 * kPi;
  const float kPiF = static_cast<float>(kPi);
  const float radii[] = {1e-30f, 1e-3f, 1.0f, 7.5f, 1e30f};
  for (int i = 0; i < kAngles; ++i) {
    const double t = two_pi * (i + 0.5) / kAngles;
    const float r = radii[i % 5];
    yx.push_back({{static_cast<float>(r * std::sin(t)), static_cast<float>(r * std::cos(t))}});
  }
  for (float sy : {1.0f, -1.0f})  // |y| = |x| and its float neighbours
    for (float sx : {1.0f, -1.0f}) {
      float y = 0.75f;
      for (int step = 0; step < 8; ++step) y = std::nextafter(y, 0.0f);
      for (int step = 0; step < 17; ++step, y = std::nextafter(y, 1.0f))
        yx.push_back({{sy * y, sx * 0.75f}});
    }
  const std::size_t axes = yx.size();
  const float axis_points[][3] = {// y, x, expected
                                  {0.0f, 1.0f, 0.0f},         {-0.0f, 1.0f, -0.0f},
                                  {0.0f, -1.0f, kPiF},        {-0.0f, -1.0f, -kPiF},
                                  {1.0f, 0.0f, 0.5f * kPiF},  {-1.0f, 0.0f, -0.5f * kPiF},
                                  {1.0f, -0.0f, 0.5f * kPiF}, {0.0f, 0.0f, 0.0f},
                                  {0.0f, -0.0f, kPiF},        {-0.0f, -0.0f, -kPiF}};
  for (const auto& p : axis_points) yx.push_back({{p[0], p[1]}});
  const auto count = static_cast<std::uint32_t>(yx.size());
  cl::Buffer in = h.buffer(yx), out = h.buffer<float>(count);
  h.run("atan2_poly_at", count, in, count, out);
  const auto v = h.read<float>(out, count);
  double worst = 0.0;
  for (std::size_t i = 0; i < axes; ++i)
    worst = std::max(worst, std::fabs(v[i] - std::atan2(double(yx[i].s[0]), double(yx[i].s[1]))));
  std::cout << "  atan2_poly: largest error " << worst << " over " << axes << " points\n";
  EXPECT_LE(worst, 4.8e-7);
  for (std::size_t k = 0; k < std::size(axis_points); ++k) {
    const float got = v[axes + k], want = axis_points[k][2];
    EXPECT_EQ(got, want) << "atan2_poly(" << axis_points[k][0] << ", " << axis_points[k][1] << ")";
    EXPECT_EQ(std::signbit(got), std::signbit(want))
        << "atan2_poly(" << axis_points[k][0] << ", " << axis_points[k][1] << ")";
  }
}

// The other functions of kernels/util/elementary.h against double precision: each at 2^20 or more
// arguments, its error in u = 2^-24 relative to the exact value (half an ulp), against the bound
// that header states, derived here from its steps (a correctly rounded + - * / rounds by at most u
// relative; Taylor and series remainders as that header gives them), and its special values. The
// derivations take division as correctly rounded, as on PoCL's CPU devices; OpenCL allows a
// device 2.5 ulp there, which could exceed them (on a lent NVIDIA H200 the measured errors stayed
// within them: docs/performance.md, "On an NVIDIA H200").
class Elementary : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { h_ = new wp::test::KernelHarness({"trig_kernels.cl"}); }
  static void TearDownTestSuite() {
    delete h_;
    h_ = nullptr;
  }
  // fn (elementary_at's numbering) at each (x, y).
  static std::vector<float> run(std::uint32_t fn, const std::vector<cl_float2>& in) {
    const auto count = static_cast<std::uint32_t>(in.size());
    cl::Buffer b = h_->buffer(in), out = h_->buffer<float>(count);
    h_->run("elementary_at", count, b, count, fn, out);
    return h_->read<float>(out, count);
  }
  // Positive finite floats with uniformly random bit patterns in [lo, hi] (all binades alike).
  static std::vector<cl_float2> random_bits(float lo, float hi, std::uint32_t n,
                                            std::uint32_t seed) {
    std::uint32_t a, b;
    std::memcpy(&a, &lo, 4), std::memcpy(&b, &hi, 4);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<std::uint32_t> bits(a, b);
    std::vector<cl_float2> v(n);
    for (auto& p : v) {
      const std::uint32_t w = bits(rng);
      std::memcpy(&p.s[0], &w, 4);
      p.s[1] = 0.0f;
    }
    return v;
  }
  static double error_u(float got, double exact) {
    return std::fabs(double(got) - exact) / (std::fabs(exact) * 0x1p-24);
  }
  // The largest error_u of fn at the x of each argument against exact, printed with `name`.
  static double worst_u(std::uint32_t fn, const std::vector<cl_float2>& in, double (*exact)(double),
                        const char* name) {
    const std::vector<float> v = run(fn, in);
    double worst = 0.0;
    for (std::size_t i = 0; i < in.size(); ++i)
      worst = std::max(worst, error_u(v[i], exact(double(in[i].s[0]))));
    std::cout << "  " << name << ": largest error " << worst << " u over " << in.size()
              << " points\n";
    return worst;
  }
  static wp::test::KernelHarness* h_;
};
wp::test::KernelHarness* Elementary::h_ = nullptr;

// exp_poly. n ln2_hi is exact and x - n ln2_hi too (Sterbenz: x and n ln2_hi are within a factor 2
// where n != 0); ln2_lo's product and the subtraction round r by u |r| and ln2_hi + ln2_lo is off
// ln 2 by 5e-15, |n| <= 128 times: e^r moves by u |r| <= 0.35 u. The Taylor remainder is below
// 1.1e-8 = 0.18 u relative. Horner's steps p_k = c_k + r p_(k+1): each rounds by u of its value,
// and the error of p_(k+1) reaches p_k scaled by |r p_(k+1) / p_k| <= 0.35 / 0.7 (inner steps
// smaller still): the last two steps' u each plus the geometric rest, under 2.3 u; the powers of
// two are exact: 0.35 + 0.18 + 2.3 < 3 u. Arguments from -87.3 to 88.7 (results normal), and
// below, where the results are subnormal.
TEST_F(Elementary, Exp) {
  std::vector<cl_float2> in;
  constexpr int kN = 1 << 20;
  for (int i = 0; i < kN; ++i)
    in.push_back({{-87.3f + 176.0f * (static_cast<float>(i) + 0.5f) / kN, 0.0f}});
  for (int i = 0; i < 4096; ++i) in.push_back({{std::ldexp(float(i) - 2048.0f, -30), 0.0f}});
  EXPECT_LE(worst_u(
                0, in, [](double x) { return std::exp(x); }, "exp_poly"),
            3.0);
  // Subnormal results (x from -103.97 to -87.34): the normal result's 3 u plus the last product's
  // rounding to a multiple of 2^-149.
  std::vector<cl_float2> low;
  for (int i = 0; i <= 1000; ++i)
    low.push_back({{-103.9f + 16.5f * static_cast<float>(i) / 1000, 0}});
  const std::vector<float> lv = run(0, low);
  for (std::size_t i = 0; i < low.size(); ++i) {
    const double exact = std::exp(double(low[i].s[0]));
    EXPECT_LE(std::fabs(lv[i] - exact), 3.0 * 0x1p-24 * exact + 0x1p-150) << "x " << low[i].s[0];
  }
  const float inf = INFINITY;
  const std::vector<float> special =
      run(0, {{{0.0f, 0}}, {{-inf, 0}}, {{inf, 0}}, {{NAN, 0}}, {{88.8f, 0}}, {{-104.0f, 0}}});
  EXPECT_EQ(special[0], 1.0f);
  EXPECT_EQ(special[1], 0.0f);
  EXPECT_EQ(special[2], inf);
  EXPECT_TRUE(std::isnan(special[3]));
  EXPECT_EQ(special[4], inf);
  EXPECT_EQ(special[5], 0.0f);
}

// log_poly. m - 1 is exact; s = f / (2 + f) rounds twice (2 u relative); the series' remainder is
// below 3e-11, and 1 + q with q <= 0.0099 carries s's error and the sum's u: ln m within 3.1 u
// relative (2 s q adds u q). With e != 0 the sum's two steps round by u of |e ln 2| and of the
// result, and |ln m| <= ln(2) / 2 <= |result| keeps ln m's 3.1 u below 3.1 u of the result: within
// 4 u where e != 0 and 3.1 u where e = 0. Over every binade of positive floats, subnormals
// included, and densely near 1, where the result is smallest.
TEST_F(Elementary, Log) {
  std::vector<cl_float2> in = random_bits(1e-45f, 3.4e38f, 1 << 20, 20261127);
  for (int i = -4096; i <= 4096; ++i)
    if (i != 0) in.push_back({{1.0f + std::ldexp(float(i), -23), 0.0f}});
  EXPECT_LE(worst_u(
                1, in, [](double x) { return std::log(x); }, "log_poly"),
            4.0);
  const float inf = INFINITY;
  const std::vector<float> special =
      run(1, {{{1.0f, 0}}, {{0.0f, 0}}, {{inf, 0}}, {{-1.0f, 0}}, {{NAN, 0}}});
  EXPECT_EQ(special[0], 0.0f);
  EXPECT_EQ(special[1], -inf);
  EXPECT_EQ(special[2], inf);
  EXPECT_TRUE(std::isnan(special[3]));
  EXPECT_TRUE(std::isnan(special[4]));
}

// log1p_poly on (-1/2, 1/2), where the kernels use it: s = y / (2 + y) rounds twice (2 u), the
// series to s^17 leaves 1e-10 and 1 + q (q <= 0.038) adds u: within 3.1 u, as log_poly's e = 0
// case. Uniform over the interval and at tiny arguments of both signs (where 1 + y rounds to 1).
TEST_F(Elementary, Log1p) {
  std::vector<cl_float2> in;
  constexpr int kN = 1 << 20;
  for (int i = 0; i < kN; ++i) in.push_back({{-0.5f + (static_cast<float>(i) + 0.5f) / kN, 0.0f}});
  for (int e = -126; e < -1; ++e)
    for (float sign : {1.0f, -1.0f}) in.push_back({{sign * std::ldexp(1.3f, e), 0.0f}});
  EXPECT_LE(worst_u(
                2, in, [](double x) { return std::log1p(x); }, "log1p_poly"),
            4.0);
  const std::vector<float> zero = run(2, {{{0.0f, 0}}, {{-0.0f, 0}}});
  EXPECT_EQ(zero[0], 0.0f);
  EXPECT_TRUE(std::signbit(zero[1]));
}

// powr_poly(x, c) = exp_poly(c log_poly(x)): log's 4 u and the product's u make the exponent t
// off by 5 u |t| (absolute), which e^t turns into 5 u |t| relative, and exp's own 3 u: within
// (3 + 5 |c ln x|) u. cbrt_poly likewise with c = 1/3 rounded (u relative more in t): within
// (3 + 6 |ln x| / 3) u. x over (0, 1] (every binade) with c in [0.1, 0.3], as sheen's fit takes;
// cube roots over all positive floats; and x = 0.
TEST_F(Elementary, PowrAndCbrt) {
  std::vector<cl_float2> in = random_bits(1e-45f, 1.0f, 1 << 20, 7);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> exponent(0.1f, 0.3f);
  for (auto& p : in) p.s[1] = exponent(rng);
  const std::vector<float> v = run(3, in);
  double worst = 0.0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const double x = in[i].s[0], c = in[i].s[1];
    const double bound = 3.0 + 5.0 * std::fabs(c * std::log(x));
    worst = std::max(worst, error_u(v[i], std::pow(x, c)) / bound);
  }
  std::cout << "  powr_poly: largest error " << worst << " of the bound\n";
  EXPECT_LE(worst, 1.0);
  const std::vector<cl_float2> roots = random_bits(1e-45f, 3.4e38f, 1 << 20, 13);
  const std::vector<float> r = run(4, roots);
  worst = 0.0;
  for (std::size_t i = 0; i < roots.size(); ++i) {
    const double x = roots[i].s[0];
    const double bound = 3.0 + 6.0 * std::fabs(std::log(x)) / 3.0;
    worst = std::max(worst, error_u(r[i], std::cbrt(x)) / bound);
  }
  std::cout << "  cbrt_poly: largest error " << worst << " of the bound\n";
  EXPECT_LE(worst, 1.0);
  const std::vector<float> zero = run(3, {{{0.0f, 0.2f}}});
  EXPECT_EQ(zero[0], 0.0f);
  EXPECT_EQ(run(4, {{{0.0f, 0}}})[0], 0.0f);
}

// log2_poly = log_poly / ln 2: log's 4 u (3.1 u where the result is smallest, near 1, as
// Elementary.Log derives) and the product's u: within 5 u. cos_poly: the turns x / (2 pi) off by
// 2 u of themselves (the float constant and the product; the whole turns come off exactly), 2 u
// |x| in the angle, and cos_sin_turn's 4e-7 (Sampling.CosSinTurn): within 4e-7 + 1.2e-7 |x|, over
// |x| <= 200 (iridescence's arguments grow with the film's optical path, but past a few hundred
// radians the Gaussian factor that multiplies the cosine there is below 1e-7).
TEST_F(Elementary, Log2AndCos) {
  const std::vector<cl_float2> in = random_bits(1e-45f, 3.4e38f, 1 << 20, 17);
  EXPECT_LE(worst_u(
                5, in, [](double x) { return std::log2(x); }, "log2_poly"),
            5.0);
  std::vector<cl_float2> angles;
  constexpr int kN = 1 << 20;
  for (int i = 0; i < kN; ++i)
    angles.push_back({{-200.0f + 400.0f * (static_cast<float>(i) + 0.5f) / kN, 0.0f}});
  const std::vector<float> v = run(6, angles);
  double worst = 0.0;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double x = angles[i].s[0];
    worst = std::max(worst, std::fabs(v[i] - std::cos(x)) / (4e-7 + 1.2e-7 * std::fabs(x)));
  }
  std::cout << "  cos_poly: largest error " << worst << " of the bound\n";
  EXPECT_LE(worst, 1.0);
  EXPECT_EQ(run(6, {{{0.0f, 0}}})[0], 1.0f);
}

// The thin lens's disc sampler (kernels/camera/camera.h): uniform on the unit disc, pdf 1/pi.
// Binned into 16 rings of equal area (r^2 in steps of 1/16) x 32 sectors, each of probability
// 1/512, from 2^20 independent points of the square (a host Mersenne Twister, so the counts are
// multinomial and Pearson's statistic chi-square with 511 degrees of freedom); no point may fall
// outside the disc beyond float rounding (|p| <= 1 + 1e-6).
TEST(Sampling, ConcentricDisk) {
  wp::test::KernelHarness h({"trig_kernels.cl"});
  constexpr std::uint32_t kCount = 1u << 20;
  constexpr int kRings = 16, kSectors = 32;
  std::mt19937 rng(20261127);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<cl_float2> u(kCount);
  for (auto& p : u) p.s[0] = uniform(rng), p.s[1] = uniform(rng);
  cl::Buffer in = h.buffer(u), out = h.buffer<cl_float2>(kCount);
  h.run("concentric_disk_at", kCount, in, kCount, out);
  const auto v = h.read<cl_float2>(out, kCount);
  std::vector<double> observed(kRings * kSectors, 0.0),
      expected(kRings * kSectors, double(kCount) / (kRings * kSectors));
  for (const cl_float2& p : v) {
    const double r2 = double(p.s[0]) * p.s[0] + double(p.s[1]) * p.s[1];
    ASSERT_LE(r2, 1.0 + 2e-6) << p.s[0] << "," << p.s[1];
    const double phi = std::atan2(double(p.s[1]), double(p.s[0])) + 3.14159265358979323846;
    const int ring = std::min(kRings - 1, int(r2 * kRings));
    const int sector = std::min(kSectors - 1, int(phi / (2 * 3.14159265358979323846) * kSectors));
    observed[ring * kSectors + sector] += 1.0;
  }
  const wp::test::Chi2Result r = wp::test::chi2_test(observed, expected);
  EXPECT_GT(r.p_value, 1e-4) << r.detail;
}

TEST(Sampling, CosineHemisphere) {
  Config c{"cosine hemisphere", kCosine};
  c.all_valid = true;
  check_config(c);
}

// Reflection about visible GGX normals: a density over the whole sphere (below-horizon
// reflections included), so it integrates to 1 at every view angle. Its support ends where the
// microfacet normal reaches the horizon, z = -v.z, a jump in the pdf: the view angles have
// v.z = k/16, so that circle is a bin edge (acos(1/16) = 86.4 degrees: grazing).
// The default suite checks three roughnesses at three angles (normal, 60 degrees, grazing),
// ...Exhaustive (slow) five at five.
void check_ggx_visible_normals(std::initializer_list<float> alphas, std::initializer_list<int> ks) {
  for (float alpha : alphas)
    for (int k : ks) {
      char name[64];
      std::snprintf(name, sizeof name, "ggx alpha %.2f v.z %d/16", alpha, k);
      Config c{name, kGgx, kPoleOnNormal};
      c.a = direction(k / 16.0);
      c.a.w = alpha;
      c.all_valid = true;
      check_config(c);
    }
}

TEST(Sampling, GgxVisibleNormalReflection) {
  check_ggx_visible_normals({0.05f, 0.3f, 1.0f}, {16, 8, 1});
}
TEST(Sampling, GgxVisibleNormalReflectionExhaustive) {
  check_ggx_visible_normals({0.05f, 0.1f, 0.3f, 0.6f, 1.0f}, {16, 12, 8, 4, 1});
}

// glTF's metallic-roughness BRDF: the default suite checks two roughnesses at normal and grazing
// view in the saturated colour, ...Exhaustive (slow) four at three angles in both colours.
void check_gltf_brdf(std::initializer_list<float> roughnesses, std::initializer_list<float4> colors,
                     std::initializer_list<double> views) {
  for (float metallic : {0.0f, 0.5f, 1.0f})
    for (float roughness : roughnesses)
      for (float4 color : colors)
        for (double view : views) check_bsdf(bsdf_config(metallic, roughness, color, view));
}

TEST(Sampling, GltfBrdf) {
  check_gltf_brdf({0.1f, 0.6f}, {kSaturated}, {0.0, 80.0});
}
TEST(Sampling, GltfBrdfExhaustive) {
  check_gltf_brdf({0.1f, 0.3f, 0.6f, 1.0f}, {kWhite, kSaturated}, {0.0, 45.0, 80.0});
}

// Roughness 0: the specular layer is a delta lobe; bsdf_eval's pdf is then the diffuse part
// alone, and metallic 1 leaves nothing but the delta lobe. The default suite takes the saturated
// colour at 45 and 80 degrees, ...Exhaustive (slow) both colours at three angles.
void check_smooth_specular(std::initializer_list<float4> colors,
                           std::initializer_list<double> views) {
  for (float metallic : {0.0f, 0.5f, 1.0f})
    for (float4 color : colors)
      for (double view : views) check_bsdf(bsdf_config(metallic, 0.0f, color, view));
}
TEST(Sampling, GltfBrdfSmoothSpecular) {
  check_smooth_specular({kSaturated}, {45.0, 80.0});
}
TEST(Sampling, GltfBrdfSmoothSpecularExhaustive) {
  check_smooth_specular({kWhite, kSaturated}, {0.0, 45.0, 80.0});
}

// The Lambert-only build (a scene without specular layers): the cosine lobe at every roughness,
// smooth included (no delta lobe), and f cos / pdf = base colour (the weight check). The default
// suite takes roughness 0 and 1 in the saturated colour at normal and grazing view,
// ...Exhaustive (slow) three roughnesses, both colours, three angles.
void check_lambert_only(std::initializer_list<float> roughnesses,
                        std::initializer_list<float4> colors, std::initializer_list<double> views) {
  for (float roughness : roughnesses)
    for (float4 color : colors)
      for (double view : views) {
        Config c = bsdf_config(0.0f, roughness, color, view);
        c.name += " lambert-only build";
        c.lambert_build = true;
        check_bsdf(c);
      }
}
TEST(Sampling, LambertOnlyBuild) {
  check_lambert_only({0.0f, 1.0f}, {kSaturated}, {0.0, 80.0});
}
TEST(Sampling, LambertOnlyBuildExhaustive) {
  check_lambert_only({0.0f, 0.5f, 1.0f}, {kWhite, kSaturated}, {0.0, 45.0, 80.0});
}

// Dielectric transmission (KHR_materials_transmission, ior 1.5), thin-walled and with a volume
// (KHR_materials_volume). "Inside" is what bsdf.h's Surface says: the normals always face wo, and
// WP_SURF_FRONT is clear on a WP_SURF_VOLUME surface when the ray arrived on the back side, from
// inside (relative ior 1 / 1.5; total internal reflection from 41.8 degrees on). Add a
// configuration by adding a line. The default suite takes each regime (thin-walled, entering,
// leaving, beyond the critical angle, every lobe) at two of its roughnesses or angles,
// ...Exhaustive (slow) every line.
std::vector<Config> dielectric_configs() {
  return {
      bsdf_config(0, 0.0f, kWhite, 30, 1, kFront),  // thin-walled
      bsdf_config(0, 0.3f, kWhite, 30, 1, kFront),
      bsdf_config(0, 0.7f, kWhite, 30, 1, kFront),
      bsdf_config(0, 0.3f, kWhite, 75, 1, kFront),
      bsdf_config(0, 0.0f, kWhite, 30, 1, kVolume | kFront),  // entering the volume
      bsdf_config(0, 0.3f, kWhite, 30, 1, kVolume | kFront),
      bsdf_config(0, 0.7f, kWhite, 30, 1, kVolume | kFront),
      bsdf_config(0, 0.3f, kWhite, 75, 1, kVolume | kFront),
      bsdf_config(0, 0.0f, kWhite, 30, 1, kVolume),  // leaving it
      bsdf_config(0, 0.3f, kWhite, 30, 1, kVolume),
      bsdf_config(0, 0.7f, kWhite, 30, 1, kVolume),
      bsdf_config(0, 0.0f, kWhite, 60, 1, kVolume),  // beyond the critical angle
      bsdf_config(0, 0.3f, kWhite, 60, 1, kVolume),
      bsdf_config(0, 0.7f, kWhite, 60, 1, kVolume),
      bsdf_config(0.5f, 0.3f, kSaturated, 30, 0.5f, kVolume | kFront),  // every lobe at once
      bsdf_config(0, 0.0f, kSaturated, 45, 0.5f, kFront),
  };
}
TEST(Sampling, DielectricTransmission) {
  const std::vector<Config> configs = dielectric_configs();
  for (const std::size_t i : {0, 3, 4, 7, 9, 10, 11, 13, 14, 15}) check_bsdf(configs[i]);
}
TEST(Sampling, DielectricTransmissionExhaustive) {
  for (const Config& c : dielectric_configs()) check_bsdf(c);
}

// The layered material extensions (kernels/bsdf/bsdf.h): every configuration is the whole BSDF, its
// samples against bsdf_eval's pdf as above, with fewer samples than kSamples to keep the run time
// down (the extensions' evaluation costs up to 3x the plain BSDF's; iridescence most). Power: a
// sampler that puts a fraction e of its samples where the pdf does not (a lobe's probability or
// density off by e, concentrated in bins of total probability p) adds ~N e^2 / p to a chi-square
// of ~1000 degrees of freedom (sigma ~45; p 1e-4 at ~+170): at N = 2^18 (kLayeredSamples) e = 0.8%
// within p = 0.1 fails, at N = 2^17 (kSweepSamples) e = 1.2%. The mass check resolves 5 binomial
// sigma of the valid fraction wherever the samples go: 1.4e-3 (2^18) or 1.9e-3 (2^17) where 98% of
// the samples are valid, at most 5e-3 or 7e-3 (half of them valid). (A coat sampled below
// its own tilted normal, which eval leaves out, put 0.5-4% of the samples there and failed both
// checks by far.) Bins follow the count (kTargetPerBin), so there are fewer to integrate.
constexpr std::uint32_t kLayeredSamples = 1u << 18, kSweepSamples = 1u << 17;
const float4 kSheenColor = {1.0f, 0.6f, 0.3f, 0}, kDtColor = {0.2f, 0.9f, 0.4f, 0};
// KHR_materials_specular's colour may exceed 1 (F0 = min(f0 colour, 1) per channel).
const float4 kSpecColor = {0.3f, 1.0f, 2.5f, 0};

// Each extension alone, on a base where it matters.
TEST(Sampling, LayeredEachAlone) {
  const std::vector<Config> configs = {
      with_coat(bsdf_config(0, 0.6f, kSaturated, 45), 1.0f, 0.3f),
      with_sheen(bsdf_config(0, 0.6f, kSaturated, 45), kSheenColor, 0.3f),
      with_specular(bsdf_config(0, 0.3f, kSaturated, 45), kSpecColor, 0.7f),
      with_specular(bsdf_config(0, 0.3f, kWhite, 30, 1, kVolume | kFront), kSpecColor),
      with_aniso(bsdf_config(1, 0.3f, kSaturated, 45), 0.8f, 30),
      with_iridescence(bsdf_config(0, 0.3f, kSaturated, 45), 1.0f),
      with_diffuse_transmission(bsdf_config(0, 0.6f, kSaturated, 45), 0.7f, kDtColor),
  };
  for (const Config& c : configs) check_bsdf(with_samples(c, kLayeredSamples));
}

// KHR_materials_clearcoat: smooth (a delta lobe about the coat normal) and rough coats over rough
// and smooth bases (then the base's delta lobes beside the coat's), metal and glass beneath, and
// coat normals tilted from ns: toward wo's azimuth, away from it (wo then grazes the coat) and
// across it. A smooth coat over a smooth metal is nothing but delta lobes.
TEST(Sampling, Clearcoat) {
  std::vector<Config> configs;
  for (float coat_r : {0.0f, 0.3f})
    for (float base_r : {0.0f, 0.6f})
      configs.push_back(with_coat(bsdf_config(0, base_r, kSaturated, 45), 1.0f, coat_r));
  configs.push_back(with_coat(bsdf_config(1, 0.0f, kSaturated, 80), 0.8f, 0.3f));
  configs.push_back(with_coat(bsdf_config(1, 0.0f, kSaturated, 30), 1.0f, 0.0f));
  configs.push_back(with_coat(bsdf_config(1, 0.6f, kSaturated, 45), 0.5f, 0.1f));
  configs.push_back(with_coat(bsdf_config(0, 0.3f, kWhite, 30, 1, kVolume | kFront), 1.0f, 0.3f));
  configs.push_back(with_coat(bsdf_config(0, 0.0f, kWhite, 30, 1, kFront), 1.0f, 0.3f));
  for (double azimuth : {0.0, 90.0, 180.0})
    configs.push_back(with_coat(bsdf_config(0, 0.6f, kSaturated, 60), 1.0f, 0.3f, 25, azimuth));
  configs.push_back(with_coat(bsdf_config(0, 0.6f, kSaturated, 45), 1.0f, 0.0f, 25, 90));
  configs.push_back(with_coat(bsdf_config(0, 0.6f, kSaturated, 60), 1.0f, 0.0f, 20, 180));
  // A rough coat seen near the horizon of its tilted normal: many of its reflections fall below
  // the coat (and some of those above ns).
  configs.push_back(with_coat(bsdf_config(1, 0.3f, kSaturated, 60), 1.0f, 0.6f, 30, 0));
  configs.push_back(with_coat(bsdf_config(1, 0.3f, kSaturated, 80), 1.0f, 0.6f, 30, 90));
  // (kSmooth integrates the jump of the coat's lobe at its own horizon, which cuts bins anywhere,
  // to the same totals as kEdges within 1e-4, at a third of the cost.)
  for (const Config& c : configs) check_bsdf(with_samples(c, kLayeredSamples));
}

// KHR_materials_sheen at sheen roughness 0.05, 0.3 and 1 seen at 0, 45 and 80 degrees, on a sheen
// over a dielectric and a metal, and under a rough and a smooth coat.
TEST(Sampling, Sheen) {
  std::vector<Config> configs;
  for (float r : {0.05f, 0.3f, 1.0f})
    for (double view : {0.0, 45.0, 80.0})
      configs.push_back(with_sheen(bsdf_config(0, 0.6f, kSaturated, view), kSheenColor, r));
  configs.push_back(with_sheen(bsdf_config(1, 0.3f, kSaturated, 45), kSheenColor, 0.5f));
  configs.push_back(
      with_coat(with_sheen(bsdf_config(0, 0.6f, kSaturated, 45), kSheenColor, 0.5f), 1, 0.3f));
  configs.push_back(
      with_coat(with_sheen(bsdf_config(0, 0.6f, kSaturated, 70), kSheenColor, 0.5f), 1, 0.0f));
  for (const Config& c : configs) check_bsdf(with_samples(c, kSweepSamples));
}

// KHR_materials_anisotropy: strengths 0.3, 0.8 and 1 with the direction rotated 0, 30 and 90
// degrees from wo's azimuth, every pair on a metal; on glass (thin-walled, entering a volume,
// leaving it: three code paths) each pair once, a Latin square, so that each path sees every
// strength and every rotation (all 27 would add ~10 s of CPU time); one narrow lobe (alpha 0.01
// across the direction). The default suite takes the metal's pairs as a Latin square too (each
// strength and rotation once), ...Exhaustive (slow) all nine.
void check_anisotropy(bool every_metal_pair) {
  const float strengths[3] = {0.3f, 0.8f, 1.0f};
  const double rotations[3] = {0.0, 30.0, 90.0};
  const Config metal = bsdf_config(1, 0.3f, kSaturated, 45);
  const Config glass[3] = {bsdf_config(0, 0.3f, kWhite, 45, 1, kFront),
                           bsdf_config(0, 0.3f, kWhite, 45, 1, kVolume | kFront),
                           bsdf_config(0, 0.3f, kWhite, 30, 1, kVolume)};
  for (int k = 0; k < 3; ++k)
    for (int r = 0; r < 3; ++r)
      if (every_metal_pair || r == k)
        check_bsdf(with_samples(with_aniso(metal, strengths[k], rotations[r]), kSweepSamples));
  for (int g = 0; g < 3; ++g)
    for (int k = 0; k < 3; ++k)
      check_bsdf(
          with_samples(with_aniso(glass[g], strengths[k], rotations[(k + g) % 3]), kSweepSamples));
  check_bsdf(
      with_samples(with_aniso(bsdf_config(1, 0.1f, kSaturated, 45), 0.8f, 30), kLayeredSamples));
}
TEST(Sampling, Anisotropy) {
  check_anisotropy(false);
}
TEST(Sampling, AnisotropyExhaustive) {
  check_anisotropy(true);
}

// KHR_materials_diffuse_transmission: thin-walled and into (and out of) a volume, with and without
// specular transmission beside it, over rough and smooth glass.
TEST(Sampling, DiffuseTransmission) {
  const std::vector<Config> configs = {
      bsdf_config(0, 0.6f, kSaturated, 45, 0, kFront),            // thin, no transmission
      bsdf_config(0, 0.3f, kWhite, 45, 0.5f, kFront),             // thin, with it
      bsdf_config(0, 0.6f, kSaturated, 45, 0, kVolume | kFront),  // into a volume
      bsdf_config(0, 0.3f, kWhite, 45, 0.5f, kVolume | kFront),
      bsdf_config(0, 0.3f, kWhite, 30, 0.5f, kVolume),           // out of it
      bsdf_config(0, 0.3f, kWhite, 60, 0.5f, kVolume),           // past the critical angle
      bsdf_config(0, 0.0f, kWhite, 30, 0.5f, kVolume | kFront),  // smooth glass
      bsdf_config(0, 0.0f, kSaturated, 45, 0.5f, kFront),
  };
  for (const Config& c : configs)
    check_bsdf(with_samples(with_diffuse_transmission(c, 0.6f, kDtColor), kSweepSamples));
}

// KHR_materials_iridescence: the thin film's Fresnel changes the lobe probabilities (and the
// reflection / transmission choice per microfacet), smooth surfaces' delta fractions included.
TEST(Sampling, Iridescence) {
  const std::vector<Config> configs = {
      with_iridescence(bsdf_config(1, 0.3f, kSaturated, 45), 1.0f),
      with_iridescence(bsdf_config(0, 0.3f, kSaturated, 45), 0.7f, 1.8f, 600),
      with_iridescence(bsdf_config(0, 0.3f, kWhite, 30, 1, kVolume | kFront), 1.0f),
      with_iridescence(bsdf_config(0, 0.0f, kSaturated, 60), 1.0f, 1.5f, 250),
      with_iridescence(bsdf_config(0, 0.0f, kWhite, 45, 0.7f, kFront), 1.0f),
  };
  for (const Config& c : configs) check_bsdf(with_samples(c, kSweepSamples));
}

// Every extension at once (dispersion aside: see the Dispersion tests below), entering a volume,
// leaving it and thin-walled.
TEST(Sampling, LayeredKitchenSink) {
  for (std::uint32_t flags : {kVolume | kFront, kVolume, kFront}) {
    Config c = bsdf_config(0.3f, 0.4f, kSaturated, 40, 0.4f, flags);
    c = with_coat(c, 0.7f, 0.2f, 15, 120);
    c = with_sheen(c, {0.5f, 0.7f, 0.9f, 0}, 0.5f);
    c = with_specular(c, {0.8f, 1.2f, 1.0f, 0}, 0.8f);
    c = with_aniso(c, 0.6f, 60);
    c = with_iridescence(c, 0.8f);
    c = with_diffuse_transmission(c, 0.5f, {0.3f, 0.8f, 0.6f, 0});
    check_bsdf(with_samples(c, kLayeredSamples));
  }
}

// KHR_materials_dispersion, a path of all three channels at a dispersive surface (c.disp.y 0):
// bsdf_sample chooses channel k (1 R, 2 G, 3 B) with probability 1/3 and samples channel k's BSDF,
// the surface with the path's channel k (docs/light-transport.md "Dispersion"). Checks:
// (a) the chosen channels' frequencies against 1/3 each: chi-square on 3 bins, p > 1e-4, and no
//     channel outside 1-3;
// (b) per channel k, the samples that chose it against the surface with channel k preset: the
//     chi-square of their directions against its bsdf_eval pdf and its mass (check_distribution),
//     and their delta fractions against its lobes (check_lobe_fractions): the distribution given
//     the channel is channel k's BSDF's;
// and per sample: the reported pdf is 0 (no light sample is taken there, bsdf_only_delta), the
// weight is 3 f_k |cos| / pdf_k on channel k and 0 on the others (relative 1e-5; f_k and pdf_k
// bsdf_eval's for channel k), and a delta sample lies on the exact direction for channel k's
// index (its refraction computed from the documented formula, path_ior in the .cl).
void check_channel_choice(const Config& c) {
  SCOPED_TRACE(c.name);
  const Draw d = Device::get(false).draw(c, "draw_channel_choice");
  EXPECT_EQ(d.pdf_error, 0.0) << "a pdf reported where the channel is chosen";
  EXPECT_LE(d.weight_error, 1e-5)
      << "weight vs 3 f_k |cos| / pdf_k on channel k (a delta sample: finite, >= 0, only on k)";
  EXPECT_LE(d.third_error, 1e-5) << "delta direction of the chosen channel's index";
  std::vector<double> observed(3, 0.0), expected(3, c.samples / 3.0);
  std::size_t outside = 0;
  Draw per[3];
  for (std::size_t i = 0; i < d.dirs.size(); ++i) {
    const float k = d.checks[i].w;
    if (!(k == 1.0f || k == 2.0f || k == 3.0f)) {
      ++outside;
      continue;
    }
    const auto j = static_cast<std::size_t>(k) - 1;
    observed[j] += 1.0;
    per[j].dirs.push_back(d.dirs[i]), per[j].checks.push_back(d.checks[i]);
  }
  EXPECT_EQ(outside, 0u) << "a channel outside 1-3";
  const auto r = wp::test::chi2_test(observed, expected);
  EXPECT_GT(r.p_value, 1e-4) << "channel frequencies vs 1/3: " << r.detail;
  std::printf("%-48s channels R %.4f G %.4f B %.4f | %s\n", c.name.c_str(), observed[0] / c.samples,
              observed[1] / c.samples, observed[2] / c.samples, r.detail.c_str());
  for (int k = 1; k <= 3; ++k) {
    Draw& dk = per[k - 1];
    tally(dk);
    Config ck = c;  // the same surface on a path of channel k
    ck.disp.y = static_cast<float>(k);
    ck.name += " | chose " + std::to_string(k);
    ck.samples = static_cast<std::uint32_t>(dk.dirs.size());
    if (ck.samples == 0) continue;  // (a) failed already
    check_distribution(ck, dk);
    check_lobe_fractions(ck, dk);
  }
}

// Dispersive glass (ior 1.5; dispersion 20: indices R 1.4013, G 1.6667, B 1.9525, critical
// angles 45.5, 36.9 and 30.8 degrees from inside), rough and smooth, entering and leaving, at a
// view where the channels disagree on total internal reflection (38 degrees: R refracts, G and B
// do not), a narrow lobe (roughness 0.1, dispersion 5) and every lobe at once (metal, diffuse and
// transmission beside each other).
TEST(Sampling, DispersionChannelChoice) {
  const std::vector<Config> configs = {
      with_dispersion(bsdf_config(0, 0.3f, kWhite, 45, 1, kVolume | kFront), 20, 0),
      with_dispersion(bsdf_config(0, 0.3f, kWhite, 38, 1, kVolume), 20, 0),
      with_dispersion(bsdf_config(0, 0.1f, kWhite, 30, 1, kVolume | kFront), 5, 0),
      with_dispersion(bsdf_config(0, 0.0f, kWhite, 45, 1, kVolume | kFront), 20, 0),
      with_dispersion(bsdf_config(0, 0.0f, kWhite, 38, 1, kVolume), 20, 0),
      with_dispersion(bsdf_config(0.3f, 0.4f, kSaturated, 40, 0.5f, kVolume | kFront), 5, 0),
  };
  for (const Config& c : configs) check_channel_choice(with_samples(c, kLayeredSamples));
}

// (c) A path that chose its channel earlier (Surface.channel preset): the surface is channel k's
// BSDF, an ordinary one, and check_bsdf holds it to bsdf_eval (pdf and weight of every sample,
// chi-square, mass, delta fractions; delta directions refracted with channel k's index by the
// documented formula, path_ior in the .cl).
TEST(Sampling, DispersionChannelPreset) {
  const std::vector<Config> configs = {
      with_dispersion(bsdf_config(0, 0.3f, kWhite, 45, 1, kVolume | kFront), 20, 1),
      with_dispersion(bsdf_config(0, 0.3f, kWhite, 38, 1, kVolume), 20, 3),  // B: past critical
      with_dispersion(bsdf_config(0, 0.3f, kWhite, 38, 1, kVolume), 20, 2),  // G: past it too
      with_dispersion(bsdf_config(0, 0.0f, kWhite, 45, 1, kVolume | kFront), 20, 3),
      with_dispersion(bsdf_config(0, 0.0f, kWhite, 38, 1, kVolume), 20, 1),  // R: not past it
      with_dispersion(bsdf_config(0.3f, 0.4f, kSaturated, 40, 0.5f, kVolume | kFront), 5, 2),
  };
  for (const Config& c : configs) check_bsdf(with_samples(c, kSweepSamples));
}

// Known answer: dispersion 0 (the feature compiled in, the factor 0) is the BSDF without
// dispersion: every bsdf_sample (direction, weight, pdf, eta_scale, valid, delta), bsdf_eval at a
// direction on the sphere and bsdf_only_delta are bit for bit those of the program built without
// KHR_materials_dispersion (WP_FEATURE_DISPERSION 0), on a path of all channels and on one that
// chose G. So is a thin-walled glass at dispersion 20 (the extension acts through a volume's
// refraction only). Glass smooth, at the delta threshold's far side (roughness 0.05) and rough,
// entering and leaving (past the critical angle too), every lobe at once, every extension.
TEST(Sampling, DispersionZeroIsTheBsdfWithoutIt) {
  std::vector<Config> configs;
  for (std::uint32_t flags : {kVolume | kFront, kVolume})
    for (float roughness : {0.0f, 0.05f, 0.3f})
      for (double view : {30.0, 60.0})
        configs.push_back(bsdf_config(0, roughness, kWhite, view, 1, flags));
  configs.push_back(bsdf_config(0.3f, 0.4f, kSaturated, 40, 0.5f, kVolume | kFront));
  Config sink = bsdf_config(0.3f, 0.4f, kSaturated, 40, 0.4f, kVolume | kFront);
  sink = with_coat(sink, 0.7f, 0.2f, 15, 120);
  sink = with_sheen(sink, {0.5f, 0.7f, 0.9f, 0}, 0.5f);
  sink = with_specular(sink, {0.8f, 1.2f, 1.0f, 0}, 0.8f);
  sink = with_aniso(sink, 0.6f, 60);
  sink = with_iridescence(sink, 0.8f);
  sink = with_diffuse_transmission(sink, 0.5f, {0.3f, 0.8f, 0.6f, 0});
  configs.push_back(sink);
  std::vector<Config> cases;
  for (const Config& c : configs)
    for (int channel : {0, 2}) cases.push_back(with_dispersion(c, 0.0f, channel));
  for (float roughness : {0.0f, 0.3f})
    cases.push_back(with_dispersion(bsdf_config(0, roughness, kWhite, 45, 1, kFront), 20, 0));
  constexpr std::uint32_t n = 1u << 14;
  Device& with = Device::get(false);
  Device& without = Device::without_dispersion();
  cl::Buffer out_with = with.harness().buffer<float4>(4 * std::size_t{n});
  cl::Buffer out_without = without.harness().buffer<float4>(4 * std::size_t{n});
  for (const Config& c : cases) {
    SCOPED_TRACE(c.name);
    with.run_config(c, "bsdf_queries", n, seed_of(c.name), n, out_with);
    without.run_config(c, "bsdf_queries", n, seed_of(c.name), n, out_without);
    const auto a = with.harness().read<float4>(out_with, 4 * std::size_t{n});
    const auto b = without.harness().read<float4>(out_without, 4 * std::size_t{n});
    std::size_t differ = 0, first = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (std::memcmp(&a[i], &b[i], sizeof(float4)) != 0 && differ++ == 0) first = i;
    if (differ > 0) {
      const float4 x = a[first], y = b[first];
      ADD_FAILURE() << std::setprecision(9) << differ << " of " << a.size()
                    << " float4s differ; the first, sample " << first / 4 << " part " << first % 4
                    << " (bsdf_queries): (" << x.x << ", " << x.y << ", " << x.z << ", " << x.w
                    << ") vs (" << y.x << ", " << y.y << ", " << y.z << ", " << y.w << ")";
    }
  }
}

// An emitting triangle seen from the origin (the shading point), binned around it.
TEST(Sampling, TriangleLight) {
  Config front{"triangle front", kTriangle};
  front.all_valid = true;
  front.quadrature = kEdges;
  Config near = front;  // large in view and oblique: the pdf varies ~10x over it
  near.name = "triangle near, oblique";
  near.triangle = {{-2, -0.5f, 0.3f, 1}, {0, 2, 0.2f, 1}, {3, -1, 0.5f, 1}};
  Config back_two = front;  // seen from behind, double-sided: emits toward the origin too
  back_two.name = "triangle back, double-sided";
  back_two.triangle = {front.triangle[0], front.triangle[2], front.triangle[1]};
  back_two.double_sided = true;
  Config back_one = back_two;  // seen from behind, single-sided: nothing valid
  back_one.name = "triangle back, single-sided";
  back_one.double_sided = false;
  back_one.all_valid = false;
  for (const Config& c : {front, near, back_two}) check_config(c);
  const Draw d = check_config(back_one);
  EXPECT_EQ(d.invalid, kSamples);
}

// Light picking from an alias table over uneven weights (zeros included): frequencies against
// the pmf by chi-square, zero-weight lights never picked, and each pick's reported pmf equal to
// weight / total. What is left of the number within the pick (which places the point on the light
// when the scene has few lights, lights.h) must be uniform on [0, 1) for each light: a
// chi-square of (light, 16 bins of it) against pmf / 16 per cell.
TEST(Sampling, LightPick) {
  std::vector<double> many(1000);
  for (std::size_t i = 0; i < many.size(); ++i)  // log-uniform over 4 decades, every 7th zero
    many[i] =
        i % 7 == 3 ? 0.0 : std::pow(10.0, 4.0 * std::fmod(0.618034 * static_cast<double>(i), 1.0));
  const std::vector<std::vector<double>> tables = {
      {1.0}, {0, 5, 0.5, 0, 20, 1, 1, 1e-3, 3, 0}, {0, 0, 1}, many};
  auto& h = Device::get(false).harness();
  cl::Buffer chosen = h.buffer<std::uint32_t>(std::size_t{kSamples});
  cl::Buffer pmfs = h.buffer<float>(std::size_t{kSamples});
  cl::Buffer rests = h.buffer<float>(std::size_t{kSamples});
  constexpr std::size_t kRestBins = 16;
  for (std::size_t t = 0; t < tables.size(); ++t) {
    SCOPED_TRACE("table " + std::to_string(t));
    const std::vector<double>& w = tables[t];
    const double total = std::accumulate(w.begin(), w.end(), 0.0);
    const auto alias = wp::build_alias_table(w);
    h.run("pick_lights", kSamples, static_cast<std::uint32_t>(w.size()), h.buffer(alias),
          seed_of("pick" + std::to_string(t)), kSamples, chosen, pmfs, rests);
    const auto idx = h.read<std::uint32_t>(chosen, kSamples);
    const auto pmf = h.read<float>(pmfs, kSamples);
    const auto rest = h.read<float>(rests, kSamples);
    std::vector<double> observed(w.size(), 0.0), expected(w.size());
    std::vector<double> joint(w.size() * kRestBins, 0.0), joint_expected(joint.size());
    double pmf_error = 0.0;
    for (std::size_t i = 0; i < kSamples; ++i) {
      ASSERT_LT(idx[i], w.size());
      ASSERT_TRUE(rest[i] >= 0.0f && rest[i] < 1.0f) << "rest " << rest[i];
      observed[idx[i]] += 1.0;
      joint[idx[i] * kRestBins + static_cast<std::size_t>(rest[i] * kRestBins)] += 1.0;
      const double p = w[idx[i]] / total;  // 0: caught below as observed_outside
      if (p > 0.0) pmf_error = std::max(pmf_error, std::fabs(pmf[i] - p) / p);
    }
    for (std::size_t i = 0; i < w.size(); ++i) {
      expected[i] = kSamples * w[i] / total;
      for (std::size_t b = 0; b < kRestBins; ++b)
        joint_expected[i * kRestBins + b] = expected[i] / kRestBins;
      EXPECT_NEAR(alias[i].pmf, w[i] / total, 1e-6 * w[i] / total) << "light " << i;
    }
    const auto rj = wp::test::chi2_test(joint, joint_expected);
    EXPECT_GT(rj.p_value, 1e-4) << "rest within the pick: " << rj.detail;
    const auto r = wp::test::chi2_test(observed, expected);
    EXPECT_EQ(r.observed_outside, 0.0) << "a zero-weight light was picked";
    if (w.size() > 1) {
      EXPECT_GT(r.p_value, 1e-4) << r.detail;
    }
    EXPECT_LE(pmf_error, 1e-6) << "reported pmf vs weight / total";
    std::printf("pick table %zu (%zu lights): %s\n", t, w.size(), r.detail.c_str());
  }
}

}  // namespace
