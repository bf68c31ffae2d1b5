// glTF 2.0 (.gltf and .glb) into the host scene (scene.h), via tinygltf.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>

#include "host/scene/scene.h"

namespace wp {

// What the default scene of a file will load, counted from its node tree and its accessors'
// counts before any vertex is read or any array allocated. Every mesh node places a copy of its
// mesh, once per EXT_mesh_gpu_instancing instance where it has them, so a mesh of T triangles
// placed by N nodes counts N x T.
struct LoadCounts {
  std::uint64_t placements = 0;  // copies of meshes the default scene's nodes place
  // Triangles: at least `triangles` (triangle lists: indices / 3, or vertices / 3 without indices;
  // strips and fans count 0, as they may be all degenerate) and at most `max_triangles` (strips
  // and fans: n - 2). Only accessors whose data lies in the file count (an accessor without a
  // bufferView, all zeros, counts none: gltf_accessor.h, readable_count).
  std::uint64_t triangles = 0, max_triangles = 0;
  // The same for each placed mesh once (what an instanced scene holds).
  std::uint64_t mesh_triangles = 0, mesh_max_triangles = 0;
  std::uint64_t meshes = 0;  // distinct meshes placed
  // Whether the scene loads instanced (LoadOptions::instancing for these counts): it then holds
  // mesh_triangles and a transform per placement, else `triangles`.
  bool instanced = false;
  std::uint64_t stored_triangles() const { return instanced ? mesh_triangles : triangles; }
};

// Whether the loader keeps each mesh once and its placements as instances (Scene::instances).
enum class Instancing : std::uint8_t {
  kAuto,    // when the placements hold at least twice the triangles of the meshes they place
  kAlways,  // whenever a mesh is placed
  kNever,   // every placement a copy in world space
};
// kAuto's rule: instances when the world would hold at least this many times the triangles of
// the distinct meshes (the memory then at most halves; a scene placing each mesh about once is
// traversed faster flat: docs/performance.md, "Instancing").
inline constexpr std::uint64_t kInstancingGain = 2;
bool use_instancing(Instancing mode, const LoadCounts& counts);

// How to load a file, beyond what it says itself.
struct LoadOptions {
  LoadOptions() = default;
  explicit LoadOptions(std::string variant_name) : variant(std::move(variant_name)) {}

  // KHR_materials_variants: the name of the variant whose materials the primitives get (each
  // primitive's mapping for it, or its own material where it has none); empty: the file's own
  // materials. A name the file does not define is an error listing the names it does.
  std::string variant;
  // Called with the file's counts once it is parsed and before its geometry is loaded; throwing
  // wp::Error refuses the scene before the loader allocates for it (the renderer checks them
  // against the device's memory: render.h, check_scene_counts).
  std::function<void(const LoadCounts&)> check_counts;
  Instancing instancing = Instancing::kAuto;
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
