// The film stage: accumulate (fixture: stage_fixture.h).
#include "tests/stages/stage_fixture.h"

namespace wp::test::stages {
namespace {

// The film's fixed point (kernels/shared/film.h), computed here independently: a = round(v 2^32)
// to nearest, ties to even, saturated to [0, 2^64 - 1] (NaN and negatives 0). v 2^32 is exact in
// double (a float times a power of 2) and nearbyint rounds it in the default mode, ties to even.
std::uint64_t fixed(float v) {
  if (!(v > 0.0f)) return 0;
  const double r = std::nearbyint(std::ldexp(double(v), 32));
  if (r >= 18446744073709551616.0) return std::numeric_limits<std::uint64_t>::max();
  return static_cast<std::uint64_t>(r);
}

// accumulate: the film's 128-bit sums after the launch equal the sums before plus, for every
// pixel of the wave and each of its samples with finite radiance, a = fixed(v) per channel and
// floor(a^2 / 2^32) (its square); a sample with a NaN or infinite channel adds nothing and is
// counted once. Two waves: the captured one (4 samples of every pixel, their real radiance, and a
// few samples set to the edge cases: rounding ties, saturation, negatives, NaN, infinity), and a
// wave of one sample of 300 pixels from pixel 100 with random radiance over 1e-13 .. 1e11. The
// film starts from random sums with low words near 2^64, so that carries into the high words
// happen. Pixels outside the wave keep their sums.
TEST_F(Stages, AccumulateAddsFixedPointSumsAndSquares) {
  std::mt19937_64 rng(5);
  const auto random_film = [&] {
    wp::FilmInfo info;
    info.width = kWidth;
    info.height = kHeight;
    info.sample_begin = 0;
    info.sample_end = 1;
    info.key = "test_stages";
    wp::Film film(info);
    for (std::size_t i = 0; i < film.words().size(); i += 2) {
      film.words()[i] = ~(rng() >> (rng() % 64));  // low word: often just below 2^64
      film.words()[i + 1] = rng() >> 24;           // high word: far from overflowing
    }
    return film;
  };
  struct Wave {
    wp::dev::Launch params;
    std::vector<float4> radiance;  // per slot of the wave
    std::vector<std::uint32_t> pixel;
  };
  std::vector<Wave> waves;
  {
    Wave w;
    w.params = wf_->launch_params(0, 0, kPixels, kSamples);
    const PathView end(end_, layout());
    for (std::uint32_t slot = 0; slot < kPaths; ++slot) {
      w.radiance.push_back(end.f4(layout().radiance, slot));
      w.pixel.push_back(w.params.pixel_offset + slot % w.params.wave_pixels);
    }
    // Edge cases on some samples (per channel; slot s is a sample of pixel s % kPixels).
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<std::pair<std::uint32_t, vec3>> edges = {
        {1, {0x1p-33f, 0x3p-33f, 0x5p-34f}},         // 0.5 -> 0, 1.5 -> 2 (ties to even), 1.25 -> 1
        {2, {4294967040.0f, 4294967296.0f, 1e30f}},  // just below 2^32; 2^32 and above saturate
        {3, {-1.0f, -0.0f, 0x1p-40f}},               // negative radiance, -0 and below 2^-33 give 0
        {4, {1.0f, nan, 1.0f}},                      // dropped whole, counted once
        {5, {kInf, 0.5f, 0.5f}},                     // likewise
        {5 + kPixels, {1e30f, 1e30f, 1e30f}},        // pixel 5: saturated samples carry...
        {5 + 2 * kPixels, {1e30f, 1e30f, 1e30f}},    // ... into S's high word
        {5 + 3 * kPixels, {1e30f, 1e30f, 1e30f}},
    };
    for (const auto& [slot, v] : edges) w.radiance[slot] = {v.x, v.y, v.z, 1.0f};
    waves.push_back(std::move(w));
  }
  {
    Wave w;
    w.params = wf_->launch_params(3, 100, 300, 1);
    std::uniform_real_distribution<double> log_v(std::log(1e-13), std::log(1e11));
    for (std::uint32_t slot = 0; slot < 300; ++slot) {
      w.radiance.push_back({float(std::exp(log_v(rng))), float(std::exp(log_v(rng))),
                            float(std::exp(log_v(rng))), 1.0f});
      w.pixel.push_back(100 + slot);
    }
    waves.push_back(std::move(w));
  }
  for (const Wave& w : waves) {
    SCOPED_TRACE("a wave of " + std::to_string(w.params.wave_pixels) + " pixels, " +
                 std::to_string(w.params.path_count / w.params.wave_pixels) + " samples");
    wf_->restore(end_);
    wf_->write_paths(layout().radiance, w.radiance);
    const wp::Film start = random_film();
    wf_->load_film(start);
    const std::uint64_t nonfinite0 = wf_->nonfinite_samples();
    wf_->launch_stage(Stage::kAccumulate, w.params.wave_pixels, w.params);
    wf_->finish();
    const wp::Film film = wf_->film(start.info());

    // The host's sums: the starting film's, plus every sample.
    std::vector<wp::Uint128> sum(kPixels * 3), squares(kPixels * 3);
    for (std::uint32_t px = 0; px < kPixels; ++px)
      for (int ch = 0; ch < 3; ++ch) {
        sum[px * 3 + ch] = start.sum(px, ch);
        squares[px * 3 + ch] = start.squares(px, ch);
      }
    std::uint64_t nonfinite = 0;
    for (std::uint32_t slot = 0; slot < w.params.path_count; ++slot) {
      const float v[3] = {w.radiance[slot].x, w.radiance[slot].y, w.radiance[slot].z};
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
        ++nonfinite;
        continue;
      }
      for (int ch = 0; ch < 3; ++ch) {
        const std::uint64_t a = fixed(v[ch]);
        sum[w.pixel[slot] * 3 + ch] += a;
        squares[w.pixel[slot] * 3 + ch] += (wp::Uint128(a) * a) >> 32;
      }
    }
    EXPECT_EQ(wf_->nonfinite_samples() - nonfinite0, nonfinite);
    Failures f("film sums");
    const auto hex = [](wp::Uint128 v) {
      char s[40];
      std::snprintf(s, sizeof s, "%016llx%016llx", static_cast<unsigned long long>(v >> 64),
                    static_cast<unsigned long long>(v));
      return std::string(s);
    };
    for (std::uint32_t px = 0; px < kPixels; ++px)
      for (int ch = 0; ch < 3; ++ch) {
        WP_CHECK(f, film.sum(px, ch) == sum[px * 3 + ch],
                 "pixel " << px << " channel " << ch << " S " << hex(film.sum(px, ch))
                          << ", expected " << hex(sum[px * 3 + ch]));
        WP_CHECK(f, film.squares(px, ch) == squares[px * 3 + ch],
                 "pixel " << px << " channel " << ch << " Q " << hex(film.squares(px, ch))
                          << ", expected " << hex(squares[px * 3 + ch]));
      }
  }
}

}  // namespace
}  // namespace wp::test::stages
