// The packed scene (device_scene.h) on a device, as the kernels' WP_SCENE_PARAMS take it
// (kernels/geom/scene.h): WP_SCENE_BUFFERS buffer arguments, then the SceneDesc.
#pragma once

#include <array>

#include <CL/opencl.hpp>

#include "host/device/device_scene.h"
#include "kernels/shared/types.h"

namespace wp {

struct SceneBuffers {
  std::array<cl::Buffer, WP_SCENE_BUFFERS> buffers;  // slots past the packed ones repeat the first
  dev::SceneDesc desc{};
};

// Uploads `packed` (read-only buffers). With `in_place` the buffers use packed's memory
// (CL_MEM_USE_HOST_PTR), which must then outlive them: on a CPU device (PoCL) that saves a copy
// of the whole scene; a GPU copies it over either way. Throws cl::Error as the allocation does.
SceneBuffers upload_scene(const cl::Context& context, const PackedScene& packed,
                          bool in_place = false);

// Sets WP_SCENE_PARAMS as `kernel`'s arguments from index `first`; returns the index after them.
cl_uint set_scene_args(cl::Kernel& kernel, cl_uint first, const SceneBuffers& scene);

}  // namespace wp
