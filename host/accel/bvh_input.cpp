#include "host/accel/bvh_input.h"

#include "host/accel/bvh_cache.h"
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

std::vector<bvh::InstanceInput> bvh_instances(const Scene& scene) {
  std::vector<bvh::InstanceInput> out;
  out.reserve(scene.instances.size());
  for (const Instance& i : scene.instances) out.push_back({i.to_world, i.mesh});
  return out;
}

std::unique_ptr<bvh::EmbreeInstances> embree_instances(const Scene& scene, bool robust) {
  std::vector<bvh::EmbreeInstances::MeshRange> meshes;
  for (const MeshRange& m : scene.meshes) meshes.push_back({m.first_triangle, m.triangle_count});
  return std::make_unique<bvh::EmbreeInstances>(scene.positions.data(), scene.indices.data(),
                                                meshes, bvh_instances(scene), robust);
}

bvh::Bvh build_scene_bvh(const Scene& scene, const bvh::BuildOptions& options,
                         const std::string& cache_dir, bool* cached,
                         const std::function<void(const bvh::Bvh&)>& accept) {
  std::vector<std::uint32_t> flags;
  const bvh::BuildInput input = bvh_input(scene, flags);
  if (scene.instances.empty()) return bvh::build_cached(input, options, cache_dir, cached, accept);
  std::vector<bvh::Bvh> meshes;
  std::vector<std::uint32_t> first;
  bool all_cached = true;
  for (const MeshRange& m : scene.meshes) {
    bvh::BuildInput mesh = input;
    mesh.indices = input.indices + 3 * std::size_t{m.first_triangle};
    mesh.triangle_flags = input.triangle_flags + m.first_triangle;
    mesh.triangle_count = m.triangle_count;
    bool hit = false;
    meshes.push_back(bvh::build_cached(mesh, options, cache_dir, &hit));
    all_cached &= hit;
    first.push_back(m.first_triangle);
  }
  bvh::Bvh out = bvh::build_two_level(std::move(meshes), first, bvh_instances(scene), options);
  if (cached) *cached = all_cached;
  if (accept) accept(out);
  return out;
}

}  // namespace wp
