#include "host/scene_buffers.h"

namespace wp {

SceneBuffers upload_scene(const cl::Context& context, const PackedScene& packed) {
  SceneBuffers s;
  s.desc = packed.desc;
  for (std::size_t i = 0; i < packed.buffers.size(); ++i) {
    auto& bytes = const_cast<std::vector<unsigned char>&>(packed.buffers[i]);
    s.buffers[i] =
        cl::Buffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes.size(), bytes.data());
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
