// glTF materials into wp::Material. Internal to the glTF loader.
#pragma once

#include <tiny_gltf.h>

#include "host/scene.h"

namespace wp::gltf {

// Material `index` of `model`: metal/rough factors, emission x KHR_materials_emissive_strength,
// doubleSided, alpha mode and cutoff, KHR_materials_ior and KHR_materials_transmission. Textures
// are ignored (the loader warns once per file). Throws wp::Error on malformed values.
Material convert_material(const tinygltf::Model& model, int index);

// glTF's default material (spec 3.9.6): white, fully metallic and rough, opaque, single-sided.
Material default_material();

}  // namespace wp::gltf
