#include "host/film/tonemap.h"

#include <algorithm>
#include <cmath>

#include "host/util/error.h"

namespace wp {

namespace {

// 3x3 matrices, row-major, in double for the constants derived at compile time (inverses), used
// in float.
struct Mat3 {
  double m[3][3];
};

constexpr Mat3 transpose(const Mat3& a) {
  Mat3 t{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t.m[i][j] = a.m[j][i];
  return t;
}

constexpr Mat3 inverse(const Mat3& a) {
  const auto& m = a.m;
  Mat3 c{};  // cofactors, transposed
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
      c.m[i][j] = m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1];
    }
  const double det = m[0][0] * c.m[0][0] + m[0][1] * c.m[1][0] + m[0][2] * c.m[2][0];
  for (auto& row : c.m)
    for (double& v : row) v /= det;
  return c;
}

constexpr Mat3 multiply(const Mat3& a, const Mat3& b) {
  Mat3 p{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) p.m[i][j] += a.m[i][k] * b.m[k][j];
  return p;
}

Rgb apply(const Mat3& a, const Rgb& v) {
  Rgb out;
  for (int i = 0; i < 3; ++i)
    out[i] = float(a.m[i][0]) * v[0] + float(a.m[i][1]) * v[1] + float(a.m[i][2]) * v[2];
  return out;
}

// AgX as three.js defines it (AgXToneMapping, src/renderers/shaders/ShaderChunk/
// tonemapping_pars_fragment.glsl.js), whose matrices and curve Filament's AgX uses too: Blender 4's
// AgX base (Troy Sobotka's AgX as Eary Chow adapted it) with its inset and outset matrices in
// linear Rec.2020 and a log2 encoding of [2^-12.47393, 2^4.026069] (-10 to +6.5 stops around 0.18),
// but the sigmoid as Benjamin Wrensch's 6th-order polynomial fit of Blender's curve instead of its
// LUT. The sigmoid's output is display-encoded for a 2.2 power, which three.js undoes, so the
// result is linear Rec.709 and the PNG's sRGB encoding is the only one applied. three.js's Rec.2020
// -> Rec.709 matrix (4 digits, ITU-R BT.2407), and its inverse, as three.js computes it.
constexpr Mat3 kRec2020ToRec709 = {
    {{1.6605, -0.5876, -0.0728}, {-0.1246, 1.1329, -0.0083}, {-0.0182, -0.1006, 1.1187}}};
// three.js writes these as GLSL mat3(column, column, column): hence transpose().
constexpr Mat3 kAgxInset =
    transpose({{{0.856627153315983, 0.137318972929847, 0.11189821299995},
                {0.0951212405381588, 0.761241990602591, 0.0767994186031903},
                {0.0482516061458583, 0.101439036467562, 0.811302368396859}}});
constexpr Mat3 kAgxOutsetInverse =
    transpose({{{0.899796955911611, 0.11142098895748, 0.11142098895748},
                {0.0871996192028351, 0.875575586156966, 0.0871996192028349},
                {0.013003424885555, 0.0130034248855548, 0.801379391839686}}});
constexpr Mat3 kRec709ToAgxInset = multiply(kAgxInset, inverse(kRec2020ToRec709));
constexpr Mat3 kAgxOutset = inverse(kAgxOutsetInverse);
constexpr float kAgxMinEv = -12.47393f, kAgxMaxEv = 4.026069f;

// Wrensch's fit of AgX's default contrast sigmoid on [0, 1] (mean squared error 3.7e-6).
float agx_sigmoid(float x) {
  const float x2 = x * x, x4 = x2 * x2;
  return 15.5f * x4 * x2 - 40.14f * x4 * x + 31.96f * x4 - 6.868f * x2 * x + 0.4298f * x2 +
         0.1191f * x - 0.00232f;
}

Rgb agx(const Rgb& linear) {
  // Rec.709 lies inside Rec.2020: non-negative input stays non-negative, so three.js's clamp at
  // zero between the two matrices changes nothing here.
  Rgb v = apply(kRec709ToAgxInset, linear);
  for (float& c : v) {
    const float encoded = (std::log2(std::max(c, 1e-10f)) - kAgxMinEv) / (kAgxMaxEv - kAgxMinEv);
    c = agx_sigmoid(std::clamp(encoded, 0.0f, 1.0f));
  }
  v = apply(kAgxOutset, v);
  for (float& c : v) c = std::pow(std::max(c, 0.0f), 2.2f);
  return apply(kRec2020ToRec709, v);
}

// Khronos PBR Neutral as the normative text of KhronosGroup/ToneMapping's PBR_Neutral/README.md
// states it (where sample code differed, e.g. an earlier pbrNeutral.glsl desaturating towards
// white rather than towards [p_n, p_n, p_n], the text rules). F90 = 0.04 is the normal-incidence
// Fresnel reflectance of IoR 1.5; below the start of compression K_s = 0.8 - F90 the colour is
// only offset, so base colours in [0.08, 0.8] come out exactly as 0.04 lower.
Rgb pbr_neutral(const Rgb& c) {
  constexpr float kF90 = 0.04f, kStartCompression = 0.8f - kF90, kDesaturation = 0.15f;
  const float x = std::min({c[0], c[1], c[2]});
  const float f = x <= 2.0f * kF90 ? x - x * x / (4.0f * kF90) : kF90;
  Rgb out = {c[0] - f, c[1] - f, c[2] - f};
  const float p = std::max({out[0], out[1], out[2]});
  if (p <= kStartCompression) return out;
  const float d = 1.0f - kStartCompression;
  const float pn = 1.0f - d * d / (p + 1.0f - 2.0f * kStartCompression);
  const float g = 1.0f / (kDesaturation * (p - pn) + 1.0f);
  for (float& o : out) o = o * (pn / p) * g + pn * (1.0f - g);
  return out;
}

// kAgx and kPbrNeutral mix the channels, so one NaN would spread to all three: it reads as 0.
// Infinity reads as 3e38, which both map to 1, as they do any large value (inf * 0 would be NaN).
Rgb non_negative(const Rgb& c) {
  Rgb out;
  for (int i = 0; i < 3; ++i) out[i] = c[i] > 0.0f ? std::min(c[i], 3.0e38f) : 0.0f;
  return out;
}

float srgb_encode(float x) {
  if (!(x > 0.0f)) x = 0.0f;  // also NaN
  x = std::min(x, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

}  // namespace

std::vector<std::string> tonemap_names() {
  return {"aces", "agx", "pbr-neutral", "clamp"};
}

Tonemap tonemap_from_name(const std::string& name) {
  const Tonemap all[] = {Tonemap::kAces, Tonemap::kAgx, Tonemap::kPbrNeutral, Tonemap::kClamp};
  const std::vector<std::string> names = tonemap_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return all[i];
  throw Error("unknown tonemap '" + name + "' (aces, agx, pbr-neutral or clamp)");
}

Rgb tonemap(const Rgb& linear, Tonemap t) {
  switch (t) {
    case Tonemap::kAces: {
      Rgb out;
      for (int i = 0; i < 3; ++i) {
        const float x = std::max(linear[i], 0.0f);
        out[i] = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
      }
      return out;
    }
    case Tonemap::kAgx:
      return agx(non_negative(linear));
    case Tonemap::kPbrNeutral:
      return pbr_neutral(non_negative(linear));
    case Tonemap::kClamp:
      break;
  }
  return linear;
}

Rgb png_display(const Rgb& linear, const PngOptions& png) {
  const float scale = std::exp2(png.exposure);
  Rgb v = tonemap({linear[0] * scale, linear[1] * scale, linear[2] * scale}, png.tonemap);
  for (float& c : v) c = srgb_encode(c);
  return v;
}

std::array<unsigned char, 3> png_encode(const Rgb& linear, const PngOptions& png) {
  const Rgb s = png_display(linear, png);
  std::array<unsigned char, 3> out;
  for (int i = 0; i < 3; ++i) out[i] = static_cast<unsigned char>(std::lround(s[i] * 255.0f));
  return out;
}

}  // namespace wp
