// The sample patterns of kernels/rng.h, drawn on the OpenCL device by tests/kernels/rng_kernels.cl
// and checked on the host:
// - uniformity: over many pixels, the numbers each dimension group draws at a given sample index
//   and bounce are uniform on [0,1) or [0,1)^2 (chi-square), for both patterns;
// - stratification (Sobol): every aligned block of 2^k samples of one pixel puts exactly one point
//   in every elementary interval of area 2^-k (one per 2^-k interval in 1D), k <= 10; the light
//   pair, chained to the pair that chose the ray (rng.h, rng_chained_group), has exactly the
//   t-values of Sobol' dimensions 2 and 3 alone and of dimensions 0-3 together with that pair,
//   those computed here from Joe and Kuo's direction numbers; the kernel's table of those
//   dimensions equals the recurrence;
// - range: every number is in the open interval (0, 1);
// - independence: numbers of different groups, bounces or neighbouring pixels are independent
//   (chi-square of their joint histogram), for both patterns; without the per-group shuffle of
//   the sample order two Sobol' groups would be functions of each other and fail this by far;
// - the payoff: integrating a smooth function with 256 Sobol' points per pixel has an error far
//   below the independent pattern's, and both are unbiased.
//
// False alarms: each chi-square passes at p > 1e-4; with the 128 of them here a correct pattern
// fails a run with probability below 1.3% (union bound). The seed is fixed, so a build passes or
// fails reproducibly.
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kernels/shared/types.h"
#include "tests/chi2.h"
#include "tests/kernel_harness.h"

namespace {

constexpr std::uint32_t kSeed = 0x5eed;
constexpr double kMinP = 1e-4;

// A dimension group as rng.h numbers it: a pair (rng_get2) or one number (rng_get).
struct Group {
  const char* name;
  std::uint32_t dim;
  bool pair;
};
// kernels/rng.h: WP_DIM_PIXEL_X, _LIGHT_PICK, _LIGHT_U, _BSDF_LOBE, _BSDF_U, _ROULETTE.
const Group kGroups[] = {{"pixel", 0, true},      {"light_pick", 2, false}, {"light_uv", 3, true},
                         {"bsdf_lobe", 5, false}, {"bsdf_uv", 6, true},     {"roulette", 8, false}};

struct Coord {
  std::uint32_t pixel, sample, bounce;
  Group group;
};

class Patterns {
 public:
  // WP_SAMPLER: 0 independent, 1 Sobol' (the light pair chained), 2 Sobol' padded.
  static Patterns& get(int sampler) {
    static Patterns independent(0), sobol(1), padded(2);
    return sampler == 1 ? sobol : sampler == 2 ? padded : independent;
  }

  std::vector<cl_float2> draw(const std::vector<Coord>& coords) {
    std::vector<wp::dev::uint4> in;
    in.reserve(coords.size());
    for (const Coord& c : coords)
      in.push_back({c.pixel, c.sample, c.bounce, c.group.dim | (c.group.pair ? 1u << 16 : 0u)});
    const auto n = static_cast<std::uint32_t>(in.size());
    cl::Buffer out = h_.buffer<cl_float2>(n);
    h_.run("draw_rng", n, h_.buffer(in), kSeed, n, out);
    return h_.read<cl_float2>(out, n);
  }

  // The kernel's reversed digits of Sobol' dimensions 2 and 3 of each index (Sobol build only).
  std::vector<cl_uint2> sobol23(const std::vector<std::uint32_t>& indices) {
    const auto n = static_cast<std::uint32_t>(indices.size());
    cl::Buffer out = h_.buffer<cl_uint2>(n);
    h_.run("sobol23_digits", n, h_.buffer(indices), n, out);
    return h_.read<cl_uint2>(out, n);
  }

  // rng_bounce at each coordinate (the group unused): eight numbers per coordinate.
  std::vector<float> draw_bounce(const std::vector<Coord>& coords) {
    std::vector<wp::dev::uint4> in;
    in.reserve(coords.size());
    for (const Coord& c : coords) in.push_back({c.pixel, c.sample, c.bounce, 0u});
    const auto n = static_cast<std::uint32_t>(in.size());
    cl::Buffer out = h_.buffer<cl_float>(std::size_t{8} * n);
    h_.run("draw_bounce", n, h_.buffer(in), kSeed, n, out);
    return h_.read<cl_float>(out, std::size_t{8} * n);
  }

 private:
  explicit Patterns(int sampler)
      : h_({"rng_kernels.cl"}, "-D WP_SAMPLER=" + std::to_string(sampler)) {}
  wp::test::KernelHarness h_;
};

int cell(float u, int cells) {
  return static_cast<int>(u * static_cast<float>(cells));
}

// Chi-square of points (x, y) in [0,1)^2 against the uniform density on nx x ny bins.
wp::test::Chi2Result uniform_2d(const std::vector<float>& x, const std::vector<float>& y, int nx,
                                int ny) {
  std::vector<double> observed(static_cast<std::size_t>(nx * ny), 0.0);
  for (std::size_t i = 0; i < x.size(); ++i)
    observed[static_cast<std::size_t>(cell(x[i], nx) * ny + cell(y[i], ny))] += 1.0;
  const std::vector<double> expected(observed.size(), static_cast<double>(x.size()) / (nx * ny));
  return wp::test::chi2_test(observed, expected);
}

const char* pattern_name(int sampler) {
  return sampler == 1 ? "sobol" : sampler == 2 ? "sobol-padded" : "independent";
}

// Over 2^16 pixels, one sample index and bounce: uniform on 16 x 16 cells (pairs) or 256 (one).
TEST(Rng, EveryGroupIsUniformOverPixels) {
  constexpr std::uint32_t kPixels = 1u << 16;
  for (int sampler : {0, 1, 2})
    for (const Group& g : kGroups)
      for (std::uint32_t bounce : {0u, 5u})
        for (std::uint32_t sample : {0u, 1u, 37u, 1000u}) {
          std::vector<Coord> coords;
          for (std::uint32_t p = 0; p < kPixels; ++p) coords.push_back({p, sample, bounce, g});
          const auto v = Patterns::get(sampler).draw(coords);
          std::vector<float> x, y;
          for (const cl_float2& u : v) {
            ASSERT_TRUE(u.s[0] > 0.0f && u.s[0] < 1.0f &&
                        (!g.pair || (u.s[1] > 0.0f && u.s[1] < 1.0f)))
                << "outside (0, 1): " << u.s[0] << ", " << u.s[1];
            x.push_back(u.s[0]);
            y.push_back(g.pair ? u.s[1] : 0.0f);
          }
          const auto r = g.pair ? uniform_2d(x, y, 16, 16) : uniform_2d(x, y, 256, 1);
          EXPECT_GT(r.p_value, kMinP) << pattern_name(sampler) << " " << g.name << " bounce "
                                      << bounce << " sample " << sample << ": " << r.detail;
        }
}

// Sobol: samples [b 2^k, (b+1) 2^k) of one pixel, for k = 0..10 and blocks b = 0, 1, 5: exactly
// one point in each of the 2^k elementary intervals of every shape 2^a x 2^(k-a) (pairs), or in
// each interval of length 2^-k (one number). Both Sobol' patterns; the chained one's light pair
// is the test after this one's.
TEST(Rng, SobolStratifiesEveryAlignedBlockOfSamples) {
  constexpr std::uint32_t kSamples = 6u << 10;
  for (int sampler : {1, 2})
    for (std::uint32_t pixel : {0u, 1u, 12345u, (1u << 20) + 7u})
      for (std::uint32_t bounce : {0u, 3u, 11u})
        for (const Group& g : kGroups) {
          if (sampler == 1 && std::string(g.name) == "light_uv") continue;
          std::vector<Coord> coords;
          for (std::uint32_t s = 0; s < kSamples; ++s) coords.push_back({pixel, s, bounce, g});
          const auto v = Patterns::get(sampler).draw(coords);
          for (int k = 0; k <= 10; ++k)
            for (std::uint32_t block : {0u, 1u, 5u}) {
              const std::uint32_t n = 1u << k, first = block * n;
              if (first + n > kSamples) continue;
              for (int a = 0; a <= (g.pair ? k : 0); ++a) {
                const int nx = g.pair ? 1 << a : 1 << k, ny = g.pair ? 1 << (k - a) : 1;
                std::vector<int> count(n, 0);
                for (std::uint32_t i = first; i < first + n; ++i)
                  ++count[static_cast<std::size_t>(cell(v[i].s[0], nx) * ny +
                                                   (g.pair ? cell(v[i].s[1], ny) : 0))];
                int wrong = 0;
                for (int c : count) wrong += c != 1;
                EXPECT_EQ(wrong, 0) << pattern_name(sampler) << " " << g.name << " pixel " << pixel
                                    << " bounce " << bounce << " samples " << first << ".."
                                    << first + n - 1 << ", cells " << nx << " x " << ny;
              }
            }
        }
}

// Sobol' dimension d (0-3) of index i as a 32-bit binary fraction (bit 31 the first digit), from
// Joe and Kuo's direction numbers (new-joe-kuo-6.21201: dimension 2 is x + 1 with m = 1, 3 is
// x^2 + x + 1 with m = 1, 3 and 4 is x^3 + x + 1 with m = 1, 3, 1; dimension 1 the identity):
// v_j = m_j / 2^j for j <= s, then v_j = a_1 v_(j-1) ^ ... ^ a_(s-1) v_(j-s+1) ^ v_(j-s) ^
// v_(j-s) / 2^s, and the point is the xor of v_j over the index's set bits j - 1.
std::uint32_t sobol(int d, std::uint32_t i) {
  struct Poly {
    int s;
    std::uint32_t a;
    std::uint32_t m[3];
  };
  static const Poly polys[3] = {{1, 0, {1}}, {2, 1, {1, 3}}, {3, 1, {1, 3, 1}}};
  std::uint32_t v[32];
  for (int j = 0; j < 32; ++j) {
    if (d == 0) {
      v[j] = 1u << (31 - j);
      continue;
    }
    const Poly& p = polys[d - 1];
    if (j < p.s) {
      v[j] = p.m[j] << (31 - j);
      continue;
    }
    v[j] = v[j - p.s] ^ (v[j - p.s] >> p.s);
    for (int k = 1; k < p.s; ++k)
      if ((p.a >> (p.s - 1 - k)) & 1u) v[j] ^= v[j - k];
  }
  std::uint32_t x = 0;
  for (int j = 0; j < 32; ++j)
    if ((i >> j) & 1u) x ^= v[j];
  return x;
}

std::uint32_t reverse_bits(std::uint32_t x) {
  std::uint32_t r = 0;
  for (int j = 0; j < 32; ++j) r |= ((x >> j) & 1u) << (31 - j);
  return r;
}

// The t-value of n = 2^k points in [0,1)^s, each coordinate a binary fraction in the top bits of
// a 32-bit word: the least t such that every elementary interval of volume 2^(t-k) holds exactly
// 2^t points (t = 0: one point in every interval of volume 1/n; t = k always holds).
int t_value(const std::vector<std::vector<std::uint32_t>>& points, int k) {
  const int s = static_cast<int>(points.front().size());
  for (int t = 0; t < k; ++t) {
    const int q = k - t;  // digits shared out over the coordinates
    bool net = true;
    std::vector<int> digits(static_cast<std::size_t>(s), 0);
    // Every composition of q into s parts, in turn.
    const auto check = [&]() {
      std::vector<int> count(std::size_t{1} << q, 0);
      for (const auto& p : points) {
        std::uint64_t cell = 0;
        for (int c = 0; c < s; ++c) {
          const int b = digits[static_cast<std::size_t>(c)];
          cell = (cell << b) | (b ? p[static_cast<std::size_t>(c)] >> (32 - b) : 0u);
        }
        ++count[cell];
      }
      for (int c : count) net = net && c == 1 << t;
    };
    const std::function<void(int, int)> compose = [&](int c, int left) {
      if (!net) return;
      if (c == s - 1) {
        digits[static_cast<std::size_t>(c)] = left;
        check();
        return;
      }
      for (int b = 0; b <= left; ++b) {
        digits[static_cast<std::size_t>(c)] = b;
        compose(c + 1, left - b);
      }
    };
    compose(0, q);
    if (net) return t;
  }
  return k;
}

std::uint32_t digits_of(float u) {  // rng_float's 23 bits, back at the top of a word
  return static_cast<std::uint32_t>(static_cast<double>(u) * 8388608.0) << 9;
}

// The kernel's table of Sobol' dimensions 2 and 3 against the recurrence above: every nibble value
// at every position (the table's entries, which the digits of any index are the xor of) and a
// spread of whole indices.
TEST(Rng, ThirdAndFourthSobolDimensionsMatchTheRecurrence) {
  std::vector<std::uint32_t> indices;
  for (std::uint32_t n = 0; n < 8; ++n)
    for (std::uint32_t v = 0; v < 16; ++v) indices.push_back(v << (4 * n));
  std::uint32_t h = 7;
  for (int i = 0; i < 1000; ++i) indices.push_back(h = h * 1664525u + 1013904223u);
  const auto got = Patterns::get(1).sobol23(indices);
  int differ = 0;
  for (std::size_t i = 0; i < indices.size(); ++i)
    for (int d = 0; d < 2; ++d) differ += got[i].s[d] != reverse_bits(sobol(2 + d, indices[i]));
  EXPECT_EQ(differ, 0);
}

// The light pair at bounce b is chained to the pair that chose the ray (the BSDF direction of
// bounce b - 1, the pixel jitter at bounce 0): over every aligned block of 2^k of a pixel's
// samples (k <= 10), the light pair's points have the t-value of Sobol' dimensions 2 and 3, and
// the four numbers together that of dimensions 0-3 (scrambling maps elementary intervals onto
// elementary intervals, so it keeps t exactly). A light pair drawn in an order of its own would
// have 4D t-values near k; one from the wrong order, or the wrong dimensions, other t-values.
TEST(Rng, LightPairIsChainedToTheRayThatFoundTheSurface) {
  constexpr int kMaxK = 10;
  constexpr std::uint32_t kSamples = 3u << kMaxK;
  // The t-values of the unscrambled sequence's first 2^k points: the same for every aligned block
  // (a block is the first one's digitally shifted copy, and shifts keep t).
  std::vector<int> t2(kMaxK + 1), t4(kMaxK + 1);
  for (int k = 0; k <= kMaxK; ++k) {
    std::vector<std::vector<std::uint32_t>> p2, p4;
    for (std::uint32_t i = 0; i < 1u << k; ++i) {
      p2.push_back({sobol(2, i), sobol(3, i)});
      p4.push_back({sobol(0, i), sobol(1, i), sobol(2, i), sobol(3, i)});
    }
    t2[static_cast<std::size_t>(k)] = t_value(p2, k);
    t4[static_cast<std::size_t>(k)] = t_value(p4, k);
  }
  EXPECT_GT(t4[kMaxK], 0);  // the test can tell: in 4D no base-2 sequence has t = 0
  const Group& pixel = kGroups[0];
  const Group& light = kGroups[2];
  const Group& bsdf = kGroups[4];
  for (std::uint32_t p : {0u, 12345u, (1u << 20) + 7u})
    for (std::uint32_t bounce : {0u, 1u, 3u, 11u}) {
      std::vector<Coord> coords;
      for (std::uint32_t s = 0; s < kSamples; ++s) {
        coords.push_back(bounce == 0 ? Coord{p, s, 0, pixel} : Coord{p, s, bounce - 1, bsdf});
        coords.push_back({p, s, bounce, light});
      }
      const auto v = Patterns::get(1).draw(coords);
      for (int k = 0; k <= kMaxK; ++k)
        for (std::uint32_t block : {0u, 1u, 2u}) {
          const std::uint32_t n = 1u << k, first = block * n;
          std::vector<std::vector<std::uint32_t>> p2, p4;
          for (std::uint32_t i = first; i < first + n; ++i) {
            const cl_float2 a = v[2 * i], l = v[2 * i + 1];
            p2.push_back({digits_of(l.s[0]), digits_of(l.s[1])});
            p4.push_back(
                {digits_of(a.s[0]), digits_of(a.s[1]), digits_of(l.s[0]), digits_of(l.s[1])});
          }
          EXPECT_EQ(t_value(p2, k), t2[static_cast<std::size_t>(k)])
              << "light pair, pixel " << p << " bounce " << bounce << " samples " << first << ".."
              << first + n - 1;
          EXPECT_EQ(t_value(p4, k), t4[static_cast<std::size_t>(k)])
              << "with the ray's pair, pixel " << p << " bounce " << bounce << " samples " << first
              << ".." << first + n - 1;
        }
    }
}

// Joint histograms (8 x 8) of two numbers that must be independent: different groups of one
// pixel's 4096 samples, one group at two bounces, and one group at neighbouring pixels.
TEST(Rng, GroupsBouncesAndPixelsAreIndependent) {
  constexpr std::uint32_t kN = 4096;
  struct Case {
    const char* name;
    Group a, b;
    std::uint32_t bounce_b, pixel_step;  // b's bounce; 0: same pixel, else b at pixel + step
  };
  const Group& pixel = kGroups[0];
  const Group& pick = kGroups[1];
  const Group& light = kGroups[2];
  const Group& lobe = kGroups[3];
  const Group& bsdf = kGroups[4];
  const Group& roulette = kGroups[5];
  const Case cases[] = {
      {"pixel x / light u", pixel, light, 0, 0},
      {"light u / bsdf u", light, bsdf, 0, 0},
      {"light pick / bsdf lobe", pick, lobe, 0, 0},
      {"pixel y / roulette", pixel, roulette, 0, 0},
      {"bsdf u / next bounce's", bsdf, bsdf, 1, 0},
      {"light pick / next bounce's", pick, pick, 1, 0},
      {"bsdf u / next pixel's", bsdf, bsdf, 0, 1},
      {"pixel x / next row's", pixel, pixel, 0, 640},
  };
  for (int sampler : {0, 1, 2})
    for (const Case& c : cases)
      for (std::uint32_t p : {3u, 99999u}) {
        std::vector<Coord> coords;
        for (std::uint32_t s = 0; s < kN; ++s) {
          // Within a pixel: sample s of both. Across pixels: sample 7 of pixels p + s step apart.
          const std::uint32_t pa = c.pixel_step ? p + s * 2 * c.pixel_step : p;
          const std::uint32_t sample = c.pixel_step ? 7u : s;
          coords.push_back({pa, sample, 2, c.a});
          coords.push_back({pa + c.pixel_step, sample, 2 + c.bounce_b, c.b});
        }
        const auto v = Patterns::get(sampler).draw(coords);
        std::vector<float> x, y;
        const bool second = std::string(c.name).find("pixel y") == 0;
        for (std::uint32_t s = 0; s < kN; ++s) {
          x.push_back(second ? v[2 * s].s[1] : v[2 * s].s[0]);
          y.push_back(v[2 * s + 1].s[0]);
        }
        const auto r = uniform_2d(x, y, 8, 8);
        EXPECT_GT(r.p_value, kMinP)
            << pattern_name(sampler) << " " << c.name << " pixel " << p << ": " << r.detail;
      }
}

// rng_bounce, which draws a bounce's numbers eight at a time for the shading kernels, gives each
// exactly what rng_get / rng_get2 give for its group (lanes as rng.h's WP_BOUNCE_GROUPS), bit for
// bit, over pixels, samples and bounces up to the 32-bit extremes.
TEST(Rng, BounceDrawEqualsTheOneByOneDraws) {
  // lane -> (group in kGroups, which number of the group)
  const std::pair<int, int> lanes[8] = {{1, 0}, {2, 0}, {3, 0}, {4, 0},
                                        {5, 0}, {2, 1}, {4, 1}, {4, 1}};
  std::vector<Coord> points;
  std::uint32_t h = 1;
  for (std::uint32_t i = 0; i < 4096; ++i) {
    h = h * 1664525u + 1013904223u;  // any spread of coordinates will do
    const std::uint32_t pixel = i < 8 ? 0xffffffffu - i : h >> (i % 13);
    const std::uint32_t sample = i % 3 == 0 ? i : h ^ (h >> 7);
    points.push_back({pixel, sample, i % 14, kGroups[0]});
  }
  for (int sampler : {0, 1, 2}) {
    Patterns& patterns = Patterns::get(sampler);
    const std::vector<float> all = patterns.draw_bounce(points);
    for (int lane = 0; lane < 8; ++lane) {
      std::vector<Coord> coords = points;
      for (Coord& c : coords) c.group = kGroups[lanes[lane].first];
      const auto one = patterns.draw(coords);
      int differ = 0;
      for (std::size_t i = 0; i < points.size(); ++i)
        differ += all[8 * i + static_cast<std::size_t>(lane)] !=
                  one[i].s[static_cast<std::size_t>(lanes[lane].second)];
      EXPECT_EQ(differ, 0) << pattern_name(sampler) << " lane " << lane << " ("
                           << kGroups[lanes[lane].first].name << ")";
    }
  }
}

// Known answer: f(u, v) = (1 + cos(2 pi u)) (1 + v^2) has the integral 1 * 4/3 over [0,1)^2.
// Per pixel, the mean of f over 256 samples of the light (u, v) group; over 4096 pixels: both
// patterns' means agree with 4/3 within 5 standard errors (unbiased), and Sobol's mean squared
// error per pixel is below a tenth of the independent pattern's (theory: Owen-scrambled nets give
// O(n^-3) variance for smooth f against O(n^-1); at n = 256 the ratio is far below 1/10).
TEST(Rng, SobolIntegratesASmoothFunctionWithLessErrorUnbiased) {
  constexpr std::uint32_t kPixels = 4096, kSpp = 256;
  const double truth = 4.0 / 3.0;
  const auto f = [](double u, double v) {
    return (1.0 + std::cos(6.283185307179586 * u)) * (1.0 + v * v);
  };
  double mse[2] = {0, 0};
  for (int sampler : {0, 1}) {
    std::vector<Coord> coords;
    for (std::uint32_t p = 0; p < kPixels; ++p)
      for (std::uint32_t s = 0; s < kSpp; ++s) coords.push_back({p, s, 1, kGroups[2]});
    const auto v = Patterns::get(sampler).draw(coords);
    double sum = 0, sum2 = 0;
    for (std::uint32_t p = 0; p < kPixels; ++p) {
      double m = 0;
      for (std::uint32_t s = 0; s < kSpp; ++s) {
        const cl_float2 u = v[p * kSpp + s];
        m += f(u.s[0], u.s[1]);
      }
      m /= kSpp;
      sum += m;
      sum2 += (m - truth) * (m - truth);
    }
    const double mean = sum / kPixels;
    mse[sampler] = sum2 / kPixels;
    const double standard_error = std::sqrt(mse[sampler] / kPixels);
    EXPECT_NEAR(mean, truth, 5.0 * standard_error + 1e-6) << pattern_name(sampler);
  }
  EXPECT_LT(mse[1], 0.1 * mse[0]) << "sobol " << mse[1] << ", independent " << mse[0];
}

}  // namespace
