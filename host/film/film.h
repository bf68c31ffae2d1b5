// The film as a value: the fixed-point sums of a range of samples of one render
// (kernels/shared/film.h), with the render's identity. Films of disjoint sample ranges of the same
// render add up exactly, in any order, to the film of one uninterrupted render: integer sums do
// not depend on the order of addition. A film is saved as a .wpfilm file (format in film.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "kernels/shared/film.h"

namespace wp {

__extension__ typedef unsigned __int128 Uint128;

// The image a film gives: per pixel and channel the mean (linear RGB, row by row from the top,
// 3 floats per pixel) and the variance of that mean (sample variance / samples).
struct FilmImages {
  std::vector<float> mean;
  std::vector<float> variance;
  // With AOVs (FilmInfo::aov), else empty: per pixel the mean over its samples of the albedo
  // (3 floats, linear RGB), the shading normal (3, world space, facing the camera's side, not
  // renormalised: the mean of unit vectors) and the depth (1, metres from the camera).
  std::vector<float> albedo, normal, depth;
};

struct FilmInfo {
  int width = 0, height = 0;  // 1..kFilmMaxSide each
  bool aov = false;           // holds AOV sums too (WP_FILM_WORDS(aov) words per pixel)
  // The samples the sums hold: indices [sample_begin, sample_end), within [0, 2^20).
  std::uint32_t sample_begin = 0, sample_end = 0;
  std::string key;     // the render key (render.h, render_key): films merge only with equal keys
  std::string device;  // where the samples were rendered; "A + B" once films of two merge
  std::uint64_t nonfinite_samples = 0;  // NaN/Inf values dropped while rendering them
  std::uint32_t samples() const { return sample_end - sample_begin; }
  std::size_t words_per_pixel() const { return WP_FILM_WORDS(aov); }
};

constexpr int kFilmMaxSide = 16384;

class Film {
 public:
  Film() = default;
  // A film of zero sums. Throws wp::Error when the size or the sample range is out of bounds.
  explicit Film(FilmInfo info);

  const FilmInfo& info() const { return info_; }
  std::size_t pixels() const { return std::size_t(info_.width) * std::size_t(info_.height); }
  // info().words_per_pixel() words per pixel in the layout of kernels/shared/film.h.
  std::vector<std::uint64_t>& words() { return words_; }
  const std::vector<std::uint64_t>& words() const { return words_; }
  // S (the sum of a) and Q (the sum of floor(a^2 / 2^32)) of one pixel's channel.
  Uint128 sum(std::size_t pixel, int channel) const { return at(pixel, WP_FILM_SUM(channel)); }
  Uint128 squares(std::size_t pixel, int channel) const {
    return at(pixel, WP_FILM_SQUARES(channel));
  }

  // Adds `other`'s samples: same key and size, and a sample range just before or just after this
  // one, so that the sum holds one range again. Throws wp::Error naming the mismatch otherwise.
  void add(const Film& other);

  // The mean and the variance of the mean of every pixel, from the sums; samples that were
  // dropped as NaN/Inf weigh as 0 (mean = S / 2^32 / samples).
  FilmImages images() const;

  // Writes the film to `path` as a .wpfilm file. Throws wp::Error naming the file on failure.
  void write(const std::string& path) const;
  // Reads a .wpfilm file. Any input is safe: a malformed, truncated or corrupted file, or one
  // whose sizes would not fit, is a wp::Error naming the file, checked before allocating.
  static Film read(const std::string& path);
  // The description of a .wpfilm file, checked entirely as by read() but without keeping the
  // data (so that many films can be checked before any is held in memory).
  static FilmInfo read_info(const std::string& path);

 private:
  Uint128 at(std::size_t pixel, unsigned word) const {
    const std::size_t i = pixel * info_.words_per_pixel() + word;
    return Uint128(words_[i + 1]) << 64 | words_[i];
  }

  FilmInfo info_;
  std::vector<std::uint64_t> words_;
};

// The estimated relative error of an image: the root of the mean over pixels of
//   (var_R + var_G + var_B) / (mean_R^2 + mean_G^2 + mean_B^2 + 3 eps^2),
// with var the variance of each channel's mean (FilmImages::variance) and eps = 1/100 of the
// image's mean value over all pixels and channels (so that black pixels do not divide by zero,
// and the measure does not depend on the image's scale). Its square estimates the relative mean
// squared error (relMSE) that the image has against the exact one; 0 for a black image.
double relative_error(const FilmImages& images);

// The devices of two films, each listed once ("A + B"), for a film that holds samples of both.
std::string join_devices(const std::string& a, const std::string& b);

// Why films `a` and `b` are not of the same render, or "": names the first field of the render
// key that differs, or the two sizes.
std::string film_identity_problem(const FilmInfo& a, const FilmInfo& b);
// Why films `a` and `b` cannot be added (Film::add), or "" when they can: an identity problem,
// or sample ranges that overlap or are not adjacent (naming both).
std::string film_merge_problem(const FilmInfo& a, const FilmInfo& b);

// What the accumulate kernel adds for one sample value v: a = round(v * 2^32) saturated to
// [0, 2^64 - 1] (NaN: 0), and floor(a^2 / 2^32). Host references for tests.
std::uint64_t film_fixed(float v);
Uint128 film_square(std::uint64_t a);

}  // namespace wp
