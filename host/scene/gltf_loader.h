// glTF 2.0 (.gltf and .glb) into the host scene (scene.h), via tinygltf.
#pragma once

#include <string>

#include "host/scene/scene.h"

namespace wp {

// How to load a file, beyond what it says itself.
struct LoadOptions {
  // KHR_materials_variants: the name of the variant whose materials the primitives get (each
  // primitive's mapping for it, or its own material where it has none); empty: the file's own
  // materials. A name the file does not define is an error listing the names it does.
  std::string variant;
};

// Loads the default scene (or scene 0) of a glTF file: the node hierarchy with full transforms,
// every triangle primitive, materials, KHR_lights_punctual lights and cameras.
// Throws wp::Error naming the file and the cause when the file is missing, unreadable or
// malformed (JSON nested deeper than 64 levels, asset.version not 2.x, a primitive mode outside
// 0-6, a byteStride below its element size, NaN or Inf in a float vertex attribute included), or
// when it requires an extension wavepath does not support (RefusedExtensions; the statuses are
// gltf_extensions.h's table). Unsupported optional extensions and non-triangle primitives are
// skipped with a line in Scene::warnings. A scene without triangles
// is valid glTF: it loads, with a warning, and bounds at the origin.
Scene load_gltf(const std::string& path, const LoadOptions& options = {});

// A perspective camera that frames the scene's bounds (for files without cameras): it looks at
// the centre of the bounds along -Z from in front (+Z side), slightly from above, with a 45 degree
// vertical field of view, far enough that the bounding sphere fits the view at `aspect`
// (width / height).
Camera framing_camera(const Scene& scene, float aspect);

}  // namespace wp
