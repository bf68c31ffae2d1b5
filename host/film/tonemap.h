// The PNG output's display transform: exposure, a tonemap, then the sRGB encoding (IEC 61966-2-1)
// into 8 bits. Input is linear Rec.709 (the film's space); every tonemap here outputs linear
// Rec.709 for the one sRGB encoding that follows. tools/generators/tonemap_reference.py holds float64
// transcriptions of the published definitions that tests/test_tonemap.cpp checks these against.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace wp {

enum class Tonemap {
  kAces,        // Narkowicz 2015's rational fit of the ACES filmic curve, per channel
  kAgx,         // AgX as three.js defines it (tonemap.cpp), on the RGB triplet
  kPbrNeutral,  // Khronos PBR Neutral (KhronosGroup/ToneMapping), on the RGB triplet
  kClamp,       // none: values above 1 clip
};

// Command-line names ("aces", "agx", "pbr-neutral", "clamp"), in that order.
std::vector<std::string> tonemap_names();
// The tonemap of a command-line name; throws wp::Error for any other.
Tonemap tonemap_from_name(const std::string& name);

struct PngOptions {
  float exposure = 0.0f;  // stops: the image is scaled by 2^exposure before tonemapping
  Tonemap tonemap = Tonemap::kAces;
};

using Rgb = std::array<float, 3>;

// Linear Rec.709 in, linear Rec.709 out (display-referred, [0, 1] up to the clipping the sRGB
// encoding does). kAgx and kPbrNeutral read NaN as 0 and negative values as 0.
Rgb tonemap(const Rgb& linear, Tonemap t);

// The sRGB-encoded value in [0, 1] PNG output stores (before 8-bit rounding) for a linear pixel:
// exposure, tonemap, clamp to [0, 1] (NaN to 0), sRGB encoding.
Rgb png_display(const Rgb& linear, const PngOptions& png);
// png_display rounded to the nearest 8-bit code.
std::array<unsigned char, 3> png_encode(const Rgb& linear, const PngOptions& png);

}  // namespace wp
