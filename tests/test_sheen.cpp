// The KHR_materials_sheen lobe (kernels/bsdf/sheen.h) on the device against this file's float64
// evaluation of the extension's formulas (sheen.h's header; written from the formulas, not from
// sheen.h's code), and the albedo table (kernels/bsdf/sheen_table.h,
// tools/generators/gen_sheen_table.py) against an independent quadrature.
//
// The reference albedo integrates over the microfacet normal h, where the generator integrates over
// wi: with d omega_i = 4 (wo.h) d omega_h and V cos_i = G / (4 mu),
//   E(mu) = (2 / mu) int_0^1 du D(u) int_0^phimax(u) G(mu, cos_i) (wo.h) dphi,   u = cos theta_h,
// cos_i = 2 (wo.h) u - mu, phimax where cos_i reaches 0 (wi at the horizon; none below
// u = cos(pi/4 + theta_o/2), the whole half-circle above cos(pi/4 - theta_o/2)). Both integrals
// are adaptive (an 8-node Gauss-Legendre rule on an interval against the same rule on its two
// halves, bisecting until they agree to the tolerance) after a smoothstep change of variable on
// each piece that flattens the square-root behaviour at the pieces' ends; the inner one is split
// where cos_i = 0.5 (Lambda's branches). The error estimate is the sum of the accepted
// differences (each bounds the error of the coarser rule, so it overstates that of the halves'
// sum) plus the inner integrals' largest relative estimate times E.
//
// Tolerances:
// - table entries: |table - E| <= WP_SHEEN_TABLE_QUAD_ERROR (the generator's stated bound: ten
//   times its largest 6- against 8-node difference) + this file's estimate + 2^-24 E (the entry is
//   the float nearest the generator's value);
// - sheen_eval, sheen_d, sheen_lambda: a first-order bound of float32 rounding computed per sample
//   from each operation's worst case in OpenCL 1.2's full profile (+ - * correctly rounded, x/y
//   2.5 ulp, exp 3, log 3, log1p 2 ulp, which bound kernels/util/elementary.h's exp_poly, log_poly
//   and log1p_poly too, and elementary.h's powr_poly, within (3 + 5 |c ln x|) u; 1 ulp <= 2 u
//   relative, u = 2^-24) propagated
//   to first order through the formulas with this sample's magnitudes (l_error, lambda_error,
//   d_error and the tests' own terms spell out each one), times 1.1 for the second-order terms
//   (relative size < 1e-4 of the first-order ones here); in a tilted frame plus the cosines' and
//   the cross product's rounding times f's sensitivities to them. Where D / K falls below FLT_MIN
//   the device may flush it to 0, which is allowed;
// - sheen_albedo off the nodes: the stated interpolation bound of sheen_table.h for the part of
//   the table (WP_SHEEN_TABLE_INTERP_ERROR for mu >= 8/31^3, _GRAZING below) + the entries' bound
//   + this file's estimate + kLookupRounding;
// - energy (Sheen.Energy*): the table's row maxima + the interpolation bound against 1.
// None of these is statistical: a failure is a real discrepancy, not bad luck.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tests/kernel_harness.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kU = 0x1p-24;  // float32's unit roundoff: half an ulp, relative

// ---------------------------------------------------------------------------------------------
// The model in float64, from the extension's formulas.

struct Fit {
  double a, b, c, d, e;
};
double lerp(double p, double q, double t) {
  return p + (q - p) * t;
}
// The fit's coefficients: (value at alpha 1, value at alpha 0), interpolated by (1 - alpha)^2.
Fit fit(double alpha) {
  const double t = (1.0 - alpha) * (1.0 - alpha);
  return {lerp(21.5473, 25.3245, t), lerp(3.82987, 3.32435, t), lerp(0.19823, 0.16801, t),
          lerp(-1.97760, -1.27393, t), lerp(-4.32054, -4.85967, t)};
}
double l_fit(double x, const Fit& f) {
  return f.a / (1.0 + f.b * std::pow(x, f.c)) + f.d * x + f.e;
}
double lambda(double c, const Fit& f) {
  return c < 0.5 ? std::exp(l_fit(c, f)) : std::exp(2.0 * l_fit(0.5, f) - l_fit(1.0 - c, f));
}
double charlie_k(double alpha) {
  return (2.0 + 1.0 / alpha) / (2.0 * kPi);
}
double charlie_d(double sin2, double alpha) {
  return charlie_k(alpha) * std::pow(sin2, 0.5 / alpha);
}

// ---------------------------------------------------------------------------------------------
// Adaptive quadrature.

struct Quad {
  double value, error;
};

struct Rule {
  double x[8], w[8];  // Gauss-Legendre on [-1, 1]
};
Rule gauss_legendre8() {
  Rule r{};
  const int n = 8;
  for (int k = 0; k < n; ++k) {
    double x = std::cos(kPi * (k + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int m = 2; m <= n; ++m) {
        const double p2 = ((2 * m - 1) * x * p1 - (m - 1) * p0) / m;
        p0 = p1, p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::fabs(dx) < 1e-16) break;
    }
    r.x[k] = x, r.w[k] = 2.0 / ((1.0 - x * x) * dp * dp);
  }
  return r;
}
const Rule kRule = gauss_legendre8();

template <class F>
double gauss(const F& f, double a, double b) {
  const double h = 0.5 * (b - a), m = 0.5 * (a + b);
  double s = 0.0;
  for (int k = 0; k < 8; ++k) s += kRule.w[k] * f(m + h * kRule.x[k]);
  return h * s;
}

// Globally adaptive: [a, b] cut into `initial` equal intervals, then the interval whose halves'
// sum differs most from its own rule is split until the differences add up to at most tol, or
// there are max_intervals intervals. (Starting from one interval, the whole's and the halves'
// rules can agree by chance across a feature they both miss: 1 of ~1000 random E's came out 12
// times further off than its estimate; from 8, none came out further than a quarter of it.)
template <class F>
Quad adaptive(const F& f, double a, double b, double tol, int initial, int max_intervals) {
  struct Interval {
    double a, b, whole, halves, error;
    bool operator<(const Interval& o) const { return error < o.error; }
  };
  const auto make = [&](double lo, double hi, double whole) {
    const double m = 0.5 * (lo + hi), halves = gauss(f, lo, m) + gauss(f, m, hi);
    return Interval{lo, hi, whole, halves, std::fabs(halves - whole)};
  };
  std::vector<Interval> heap;
  for (int k = 0; k < initial; ++k) {
    const double lo = a + (b - a) * k / initial, hi = a + (b - a) * (k + 1) / initial;
    heap.push_back(make(lo, hi, gauss(f, lo, hi)));
  }
  std::make_heap(heap.begin(), heap.end());
  double value = 0.0, error = 0.0;
  for (const Interval& c : heap) value += c.halves, error += c.error;
  while (error > tol && int(heap.size()) < max_intervals) {
    std::pop_heap(heap.begin(), heap.end());
    const Interval worst = heap.back();
    heap.pop_back();
    const double m = 0.5 * (worst.a + worst.b);
    const double left = gauss(f, worst.a, m), right = gauss(f, m, worst.b);
    for (const Interval& c : {make(worst.a, m, left), make(m, worst.b, right)}) {
      heap.push_back(c);
      std::push_heap(heap.begin(), heap.end());
    }
    value = 0.0, error = 0.0;  // re-summed: no drift from repeated subtraction
    for (const Interval& c : heap) value += c.halves, error += c.error;
  }
  return {value, error};
}

// The integral of f over the pieces [cuts[k], cuts[k + 1]] to relative tolerance rel (of the
// whole: an 8-node estimate of each piece first sets the absolute tolerance, shared out by
// width), each in t with x = a + (b - a) s(t), s(t) = t^2 (3 - 2 t) (s' = 0 at both ends).
template <class F>
Quad integrate(const F& f, const std::vector<double>& cuts, double rel, int initial) {
  std::vector<std::function<double(double)>> pieces;
  double rough = 0.0;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k], b = cuts[k + 1];
    pieces.push_back([&f, a, b](double t) {
      return b > a ? f(a + (b - a) * t * t * (3.0 - 2.0 * t)) * (b - a) * 6.0 * t * (1.0 - t) : 0.0;
    });
    rough += std::fabs(gauss(pieces.back(), 0.0, 1.0));
  }
  const double width = cuts.back() - cuts.front();
  Quad total = {0.0, 0.0};
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    if (!(cuts[k + 1] > cuts[k])) continue;
    const double share = (cuts[k + 1] - cuts[k]) / width;
    const Quad q = adaptive(pieces[k], 0.0, 1.0, rel * rough * share + 1e-300, initial, 64);
    total.value += q.value, total.error += q.error;
  }
  return total;
}

// E(mu) at alpha (file comment). The tolerances are relative to the integrals: 1e-6 of E; the
// estimates that come back (up to ~2e-6) are what the tests add to their tolerances. Against runs
// at 1e-10 over 1000 random (mu, roughness) no E was off by more than a quarter of its estimate
// (+ 1e-8). ~3 ms per E.
constexpr double kInnerRel = 1e-7, kOuterRel = 1e-6;
Quad albedo(double mu, double alpha) {
  const Fit f = fit(alpha);
  const double so = std::sqrt((1.0 - mu) * (1.0 + mu)), g_o = 1.0 + lambda(mu, f);
  const double theta_o = std::acos(mu);
  const double u_lo = std::cos(kPi / 4 + theta_o / 2), u_full = std::cos(kPi / 4 - theta_o / 2);
  double inner_rel = 0.0;
  const auto outer = [&](double u) {
    const double s = std::sqrt((1.0 - u) * (1.0 + u));
    // cos_i > 0 <=> cos(phi) > q = mu (1 - 2u^2) / (2 u so s)
    const double num = mu * (1.0 - 2.0 * u * u), den = 2.0 * u * so * s;
    if (!(u > 0.0) || num >= den) return 0.0;
    const double phimax = num <= -den ? kPi : std::acos(num / den);
    const auto g = [&](double phi) {
      const double oh = so * s * std::cos(phi) + mu * u, ci = 2.0 * oh * u - mu;
      return ci > 0.0 ? oh / (g_o + lambda(std::min(ci, 1.0), f)) : 0.0;
    };
    // cos_i = 0.5 where cos(phi) = (0.5 + mu (1 - 2u^2)) / (2 u so s).
    double split = phimax;
    if (den > 0.0) {
      const double c = (0.5 + num) / den;
      if (c > std::cos(phimax) && c < 1.0) split = std::acos(c);
    }
    const Quad q = integrate(g, {0.0, split, phimax}, kInnerRel, 2);
    if (q.value > 0.0) inner_rel = std::max(inner_rel, q.error / q.value);
    return charlie_d(s * s, alpha) * q.value;
  };
  // Pieces: [u_lo, u_full] cut geometrically from u_lo (the phi range opens over u ~ mu, a
  // feature the bisection would otherwise chase down from the whole interval), and [u_full, 1].
  std::vector<double> cuts = {u_lo};
  for (double u = 4.0 * u_lo; u < 0.25 * u_full; u *= 4.0) cuts.push_back(u);
  cuts.push_back(u_full);
  cuts.push_back(1.0);
  const Quad q = integrate(outer, cuts, kOuterRel, 8);
  const double e = 2.0 / mu * q.value;
  return {e, 2.0 / mu * q.error + inner_rel * e};
}

// ---------------------------------------------------------------------------------------------
// The first-order float32 error bound of sheen.h's evaluation (file comment), relative.

// Relative error of the device's Lambda at an exact float cosine x, over the alpha's fit. Each
// coefficient mix(p, q, t) = p + (q - p) t, t = (1 - alpha)^2 (3 u), carries the float rounding of
// its two literals (u each, relative) and 2 more roundings: <= 3 u + 5 u |q - p| / |mix|, under
// 6 u for all five. l = a / (1 + b P) + d x + e with P = powr_poly(x, c): P's own (3 + 5 |c ln x|)
// u plus c's 6 u times |c ln x|; b P 6 u more; the quotient 2.5 ulp = 5 u and a's 6 u; d x 7 u; e 6
// u; two sums u each of their magnitude.
double l_error(double x, const Fit& f) {
  const double p = std::pow(x, f.c), bp = f.b * p;
  const double t1 = f.a / (1.0 + bp), t2 = f.d * x;
  const double rel_p = 3.0 + 11.0 * std::fabs(f.c * std::log(std::max(x, 1e-300)));
  const double rel_t1 = 6.0 + 5.0 + (rel_p + 6.0 + 1.0) * bp / (1.0 + bp);
  return kU * (std::fabs(t1) * rel_t1 + std::fabs(t2) * 7.0 + std::fabs(f.e) * 6.0 +
               2.0 * (std::fabs(t1) + std::fabs(t2) + std::fabs(f.e)));
}
double lambda_error(double x, const Fit& f) {  // relative; exp adds 3 ulp
  if (x < 0.5) return l_error(x, f) + 6.0 * kU;
  const double l = 2.0 * l_fit(0.5, f) - l_fit(1.0 - x, f);
  return 2.0 * l_error(0.5, f) + l_error(1.0 - x, f) + kU * std::fabs(l) + 6.0 * kU;
}
// D = K exp(t), t = e L, e = 1 / (2 alpha), L = log(sin^2 theta_h) with absolute error dl: K's
// 8 u (1 / alpha 5 u, + 2, * the float 1/(2 pi), its literal); e's 5 u; t's product u; exp 6 u;
// the product K exp u.
double d_error(double l, double dl, double alpha) {
  const double e = 0.5 / alpha, t = std::fabs(e * l);
  return e * dl + 6.0 * kU * t + 6.0 * kU + 8.0 * kU + kU;
}

// ---------------------------------------------------------------------------------------------

struct Layout {
  int nmu = 0, nr = 0;
  double sqrt_rmin = 0, quad_error = 0, interp_error = 0, interp_grazing = 0;
  double roughness_min = 0, alpha_min = 0;
  std::vector<float> table;
  double entry(int i, int j) const { return table[std::size_t(j * nmu + i)]; }
  double mu(int i) const { return std::pow(double(i) / (nmu - 1), 3.0); }
  // The generator's node roughness, from WP_SHEEN_ROUGHNESS_MIN as a double (0.07 read back from
  // float: 3e-9 off, which moves E by < 1e-8).
  double roughness(int j) const {
    const double s0 = std::sqrt(roughness_min);
    return std::pow(s0 + (1.0 - s0) * j / (nr - 1), 2.0);
  }
};

// Device rounding of sheen_albedo's lookup: cbrt_poly ((3 + 2 |ln mu|) u,
// kernels/util/elementary.h) and the scaling put x off by < (4 + 2 |ln mu|) u x, x = 31 mu^(1/3):
// at most 6 e^(-1/3) 31 u (at mu = 1/e) <= 160 u cell widths, sqrt and its scaling y by < 10 u
// (sqrt(r) - s0) 31 / (1 - s0) < 250 u; times slopes below 0.5 per cell and the three mixes' few u
// E: < 250 u ~ 1.5e-5.
constexpr double kLookupRounding = 1.5e-5;

class Sheen : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    h_ = new wp::test::KernelHarness({"sheen_kernels.cl"});
    const cl_uint capacity = 8 + 32 * 32;
    cl::Buffer out = h_->buffer<float>(capacity);
    h_->run("table_info", 1, capacity, out);
    const std::vector<float> v = h_->read<float>(out, capacity);
    layout_ = new Layout;
    Layout& L = *layout_;
    if (v[0] != 32.0f || v[1] != 32.0f) {  // what this file's loops assume
      ADD_FAILURE() << "the table is " << v[0] << " x " << v[1] << ", not 32 x 32";
      return;
    }
    L.nmu = 32, L.nr = 32;
    L.sqrt_rmin = v[2], L.quad_error = v[3], L.interp_error = v[4], L.interp_grazing = v[5];
    L.roughness_min = v[6], L.alpha_min = v[7];
    L.table.assign(v.begin() + 8, v.end());
  }
  static void TearDownTestSuite() {
    delete h_;
    delete layout_;
    h_ = nullptr, layout_ = nullptr;
  }

  static std::vector<cl_float2> albedo_and_alpha(const std::vector<cl_float2>& in) {
    cl::Buffer a = h_->buffer(in), out = h_->buffer<cl_float2>(in.size());
    h_->run("albedo_and_alpha", in.size(), a, cl_uint(in.size()), out);
    return h_->read<cl_float2>(out, in.size());
  }

  static wp::test::KernelHarness* h_;
  static Layout* layout_;
};
wp::test::KernelHarness* Sheen::h_ = nullptr;
Layout* Sheen::layout_ = nullptr;

// The reference quadrature where the answer is known: D's projected area is 1
// (int D cos theta_h d omega_h), and E at alpha 1, mu 1 against a plain midpoint sum over wi.
TEST(SheenReference, KnownValues) {
  for (double alpha : {0.0049, 0.1, 1.0}) {
    const Quad q =
        integrate([&](double u) { return 2.0 * kPi * charlie_d((1.0 - u) * (1.0 + u), alpha) * u; },
                  {0.0, 1.0}, 1e-12, 8);
    EXPECT_NEAR(q.value, 1.0, 1e-10) << "alpha " << alpha;
  }
  // wo = n: h = (wo + wi) / |wo + wi| has sin^2 theta_h = (1 - cos_i) / 2 whatever phi, so
  // E = 2 pi / 4 int_0^1 D G dcos_i: a 1-d midpoint sum with 2e6 points (error ~1e-9 away from the
  // sqrt end point, ~1e-7 in all).
  const Fit f = fit(1.0);
  double sum = 0.0;
  const int n = 2000000;
  for (int k = 0; k < n; ++k) {
    const double ci = (k + 0.5) / n;
    sum += charlie_d(0.5 * (1.0 - ci), 1.0) / (1.0 + lambda(1.0, f) + lambda(ci, f));
  }
  EXPECT_NEAR(albedo(1.0, 1.0).value, 2.0 * kPi / 4.0 * sum / n, 1e-6);
}

// (a) Every entry against the independent quadrature; column 0 repeats column 1 (sheen_table.h).
TEST_F(Sheen, TableEntriesMatchIndependentQuadrature) {
  const Layout& L = *layout_;
  ASSERT_GT(L.nmu, 0);
  EXPECT_GT(L.quad_error, 0.0);
  EXPECT_LE(L.quad_error, 1e-4);  // the table's requirement
  EXPECT_NEAR(L.sqrt_rmin, std::sqrt(double(L.roughness_min)), 1e-7);
  double worst = 0.0, worst_ref_err = 0.0;
  for (int j = 0; j < L.nr; ++j) {
    const double r = L.roughness(j);
    EXPECT_EQ(L.entry(0, j), L.entry(1, j)) << "row " << j;
    for (int i = 1; i < L.nmu; ++i) {
      const Quad ref = albedo(L.mu(i), r * r);
      const double got = L.entry(i, j);
      const double tol = L.quad_error + ref.error + kU * ref.value;
      EXPECT_NEAR(got, ref.value, tol)
          << "mu " << L.mu(i) << " roughness " << r << " (quadrature error " << ref.error << ")";
      worst = std::max(worst, std::fabs(got - ref.value));
      worst_ref_err = std::max(worst_ref_err, ref.error);
    }
  }
  std::printf(
      "table: largest |entry - reference| %.2e, reference error estimate <= %.1e, "
      "stated entry bound %.0e\n",
      worst, worst_ref_err, L.quad_error);
}

// sheen_alpha: roughness^2 clamped into [WP_SHEEN_ROUGHNESS_MIN, 1], a NaN to the minimum.
TEST_F(Sheen, AlphaClamp) {
  const Layout& L = *layout_;
  const float rmin = float(L.roughness_min);
  const std::vector<cl_float2> in = {{{0.5f, 0.0f}}, {{0.5f, -1.0f}}, {{0.5f, rmin}},
                                     {{0.5f, 0.5f}}, {{0.5f, 1.0f}},  {{0.5f, 3.0f}},
                                     {{0.5f, NAN}},  {{0.5f, 1e-30f}}};
  const std::vector<float> want = {rmin * rmin, rmin * rmin, rmin * rmin, 0.25f,
                                   1.0f,        1.0f,        rmin * rmin, rmin * rmin};
  const auto out = albedo_and_alpha(in);
  for (std::size_t k = 0; k < in.size(); ++k)
    EXPECT_EQ(out[k].s[1], want[k]) << "roughness " << in[k].s[1];
  EXPECT_EQ(float(L.alpha_min), rmin * rmin);
}

// (b) sheen_eval, sheen_d and sheen_lambda against float64, n = +z (the cosines are the inputs'
// z exactly, so the bound is the evaluation's own rounding), at grazing and normal angles, alpha
// from roughness 0 (clamped) to 1.
TEST_F(Sheen, EvalMatchesFloat64) {
  const Layout& L = *layout_;
  const std::vector<double> cosines = {1e-7, 1e-6, 1e-5, 1e-4, 1e-3,     0.003, 0.01,
                                       0.03, 0.07, 0.1,  0.2,  0.3,      0.45,  0.5,
                                       0.55, 0.7,  0.9,  0.99, 0.999999, 1.0};
  const std::vector<double> azimuths = {0.0, 0.1, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.1, kPi};
  const std::vector<float> roughness = {0.0f, 0.01f, 0.0699f, 0.07f, 0.0701f, 0.08f,  0.1f, 0.2f,
                                        0.3f, 0.5f,  0.7f,    0.9f,  0.99f,   0.999f, 1.0f};
  std::vector<cl_float4> in;
  std::vector<double> alphas;  // what the kernel uses
  for (float r : roughness)
    for (double co : cosines)
      for (double ci : cosines)
        for (double phi : azimuths) {
          const float alpha = std::max(r * r, float(L.alpha_min));
          const float so = float(std::sqrt(1.0 - co * co)), si = float(std::sqrt(1.0 - ci * ci));
          in.push_back({{0.0f, 0.0f, 1.0f, 0.0f}});
          in.push_back({{so, 0.0f, float(co), r * r}});
          in.push_back({{si * float(std::cos(phi)), si * float(std::sin(phi)), float(ci), 0.0f}});
          alphas.push_back(alpha);
        }
  const std::size_t count = alphas.size();
  cl::Buffer bin = h_->buffer(in), bout = h_->buffer<cl_float4>(count);
  h_->run("eval_sheen", count, bin, cl_uint(count), bout);
  const auto out = h_->read<cl_float4>(bout, count);
  double worst_ratio = 0.0, worst_rel = 0.0;
  int failures = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const cl_float4 &wo = in[3 * k + 1], &wi = in[3 * k + 2];
    const double alpha = alphas[k];
    const Fit f = fit(alpha);
    const double co = wo.s[2], ci = wi.s[2];
    // The half vector of the given floats, in float64 (each sum exact or within 2^-53).
    const double sx = double(wo.s[0]) + wi.s[0], sy = double(wo.s[1]) + wi.s[1], sz = co + ci;
    const double len2 = sx * sx + sy * sy + sz * sz, sin2 = (sx * sx + sy * sy) / len2;
    const double lo = lambda(co, f), li = lambda(ci, f);
    const double g_inv = 1.0 + lo + li;
    const double d = charlie_d(sin2, alpha), ref = d / (4.0 * co * ci * g_inv);
    // The bound: cos^2 = (co + ci)^2 / len2 and sin^2 = |n x s|^2 / len2 (n = z: exact in s)
    // each within 13 u (s's components u, len2 5 u, the square 3 u, the quotient 5 u); L's own
    // 4 u (log1p) or 6 u (log) of |L|, and the input's 13 u passed on with cos^2 / (1 - cos^2)
    // <= 1 or 1.
    const double cos2 = sz * sz / len2, l = std::log(sin2);
    const double dl =
        13.0 * kU * (cos2 < 0.5 ? cos2 / (1.0 - cos2) : 1.0) + 6.0 * kU * std::fabs(l);
    const double g_rel =
        std::max(lambda_error(co, f), lambda_error(ci, f)) * (lo + li) / g_inv + 2.0 * kU;
    const double bound = d_error(l, dl, alpha) + g_rel + 2.0 * kU + 5.0 * kU;
    // D / K below FLT_MIN may be flushed to 0 on the device, and f below FLT_MIN too.
    const double slack = (charlie_k(alpha) + 1.0) * FLT_MIN / (4.0 * co * ci * g_inv) + FLT_MIN;
    const double got = out[k].s[0], err = std::fabs(got - ref);
    // (h = n: D = 0 exactly, and so must the device's be, to the flush.)
    const double allowed =
        ref > 0.0 ? 1.1 * bound * ref + (d / charlie_k(alpha) < 2.0 * FLT_MIN ? slack : 0.0)
                  : slack;
    if (ref > 1e-30) {
      worst_ratio = std::max(worst_ratio, err / (bound * ref));
      worst_rel = std::max(worst_rel, err / ref);
    }
    // Lambda alone: its own bound.
    const double lam_tol[2] = {1.1 * lambda_error(co, f) * lo, 1.1 * lambda_error(ci, f) * li};
    const bool ok = err <= allowed && std::isfinite(got) &&
                    std::fabs(out[k].s[1] - lo) <= lam_tol[0] &&
                    std::fabs(out[k].s[2] - li) <= lam_tol[1];
    if (!ok && ++failures <= 20)
      ADD_FAILURE() << "cos_o " << co << " cos_i " << ci << " wi (" << wi.s[0] << ", " << wi.s[1]
                    << ") alpha " << alpha << ": f " << got << " reference " << ref << " (allowed "
                    << allowed << "), Lambda " << out[k].s[1] << " / " << lo << ", " << out[k].s[2]
                    << " / " << li;
  }
  EXPECT_EQ(failures, 0);
  std::printf("sheen_eval: %zu samples, largest error %.2e relative, %.3f of the bound\n", count,
              worst_rel, worst_ratio);

  // sheen_d(cos_h) and sheen_lambda(cos) alone, cos_h from 0 to 1.
  std::vector<cl_float2> dl_in;
  for (float r : roughness)
    for (int k = 0; k <= 400; ++k) {
      const double c = k < 100 ? std::pow(10.0, -8.0 + 8.0 * k / 100.0) : (k - 100) / 300.0;
      dl_in.push_back({{float(c), std::max(r * r, float(L.alpha_min))}});
    }
  cl::Buffer din = h_->buffer(dl_in), dout = h_->buffer<cl_float2>(dl_in.size());
  h_->run("d_and_lambda", dl_in.size(), din, cl_uint(dl_in.size()), dout);
  const auto dv = h_->read<cl_float2>(dout, dl_in.size());
  failures = 0;
  for (std::size_t k = 0; k < dl_in.size(); ++k) {
    const double c = dl_in[k].s[0], alpha = dl_in[k].s[1];
    const double sin2 = (1.0 - c) * (1.0 + c), l = std::log(sin2);
    const double d = charlie_d(sin2, alpha);
    // cos^2 u; L's own 4 u / 6 u, the input's u / (1 - c^2) (log1p) or (1 - c)(1 + c)'s 2 u.
    const double dl = (c * c < 0.5 ? kU * c * c / sin2 : 2.0 * kU) + 6.0 * kU * std::fabs(l);
    const double tol = d > 0.0 ? 1.1 * d_error(l, dl, alpha) * d +
                                     (d / charlie_k(alpha) < 2.0 * FLT_MIN ? FLT_MIN : 0.0)
                               : FLT_MIN;
    const Fit f = fit(alpha);
    const double lam = lambda(c, f);
    if ((std::fabs(dv[k].s[0] - d) > tol ||
         std::fabs(dv[k].s[1] - lam) > 1.1 * lambda_error(c, f) * lam) &&
        ++failures <= 20)
      ADD_FAILURE() << "cos " << c << " alpha " << alpha << ": D " << dv[k].s[0] << " / " << d
                    << " (tolerance " << tol << "), Lambda " << dv[k].s[1] << " / " << lam;
  }
  EXPECT_EQ(failures, 0);
}

// (b) In a tilted frame, away from grazing (the cosines are float dot products there, with
// absolute errors up to 3 u, which grazing cosines cannot absorb): the bound adds the inputs'
// errors times f's sensitivities, from central differences of the float64 model.
TEST_F(Sheen, EvalInTiltedFrame) {
  const Layout& L = *layout_;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<cl_float4> in;
  std::vector<double> alphas;
  const double nx = 0.3, ny = -0.5, nz = 0.8, nl = std::sqrt(nx * nx + ny * ny + nz * nz);
  const cl_float4 n = {{float(nx / nl), float(ny / nl), float(nz / nl), 0.0f}};
  // A frame around n (float64), in which the directions are drawn.
  const double N[3] = {n.s[0], n.s[1], n.s[2]};
  double T[3] = {N[1], -N[0], 0.0};
  const double tl = std::sqrt(T[0] * T[0] + T[1] * T[1]);
  for (double& t : T) t /= tl;
  const double B[3] = {N[1] * T[2] - N[2] * T[1], N[2] * T[0] - N[0] * T[2],
                       N[0] * T[1] - N[1] * T[0]};
  const auto dir = [&](double c, double phi) {
    const double s = std::sqrt(1.0 - c * c);
    cl_float4 w;
    for (int k = 0; k < 3; ++k)
      w.s[k] = float(s * std::cos(phi) * T[k] + s * std::sin(phi) * B[k] + c * N[k]);
    w.s[3] = 0.0f;
    return w;
  };
  for (int k = 0; k < 4000; ++k) {
    const double r = k % 4 == 0 ? 0.0 : uni(rng);
    const float alpha = std::max(float(r * r), float(L.alpha_min));
    const double co = 0.05 + 0.95 * uni(rng), ci = 0.05 + 0.95 * uni(rng);
    in.push_back(n);
    cl_float4 wo = dir(co, 0.0);
    wo.s[3] = alpha;
    in.push_back(wo);
    in.push_back(dir(ci, 2.0 * kPi * uni(rng)));
    alphas.push_back(alpha);
  }
  const std::size_t count = alphas.size();
  cl::Buffer bin = h_->buffer(in), bout = h_->buffer<cl_float4>(count);
  h_->run("eval_sheen", count, bin, cl_uint(count), bout);
  const auto out = h_->read<cl_float4>(bout, count);
  int failures = 0;
  double worst_ratio = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const double alpha = alphas[k];
    const Fit f = fit(alpha);
    double wo[3], wi[3], s[3];
    for (int q = 0; q < 3; ++q)
      wo[q] = in[3 * k + 1].s[q], wi[q] = in[3 * k + 2].s[q], s[q] = wo[q] + wi[q];
    double co = 0, ci = 0, mo = 0, mi = 0;  // the dots and the sums of |products|
    for (int q = 0; q < 3; ++q) {
      co += N[q] * wo[q], ci += N[q] * wi[q];
      mo += std::fabs(N[q] * wo[q]), mi += std::fabs(N[q] * wi[q]);
    }
    const double x[3] = {N[1] * s[2] - N[2] * s[1], N[2] * s[0] - N[0] * s[2],
                         N[0] * s[1] - N[1] * s[0]};
    const double xm[3] = {std::fabs(N[1] * s[2]) + std::fabs(N[2] * s[1]),
                          std::fabs(N[2] * s[0]) + std::fabs(N[0] * s[2]),
                          std::fabs(N[0] * s[1]) + std::fabs(N[1] * s[0])};
    const double len2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
    const double x2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2], sin2 = x2 / len2;
    const double cos2 = (co + ci) * (co + ci) / len2;
    // f(co, ci, L) in float64 and its sensitivities.
    const auto model = [&](double c_o, double c_i, double l) {
      return charlie_k(alpha) * std::exp(0.5 / alpha * l) /
             (4.0 * c_o * c_i * (1.0 + lambda(c_o, f) + lambda(c_i, f)));
    };
    const double l = std::log(sin2), ref = model(co, ci, l);
    const auto sens = [&](int which) {  // |d ln f / d input|
      const double h = 1e-6;
      double a[3] = {co, ci, l}, b[3] = {co, ci, l};
      const double step = which == 2 ? h : h * a[which];
      a[which] += step, b[which] -= step;
      return std::fabs(std::log(model(a[0], a[1], a[2]) / model(b[0], b[1], b[2]))) / (2 * step);
    };
    // Input errors: a dot product of 3 terms within 3 u of the sum of |terms| (plus u for the
    // result's rounding); cross(n, s) per component within 3 u of its |terms| (s's u, the
    // products' and the difference's); L from |x|^2 / len2 or from cos^2 as in EvalMatchesFloat64.
    const double dco = 4.0 * kU * mo, dci = 4.0 * kU * mi;
    double dx2 = 3.0 * kU * x2;
    for (int q = 0; q < 3; ++q) dx2 += 2.0 * std::fabs(x[q]) * 3.0 * kU * xm[q];
    const double dl = cos2 < 0.5 ? cos2 / (1.0 - cos2) *
                                       (2.0 * (dco + dci + kU * (co + ci)) / (co + ci) + 11.0 * kU)
                                 : dx2 / x2 + 10.0 * kU;
    // The evaluation's own rounding at exact inputs (as in EvalMatchesFloat64) on top.
    const double lo = lambda(co, f), li = lambda(ci, f), g_inv = 1.0 + lo + li;
    const double own = d_error(l, 6.0 * kU * std::fabs(l), alpha) +
                       std::max(lambda_error(co, f), lambda_error(ci, f)) * (lo + li) / g_inv +
                       9.0 * kU;
    const double bound = own + sens(0) * dco + sens(1) * dci + sens(2) * dl;
    const double slack =
        std::exp(0.5 / alpha * l) < 2.0 * FLT_MIN
            ? (charlie_k(alpha) + 1.0) * FLT_MIN / (4.0 * co * ci * g_inv) + FLT_MIN
            : 0.0;
    const double got = out[k].s[0], err = std::fabs(got - ref);
    if (ref > 1e-30) worst_ratio = std::max(worst_ratio, err / (bound * ref));
    if (!(err <= 1.1 * bound * ref + slack) && ++failures <= 20)
      ADD_FAILURE() << "cos_o " << co << " cos_i " << ci << " alpha " << alpha << ": " << got
                    << " against " << ref << " (bound " << bound << " relative)";
  }
  EXPECT_EQ(failures, 0);
  std::printf("sheen_eval, tilted frame: %zu samples, largest error %.3f of the bound\n", count,
              worst_ratio);
}

// (c) sheen_albedo off the nodes against the quadrature; below mu_1 = 1/31^3 the table is flat.
TEST_F(Sheen, AlbedoInterpolationWithinStatedBound) {
  const Layout& L = *layout_;
  ASSERT_GT(L.nmu, 0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double mu1 = L.mu(1), mu2 = L.mu(2);
  std::vector<cl_float2> in;
  for (int k = 0; k < 400; ++k) {
    // cbrt(mu) uniform over [1/31, 1]; sqrt(roughness) uniform over [sqrt(r_min), 1], and some
    // roughness below the minimum (clamped: the minimum's row).
    const double x = (1.0 + 30.0 * uni(rng)) / 31.0;
    const double r = k % 10 == 0 ? L.roughness_min * uni(rng)
                                 : std::pow(L.sqrt_rmin + (1.0 - L.sqrt_rmin) * uni(rng), 2.0);
    in.push_back({{float(x * x * x), float(r)}});
  }
  const auto out = albedo_and_alpha(in);
  double worst[2] = {0.0, 0.0};
  for (std::size_t k = 0; k < in.size(); ++k) {
    const double mu = in[k].s[0], r = std::max(double(in[k].s[1]), L.roughness_min);
    const Quad ref = albedo(mu, r * r);
    const bool grazing = mu < mu2;
    const double bound = grazing ? L.interp_grazing : L.interp_error;
    const double err = std::fabs(out[k].s[0] - ref.value);
    worst[grazing] = std::max(worst[grazing], err);
    EXPECT_LE(err, bound + L.quad_error + ref.error + kLookupRounding)
        << "mu " << mu << " roughness " << in[k].s[1] << ": " << out[k].s[0] << " against "
        << ref.value;
  }
  std::printf(
      "sheen_albedo: largest error %.2e for mu >= %.2e (bound %.0e), %.2e below "
      "(bound %.0e)\n",
      worst[0], mu2, L.interp_error, worst[1], L.interp_grazing);
  // Flat below mu_1: the value at mu_1, to the lookup's rounding.
  std::vector<cl_float2> flat;
  for (double r : {0.0, 0.1, 0.5, 1.0})
    for (double mu : {0.0, 1e-12, 1e-7, 1e-5, mu1}) flat.push_back({{float(mu), float(r)}});
  const auto fv = albedo_and_alpha(flat);
  for (std::size_t k = 0; k < flat.size(); ++k)
    EXPECT_NEAR(fv[k].s[0], fv[k - k % 5 + 4].s[0], kLookupRounding)
        << "mu " << flat[k].s[0] << " roughness " << flat[k].s[1];
}

// (d) No NaN, infinity or negative value anywhere: cosines 0 (and -0), denormal, 1e-30 ... 1,
// azimuths including the mirror (pi) and retro (0) directions, alpha 0, denormal, NaN, inf, the
// minimum, 1 and above; three normals.
TEST_F(Sheen, FiniteEverywhere) {
  std::vector<float> cosines = {0.0f,        -0.0f, 1e-40f,    1e-38f, 1e-30f, 1e-20f,
                                1e-12f,      1e-7f, 1e-4f,     0.01f,  0.3f,   0.5f,
                                0.70710677f, 0.9f,  0.999999f, 1.0f,   -0.5f,  1.0000001f};
  for (int k = 1; k < 20; ++k) cosines.push_back(float(k) / 20.0f);
  const std::vector<float> azimuths = {0.0f, 1e-6f,      0.5f,       1.5707964f,
                                       3.0f, 3.1415925f, 3.1415927f, 4.0f};
  const std::vector<float> alphas = {0.0f, 1e-45f, 1e-30f, 1e-7f, 1e-4f, 0.0049f,  0.01f, 0.25f,
                                     0.5f, 0.99f,  1.0f,   2.0f,  1e30f, INFINITY, NAN,   -1.0f};
  const std::vector<cl_float4> normals = {
      {{0.0f, 0.0f, 1.0f, 0.0f}}, {{0.0f, 0.0f, -1.0f, 0.0f}}, {{0.36f, -0.48f, 0.8f, 0.0f}}};
  const cl_uint nc = cl_uint(cosines.size());
  cl::Buffer bc = h_->buffer(cosines), ba = h_->buffer(azimuths), bal = h_->buffer(alphas);
  cl::Buffer bn = h_->buffer(normals), out = h_->buffer<cl_uint>(std::size_t(nc) * nc);
  h_->run("finite_sweep", std::size_t(nc) * nc, bc, nc, ba, cl_uint(azimuths.size()), bal,
          cl_uint(alphas.size()), bn, cl_uint(normals.size()), out);
  const auto bad = h_->read<cl_uint>(out, std::size_t(nc) * nc);
  for (cl_uint i = 0; i < nc * nc; ++i)
    EXPECT_EQ(bad[i], 0u) << "cos_o " << cosines[i % nc] << " cos_i " << cosines[i / nc];
  // sheen_albedo and sheen_alpha at odd inputs.
  const auto v = albedo_and_alpha({{{NAN, NAN}},
                                   {{-1.0f, -1.0f}},
                                   {{2.0f, 2.0f}},
                                   {{INFINITY, INFINITY}},
                                   {{-INFINITY, -INFINITY}}});
  for (const cl_float2& x : v) EXPECT_TRUE(std::isfinite(x.s[0]) && std::isfinite(x.s[1]));
}

// (e) Energy. E <= 1 is what a single-scattering lobe should give; with the fitted Lambda it
// holds for roughness above ~0.26 and fails below, at grazing angles (sheen.h's header). The
// table rows are the quadrature's (TableEntriesMatchIndependentQuadrature), and between nodes E
// is within the interpolation bound of them: the row maxima + that bound decide.
TEST_F(Sheen, EnergyAtMostOneAboveRoughness026) {
  const Layout& L = *layout_;
  ASSERT_GT(L.nmu, 0);
  std::printf("max over mu >= %.2e of E (table nodes): roughness -> E\n", L.mu(1));
  for (int j = 0; j < L.nr; ++j) {
    double m = 0.0;
    for (int i = 1; i < L.nmu; ++i) m = std::max(m, L.entry(i, j));
    const double r = L.roughness(j);
    std::printf("  %.4f %.4f%s", r, m, j % 4 == 3 ? "\n" : "");
    if (r >= 0.26) {
      EXPECT_LE(m + L.interp_error, 1.0) << "roughness " << r;
    }
    if (r <= 0.25) {
      EXPECT_GT(m, 1.0) << "roughness " << r << ": E <= 1 now (update sheen.h)";
    }
  }
  // The largest E of all at the clamp, and below it (unreachable through sheen_alpha: for the
  // decision on WP_SHEEN_ROUGHNESS_MIN), and the divergence toward mu = 0 at any roughness.
  const auto peak = [](double r) {
    double m = 0.0, at = 0.0;
    for (double mu = 1e-4; mu < 0.2; mu *= 1.25) {
      const double e = albedo(mu, r * r).value;
      if (e > m) m = e, at = mu;
    }
    std::printf("  roughness %.2f: largest E %.3f at mu ~ %.1e\n", r, m, at);
    return m;
  };
  EXPECT_NEAR(peak(0.07), 2.93, 0.02);
  peak(0.03);
  peak(0.01);
  for (double r : {0.3, 1.0}) {
    std::printf("  roughness %.1f: E(mu) at mu = 1e-5, 1e-6, 1e-7:", r);
    for (double mu : {1e-5, 1e-6, 1e-7}) std::printf(" %.3f", albedo(mu, r * r).value);
    std::printf("\n");
  }
  EXPECT_GT(albedo(1e-7, 1.0).value, 1.0);  // the fit's finite Lambda(0) (sheen_table.h)
}

}  // namespace
