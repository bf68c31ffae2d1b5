// glTF materials into wp::Material. Internal to the glTF loader.
#pragma once

#include <tiny_gltf.h>

#include "host/scene/gltf_textures.h"
#include "host/scene/scene.h"

namespace wp::gltf {

// Material `index` of `model`: metal/rough factors, emission x KHR_materials_emissive_strength,
// doubleSided, alpha mode and cutoff, and the extensions KHR_materials_ior, _transmission,
// _volume, _unlit, _specular, _clearcoat, _sheen, _anisotropy, _iridescence, _dispersion and
// _diffuse_transmission, every factor with the extension's default when absent. Textures are
// added to `textures`, sRGB for colour (base colour, emissive, specularColorTexture,
// sheenColorTexture, diffuseTransmissionColorTexture) and linear for the rest; the normal
// textures (base and clearcoat) keep their scale. KHR_materials_volume's thicknessTexture is
// checked (texture, sampler, image, transform) but not read: it bakes the thickness of the
// geometry for rasterisers, and a path tracer measures the real geometry. Throws wp::Error, one
// line naming the material and the field, on malformed values, on factors outside their
// extension's range (e.g. clearcoatFactor outside [0, 1], iridescenceIor below 1, a negative
// dispersion) and on references to textures, images or samplers that do not exist.
// Values float32 cannot carry (an emission or an index of refraction beyond scene.h's limits) are
// clamped, with a warning naming the material into `warnings` (may be null).
Material convert_material(const tinygltf::Model& model, int index, TextureTable& textures,
                          std::vector<std::string>* warnings = nullptr);

// glTF's default material (spec 3.9.6): white, fully metallic and rough, opaque, single-sided.
Material default_material();

}  // namespace wp::gltf
