// The scene as the device sees it: its arrays packed into up to WP_SCENE_BUFFERS byte buffers, each
// no larger than the device's largest allocation, at 64-byte aligned offsets. A SceneDesc
// (kernels/shared/types.h) records each array's offset, the program's WP_SCENE_BUFFER_MAP its
// buffer. Plus the device camera.
#pragma once

#include <cstdint>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "bvh/bvh.h"
#include "host/lights/environment.h"
#include "host/device/scene_features.h"
#include "host/lights/light_table.h"
#include "host/scene/scene.h"
#include "kernels/shared/types.h"

namespace wp {

// Bytes at a page boundary, so that a CPU device can use them in place (CL_MEM_USE_HOST_PTR:
// PoCL then makes no copy of a scene that may be gigabytes; scene_buffers.h). Elements are
// default-initialised: a buffer of bytes that is resized is not written (pack_scene writes every
// byte itself), so its pages become resident only as they are filled.
template <class T>
struct PageAligned {
  using value_type = T;
  static constexpr std::align_val_t kAlign{4096};
  PageAligned() = default;
  template <class U>
  PageAligned(const PageAligned<U>&) {}
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kAlign)); }
  void deallocate(T* p, std::size_t) { ::operator delete(p, kAlign); }
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const PageAligned<U>&) const {
    return true;
  }
  template <class U>
  bool operator!=(const PageAligned<U>&) const {
    return false;
  }
};
using SceneBytes = std::vector<unsigned char, PageAligned<unsigned char>>;

struct PackedScene {
  std::vector<SceneBytes> buffers;  // 1 to WP_SCENE_BUFFERS, uploaded as they are
  dev::SceneDesc desc{};
  std::uint64_t buffer_map = 0;  // the program's WP_SCENE_BUFFER_MAP (SceneLayout::buffer_map)
  // The texel array's bytes, and those of it that are mip levels (SceneExtras::mipmaps).
  std::uint64_t texel_bytes = 0, mip_bytes = 0;
};

// The most bytes one scene buffer may hold: a uint of 64-byte units reaches 256 GiB.
inline constexpr std::uint64_t kSceneBufferReach = std::uint64_t(1) << 38;

// The device camera for an image of width x height. Perspective: image-plane half extents
// tan(yfov/2) * aspect and tan(yfov/2) with aspect = width / height (glTF's convention: yfov is
// vertical, the image's aspect wins over the camera's aspectRatio). Orthographic: half extents
// ymag * aspect and ymag (likewise, the image's aspect decides the horizontal extent).
dev::Camera device_camera(const Camera& camera, int width, int height);

// Everything about the render that is not in Scene: the camera, what escaped rays see, the lights.
// Which of the optional per-vertex arrays (tangents, texture coordinates, colours) are packed:
// each costs 16 bytes a vertex, as much as the positions.
struct VertexArrays {
  bool tangents = true, uvs = true, colors = true;
  // Those a program of `features` reads.
  static VertexArrays of(const SceneFeatures& f) {
    return {f.reads_tangents(), f.reads_uvs(), f.reads_colors()};
  }
};

struct SceneExtras {
  dev::Camera camera{};
  glm::vec3 background{0.0f};           // constant radiance without a map
  const EnvironmentMap* env = nullptr;  // may be null
  float env_intensity = 1.0f;
  float env_rotation_degrees = 0.0f;
  const LightTable* lights = nullptr;  // required
  // Mip chains after the images that textures minify through mip-maps (host/scene/mipmap.h), for
  // programs with WP_FEATURE_TEXTURE_LOD; without them every image has one level.
  bool mipmaps = false;
  // The per-vertex arrays the program reads (SceneFeatures::reads_*); one it does not is empty.
  VertexArrays vertex_arrays;
};

// Packs the scene into buffers of at most `max_buffer` bytes (the device's CL_DEVICE_MAX_MEM_ALLOC
// _SIZE; capped at kSceneBufferReach). Throws plan_scene_layout's wp::Error when it does not fit.
PackedScene pack_scene(const Scene& scene, const bvh::Bvh& bvh, const SceneExtras& extras,
                       std::uint64_t max_buffer = kSceneBufferReach);

// Whether packing frees the host arrays it has copied.
enum class HostArrays {
  kKeep,
  // Each of the scene's per-vertex and per-triangle arrays (positions, normals, tangents, UVs,
  // colours, indices, triangle materials), its images' texels and the BVH's nodes and primitives
  // is emptied (its memory returned) as it is packed, 16 MiB at a time (the pages read so far
  // returned after each slice), so that the host never holds a large scene twice: packing adds
  // about one slice to the packed scene. Their counts go with them (Scene::triangle_count() is 0
  // after); the rest of both stays: materials, image sizes, lights, cameras, meshes and
  // instances, the BVH's stats and instances.
  kRelease,
};
// pack_scene, freeing the host arrays with HostArrays::kRelease.
PackedScene pack_scene(Scene& scene, bvh::Bvh& bvh, const SceneExtras& extras,
                       std::uint64_t max_buffer, HostArrays host);

// Where the arrays go. Each array, in pack_scene's order, starts at the next 64-byte boundary of
// the last buffer, or at the start of a new buffer when it would end past max_buffer there.
struct SceneLayout {
  struct Place {
    int buffer = 0;
    std::uint64_t offset = 0;  // bytes, a multiple of WP_SCENE_ALIGN
  };
  std::vector<Place> places;                // per array
  std::vector<std::uint64_t> sizes;         // per array: its bytes (unpadded)
  std::vector<std::uint64_t> buffer_bytes;  // per buffer: where its last array ends (padded)
  std::uint64_t total_bytes() const;
  // Each array's buffer in WP_SCENE_BUFFER_BITS bits, the first array's lowest (0: one buffer).
  std::uint64_t buffer_map() const;
};
// The layout of arrays of `sizes` bytes. Throws wp::Error("scene too large for the device: ...")
// naming the array when one alone exceeds max_buffer, or the total when more than
// WP_SCENE_BUFFERS buffers would be needed. Larger sizes never need fewer buffers (each array's
// buffer and end only move forward), so a layout of lower bounds that fails means the real fails.
SceneLayout plan_scene_layout(const std::vector<std::uint64_t>& sizes, std::uint64_t max_buffer);
// What array `index` of a layout holds, e.g. "BVH node", "texel" (the words of the errors above).
const char* scene_array_name(std::size_t index);
// "2.50 GiB", "3.2 MiB" or "900 bytes", as the errors above write sizes.
std::string human_bytes(std::uint64_t bytes);
// The bytes of one texel in the packed images: RGBA8 in one uint, R in the lowest byte.
inline constexpr std::uint64_t kTexelBytes = sizeof(dev::uint);

// The size check of pack_scene, ahead of it: a scene too large to pack fails before its BVH is
// built (minutes, and an entry in the BVH cache, for tens of millions of triangles).
//
// The element counts of what pack_scene packs, known before the BVH and the light table exist.
struct SceneCounts {
  std::uint64_t triangles = 0, vertices = 0;
  std::uint64_t materials = 0, textures = 0, images = 0, texels = 0;
  // The light table's lights: scene_counts gives the punctual lights, a lower bound; the table's
  // size (LightTable::lights) makes the layout exact.
  std::uint64_t lights = 0;
  std::uint64_t env_texels = 0, env_marginal = 0, env_conditional = 0;  // no map: 0
  std::uint64_t instances = 0;  // Scene::instances (a two-level BVH's)
  VertexArrays vertex_arrays;   // those packed, as SceneExtras::vertex_arrays
};
// env may be null; `mipmaps` counts the mip chains pack_scene adds with SceneExtras::mipmaps.
SceneCounts scene_counts(const Scene& scene, const EnvironmentMap* env, bool mipmaps = false);

// The bytes of the BVH's two packed arrays (nodes, then triangles or blocks).
struct BvhBytes {
  std::uint64_t nodes = 0, primitives = 0;
  std::uint64_t instance_refs = 0;  // a two-level BVH's top-level leaves (0: not known yet)
};
BvhBytes bvh_bytes(const bvh::Bvh& bvh);
// At most the bytes of any BVH of layout `width` (2 or 8) over `triangles` triangles: every
// triangle referenced, leaves of at most WP_BVH_MAX_LEAF_SIZE triangles or WP_BVH8_MAX_LEAF_BLOCKS
// blocks of 4, inner nodes of 2 (or up to 8) children.
BvhBytes min_bvh_bytes(std::uint64_t triangles, int width);

// pack_scene's layout for these counts and BVH sizes. A lower bound when they are lower bounds:
// min_bvh_bytes before the build, and always the lights (the light table's emissive triangles and
// environment light are not counted), so no scene that fits is refused. Throws like
// plan_scene_layout, and when the images hold 2^32 texels or more (uint texel offsets).
SceneLayout scene_layout(const SceneCounts& counts, const BvhBytes& bvh, std::uint64_t max_buffer);

}  // namespace wp
