// The sRGB transfer functions of IEC 61966-2-1, in double precision: texels of colour textures are
// decoded with the EOTF before they are filtered, and mip levels encoded back (mipmap.cpp).
#pragma once

#include <algorithm>
#include <cmath>

namespace wp {

// Encoded value c in [0, 1] to linear.
inline double srgb_to_linear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// Linear value x to encoded, x clamped to [0, 1] first.
inline double linear_to_srgb(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

}  // namespace wp
