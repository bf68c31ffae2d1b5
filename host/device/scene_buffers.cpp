#include "host/device/scene_buffers.h"

namespace wp {

SceneBuffers upload_scene(const cl::Context& context, const PackedScene& packed, bool in_place) {
  SceneBuffers s;
  s.desc = packed.desc;
  const cl_mem_flags flags =
      CL_MEM_READ_ONLY | (in_place ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR);
  for (std::size_t i = 0; i < packed.buffers.size(); ++i) {
    auto& bytes = const_cast<SceneBytes&>(packed.buffers[i]);  // read-only: never written
    s.buffers[i] = cl::Buffer(context, flags, bytes.size(), bytes.data());
  }
  for (std::size_t i = packed.buffers.size(); i < s.buffers.size(); ++i)
    s.buffers[i] = s.buffers[0];
  return s;
}

cl_uint set_scene_args(cl::Kernel& kernel, cl_uint first, const SceneBuffers& scene) {
  for (const cl::Buffer& b : scene.buffers) kernel.setArg(first++, b);
  kernel.setArg(first++, scene.desc);
  return first;
}

}  // namespace wp
