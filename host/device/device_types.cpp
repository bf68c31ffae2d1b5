// Layout checks of the structs shared with OpenCL C (kernels/shared/). OpenCL C aligns float4,
// int4 and uint4 to 16 bytes and lays struct members out in order with natural alignment; these
// assertions pin the C++ side to the same sizes and offsets.
#include <cstddef>

#include "kernels/shared/types.h"

namespace wp::dev {

static_assert(sizeof(float4) == 16 && alignof(float4) == 16);
static_assert(sizeof(int4) == 16 && sizeof(uint4) == 16);
static_assert(sizeof(BvhNode) == 64);
static_assert(offsetof(BvhNode, link) == 48);
static_assert(sizeof(IsectTri) == 48);
static_assert(sizeof(float8) == 32 && alignof(float8) == 32);
static_assert(sizeof(BvhNode8) == 224 && offsetof(BvhNode8, child) == 192);
static_assert(sizeof(TriBlock4) == 176 && offsetof(TriBlock4, prim) == 144);
static_assert(sizeof(Material) == 272);
static_assert(offsetof(Material, textures0) == 96);
static_assert(sizeof(TextureRef) == 48);
static_assert(sizeof(TextureImage) == 16);
static_assert(sizeof(Light) == 80);
static_assert(sizeof(LightAlias) == 16);
static_assert(sizeof(Camera) == 96);
static_assert(offsetof(SceneDesc, background) == 96);
static_assert(offsetof(SceneDesc, env_params) == 112);
static_assert(offsetof(SceneDesc, bvh_nodes) == 128);
static_assert(sizeof(SceneDesc) == 240);
static_assert(sizeof(Launch) == 64);
static_assert(sizeof(PathLayout) % 4 == 0);

}  // namespace wp::dev
