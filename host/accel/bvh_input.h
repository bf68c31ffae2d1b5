// The scene's triangles as the BVH builder takes them.
#pragma once

#include <cstdint>
#include <vector>

#include "bvh/bvh.h"
#include "host/scene/scene.h"

namespace wp {

// The BVH build input for `scene`: its triangles, and per triangle the WP_TRI_* flags its
// material implies (back-face culling for single-sided materials, alpha testing), kept in `flags`.
bvh::BuildInput bvh_input(const Scene& scene, std::vector<std::uint32_t>& flags);

}  // namespace wp
