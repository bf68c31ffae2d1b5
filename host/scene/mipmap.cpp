#include "host/scene/mipmap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "host/scene/srgb.h"
#include "host/util/error.h"

namespace wp {

int mip_levels(int width, int height) {
  int levels = 1;
  for (int s = std::min(width, height); s > 1; s >>= 1) ++levels;
  return levels;
}

int mip_size(int size, int level) {
  return std::max(size >> level, 1);
}

namespace {

// The box filter of n source texels onto m <= n targets: target i covers [i s, (i + 1) s) of the
// source, s = n / m, and takes each source texel by the part of it that lies inside, divided by s.
struct Taps {
  std::vector<int> first;                   // per target: its first source texel
  std::vector<std::vector<double>> weight;  // per target: its source texels' weights, in order
};

Taps box_taps(int n, int m) {
  const double s = static_cast<double>(n) / m;
  Taps t;
  for (int i = 0; i < m; ++i) {
    const double lo = i * s, hi = (i + 1) * s;
    const int first = static_cast<int>(std::floor(lo));
    const int end = std::min(n, static_cast<int>(std::ceil(hi)));
    std::vector<double> w;
    for (int k = first; k < end; ++k)
      w.push_back((std::min(hi, double(k + 1)) - std::max(lo, double(k))) / s);
    t.first.push_back(first);
    t.weight.push_back(std::move(w));
  }
  return t;
}

// One level in float, 4 channels per texel (linear for colour images).
struct Level {
  int width = 0, height = 0;
  std::vector<float> texels;
};

// A width x height level made from a source_width x source_height one whose channel i (texel
// i / 4) is src(i): the box in x, then in y (the 2D box is their product), a target row at a time.
template <class Source>
Level box_level(int source_width, int source_height, const Source& src, int width, int height) {
  const Taps tx = box_taps(source_width, width), ty = box_taps(source_height, height);
  Level out{width, height, std::vector<float>(std::size_t(4) * width * height)};
  std::vector<double> row(std::size_t(4) * width);
  for (int y = 0; y < height; ++y) {
    std::fill(row.begin(), row.end(), 0.0);
    const std::vector<double>& wy = ty.weight[std::size_t(y)];
    for (std::size_t ky = 0; ky < wy.size(); ++ky) {
      const std::size_t source_row = std::size_t(ty.first[std::size_t(y)] + int(ky)) * source_width;
      for (int x = 0; x < width; ++x) {
        const std::vector<double>& wx = tx.weight[std::size_t(x)];
        for (std::size_t kx = 0; kx < wx.size(); ++kx) {
          const double w = wy[ky] * wx[kx];
          const std::size_t from = 4 * (source_row + std::size_t(tx.first[std::size_t(x)]) + kx);
          for (std::size_t c = 0; c < 4; ++c) row[4 * std::size_t(x) + c] += w * src(from + c);
        }
      }
    }
    std::copy(row.begin(), row.end(), out.texels.begin() + std::ptrdiff_t(row.size()) * y);
  }
  return out;
}

// A level's value v to its 8-bit code: round(255 linear_to_srgb(v)) for colour, round(255 v) for
// data and alpha, v clamped to [0, 1].
std::uint8_t encode(double v, bool srgb) {
  if (srgb) v = linear_to_srgb(v);
  return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

float float_of_bits(std::uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

// encode's colour codes without a pow per texel. first_[c] is the least float whose code exceeds c,
// found once by bisection over the float bit patterns of [0, 1] with encode itself, which is
// non-decreasing in v. A value's cell, floor(v kCells) (also non-decreasing in v), holds at most
// one of those first values (the cells are narrower than the closest two, 3.0e-4 apart near 0,
// where the curve is steepest: checked when the table is made), so the code is the code of the
// cell's least float, cell_[i], or one more from first_[cell_[i]] on: the same code as encode's
// for every float (tests/test_textures.cpp, MipChain.ColourEncodingMatchesThePowForm).
class SrgbEncoder {
 public:
  SrgbEncoder() {
    const auto least = [](auto above) {  // the least float of [0, 1] where above(v) holds
      std::uint32_t lo = 0, hi = 0x3f800000u;
      if (above(0.0f)) return 0.0f;
      while (hi - lo > 1) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        (above(float_of_bits(mid)) ? hi : lo) = mid;
      }
      return float_of_bits(hi);
    };
    for (int c = 0; c < 255; ++c)
      first_[std::size_t(c)] = least([c](float v) { return encode(v, true) > c; });
    for (int c = 0; c + 1 < 255; ++c)
      if (cell(first_[std::size_t(c)]) == cell(first_[std::size_t(c) + 1]))
        throw Error("sRGB encoder: two codes begin in one cell");  // kCells too small
    for (int i = 0; i < kCells; ++i)
      cell_[std::size_t(i)] = encode(least([i](float v) { return cell(v) >= i; }), true);
  }
  std::uint8_t operator()(float v) const {
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return 255;
    const std::uint8_t c = cell_[std::size_t(cell(v))];
    return c < 255 && v >= first_[c] ? std::uint8_t(c + 1) : c;
  }

 private:
  static constexpr int kCells = 4096;
  static int cell(float v) { return static_cast<int>(v * float(kCells)); }  // v in [0, 1)
  std::array<float, 255> first_{};
  std::array<std::uint8_t, kCells> cell_{};
};

const SrgbEncoder& srgb_encoder() {
  static const SrgbEncoder encoder;
  return encoder;
}

// The data code: lround of v 255 >= 0, which is exact in double for a float v, as floor(x + 0.5).
std::uint8_t encode_linear(float v) {
  return static_cast<std::uint8_t>(std::floor(std::clamp(double(v), 0.0, 1.0) * 255.0 + 0.5));
}

}  // namespace

std::uint8_t encode_srgb8(float v) {
  return srgb_encoder()(v);
}

std::uint8_t encode_srgb8_pow(double v) {
  return encode(v, true);
}

std::vector<std::uint8_t> mip_chain(const Image& image, bool srgb) {
  std::array<float, 256> decode{}, linear{};
  for (int c = 0; c < 256; ++c) {
    linear[std::size_t(c)] = static_cast<float>(c / 255.0);
    decode[std::size_t(c)] = static_cast<float>(srgb ? srgb_to_linear(c / 255.0) : c / 255.0);
  }
  const auto level0 = [&](std::size_t i) { return (i % 4 == 3 ? linear : decode)[image.rgba[i]]; };
  const SrgbEncoder& encode_colour = srgb_encoder();
  std::vector<Level> levels(1);  // float levels 1.. (levels[0]: level 0, read from the bytes)
  std::vector<std::uint8_t> out;
  for (int k = 1; k < mip_levels(image.width, image.height); ++k) {
    const int w = mip_size(image.width, k), h = mip_size(image.height, k);
    // The source: the nearest level whose size is w x h times a power of two, whose texels each
    // target texel then covers whole (so the box over them is the box over level 0); otherwise
    // level 0 itself, with the parts of texels an odd size leaves.
    int j = k - 1;
    while (j > 0 && !(levels[std::size_t(j)].width == (w << (k - j)) &&
                      levels[std::size_t(j)].height == (h << (k - j))))
      --j;
    if (j == 0) {
      levels.push_back(box_level(image.width, image.height, level0, w, h));
    } else {
      const Level& src = levels[std::size_t(j)];
      levels.push_back(box_level(
          src.width, src.height, [&src](std::size_t i) { return src.texels[i]; }, w, h));
    }
    const Level& level = levels.back();
    for (std::size_t i = 0; i < level.texels.size(); ++i)
      out.push_back(srgb && i % 4 != 3 ? encode_colour(level.texels[i])
                                       : encode_linear(level.texels[i]));
  }
  return out;
}

}  // namespace wp
