// unit: the PNG tonemaps (host/film/tonemap.h) against their published definitions, known answers
// and Blender's own view transforms.
//
// tests/data/tonemap_reference.csv: tools/generators/tonemap_reference.py's float64 transcriptions of
// three.js's AgX, the Khronos PBR Neutral text, Narkowicz's ACES fit and the clamp, on a grey ramp
// (0 and 2^-12 .. 16 in quarter stops), primaries and secondaries, hue sweeps and small-minimum
// colours (the ctest tonemap_reference_py checks that the file is still the script's output).
// tests/data/tonemap_blender.csv: the same colours through Blender's "AgX" and "Khronos PBR
// Neutral" views (tools/generators/tonemap_blender.py), 8-bit.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "host/film/tonemap.h"
#include "host/util/error.h"
#include "tests/test_assets.h"

namespace {

using wp::Rgb;
using wp::Tonemap;

struct Row {
  std::string mapper;
  Rgb in;
  double srgb[3] = {};  // reference only: the sRGB-encoded value before rounding
  int code[3] = {};
};

// The rows of a CSV file in tests/data ('#' lines are comments; the first other line is a header).
std::vector<Row> read_rows(const std::string& name, bool with_srgb) {
  std::ifstream file(wp::test::source_path("tests/data/" + name));
  EXPECT_TRUE(file) << name;
  std::vector<Row> rows;
  std::string line;
  bool header = true;
  while (std::getline(file, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::istringstream fields(line);
    std::string f;
    Row row;
    std::getline(fields, row.mapper, ',');
    for (float& v : row.in) std::getline(fields, f, ','), v = std::stof(f);
    if (with_srgb)
      for (double& v : row.srgb) std::getline(fields, f, ','), v = std::stod(f);
    for (int& v : row.code) std::getline(fields, f, ','), v = std::stoi(f);
    rows.push_back(row);
  }
  return rows;
}

// Tolerance on the sRGB-encoded value between this float32 code and the float64 reference. Each
// float operation rounds to 6e-8 relative; the deepest chain is AgX's (two matrices, log2, a
// polynomial whose terms reach 40 while the sum is below 1, i.e. ~2.4e-6 per rounding there, a
// matrix, pow 2.2, a matrix, the sRGB encoding with slopes up to 12.92), which bounds the
// difference by about 1e-5 of full scale. Measured over the reference's 200 colours (the test
// prints it): 4.9e-6 for AgX, 2e-7 for the others, and all 800 codes equal. 2e-5 is 0.005 of an
// 8-bit level: the codes must agree, except where the reference lies within 2e-5 of a rounding
// point (k + 0.5) / 255, where they may differ by 1.
constexpr double kSrgbTolerance = 2e-5;

void expect_matches_reference(const std::string& mapper, Tonemap t) {
  double worst = 0.0;
  int rows = 0, straddled = 0;
  for (const Row& row : read_rows("tonemap_reference.csv", true)) {
    if (row.mapper != mapper) continue;
    ++rows;
    const Rgb s = wp::png_display(row.in, {0.0f, t});
    const std::array<unsigned char, 3> code = wp::png_encode(row.in, {0.0f, t});
    for (int c = 0; c < 3; ++c) {
      SCOPED_TRACE(mapper + " (" + std::to_string(row.in[0]) + ", " + std::to_string(row.in[1]) +
                   ", " + std::to_string(row.in[2]) + ") channel " + std::to_string(c));
      const double diff = std::abs(s[c] - row.srgb[c]);
      worst = std::max(worst, diff);
      EXPECT_LE(diff, kSrgbTolerance);
      const double scaled = row.srgb[c] * 255.0;
      const bool near_rounding_point =
          std::abs(scaled - std::floor(scaled) - 0.5) < kSrgbTolerance * 255.0;
      straddled += code[c] != row.code[c];
      EXPECT_LE(std::abs(code[c] - row.code[c]), near_rounding_point ? 1 : 0);
    }
  }
  EXPECT_EQ(rows, 200) << mapper << ": reference rows missing";
  std::printf("%s: %d colours, largest sRGB difference %.2g, %d codes 1 off\n", mapper.c_str(),
              rows, worst, straddled);
}

TEST(TonemapReference, Agx) {
  expect_matches_reference("agx", Tonemap::kAgx);
}
TEST(TonemapReference, PbrNeutral) {
  expect_matches_reference("pbr-neutral", Tonemap::kPbrNeutral);
}
TEST(TonemapReference, Aces) {
  expect_matches_reference("aces", Tonemap::kAces);
}
TEST(TonemapReference, Clamp) {
  expect_matches_reference("clamp", Tonemap::kClamp);
}

// Blender's views, 8-bit, against ours. PBR Neutral: Blender's is a 57^3 LUT of the same function
// over log2 [-9, 10], tetrahedrally interpolated: within 2 levels (measured: 1 on greys, 2 on
// saturated primaries). AgX: Blender's is Eary Chow's LUT AgX (FilmLight E-Gamut, its own inset
// and rotation, the base decoded as a 2.4 power), which three.js approximates: measured 14 levels
// on greys (shadows: three.js decodes a 2.2 power; with 2.4 it would be 7) and 44 on saturated
// colours. The bounds are those measurements: a double sRGB encoding or a lost matrix exceeds them.
void expect_near_blender(const std::string& mapper, Tonemap t, int grey_levels, int levels) {
  int rows = 0, worst_grey = 0, worst = 0;
  for (const Row& row : read_rows("tonemap_blender.csv", false)) {
    if (row.mapper != mapper) continue;
    ++rows;
    const std::array<unsigned char, 3> code = wp::png_encode(row.in, {0.0f, t});
    const bool grey = row.in[0] == row.in[1] && row.in[1] == row.in[2];
    for (int c = 0; c < 3; ++c) {
      const int diff = std::abs(code[c] - row.code[c]);
      worst = std::max(worst, diff);
      if (grey) worst_grey = std::max(worst_grey, diff);
    }
  }
  EXPECT_EQ(rows, 200) << mapper << ": Blender rows missing";
  EXPECT_LE(worst_grey, grey_levels) << mapper;
  EXPECT_LE(worst, levels) << mapper;
  std::printf("%s vs Blender: largest difference %d levels on greys, %d on all colours\n",
              mapper.c_str(), worst_grey, worst);
}

TEST(TonemapBlender, PbrNeutralWithinTwoLevels) {
  expect_near_blender("pbr-neutral", Tonemap::kPbrNeutral, 1, 2);
}
TEST(TonemapBlender, AgxWithinTheMeasuredDifference) {
  expect_near_blender("agx", Tonemap::kAgx, 14, 44);
}

// Below the start of compression (p = max(c) - f <= 0.76), PBR Neutral only subtracts the offset
// f: 0.04 when min(c) >= 0.08, so base colours in [0.08, 0.8] come out 0.04 lower, exactly in
// float; x - 6.25 x^2 for a smaller minimum x.
TEST(PbrNeutral, OffsetOnlyBelowStartCompression) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> base(0.0801f, 0.8f), any(0.0f, 0.8f);
  for (int i = 0; i < 2000; ++i) {
    const Rgb c = {base(rng), base(rng), base(rng)};
    const Rgb out = wp::tonemap(c, Tonemap::kPbrNeutral);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(out[k], c[k] - 0.04f) << i;
  }
  for (int i = 0; i < 2000; ++i) {
    Rgb c = {any(rng), any(rng), any(rng)};
    c[i % 3] = std::min(c[i % 3], 0.079f);
    const double x = std::min({c[0], c[1], c[2]});
    const double f = x < 0.08 ? x - 6.25 * x * x : 0.04;
    if (std::max({c[0], c[1], c[2]}) - f > 0.76) continue;
    const Rgb out = wp::tonemap(c, Tonemap::kPbrNeutral);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(out[k], c[k] - f, 1e-7) << i;
  }
}

// Above it the peak p goes to p_n = 1 - 0.24^2 / (p - 0.52) and the colour is desaturated towards
// [p_n, p_n, p_n] (the normative text), so the peak stays p_n and the hue is kept: each channel's
// place between the minimum and the peak is unchanged.
TEST(PbrNeutral, CompressesThePeakAndKeepsTheHue) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    const float peak = std::exp2(u(rng) * 8.0f);  // 1 .. 256
    const Rgb c = {peak, peak * u(rng), peak * u(rng)};
    const double x = std::min({c[0], c[1], c[2]}), f = x < 0.08 ? x - 6.25 * x * x : 0.04;
    if (c[0] - x < 0.1 * peak) continue;  // nearly grey: the hue ratios below are ill-conditioned
    const double p = c[0] - f, pn = 1.0 - 0.24 * 0.24 / (p - 0.52);
    const Rgb out = wp::tonemap(c, Tonemap::kPbrNeutral);
    ASSERT_NEAR(out[0], pn, 2e-6) << i;
    ASSERT_LE(std::max(out[1], out[2]), out[0]);
    const double lo = std::min({out[0], out[1], out[2]});
    for (int k = 1; k < 3; ++k)
      ASSERT_NEAR((out[k] - lo) / (out[0] - lo), (c[k] - x) / (c[0] - x), 1e-4) << i;
  }
}

// The clamp is exact, per channel; ACES is the per-channel rational fit it always was.
TEST(Tonemap, ClampAndAcesPerChannel) {
  for (float x : {0.0f, 1e-6f, 0.18f, 0.5f, 1.0f}) {
    EXPECT_EQ(wp::tonemap({x, x, x}, Tonemap::kClamp), (Rgb{x, x, x}));
    const float aces = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    EXPECT_FLOAT_EQ(wp::tonemap({x, 0.0f, 4.0f}, Tonemap::kAces)[0], aces);
  }
  EXPECT_EQ(wp::png_encode({0.18f, 1.0f, 2.0f}, {0.0f, Tonemap::kClamp}),
            (std::array<unsigned char, 3>{118, 255, 255}));
  // The bytes the per-channel png_encode gave before AgX and PBR Neutral came: a grey, white and
  // a highlight.
  EXPECT_EQ(wp::png_encode({0.18f, 1.0f, 4.0f}, {0.0f, Tonemap::kAces}),
            (std::array<unsigned char, 3>{141, 232, 252}));
}

// AgX along the grey ramp: black to 0, rising, below 1 up to 16 (three.js's curve reaches 1 only
// at the top of its range), and nearly neutral (three.js's 4-digit Rec.2020 matrix tints greys by
// less than 1e-4).
TEST(Agx, GreyRamp) {
  EXPECT_EQ(wp::png_encode({0.0f, 0.0f, 0.0f}, {0.0f, Tonemap::kAgx}),
            (std::array<unsigned char, 3>{0, 0, 0}));
  float previous = 0.0f;
  for (int k = -48; k <= 16; ++k) {
    const float x = std::exp2(float(k) / 4.0f);
    const Rgb s = wp::png_display({x, x, x}, {0.0f, Tonemap::kAgx});
    EXPECT_GT(s[1], previous) << x;
    EXPECT_LT(s[1], 1.0f) << x;
    EXPECT_NEAR(s[0], s[1], 1e-4) << x;
    EXPECT_NEAR(s[2], s[1], 1e-4) << x;
    previous = s[1];
  }
}

// Exposure scales the linear input before the tonemap: +1 stop is the doubled colour.
TEST(Tonemap, ExposureBeforeTonemap) {
  for (const std::string& name : wp::tonemap_names()) {
    const Tonemap t = wp::tonemap_from_name(name);
    for (const Rgb& c : {Rgb{0.1f, 0.2f, 0.3f}, Rgb{0.9f, 0.05f, 0.4f}, Rgb{3.0f, 2.0f, 1.0f}})
      EXPECT_EQ(wp::png_encode(c, {1.0f, t}),
                wp::png_encode({2.0f * c[0], 2.0f * c[1], 2.0f * c[2]}, {0.0f, t}))
          << name;
  }
}

// AgX and PBR Neutral mix channels: a NaN reads as 0 (not spreading to the others), infinity and
// huge values as white-ish, negative as 0.
TEST(Tonemap, NonFiniteAndNegativeInputs) {
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  for (Tonemap t : {Tonemap::kAgx, Tonemap::kPbrNeutral}) {
    EXPECT_EQ(wp::png_encode({nan, 0.5f, 0.25f}, {0.0f, t}),
              wp::png_encode({0.0f, 0.5f, 0.25f}, {0.0f, t}));
    EXPECT_EQ(wp::png_encode({-1.0f, 0.5f, 0.25f}, {0.0f, t}),
              wp::png_encode({0.0f, 0.5f, 0.25f}, {0.0f, t}));
    EXPECT_EQ(wp::png_encode({inf, 0.5f, 0.25f}, {0.0f, t}),
              wp::png_encode({3e38f, 0.5f, 0.25f}, {0.0f, t}));
    EXPECT_EQ(wp::png_encode({inf, inf, inf}, {0.0f, t})[0], 255);
  }
}

TEST(Tonemap, Names) {
  EXPECT_EQ(wp::tonemap_names(), (std::vector<std::string>{"aces", "agx", "pbr-neutral", "clamp"}));
  EXPECT_EQ(wp::tonemap_from_name("agx"), Tonemap::kAgx);
  EXPECT_EQ(wp::tonemap_from_name("pbr-neutral"), Tonemap::kPbrNeutral);
  EXPECT_THROW(wp::tonemap_from_name("sepia"), wp::Error);
}

}  // namespace
