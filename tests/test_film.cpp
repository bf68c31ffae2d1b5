// The film in fixed point (host/film/film.h, kernels/accumulate.cl, kernels/shared/film.h): the
// arithmetic against 128-bit references, the accumulate kernel against the same references, the
// .wpfilm file against truncation and corruption, and the promise it all exists for: renders of
// sample ranges merged in any order give the single render's film and image bit for bit, whatever
// the wave size, and merging refuses what does not belong together.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "host/accel/bvh_input.h"
#include "host/device/cl_runtime.h"
#include "host/util/error.h"
#include "host/film/film.h"
#include "host/film/image_io.h"
#include "host/render/render.h"
#include "host/render/wavefront.h"
#include "tests/cli_run.h"
#include "tests/float_bits.h"
#include "tests/scene_factory.h"
#include "tests/test_assets.h"

namespace {

namespace fs = std::filesystem;
using wp::Film;
using wp::FilmInfo;
using wp::Uint128;

constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();

FilmInfo film_info(int width, int height, std::uint32_t begin, std::uint32_t end,
                   const std::string& key = "scene=1;seed=0") {
  FilmInfo info;
  info.width = width;
  info.height = height;
  info.sample_begin = begin;
  info.sample_end = end;
  info.key = key;
  info.device = "test device";
  return info;
}

// Sets 128-bit value `word` (WP_FILM_SUM(c) or WP_FILM_SQUARES(c)) of pixel p.
void set(Film& f, std::size_t p, unsigned word, Uint128 v) {
  f.words()[p * WP_FILM_WORDS_PER_PIXEL + word] = static_cast<std::uint64_t>(v);
  f.words()[p * WP_FILM_WORDS_PER_PIXEL + word + 1] = static_cast<std::uint64_t>(v >> 64);
}

// A film whose sums are those of `samples()` random samples per pixel and channel, drawn from
// values that span the fixed-point range (saturated ones included).
Film random_film(int width, int height, std::uint32_t begin, std::uint32_t end,
                 std::uint32_t seed) {
  Film f(film_info(width, height, begin, end));
  std::mt19937_64 rng(seed);
  for (std::size_t p = 0; p < f.pixels(); ++p)
    for (unsigned c = 0; c < 3; ++c) {
      Uint128 s = 0, q = 0;
      for (std::uint32_t i = begin; i < end; ++i) {
        const std::uint64_t a = rng() % 4 == 0 ? kMax : rng() >> (rng() % 64);
        s += a;
        q += wp::film_square(a);
      }
      set(f, p, WP_FILM_SUM(c), s);
      set(f, p, WP_FILM_SQUARES(c), q);
    }
  return f;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const wp::Error& e) {
    return e.what();
  }
  return "";
}

TEST(FilmFixed, ScaleRoundingAndSaturation) {
  using wp::film_fixed;
  EXPECT_EQ(film_fixed(0.0f), 0u);
  EXPECT_EQ(film_fixed(-0.0f), 0u);
  EXPECT_EQ(film_fixed(1.0f), std::uint64_t(1) << 32);
  EXPECT_EQ(film_fixed(0.5f), std::uint64_t(1) << 31);
  EXPECT_EQ(film_fixed(0x1p-32f), 1u);
  EXPECT_EQ(film_fixed(0x1p-33f), 0u);  // 0.5 units: ties to even
  EXPECT_EQ(film_fixed(0x3p-33f), 2u);  // 1.5 units: ties to even
  EXPECT_EQ(film_fixed(0x5p-34f), 1u);  // 1.25 units
  EXPECT_EQ(film_fixed(123.25f), std::uint64_t(493) << 30);
  EXPECT_EQ(film_fixed(4294967040.0f), ((std::uint64_t(1) << 32) - 256u) << 32);  // below 2^32
  EXPECT_EQ(film_fixed(4294967296.0f), kMax);                                     // 2^32 saturates
  EXPECT_EQ(film_fixed(1e30f), kMax);
  EXPECT_EQ(film_fixed(INFINITY), kMax);
  EXPECT_EQ(film_fixed(-1.0f), 0u);  // negative radiance (invalid input) saturates to 0
  EXPECT_EQ(film_fixed(NAN), 0u);
}

TEST(FilmFixed, SquaresKeepTheirHighBits) {
  using wp::film_square;
  EXPECT_EQ(film_square(0), Uint128(0));
  EXPECT_EQ(film_square(std::uint64_t(1) << 32), Uint128(1) << 32);  // 1.0^2 = 1.0
  EXPECT_EQ(film_square(std::uint64_t(3) << 31), Uint128(9) << 30);  // 1.5^2 = 2.25
  EXPECT_EQ(film_square(0xffffffffu), Uint128(0xfffffffeu));         // floor((2^32-1)^2 / 2^32)
  // (2^64 - 1)^2 = 2^128 - 2^65 + 1: shifted right by 32, 2^96 - 2^33 (the +1 is the floor's).
  EXPECT_EQ(film_square(kMax), (Uint128(1) << 96) - (Uint128(1) << 33));
  // A value whose square's low word carries into the high word.
  const std::uint64_t a = 0x123456789abcdef1ull;
  EXPECT_EQ(film_square(a), (Uint128(a) * a) >> 32);
  EXPECT_EQ(static_cast<std::uint64_t>(film_square(a) >> 64), 0x14b66dcu);
}

TEST(FilmMerge, CarriesAcrossTheLowWord) {
  Film a(film_info(1, 1, 0, 2)), b(film_info(1, 1, 2, 3));
  set(a, 0, WP_FILM_SUM(0), Uint128(kMax) + kMax);  // two saturated samples: 2^65 - 2
  set(b, 0, WP_FILM_SUM(0), kMax);
  set(a, 0, WP_FILM_SQUARES(2), (Uint128(1) << 97) - 1);
  set(b, 0, WP_FILM_SQUARES(2), 1);
  a.add(b);
  EXPECT_EQ(a.sum(0, 0), Uint128(kMax) * 3);
  EXPECT_EQ(a.squares(0, 2), Uint128(1) << 97);
  EXPECT_EQ(a.sum(0, 1), Uint128(0));
  EXPECT_EQ(a.info().sample_begin, 0u);
  EXPECT_EQ(a.info().sample_end, 3u);
}

// Integer sums: any grouping and order of the parts gives the same words, and those of the
// samples summed in one go.
TEST(FilmMerge, AnyOrderAndGroupingGivesTheSameSums) {
  const Film p0 = random_film(5, 3, 0, 3, 1), p1 = random_film(5, 3, 3, 4, 2),
             p2 = random_film(5, 3, 4, 9, 3);
  Film left = p0;  // (p0 + p1) + p2
  left.add(p1);
  left.add(p2);
  Film right = p1;  // p0 + (p1 + p2), added the other way round
  right.add(p2);
  right.add(p0);
  Film reverse = p2;  // (p2 + p1) + p0
  reverse.add(p1);
  reverse.add(p0);
  for (const Film* f : {&right, &reverse}) {
    EXPECT_EQ(f->words(), left.words());
    EXPECT_EQ(f->info().sample_begin, 0u);
    EXPECT_EQ(f->info().sample_end, 9u);
  }
  for (std::size_t p = 0; p < left.pixels(); ++p)
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(left.sum(p, c), p0.sum(p, c) + p1.sum(p, c) + p2.sum(p, c));
      EXPECT_EQ(left.squares(p, c), p0.squares(p, c) + p1.squares(p, c) + p2.squares(p, c));
    }
}

TEST(FilmMerge, RefusesOtherRendersSizesAndRanges) {
  const Film a(film_info(4, 4, 0, 2));
  const auto add = [&](const FilmInfo& other) {
    return error_of([&] {
      Film copy = a;
      copy.add(Film(other));
    });
  };
  EXPECT_NE(add(film_info(4, 4, 2, 3, "scene=1;seed=1")).find("seed=0 vs seed=1"),
            std::string::npos);
  EXPECT_NE(add(film_info(4, 3, 2, 3)).find("different sizes (4x4 and 4x3)"), std::string::npos);
  EXPECT_NE(add(film_info(4, 4, 1, 3)).find("overlapping samples (0:2 and 1:3)"),
            std::string::npos);
  EXPECT_NE(add(film_info(4, 4, 0, 2)).find("overlapping"), std::string::npos);
  EXPECT_NE(add(film_info(4, 4, 3, 5)).find("leave 2:3 out"), std::string::npos);
  EXPECT_EQ(add(film_info(4, 4, 2, 5)), "");
  EXPECT_NE(error_of([] { Film(film_info(4, 4, 3, 3)); }).find("3:3"), std::string::npos);
  EXPECT_NE(error_of([] { Film(film_info(4, 4, 0, WP_FILM_MAX_SAMPLES + 1)); }), "");
  EXPECT_NE(error_of([] { Film(film_info(0, 4, 0, 1)); }), "");
}

// The image from known samples: v = 0.5, 1.5, 2, 0 has mean 1 and sample variance 5/6, so the
// variance of the mean is 5/24.
TEST(FilmImages, MeanAndVarianceOfTheMean) {
  Film f(film_info(2, 1, 0, 4));
  Uint128 s = 0, q = 0;
  for (const float v : {0.5f, 1.5f, 2.0f, 0.0f}) {
    s += wp::film_fixed(v);
    q += wp::film_square(wp::film_fixed(v));
  }
  set(f, 1, WP_FILM_SUM(2), s);
  set(f, 1, WP_FILM_SQUARES(2), q);
  const wp::FilmImages img = f.images();
  EXPECT_EQ(img.mean[5], 1.0f);
  EXPECT_FLOAT_EQ(img.variance[5], 5.0f / 24.0f);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(img.mean[i], 0.0f) << i;
  // 2^20 saturated samples: the largest sums a film can hold, still exact in the mean.
  Film big(film_info(1, 1, 0, WP_FILM_MAX_SAMPLES));
  set(big, 0, WP_FILM_SUM(0), Uint128(kMax) * WP_FILM_MAX_SAMPLES);
  set(big, 0, WP_FILM_SQUARES(0), wp::film_square(kMax) * WP_FILM_MAX_SAMPLES);
  EXPECT_FLOAT_EQ(big.images().mean[0], 4294967296.0f);
  EXPECT_LT(big.images().variance[0], 1e-3f);
}

class FilmFile : public wp::test::FolderTest {
 protected:
  void put(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }
  // The cause Film::read gives for `bytes`, which must name the file.
  std::string read_error(const std::string& bytes) const {
    put("bad.wpfilm", bytes);
    const std::string e = error_of([&] { Film::read(path("bad.wpfilm")); });
    EXPECT_EQ(e.rfind(path("bad.wpfilm") + ": ", 0), 0u) << "'" << e << "'";
    return e;
  }
};

TEST_F(FilmFile, RoundTrip) {
  Film f = random_film(7, 5, 10, 17, 4);
  FilmInfo info = f.info();
  info.device = "dev \"quoted\" \\ \xc3\xa9";
  info.nonfinite_samples = 3;
  Film g(info);
  g.words() = f.words();
  g.write(path("a.wpfilm"));
  const Film r = Film::read(path("a.wpfilm"));
  EXPECT_EQ(r.words(), g.words());
  EXPECT_EQ(r.info().width, 7);
  EXPECT_EQ(r.info().height, 5);
  EXPECT_EQ(r.info().sample_begin, 10u);
  EXPECT_EQ(r.info().sample_end, 17u);
  EXPECT_EQ(r.info().key, g.info().key);
  EXPECT_EQ(r.info().device, g.info().device);
  EXPECT_EQ(r.info().nonfinite_samples, 3u);
  const std::string bytes = wp::test::slurp(path("a.wpfilm"));
  EXPECT_EQ(bytes.rfind("wavepath-film\n{\"format\":1,", 0), 0u);
  EXPECT_EQ(bytes.size() - (bytes.find('\n', 14) + 1), 7u * 5u * 96u);
}

TEST_F(FilmFile, TruncatedAnywhereIsAnError) {
  random_film(3, 2, 0, 2, 5).write(path("a.wpfilm"));
  const std::string bytes = wp::test::slurp(path("a.wpfilm"));
  const std::size_t data = bytes.find('\n', 14) + 1;
  std::set<std::size_t> cuts;
  for (std::size_t n = 0; n < data + 8; ++n) cuts.insert(n);  // every byte of the header
  for (std::size_t n = data; n < bytes.size(); n += 41) cuts.insert(n);
  cuts.insert(bytes.size() - 1);
  for (const std::size_t n : cuts) {
    SCOPED_TRACE("truncated to " + std::to_string(n) + " bytes");
    EXPECT_NE(read_error(bytes.substr(0, n)), "");
  }
  EXPECT_NE(read_error(bytes.substr(0, data)).find("truncated: 0 bytes of film data, 576 expected"),
            std::string::npos);
  EXPECT_NE(read_error(bytes + "x").find("1 bytes after the film data"), std::string::npos);
  EXPECT_NE(read_error("").find("not a wavepath film"), std::string::npos);
}

// Every byte of the magic and header lines, changed, is found: a syntax or field error, or the
// checksum (which covers the header too); so is a changed data byte.
TEST_F(FilmFile, CorruptedHeaderOrDataIsAnError) {
  random_film(3, 2, 0, 2, 6).write(path("a.wpfilm"));
  const std::string bytes = wp::test::slurp(path("a.wpfilm"));
  const std::size_t data = bytes.find('\n', 14) + 1;
  for (std::size_t i = 0; i < data; ++i)
    for (const int flip : {0x01, 0x20, 0x80}) {
      std::string bad = bytes;
      bad[i] = static_cast<char>(bad[i] ^ flip);
      SCOPED_TRACE("byte " + std::to_string(i) + " ^ " + std::to_string(flip));
      EXPECT_NE(read_error(bad), "");
    }
  std::string bad = bytes;
  bad[data + 100] ^= 4;
  EXPECT_NE(read_error(bad).find("corrupted"), std::string::npos);
}

TEST_F(FilmFile, MalformedHeadersAreErrors) {
  const auto header = [](const std::string& json) { return "wavepath-film\n" + json + "\n"; };
  EXPECT_NE(read_error(header("{\"format\":2}")).find("film format 2 is not supported"),
            std::string::npos);
  EXPECT_NE(read_error(header("{\"format\":1}")).find("\"fraction_bits\" is missing"),
            std::string::npos);
  EXPECT_NE(read_error(header("{\"format\":\"1\"}")).find("\"format\" is not a whole number"),
            std::string::npos);
  EXPECT_NE(read_error(header("{\"format\":-1}")).find("malformed header"), std::string::npos);
  EXPECT_NE(read_error(header("{\"format\":1,\"format\":1}")).find("duplicate"), std::string::npos);
  EXPECT_NE(read_error(header("{\"format\":99999999999999999999999}")).find("too large"),
            std::string::npos);
  EXPECT_NE(read_error(header("{\"format\":1")).find("malformed header"), std::string::npos);
  EXPECT_NE(read_error(header("[")).find("malformed header"), std::string::npos);
  EXPECT_NE(read_error(header("{\"a\":\"\\n\"}")).find("unsupported escape"), std::string::npos);
  EXPECT_NE(read_error("wavepath-film\n" + std::string(20000, ' ')).find("longer than 16384"),
            std::string::npos);
  // A header that would describe 16384 x 16384 pixels (25 GB) in a short file: refused on its
  // size, before anything is allocated.
  Film f(film_info(1, 1, 0, 1));
  f.write(path("a.wpfilm"));
  std::string big = wp::test::slurp(path("a.wpfilm"));
  for (const char* field : {"\"width\":1,", "\"height\":1,"}) {
    const std::size_t at = big.find(field);
    ASSERT_NE(at, std::string::npos);
    big.replace(at, std::strlen(field),
                std::string(field).replace(std::strlen(field) - 2, 1, "16384"));
  }
  big.replace(big.find("\"data_bytes\":96"), 15, "\"data_bytes\":25769803776");
  EXPECT_NE(read_error(big).find("truncated: 96 bytes of film data, 25769803776 expected"),
            std::string::npos);
  EXPECT_NE(error_of([&] { Film::read(dir_.string()); }).find("not a regular file"),
            std::string::npos);
  EXPECT_NE(error_of([&] { Film::read(path("none.wpfilm")); }).find("no such file"),
            std::string::npos);
}

// Sums larger than the header's sample count can give (a consistent but forged file) are refused:
// the no-overflow argument relies on them.
TEST_F(FilmFile, ImplausibleSumsAreErrors) {
  Film f(film_info(2, 2, 0, 3));
  set(f, 3, WP_FILM_SUM(1), Uint128(3) << 64);  // S < 3 * 2^64 for 3 samples
  f.write(path("a.wpfilm"));
  EXPECT_NE(error_of([&] { Film::read(path("a.wpfilm")); }).find("pixel 3 holds more than 3"),
            std::string::npos);
  set(f, 3, WP_FILM_SUM(1), Uint128(kMax) * 3);
  set(f, 2, WP_FILM_SQUARES(0), Uint128(3) << 96);
  f.write(path("b.wpfilm"));
  EXPECT_NE(error_of([&] { Film::read(path("b.wpfilm")); }).find("pixel 2"), std::string::npos);
}

// The accumulate kernel on a wave of width x height paths, one per pixel: radiance(pass, pixel)
// written into the path state before each of `passes` passes, the film read back.
Film accumulate_on_device(
    int width, int height, std::uint32_t passes,
    const std::function<wp::dev::float4(std::uint32_t, std::uint32_t)>& radiance) {
  wp::ClRuntime runtime(wp::select_device(""));
  wp::Scene scene;
  scene.materials.push_back(wp::test::diffuse_material({0.5f, 0.5f, 0.5f}));
  wp::test::add_quad(scene, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 0);
  wp::test::finish_bounds(scene);
  scene.cameras.push_back(wp::test::look_at({0, 0, 3}, {0, 0, 0}, 0.8f));
  wp::RenderSettings settings;
  settings.width = width;
  settings.height = height;
  // One path a pixel, whatever the machine's cache or WAVEPATH_WAVE_SIZE would choose.
  settings.wave_size = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  std::vector<std::uint32_t> flags;
  wp::bvh::BuildOptions options;
  options.width = wp::bvh_width(runtime.device(), settings);
  const wp::bvh::Bvh bvh = wp::bvh::build(wp::bvh_input(scene, flags), options);
  wp::Wavefront wf(runtime, scene, bvh, settings);
  const auto pixels = static_cast<std::uint32_t>(width * height);
  const auto& layout = wf.path_state().layout;
  for (std::uint32_t pass = 0; pass < passes; ++pass) {
    std::vector<wp::dev::float4> values(pixels);
    for (std::uint32_t i = 0; i < pixels; ++i) values[i] = radiance(pass, i);
    wf.write_paths(layout.radiance, values);
    wf.launch_stage(wp::Stage::kAccumulate, pixels, wf.launch_params(pass, 0, pixels));
  }
  wf.finish();
  EXPECT_EQ(wf.nonfinite_samples(), 0u);
  return wf.film(film_info(width, height, 0, passes));
}

// The film of accumulate_on_device as the host computes it (film_fixed, film_square).
void expect_host_film(
    const Film& film, std::uint32_t passes,
    const std::function<wp::dev::float4(std::uint32_t, std::uint32_t)>& radiance) {
  for (std::size_t p = 0; p < film.pixels(); ++p) {
    Uint128 sums[3] = {0, 0, 0}, squares[3] = {0, 0, 0};
    for (std::uint32_t pass = 0; pass < passes; ++pass) {
      const wp::dev::float4 v = radiance(pass, static_cast<std::uint32_t>(p));
      const float c3[3] = {v.x, v.y, v.z};
      for (int c = 0; c < 3; ++c) {
        const std::uint64_t a = wp::film_fixed(c3[c]);
        sums[c] += a;
        squares[c] += wp::film_square(a);
      }
    }
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(film.sum(p, c) == sums[c]) << "pixel " << p << " channel " << c;
      EXPECT_TRUE(film.squares(p, c) == squares[c]) << "pixel " << p << " channel " << c;
    }
  }
}

// The accumulate kernel against the host reference: radiance values across the fixed-point range
// (saturation, rounding, negatives, carries into the high word over several passes) written into
// the path state, accumulated, read back.
TEST(FilmKernel, AccumulateMatchesTheHostReference) {
  // Units of 2^-32 (the film's): ties 0.5, 1.5, 2.5 and 2^23 - 0.5, 2^23 - 1.5 (the kernel rounds
  // below 2^23 units by adding 2^23), 2^23 and 2^23 + 1, the largest value below 2^32 and 2^32
  // (saturates).
  const std::vector<float> values = {
      0.0f,           1.0f,     0.5f,          0x1p-33f,        0x3p-33f,        0x5p-33f,
      1e-10f,         123.456f, 65535.99f,     0x1.fffffep-10f, 0x1.fffffap-10f, 0x1p-9f,
      0x1.000002p-9f, 0x1p31f,  4294967040.0f, 4294967296.0f,   1e20f,           -1.0f,
      -0.0f,          3.0e9f,   7.25f,         0x1.fffffcp-10f};
  const auto radiance = [&](std::uint32_t pass, std::uint32_t i) {
    float v[3];
    for (std::uint32_t c = 0; c < 3; ++c) {
      v[c] = values[(5 * pass + 3 * i + c) % values.size()];
      if (pass % 2 == 1 && i == 2) v[c] = 4294967296.0f;  // saturated: carries every time
    }
    return wp::dev::float4{v[0], v[1], v[2], 0.0f};
  };
  const Film film = accumulate_on_device(4, 2, 6, radiance);
  expect_host_film(film, 6, radiance);
  EXPECT_GE(film.sum(2, 0), Uint128(kMax) * 3);  // carried into the high word
}

// The same, densely: floats in [2^-40, 2^34) (the film's units [2^-8, 2^66), saturation included)
// from random bit patterns, 2^16 pixels by 3 channels by 2 passes; and the 128 floats below 2^23
// units and the 128 from it (the kernel's two ways of rounding meet there; ties below).
TEST(FilmKernel, AccumulateMatchesTheHostReferenceDensely) {
  constexpr int kSide = 256;
  const auto bits_of = [](std::uint32_t pass, std::uint32_t i, std::uint32_t c) {
    std::uint64_t z = (std::uint64_t(pass) << 40) ^ (std::uint64_t(i) << 2) ^ c;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;  // a splitmix64 finaliser: well-mixed bits
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return static_cast<std::uint32_t>(z ^ (z >> 31));
  };
  const auto radiance = [&](std::uint32_t pass, std::uint32_t i) {
    float v[3];
    for (std::uint32_t c = 0; c < 3; ++c) {
      const std::uint32_t k = 3 * i + c;
      if (pass == 0 && k < 256) {  // 2^23 units = 2^-9: 128 floats below it, 128 from it
        v[c] = wp::test::as_float(wp::test::bits(0x1p-9f) - 128u + k);
      } else {  // exponents -40 to 33: biased 87 to 160, any mantissa
        const std::uint32_t r = bits_of(pass, i, c);
        v[c] = wp::test::as_float(((87u + (r >> 23) % 74u) << 23) | (r & 0x7fffffu));
      }
    }
    return wp::dev::float4{v[0], v[1], v[2], 0.0f};
  };
  const Film film = accumulate_on_device(kSide, kSide, 2, radiance);
  expect_host_film(film, 2, radiance);
}

// The command line, as users run it: the Cornell box at 24 x 16, rendered once with 6 samples and
// once in three parts (0:2, 2:4, 4:6), for the whole suite.
class FilmCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("wavepath_film_cli_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    setup_error_ = new std::string;
    full_ = new wp::test::CliRun(
        run(render_args() + "--spp 6 -o full.exr -o full.pfm -o full.wpfilm --variance --json"));
    part_json_ = new std::string;
    const char* ranges[] = {"0:2", "2:4", "4:6"};
    for (int i = 0; i < 3; ++i) {
      const wp::test::CliRun r =
          run(render_args() + "--samples " + ranges[i] + " -o p" + std::to_string(i) +
              ".wpfilm -o p" + std::to_string(i) + ".pfm --json");
      if (r.status != 0) *setup_error_ += "part " + std::string(ranges[i]) + ": " + r.err;
      if (i == 1) *part_json_ = r.out;
    }
    if (full_->status != 0) *setup_error_ += "full render: " + full_->err;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete full_;
    delete part_json_;
    delete setup_error_;
  }
  void SetUp() override { ASSERT_EQ(*setup_error_, ""); }

  static std::string render_args(int width = 24) {
    return "render '" + wp::test::source_path("scenes/cornell_box.gltf") + "' --width " +
           std::to_string(width) + " --height 16 -q ";
  }
  static wp::test::CliRun run(const std::string& args) {
    return wp::test::run_wavepath(*dir_, args);
  }
  static std::string path(const std::string& name) { return (*dir_ / name).string(); }
  static Film film(const std::string& name) { return Film::read(path(name)); }

  // A failed merge: status 1, one line "wavepath: error: ..." containing `cause`, and nothing in
  // the (fresh) output folder `out`.
  static void expect_refused(const std::string& args, const std::string& cause) {
    SCOPED_TRACE("merge " + args);
    fs::remove_all(*dir_ / "out");
    fs::create_directories(*dir_ / "out");
    const wp::test::CliRun r = run("merge " + args + " -o out/m.exr -o out/m.wpfilm -o out/m.pfm");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err.rfind("wavepath: error: ", 0), 0u) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
    EXPECT_NE(r.err.find(cause), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(*dir_ / "out")) << "left behind in out/";
  }

  static fs::path* dir_;
  static wp::test::CliRun* full_;
  static std::string* part_json_;
  static std::string* setup_error_;
};
fs::path* FilmCli::dir_ = nullptr;
wp::test::CliRun* FilmCli::full_ = nullptr;
std::string* FilmCli::part_json_ = nullptr;
std::string* FilmCli::setup_error_ = nullptr;

// Values that differ in their bits (not merely in value: -0 and 0 differ, NaNs are not equal).
std::size_t differing_bits(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return std::max(a.size(), b.size());
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(float)) != 0;
  return n;
}

// The point of the fixed-point film: parts merged in two different orders give the single render's
// image and film, bit for bit.
TEST_F(FilmCli, MergedPartsEqualOneRenderBitForBit) {
  const wp::test::CliRun a =
      run("merge p2.wpfilm p0.wpfilm p1.wpfilm -o m1.exr -o m1.pfm "
          "-o m1.wpfilm --variance -q");
  ASSERT_EQ(a.status, 0) << a.err;
  const wp::test::CliRun b =
      run("merge p1.wpfilm p2.wpfilm p0.wpfilm -o m2.exr -o m2.wpfilm --json");
  ASSERT_EQ(b.status, 0) << b.err;

  const wp::ImageRgb full = wp::read_exr(path("full.exr"));
  ASSERT_EQ(full.width, 24);
  ASSERT_EQ(full.height, 16);
  for (const char* merged : {"m1.exr", "m2.exr"}) {
    const wp::ImageRgb m = wp::read_exr(path(merged));
    EXPECT_EQ(m.width, 24);
    EXPECT_EQ(m.height, 16);
    EXPECT_EQ(differing_bits(m.rgb, full.rgb), 0u) << merged;
  }
  EXPECT_EQ(wp::test::slurp(path("m1.pfm")), wp::test::slurp(path("full.pfm")));
  // The render writes the mean and variance it made from its film (render()), the merge those of
  // the merged film (Film::images): the same function of the same sums, so the same files.
  EXPECT_EQ(wp::test::slurp(path("m1.variance.pfm")), wp::test::slurp(path("full.variance.pfm")));
  EXPECT_GT(wp::test::slurp(path("full.variance.pfm")).size(), 24u * 16u * 12u);

  const Film single = film("full.wpfilm");
  for (const char* merged : {"m1.wpfilm", "m2.wpfilm"}) {
    const Film m = film(merged);
    EXPECT_TRUE(m.words() == single.words()) << merged;
    EXPECT_EQ(m.info().sample_begin, 0u);
    EXPECT_EQ(m.info().sample_end, 6u);
    EXPECT_EQ(m.info().key, single.info().key);
    // Same device, same (zero) NaN count: the very files are equal.
    EXPECT_EQ(wp::test::slurp(path(merged)), wp::test::slurp(path("full.wpfilm"))) << merged;
  }
  const auto attributes = wp::read_exr_attributes(path("m2.exr"));
  EXPECT_EQ(attributes.at("wavepath:samples"), "0:6");
  EXPECT_EQ(attributes.at("wavepath:render_key"),
            wp::read_exr_attributes(path("full.exr")).at("wavepath:render_key"));
  for (const char* key : {"\"parts\":3", "\"spp\":6", "\"sample_begin\":0", "\"sample_end\":6"})
    EXPECT_NE(b.out.find(key), std::string::npos) << key << " in " << b.out;

  // Not trivially equal: the image is lit, and the parts hold different samples.
  const std::size_t lit = static_cast<std::size_t>(
      std::count_if(full.rgb.begin(), full.rgb.end(), [](float v) { return v > 0.0f; }));
  EXPECT_GT(lit, full.rgb.size() / 2);
  EXPECT_GT(*std::max_element(full.rgb.begin(), full.rgb.end()), 0.1f);
  EXPECT_FALSE(film("p0.wpfilm").words() == film("p1.wpfilm").words());
}

// A part's image is the mean of its own samples, and the three parts' means average to the full
// image (up to float rounding).
TEST_F(FilmCli, PartImageIsTheMeanOfItsSamples) {
  const wp::test::CliRun r = run("merge p1.wpfilm -o single.pfm -q");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(wp::test::slurp(path("single.pfm")), wp::test::slurp(path("p1.pfm")));
  for (const char* key : {"\"spp\":2", "\"sample_begin\":2", "\"sample_end\":4"})
    EXPECT_NE(part_json_->find(key), std::string::npos) << key << " in " << *part_json_;
  for (const char* key : {"\"spp\":6", "\"sample_begin\":0", "\"sample_end\":6"})
    EXPECT_NE(full_->out.find(key), std::string::npos) << key << " in " << full_->out;
  const wp::FilmImages full = film("full.wpfilm").images();
  const wp::FilmImages p[3] = {film("p0.wpfilm").images(), film("p1.wpfilm").images(),
                               film("p2.wpfilm").images()};
  for (std::size_t i = 0; i < full.mean.size(); ++i) {
    const double avg = (double(p[0].mean[i]) + p[1].mean[i] + p[2].mean[i]) / 3.0;
    ASSERT_NEAR(full.mean[i], avg, 1e-6 * std::max(1.0, avg)) << "value " << i;
  }
}

// Waves and work-groups change which slot a pixel takes and the order of everything, not the film.
TEST_F(FilmCli, FilmDoesNotDependOnWaveSize) {
  const wp::test::CliRun r =
      run(render_args() + "--spp 6 --wave-size 100 --local-size 16 -o waves.wpfilm");
  ASSERT_EQ(r.status, 0) << r.err;
  const Film waves = film("waves.wpfilm"), single = film("full.wpfilm");
  EXPECT_TRUE(waves.words() == single.words());
  EXPECT_EQ(waves.info().key, single.info().key);
}

TEST_F(FilmCli, MergeRefusesWhatDoesNotBelongTogether) {
  for (const auto& [args, name] :
       {std::pair<std::string, std::string>{render_args() + "--samples 2:4 --seed 1", "seed1"},
        {render_args(20) + "--samples 2:4", "narrow"},
        {render_args() + "--samples 1:3", "overlap"}}) {
    const wp::test::CliRun r = run(args + " -o " + name + ".wpfilm");
    ASSERT_EQ(r.status, 0) << args << ": " << r.err;
  }
  expect_refused("p0.wpfilm seed1.wpfilm",
                 "seed1.wpfilm does not merge with p0.wpfilm: "
                 "different renders (seed=0 vs seed=1)");
  expect_refused("p0.wpfilm narrow.wpfilm", "different sizes (24x16 and 20x16)");
  expect_refused("p2.wpfilm overlap.wpfilm p0.wpfilm",
                 "p0.wpfilm and overlap.wpfilm do not merge: overlapping samples (0:2 and 1:3)");
  expect_refused("p0.wpfilm p1.wpfilm p1.wpfilm", "overlapping samples (2:4 and 2:4)");
  expect_refused("p2.wpfilm p0.wpfilm", "samples 0:2 and 4:6 leave 2:4 out");
  expect_refused("p0.wpfilm missing.wpfilm", "missing.wpfilm: no such file");
  expect_refused("p0.wpfilm full.pfm", "full.pfm: not a wavepath film");

  const std::string bytes = wp::test::slurp(path("p1.wpfilm"));
  const std::size_t data = bytes.find('\n', 14) + 1;
  for (const std::size_t n : {std::size_t(0), std::size_t(9), std::size_t(100), data - 1, data,
                              data + 1000, bytes.size() - 1}) {
    std::ofstream(path("cut.wpfilm"), std::ios::binary) << bytes.substr(0, n);
    expect_refused("p0.wpfilm cut.wpfilm p2.wpfilm", "cut.wpfilm: ");
  }
  const std::size_t seed = bytes.find("seed=0"), device = bytes.find("\"device\":\"") + 10;
  for (const std::size_t at :
       {std::size_t(3), std::size_t(20), seed + 5, device, data - 5, data + 7, bytes.size() - 1}) {
    std::string bad = bytes;
    bad[at] = static_cast<char>(bad[at] ^ 0x01);
    std::ofstream(path("flip.wpfilm"), std::ios::binary) << bad;
    expect_refused("p0.wpfilm flip.wpfilm p2.wpfilm", "flip.wpfilm: ");
  }
  // A changed byte is corruption, not a different render, even where it changes the key.
  for (const std::size_t at : {seed + 5, data + 500}) {
    std::string bad = bytes;
    bad[at] = static_cast<char>(bad[at] ^ 0x01);
    std::ofstream(path("flip.wpfilm"), std::ios::binary) << bad;
    expect_refused("p0.wpfilm flip.wpfilm p2.wpfilm", "flip.wpfilm: corrupted");
  }
  expect_refused("p0.wpfilm p1.wpfilm p2.wpfilm --exposure nan", "--exposure");
}

TEST_F(FilmCli, SampleRangeOptions) {
  const std::string tiny = "render '" + wp::test::source_path("scenes/cornell_box.gltf") +
                           "' --width 4 --height 4 -q -o out/x.exr ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--samples 4", "--samples 4: expected A:B with 0 <= A < B <= 1048576"},
      {"--samples 3:2", "--samples 3:2: expected A:B"},
      {"--samples 2:2", "--samples 2:2: expected A:B"},
      {"--samples 0:1048577", "--samples 0:1048577: expected A:B"},
      {"--samples -1:2", "expected A:B"},
      {"--samples a:b", "expected A:B"},
      {"--samples 1:2:3", "expected A:B"},
      {"--spp 4 --samples 0:5", "--spp 4 and --samples 0:5 disagree"},
      {"--spp 4 --samples 2:6", "disagree"},
      {"-o out/x.jpg", "use .exr, .png, .pfm or .wpfilm"}};
  for (const auto& [args, cause] : cases) {
    fs::remove_all(*dir_ / "out");
    fs::create_directories(*dir_ / "out");
    const wp::test::CliRun r = run(tiny + args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_NE(r.err.find(cause), std::string::npos) << args << ": " << r.err;
    EXPECT_TRUE(fs::is_empty(*dir_ / "out")) << args;
  }
  fs::create_directories(*dir_ / "out");
  const wp::test::CliRun ok = run(tiny + "--spp 3 --samples 0:3 -o out/x.wpfilm");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_EQ(film("out/x.wpfilm").info().sample_end, 3u);
  const wp::test::CliRun last = run(tiny + "--samples 1048575:1048576 -o out/y.wpfilm");
  EXPECT_EQ(last.status, 0) << last.err;
  EXPECT_EQ(film("out/y.wpfilm").info().sample_begin, 1048575u);
}

}  // namespace
