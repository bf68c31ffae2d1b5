// The sample patterns of kernels/sampling/rng.h, drawn on the OpenCL device by
// tests/kernels/rng_kernels.cl and checked on the host:
// - uniformity: over many pixels, the numbers each dimension group draws at a given sample index
//   and bounce are uniform on [0,1) or [0,1)^2 (chi-square), for both patterns;
// - stratification (Sobol): every aligned block of 2^k samples of one pixel puts exactly one point
//   in every elementary interval of area 2^-k (one per 2^-k interval in 1D), k <= 10; the chained
//   pairs (rng.h, rng_pair_source) have exactly the t-values of the Sobol' dimensions they take,
//   alone and with the pairs they are chained to, those computed here from Joe and Kuo's
//   direction numbers; the kernel's table of dimensions 2-7 equals the recurrence;
// - range: every number is in the open interval (0, 1);
// - independence: numbers of different groups, bounces or neighbouring pixels are independent
//   (chi-square of their joint histogram), for both patterns; without the per-group shuffle of
//   the sample order two Sobol' groups would be functions of each other and fail this by far;
// - the payoff: integrating a smooth function with 256 Sobol' points per pixel has an error far
//   below the independent pattern's, and both are unbiased.
//
// False alarms: each uniformity chi-square passes at p > 1e-4 (144 of them), each independence case
// at most 10 of 64 pixels at p < 1e-3 (24 cases, see the test); a correct pattern fails a run with
// probability below 1.8% (union bound). The seed is fixed, so a build passes or fails
// reproducibly.
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
// kernels/sampling/rng.h: WP_DIM_PIXEL_X, _LIGHT_PICK, _LIGHT_U, _BSDF_LOBE, _BSDF_U, _ROULETTE.
const Group kGroups[] = {{"pixel", 0, true},      {"light_pick", 2, false}, {"light_uv", 3, true},
                         {"bsdf_lobe", 5, false}, {"bsdf_uv", 6, true},     {"roulette", 8, false}};

struct Coord {
  std::uint32_t pixel, sample, bounce;
  Group group;
};

class Patterns {
 public:
  // WP_SAMPLER: 0 independent, 1 Sobol' (pairs chained), 2 Sobol' padded.
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

  // The kernel's reversed digits of Sobol' dimensions 2p and 2p + 1 of each index (Sobol' builds
  // only).
  std::vector<cl_uint2> sobol_pair(const std::vector<std::uint32_t>& indices, std::uint32_t p) {
    const auto n = static_cast<std::uint32_t>(indices.size());
    cl::Buffer out = h_.buffer<cl_uint2>(n);
    h_.run("sobol_pair_digits", n, h_.buffer(indices), p, n, out);
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
// each interval of length 2^-k (one number). Both Sobol' patterns; of the chained one, not the
// pairs that take higher dimensions (the test after this one).
TEST(Rng, SobolStratifiesEveryAlignedBlockOfSamples) {
  constexpr std::uint32_t kSamples = 6u << 10;
  for (int sampler : {1, 2})
    for (std::uint32_t pixel : {0u, 1u, 12345u, (1u << 20) + 7u})
      for (std::uint32_t bounce : {0u, 3u, 11u})
        for (const Group& g : kGroups) {
          const std::string name = g.name;
          if (sampler == 1 && (name == "light_uv" || (name == "bsdf_uv" && bounce % 2 == 1)))
            continue;
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

// Sobol' dimension d (0-7) of index i as a 32-bit binary fraction (bit 31 the first digit), from
// Joe and Kuo's direction numbers (new-joe-kuo-6.21201, their dimensions 2-8, lines "d s a m_i":
// 2 1 0 1, 3 2 1 1 3, 4 3 1 1 3 1, 5 3 2 1 1 1, 6 4 1 1 1 3 3, 7 4 4 1 3 5 13, 8 5 2 1 1 5 5 17;
// their dimension 1, the identity, is d = 0 here): v_j = m_j / 2^j for j <= s, then v_j =
// a_1 v_(j-1) ^ ... ^ a_(s-1) v_(j-s+1) ^ v_(j-s) ^ v_(j-s) / 2^s, and the point is the xor of v_j
// over the index's set bits j - 1.
std::uint32_t sobol(int d, std::uint32_t i) {
  struct Poly {
    int s;
    std::uint32_t a;
    std::uint32_t m[5];
  };
  static const Poly polys[7] = {
      {1, 0, {1}},          {2, 1, {1, 3}},        {3, 1, {1, 3, 1}},       {3, 2, {1, 1, 1}},
      {4, 1, {1, 1, 3, 3}}, {4, 4, {1, 3, 5, 13}}, {5, 2, {1, 1, 5, 5, 17}}};
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

// The kernel's table of Sobol' dimensions 2-7 against the recurrence above: every nibble value at
// every position (the table's entries, which the digits of any index are the xor of) and a spread
// of whole indices.
TEST(Rng, HigherSobolDimensionsMatchTheRecurrence) {
  std::vector<std::uint32_t> indices;
  for (std::uint32_t n = 0; n < 8; ++n)
    for (std::uint32_t v = 0; v < 16; ++v) indices.push_back(v << (4 * n));
  std::uint32_t h = 7;
  for (int i = 0; i < 1000; ++i) indices.push_back(h = h * 1664525u + 1013904223u);
  for (std::uint32_t p = 1; p <= 3; ++p) {
    const auto got = Patterns::get(1).sobol_pair(indices, p);
    int differ = 0;
    for (std::size_t i = 0; i < indices.size(); ++i)
      for (int c = 0; c < 2; ++c)
        differ += got[i].s[c] != reverse_bits(sobol(static_cast<int>(2 * p) + c, indices[i]));
    EXPECT_EQ(differ, 0) << "dimensions " << 2 * p << ", " << 2 * p + 1;
  }
}

// The chained pattern (rng.h, rng_pair_source): over every aligned block of 2^k of a pixel's
// samples (k <= 10), each chained pair has the t-value of the Sobol' dimensions it takes, and each
// two pairs chained together that of their four dimensions (scrambling maps elementary intervals
// onto elementary intervals, so it keeps t exactly): the pixel jitter and the light point at
// bounce 0 (dimensions 0-3 of one order); for an even bounce b, its BSDF direction (0, 1), the
// next bounce's direction (2, 3) and light point (4, 5), and the light point at b + 2 (6, 7), with
// the couples (0-3), (0, 1, 4, 5) and (2, 3, 6, 7). Pairs drawn in orders of their own would have
// 4D t-values near k; from the wrong order or the wrong dimensions, other t-values.
TEST(Rng, ChainedPairsHaveTheTValuesOfTheirSobolDimensions) {
  constexpr int kMaxK = 10;
  constexpr std::uint32_t kSamples = 3u << kMaxK;
  // The t-values of the unscrambled sequence's first 2^k points in the given dimensions: the same
  // for every aligned block (a block is the first one's digitally shifted copy; shifts keep t).
  const auto sobol_t = [&](std::vector<int> dims, int k) {
    std::vector<std::vector<std::uint32_t>> points;
    for (std::uint32_t i = 0; i < 1u << k; ++i) {
      std::vector<std::uint32_t> p;
      for (int d : dims) p.push_back(sobol(d, i));
      points.push_back(p);
    }
    return t_value(points, k);
  };
  struct Chain {  // pair a of bounce ba and pair b of bounce bb, Sobol' dimensions da and db
    const char* name;
    Group a, b;
    std::uint32_t ba, bb;  // bounces, relative to the even bounce under test
    int da, db;            // each pair's first dimension
  };
  const Group& pixel = kGroups[0];
  const Group& light = kGroups[2];
  const Group& bsdf = kGroups[4];
  const Chain chains[] = {
      {"bsdf b / bsdf b+1", bsdf, bsdf, 0, 1, 0, 2},
      {"bsdf b / light b+1", bsdf, light, 0, 1, 0, 4},
      {"bsdf b+1 / light b+2", bsdf, light, 1, 2, 2, 6},
  };
  std::vector<int> t2[8], t4[8][8];
  for (int k = 0; k <= kMaxK; ++k)
    for (int da = 0; da < 8; da += 2) {
      t2[da].push_back(sobol_t({da, da + 1}, k));
      for (int db = da + 2; db < 8; db += 2)
        t4[da][db].push_back(sobol_t({da, da + 1, db, db + 1}, k));
    }
  EXPECT_GT(t4[0][2][kMaxK], 0);  // the test can tell: no base-2 4D sequence has t = 0
  for (std::uint32_t p : {0u, 12345u, (1u << 20) + 7u})
    for (std::uint32_t base : {0u, 2u, 10u}) {
      std::vector<Chain> cases(std::begin(chains), std::end(chains));
      if (base == 0) cases.push_back({"pixel / light 0", pixel, light, 0, 0, 0, 2});
      for (const Chain& c : cases) {
        std::vector<Coord> coords;
        for (std::uint32_t s = 0; s < kSamples; ++s) {
          coords.push_back({p, s, base + c.ba, c.a});
          coords.push_back({p, s, base + c.bb, c.b});
        }
        const auto v = Patterns::get(1).draw(coords);
        for (int k = 0; k <= kMaxK; ++k)
          for (std::uint32_t block : {0u, 1u, 2u}) {
            const std::uint32_t n = 1u << k, first = block * n;
            std::vector<std::vector<std::uint32_t>> pa, pb, pab;
            for (std::uint32_t i = first; i < first + n; ++i) {
              const cl_float2 a = v[2 * i], b = v[2 * i + 1];
              pa.push_back({digits_of(a.s[0]), digits_of(a.s[1])});
              pb.push_back({digits_of(b.s[0]), digits_of(b.s[1])});
              pab.push_back(
                  {digits_of(a.s[0]), digits_of(a.s[1]), digits_of(b.s[0]), digits_of(b.s[1])});
            }
            const auto kk = static_cast<std::size_t>(k);
            const std::string where = std::string(c.name) + ", pixel " + std::to_string(p) +
                                      ", b = " + std::to_string(base) + ", samples " +
                                      std::to_string(first) + ".." + std::to_string(first + n - 1);
            EXPECT_EQ(t_value(pa, k), t2[c.da][kk]) << "first pair: " << where;
            EXPECT_EQ(t_value(pb, k), t2[c.db][kk]) << "second pair: " << where;
            EXPECT_EQ(t_value(pab, k), t4[c.da][c.db][kk]) << "together: " << where;
          }
      }
    }
}

// Joint histograms (8 x 8) of two numbers that must be independent: different groups of one
// pixel's 4096 samples, one group at two bounces, and one group at neighbouring pixels; each case
// at 64 pixels, of which at most 10 may have a chi-square p-value below 10^-3.
//
// Why not every pixel: two groups of one pixel take their points in two nested-uniform shuffles of
// the same sample indices, which keep aligned blocks of indices together (samples 2m and 2m + 1 go
// to a pair of neighbouring indices in both orders, and so on up), so within one pixel the pairs
// are not a uniformly random matching and the chi-square statistic has a heavier tail than its
// distribution: over 1000 pixels per case (2026-11-25), p < 10^-3 at 1.4-2.6% of the pixels for
// every within-pixel case of both Sobol' patterns, the least p 6e-14, against 0-0.1% and 2e-4 for
// the independent pattern (the padded pattern was the default for months with these numbers). Over
// the scrambles, i.e. over pixels, the pairs are independent, which is what an unbiased estimate
// needs; what this test guards against is systematic dependence -- a missing shuffle makes the two
// numbers functions of each other in every pixel (p ~ 0 at all 64). False alarms: with a rate of
// at most 4% per pixel (above the 2.6% seen), P(more than 10 of 64) < 1.4e-4 per case (binomial).
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
    for (const Case& c : cases) {
      int low = 0;
      std::string worst;
      double worst_p = 1.0;
      for (std::uint32_t i = 0; i < 64; ++i) {
        const std::uint32_t p = 3u + i * 99991u;
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
        low += r.p_value < 1e-3;
        if (r.p_value < worst_p)
          worst_p = r.p_value, worst = "pixel " + std::to_string(p) + ": " + r.detail;
      }
      EXPECT_LE(low, 10) << pattern_name(sampler) << " " << c.name << ": " << low
                         << " of 64 pixels at p < 1e-3; the least " << worst;
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
