// glTF materials into wp::Material. Internal to the glTF loader.
#pragma once

#include <tiny_gltf.h>

#include "host/scene/gltf_textures.h"
#include "host/scene/scene.h"

namespace wp::gltf {

// Material `index` of `model`: metal/rough factors, emission x KHR_materials_emissive_strength,
// doubleSided, alpha mode and cutoff, KHR_materials_ior, KHR_materials_transmission,
// KHR_materials_volume and KHR_materials_unlit, and the base colour, metallic-roughness, normal
// (with its scale), emissive and transmission textures, added to `textures`. Throws wp::Error on
// malformed values and on references to textures, images or samplers that do not exist.
Material convert_material(const tinygltf::Model& model, int index, TextureTable& textures);

// glTF's default material (spec 3.9.6): white, fully metallic and rough, opaque, single-sided.
Material default_material();

}  // namespace wp::gltf
