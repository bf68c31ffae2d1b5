// libFuzzer target: wp::load_gltf on arbitrary bytes. Inputs starting with the binary magic "glTF"
// are loaded as .glb, all others as .gltf (JSON). The loader's contract (host/scene/gltf_loader.h):
// any input ends in a Scene or in one wp::Error. Any other exception, a crash, a sanitizer report,
// a hang or a Scene whose arrays disagree (which the BVH build and the device upload would read out
// of bounds) is a finding.
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <string>

#include "host/util/error.h"
#include "host/scene/gltf_loader.h"
#include "tests/fuzz/fuzz_file.h"

namespace {

using wp::fuzz::invariant_failed;

void check_same_size(std::size_t n, std::size_t vertices, const char* name, bool may_be_empty) {
  if (n == vertices || (may_be_empty && n == 0)) return;
  invariant_failed(std::string(name) + " has " + std::to_string(n) + " entries for " +
                   std::to_string(vertices) + " vertices");
}

void check_texture_slot(int slot, std::size_t textures, std::size_t material, const char* name) {
  if (slot >= -1 && (slot < 0 || std::size_t(slot) < textures)) return;
  invariant_failed("material " + std::to_string(material) + " " + name + " " +
                   std::to_string(slot) + " of " + std::to_string(textures) + " textures");
}

// The cross-references host/scene/scene.h promises, everything downstream indexes with.
void check_scene(const wp::Scene& s) {
  const std::size_t v = s.positions.size();
  check_same_size(s.normals.size(), v, "normals", false);
  check_same_size(s.uv0.size(), v, "uv0", true);
  check_same_size(s.uv1.size(), v, "uv1", true);
  check_same_size(s.color0.size(), v, "color0", true);
  check_same_size(s.tangents.size(), v, "tangents", true);
  if (s.indices.size() % 3 != 0) invariant_failed("indices is not a multiple of 3");
  if (s.triangle_material.size() != s.triangle_count())
    invariant_failed("triangle_material does not have one entry per triangle");
  for (std::size_t i = 0; i < s.indices.size(); ++i)
    if (s.indices[i] >= v)
      invariant_failed("index " + std::to_string(i) + " = " + std::to_string(s.indices[i]) +
                       " of " + std::to_string(v) + " vertices");
  for (std::size_t t = 0; t < s.triangle_material.size(); ++t)
    if (s.triangle_material[t] >= s.materials.size())
      invariant_failed("triangle " + std::to_string(t) + " material " +
                       std::to_string(s.triangle_material[t]) + " of " +
                       std::to_string(s.materials.size()));
  for (const wp::Image& image : s.images)
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != 4 * std::size_t(image.width) * std::size_t(image.height))
      invariant_failed("image '" + image.name + "' size does not match its pixels");
  for (const wp::TextureRef& t : s.textures)
    if (t.image < 0 || std::size_t(t.image) >= s.images.size() || t.texcoord < 0 || t.texcoord > 1)
      invariant_failed("texture refers to image " + std::to_string(t.image) + " of " +
                       std::to_string(s.images.size()) + ", texcoord " +
                       std::to_string(t.texcoord));
  for (std::size_t m = 0; m < s.materials.size(); ++m) {
    const wp::Material& mat = s.materials[m];
    const std::size_t n = s.textures.size();
    check_texture_slot(mat.base_color_texture, n, m, "base_color_texture");
    check_texture_slot(mat.metallic_roughness_texture, n, m, "metallic_roughness_texture");
    check_texture_slot(mat.normal_texture, n, m, "normal_texture");
    check_texture_slot(mat.emissive_texture, n, m, "emissive_texture");
    check_texture_slot(mat.transmission_texture, n, m, "transmission_texture");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // WP_FUZZ_VERBOSE=1: one line per input, to check what a corpus or a crash input reaches.
  static const bool verbose = std::getenv("WP_FUZZ_VERBOSE") != nullptr;
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::string path = wp::fuzz::write_input(data, size, glb ? ".glb" : ".gltf");
  try {
    const wp::Scene scene = wp::load_gltf(path, wp::fuzz::load_options());
    check_scene(scene);
    (void)wp::framing_camera(scene, 1.5f);
    if (verbose) std::fprintf(stderr, "loaded: %zu triangles\n", scene.triangle_count());
  } catch (const wp::Error& e) {
    // The documented outcome for malformed input.
    if (verbose) std::fprintf(stderr, "wp::Error: %s\n", e.what());
  }
  return 0;
}
