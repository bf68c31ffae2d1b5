// Pearson's chi-square goodness-of-fit test, for sampling routines against their densities.
//
// Usage: bin N samples, compute each bin's expected count N * (integral of the pdf over the bin),
// then chi2_test(observed, expected). Bins with an expected count below 5 are pooled into one (the
// chi-square approximation needs expected counts of about 5 or more); the statistic then has
// (bins used - 1) degrees of freedom. A routine passes when the p-value exceeds a threshold chosen
// for the number of tests run (e.g. 1e-4 per test: a correct routine then fails one run in 10^4).
#pragma once

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace wp::test {

// Regularised upper incomplete gamma Q(a, x) by series (x < a + 1) or continued fraction.
inline double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double lg = std::lgamma(a);
  if (x < a + 1.0) {
    double sum = 1.0 / a, term = sum;
    for (int n = 1; n < 100000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::fabs(term) < std::fabs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - lg);
  }
  // Modified Lentz for the continued fraction of Q.
  double b = x + 1.0 - a, c = 1e300, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::fabs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - lg) * h;
}

// P(X >= x) for X chi-square distributed with `dof` degrees of freedom.
inline double chi2_sf(double x, int dof) {
  return gamma_q(0.5 * dof, 0.5 * x);
}

struct Chi2Result {
  double statistic = 0.0;
  int dof = 0;
  double p_value = 1.0;
  double observed_outside = 0.0;  // samples in bins whose expected count is 0 (must be none)
  std::string detail;
};

inline Chi2Result chi2_test(const std::vector<double>& observed,
                            const std::vector<double>& expected, double min_expected = 5.0) {
  Chi2Result r;
  double pooled_obs = 0.0, pooled_exp = 0.0;
  int bins = 0;
  for (std::size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] <= 0.0) {
      r.observed_outside += observed[i];
      continue;
    }
    if (expected[i] < min_expected) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
      continue;
    }
    r.statistic += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++bins;
  }
  if (pooled_exp > 0.0) {
    r.statistic += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++bins;
  }
  r.dof = std::max(1, bins - 1);
  r.p_value = r.observed_outside > 0.0 ? 0.0 : chi2_sf(r.statistic, r.dof);
  std::ostringstream s;
  s << "chi2 " << r.statistic << " dof " << r.dof << " p " << r.p_value
    << " (samples where the pdf is 0: " << r.observed_outside << ")";
  r.detail = s.str();
  return r;
}

}  // namespace wp::test
