// The scene as the device sees it: every array packed into one byte buffer at 64-byte aligned
// offsets recorded in a SceneDesc (kernels/shared/types.h), plus the device camera.
#pragma once

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

PackedScene pack_scene(const Scene& scene, const bvh::Bvh& bvh, const SceneExtras& extras);

}  // namespace wp
