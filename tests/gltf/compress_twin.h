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
#include <string>
#include <vector>

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

}  // namespace wp::test
