// The scene's triangles as the BVH builder takes them.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/embree_scene.h"
#include "host/scene/scene.h"

namespace wp {

// The BVH build input for `scene`: its triangles, and per triangle the WP_TRI_* flags its
// material implies (back-face culling for single-sided materials, alpha testing), kept in `flags`.
bvh::BuildInput bvh_input(const Scene& scene, std::vector<std::uint32_t>& flags);

// An instanced scene's instances as the two-level builder and Embree take them.
std::vector<bvh::InstanceInput> bvh_instances(const Scene& scene);

// Embree's own instancing of an instanced scene's meshes and instances (the tests' oracle, the
// bench's reference); `robust` as for bvh::EmbreeScene.
std::unique_ptr<bvh::EmbreeInstances> embree_instances(const Scene& scene, bool robust);

// The scene's BVH: one tree over its triangles, or, for an instanced scene (Scene::instances),
// the two-level BVH over its instances (bvh.h, build_two_level), each mesh's tree built over that
// mesh's triangles alone. Every tree goes through the cache in `cache_dir` (bvh_cache.h; empty:
// none), so a mesh's tree is cached by its own triangles; *cached tells whether all of them were
// loaded. `accept`, when given, sees the BVH before it is returned (a tree just built: before it
// is stored) and may throw to refuse it.
bvh::Bvh build_scene_bvh(const Scene& scene, const bvh::BuildOptions& options,
                         const std::string& cache_dir, bool* cached = nullptr,
                         const std::function<void(const bvh::Bvh&)>& accept = {});

}  // namespace wp
