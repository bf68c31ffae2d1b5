// Mip chains of texture images, built on the host and packed after each image in the device's
// texel array (kernels/shared/types.h, TextureImage; looked up by kernels/texture/textures.h
// through the ray cones of kernels/texture/ray_cone.h).
//
// Level k + 1 has half the width and height of level k, rounding down, and each of its texels is
// the exact box filter of level k over the texel's footprint: the mean of the piecewise-constant
// image over [i w_k / w_k+1, (i + 1) w_k / w_k+1) x (the same in y), so a level of an odd-sized
// image weighs the source texels it covers in part by the part it covers. Footprints never leave
// the image, so the wrap modes do not enter the filter (the lookup wraps at each level's own
// size). Level k is the box filter of level 0 over its footprint, up to its own rounding: it is
// made, in float, from the nearest level whose texels its texels cover whole (the previous one
// where that level's sides are even), else from level 0 (a box of a box that cuts texels in part
// would weigh level 0 unevenly), and never from an 8-bit encoding. Colour
// (sRGB) images are filtered in linear light and encoded back; alpha and data images are
// filtered as they are stored. The chain ends at the level whose shorter side is one texel, so it
// adds at most a third to the image's texels.
#pragma once

#include <cstdint>
#include <vector>

#include "host/scene/scene.h"

namespace wp {

// The number of levels of a width x height image's chain, the image included:
// 1 + floor(log2(min(width, height))).
int mip_levels(int width, int height);

// The width (or height) of `level` of an image `size` texels wide (or high), size >= 1.
int mip_size(int size, int level);

// Levels 1 .. mip_levels - 1 of `image`, one after another, RGBA8 like Image::rgba; `srgb` for
// colour images (RGB sRGB-encoded, alpha linear).
std::vector<std::uint8_t> mip_chain(const Image& image, bool srgb);

// The 8-bit sRGB code of linear value v (clamped to [0, 1]) as the chains encode colour:
// round(255 linear_to_srgb(v)) (host/scene/srgb.h), computed with pow by encode_srgb8_pow and from
// a table of the codes' first values by encode_srgb8, which gives the same code for every float.
std::uint8_t encode_srgb8(float v);
std::uint8_t encode_srgb8_pow(double v);

}  // namespace wp
