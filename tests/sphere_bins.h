// Equal-area bins on the unit sphere for chi-square tests of direction sampling, with local
// refinement where a density is concentrated.
//
// Coordinates: direction d = (x, y, z) of the routine's frame (z: the normal) has
// c = y in [-1, 1] and phi = atan2(z, x) in [-pi, pi]; conversely
// d = (sqrt(1 - c^2) cos phi, c, sqrt(1 - c^2) sin phi). The bins are uniform in (c, phi), so bins
// of one grid have equal solid angle (dc dphi, Archimedes). The pole of these coordinates lies on
// the horizon, perpendicular to the x-z plane of incidence: lobes centred in that plane (the
// normal, mirror and refraction directions) fall near c = 0, where bins are nearly square, never
// at a pole, where bins are slivers. With an even phi count the horizon (z = 0: phi = 0, +-pi) is
// a bin boundary, so no bin straddles a BSDF's discontinuity there.
//
// Refinement: each base bin may be split into m x m equal sub-bins (refine()); a bin's index runs
// over the base bins in order, each contributing 1 or m^2 consecutive indices. Bins must be chosen
// without looking at the samples (from the density's integrals, say), or the chi-square
// statistic loses its distribution.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace wp::test {

struct BinRect {
  double c0, c1, phi0, phi1;  // c in [c0, c1), phi in [phi0, phi1)
};

class SphereBins {
 public:
  SphereBins(int n_c, int n_phi)
      : n_c_(n_c), n_phi_(n_phi), split_(static_cast<std::size_t>(n_c * n_phi), 1) {
    reindex();
  }

  int base_count() const { return n_c_ * n_phi_; }
  std::size_t size() const { return first_.back(); }

  // split[b] >= 1: base bin b becomes split[b] x split[b] sub-bins.
  void refine(const std::vector<int>& split) {
    for (std::size_t b = 0; b < split_.size(); ++b) split_[b] = std::max(1, split[b]);
    reindex();
  }

  // Base bin b's split factor and the index of its first bin.
  int split_of(std::size_t b) const { return split_[b]; }
  std::size_t first_of(std::size_t b) const { return first_[b]; }

  // The bin holding direction (x, y, z), unit length (normalised here for safety).
  std::size_t bin_of(double x, double y, double z) const {
    const double len = std::sqrt(x * x + y * y + z * z);
    const double c = std::clamp(y / len, -1.0, 1.0), phi = std::atan2(z, x);
    const double fc = (c + 1.0) / 2.0 * n_c_, fp = (phi + kPi) / (2.0 * kPi) * n_phi_;
    const int ic = clamp_index(fc, n_c_), ip = clamp_index(fp, n_phi_);
    const std::size_t b = static_cast<std::size_t>(ic * n_phi_ + ip);
    const int m = split_[b];
    if (m == 1) return first_[b];
    const int sc = clamp_index((fc - ic) * m, m), sp = clamp_index((fp - ip) * m, m);
    return first_[b] + static_cast<std::size_t>(sc * m + sp);
  }

  // Every bin's rectangle in (c, phi), in index order.
  std::vector<BinRect> rects() const {
    std::vector<BinRect> out;
    out.reserve(size());
    const double dc = 2.0 / n_c_, dp = 2.0 * kPi / n_phi_;
    for (int ic = 0; ic < n_c_; ++ic)
      for (int ip = 0; ip < n_phi_; ++ip) {
        const int m = split_[static_cast<std::size_t>(ic * n_phi_ + ip)];
        for (int sc = 0; sc < m; ++sc)
          for (int sp = 0; sp < m; ++sp)
            out.push_back({-1.0 + dc * (ic + static_cast<double>(sc) / m),
                           -1.0 + dc * (ic + static_cast<double>(sc + 1) / m),
                           -kPi + dp * (ip + static_cast<double>(sp) / m),
                           -kPi + dp * (ip + static_cast<double>(sp + 1) / m)});
      }
    return out;
  }

  static constexpr double kPi = 3.14159265358979323846;

 private:
  static int clamp_index(double f, int n) {
    return std::clamp(static_cast<int>(std::floor(f)), 0, n - 1);
  }
  void reindex() {
    first_.assign(split_.size() + 1, 0);
    for (std::size_t b = 0; b < split_.size(); ++b)
      first_[b + 1] = first_[b] + static_cast<std::size_t>(split_[b] * split_[b]);
  }

  int n_c_, n_phi_;
  std::vector<int> split_;          // per base bin
  std::vector<std::size_t> first_;  // index of each base bin's first bin; back(): the count
};

}  // namespace wp::test
