#include "host/accel/bvh_input.h"

#include "kernels/shared/types.h"

namespace wp {

bvh::BuildInput bvh_input(const Scene& scene, std::vector<std::uint32_t>& flags) {
  bvh::BuildInput input;
  input.positions = scene.positions.data();
  input.indices = scene.indices.data();
  input.triangle_count = scene.triangle_count();
  flags.assign(scene.triangle_count(), 0u);
  for (std::size_t i = 0; i < flags.size(); ++i) {
    const Material& m = scene.materials[scene.triangle_material[i]];
    // Back faces of a volume are where rays leave it: never culled.
    const bool cull = !m.double_sided && !(m.transmission > 0.0f && m.thickness > 0.0f);
    flags[i] = (cull ? WP_TRI_CULL_BACKFACE : 0u) |
               (m.alpha_mode != AlphaMode::kOpaque ? WP_TRI_ALPHA : 0u);
  }
  input.triangle_flags = flags.data();
  return input;
}

}  // namespace wp
