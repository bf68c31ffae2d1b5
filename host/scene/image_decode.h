// Texture images from their encoded bytes to 8-bit RGBA: PNG through libpng, JPEG through
// libjpeg-turbo, WebP (EXT_texture_webp) through libwebp. Used by the glTF loader's texture table
// (gltf_textures.cpp) and by the tests' compressed twins (tests/gltf/compress_twin.cpp), which must
// see the texels the loader sees.
#pragma once

#include <cstddef>
#include <string>

#include "host/scene/scene.h"

namespace wp {

// Decodes `size` bytes of a PNG, JPEG or WebP image into out.width, out.height and out.rgba (4 x
// width x height bytes, rows top to bottom); out.name is left alone. PNG texels are the file's
// samples, without gamma or colour-space conversion: palette expanded, tRNS as alpha, grey as RGB,
// 1/2/4-bit grey scaled to 8 bits (x 255, 85, 17), 16-bit samples cut to their high byte, alpha
// 255 where the file has none. JPEG texels are libjpeg-turbo's (accurate integer IDCT, smooth
// chroma upsampling); CMYK and YCCK files (Adobe's inverted CMYK) become RGB as c x k / 255.
// Throws wp::Error naming `what` (e.g. "image 3 'foo' (foo.png)") when the bytes are none of
// those formats, cannot be decoded, or claim more texels than their bytes or the texture limit
// allow; out is then not a valid image.
void decode_image(const unsigned char* bytes, std::size_t size, const std::string& what,
                  Image& out);

}  // namespace wp
