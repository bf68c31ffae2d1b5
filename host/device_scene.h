// The scene as the device sees it: every array packed into one byte buffer at 64-byte aligned
// offsets recorded in a SceneDesc (kernels/shared/types.h), plus the device camera.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "bvh/bvh.h"
#include "host/environment.h"
#include "host/light_table.h"
#include "host/scene.h"
#include "kernels/shared/types.h"

namespace wp {

struct PackedScene {
  std::vector<unsigned char> bytes;  // uploaded as is
  dev::SceneDesc desc{};
};

// The device camera for an image of width x height. Perspective: image-plane half extents
// tan(yfov/2) * aspect and tan(yfov/2) with aspect = width / height (glTF's convention: yfov is
// vertical, the image's aspect wins over the camera's aspectRatio). Orthographic: half extents
// ymag * aspect and ymag (likewise, the image's aspect decides the horizontal extent).
dev::Camera device_camera(const Camera& camera, int width, int height);

// Everything about the render that is not in Scene: the camera, what escaped rays see, the lights.
struct SceneExtras {
  dev::Camera camera{};
  glm::vec3 background{0.0f};           // constant radiance without a map
  const EnvironmentMap* env = nullptr;  // may be null
  float env_intensity = 1.0f;
  float env_rotation_degrees = 0.0f;
  const LightTable* lights = nullptr;  // required
};

// Throws wp::Error("scene too large for 32-bit buffer offsets") when an array would end past 4 GiB
// (SceneDesc holds 32-bit offsets).
PackedScene pack_scene(const Scene& scene, const bvh::Bvh& bvh, const SceneExtras& extras);

// The size check of pack_scene, ahead of it: a scene too large to pack fails before its BVH is
// built (minutes, and an entry in the BVH cache, for tens of millions of triangles).
//
// The element counts of what pack_scene packs, known before the BVH and the light table exist.
struct SceneCounts {
  std::uint64_t triangles = 0, vertices = 0;
  std::uint64_t materials = 0, textures = 0, images = 0, texels = 0;
  std::uint64_t punctual_lights = 0;  // a lower bound on the light table's lights
  std::uint64_t env_texels = 0, env_marginal = 0, env_conditional = 0;  // no map: 0
};
SceneCounts scene_counts(const Scene& scene, const EnvironmentMap* env);  // env may be null

// The bytes of the BVH's two packed arrays (nodes, then triangles or blocks).
struct BvhBytes {
  std::uint64_t nodes = 0, primitives = 0;
};
BvhBytes bvh_bytes(const bvh::Bvh& bvh);
// At most the bytes of any BVH of layout `width` (2 or 8) over `triangles` triangles: every
// triangle referenced, leaves of at most WP_BVH_MAX_LEAF_SIZE triangles or WP_BVH8_MAX_LEAF_BLOCKS
// blocks of 4, inner nodes of 2 (or up to 8) children.
BvhBytes min_bvh_bytes(std::uint64_t triangles, int width);

// Where the last array pack_scene packs would end with these counts and BVH sizes. A lower bound
// when they are lower bounds: min_bvh_bytes before the build, and always the lights (the light
// table's emissive triangles and environment light are not counted), so no scene that fits fails.
std::uint64_t packed_end(const SceneCounts& counts, const BvhBytes& bvh);
// Throws pack_scene's wp::Error when packed_end(counts, bvh) is past the 32-bit offsets' reach.
void check_packed_size(const SceneCounts& counts, const BvhBytes& bvh);

}  // namespace wp
