// Compressed twins of .glb files, written at test time with the codecs' own encoders (nothing
// binary is committed, nothing downloaded): Draco meshes (KHR_draco_mesh_compression), meshopt
// buffer views (EXT_meshopt_compression, with or without filters) and lossless WebP images
// (EXT_texture_webp). Used by tests/gltf/test_gltf_compressed.cpp, tests/test_compressed_render.cpp
// and the fuzz seeds (tests/fuzz/make_compressed_seeds.cpp).
//
// Each twin keeps the original's binary chunk and appends the compressed data; the compressed
// elements stop referring to the original bytes, and the extension is required, so a loader that
// ignored it would fail rather than read the originals.
#pragma once

#include <cstdint>
#include <cstdio>  // before jpeglib.h, which uses FILE without including it
#include <string>
#include <vector>

#include <jpeglib.h>

namespace wp::test {

// A .glb split into its JSON text and binary chunk.
struct Glb {
  std::string json;
  std::vector<unsigned char> bin;
};

Glb read_glb(const std::string& path);                 // throws std::runtime_error
std::vector<unsigned char> glb_bytes(const Glb& glb);  // the .glb file
void write_file(const std::string& path, const std::vector<unsigned char>& bytes);

// Draco quantisation bits (Draco's Encoder: each attribute's values over its bounding box's
// largest extent; normals octahedral).
struct DracoBits {
  int position = 14, normal = 10, texcoord = 12, generic = 12;
  bool edgebreaker = true;  // else the sequential connectivity coder
};

// What the Draco twin quantised, for the tests' tolerances: per mesh, the step of the position
// grid (its largest POSITION extent / (2^bits - 1)) and of the texture coordinates'.
struct DracoSteps {
  std::vector<double> position, texcoord;
};

// Every triangle primitive whose attributes are all float (and indexed, or not) as one Draco mesh.
Glb draco_twin(const Glb& in, const DracoBits& bits, DracoSteps* steps = nullptr);

// Mesh attribute and index buffer views as EXT_meshopt_compression streams (ATTRIBUTES,
// TRIANGLES), the uncompressed data only in a fallback buffer without data. With `filters`,
// float NORMAL views become OCTAHEDRAL 16-bit (KHR_mesh_quantization: SHORT normalized, stride 8,
// `octahedral_bits` per component) and float POSITION views EXPONENTIAL with `exponential_bits`
// of mantissa.
struct MeshoptFilters {
  bool on = false;
  int octahedral_bits = 12, exponential_bits = 16;
};
Glb meshopt_twin(const Glb& in, const MeshoptFilters& filters = {});

// Every image as a lossless WebP (exact RGBA: the texels the loader decodes from the original,
// wp::decode_image), the textures' EXT_texture_webp source; the textures' own `source` is dropped.
Glb webp_twin(const Glb& in);

// A lossless WebP of `width` x `height` RGBA8 texels (exact: RGB kept under alpha 0 too).
std::vector<unsigned char> webp_lossless(const unsigned char* rgba, int width, int height);

// A JPEG of `samples` (rows top down, `components` a texel) from libjpeg's compressor at quality
// 100 (the tests check the decoder against the texels it was given; the fuzz seeds): `components` 1
// (grey), 3 (RGB, stored as YCbCr) or 4 (CMYK, stored as Adobe's inverted CMYK); every component at
// full resolution (4:4:4), so chroma upsampling plays no part in the bounds below. `scans`: the
// progressive scan script to write, if any.
std::vector<unsigned char> jpeg_encode(const std::vector<unsigned char>& samples, int width,
                                       int height, int components, bool progressive,
                                       const std::vector<jpeg_scan_info>& scans = {});

}  // namespace wp::test
