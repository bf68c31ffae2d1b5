// Runs test kernels (tests/kernels/*.cl, which include the project's kernel headers) on the default
// OpenCL device, for the kernel, sampling and energy tiers (docs/testing.md): device functions
// against host references, sampling routines against their pdfs.
#pragma once

#include <string>
#include <vector>

#include <CL/opencl.hpp>

#include "host/device/cl_runtime.h"
#include "host/device/kernel_sources.h"
#include "host/device/scene_buffers.h"

namespace wp {
// The test target's tests/kernels tree, embedded like the core kernels (tests/CMakeLists.txt).
const std::vector<EmbeddedFile>& test_kernel_sources();
}  // namespace wp

namespace wp::test {

class KernelHarness {
 public:
  // Builds the program made of `files` (names relative to tests/kernels/ or kernels/) with
  // `options` (e.g. "-D WP_FEATURE_TRANSMISSION=1") on the default device.
  explicit KernelHarness(const std::vector<std::string>& files, const std::string& options = "")
      : runtime_(select_device("")) {
    KernelSources sources;
    sources.add(test_kernel_sources());
    program_ = runtime_.build(sources.expand(files), "-cl-std=CL1.2 " + options);
  }

  ClRuntime& runtime() { return runtime_; }
  cl::Program& program() { return program_; }

  template <class T>
  cl::Buffer buffer(const std::vector<T>& data) {
    return cl::Buffer(runtime_.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR,
                      std::max<std::size_t>(1, data.size()) * sizeof(T),
                      const_cast<T*>(data.data()));
  }
  template <class T>
  cl::Buffer buffer(std::size_t count) {
    return cl::Buffer(runtime_.context(), CL_MEM_READ_WRITE,
                      std::max<std::size_t>(1, count) * sizeof(T));
  }
  template <class T>
  std::vector<T> read(const cl::Buffer& b, std::size_t count) {
    std::vector<T> out(count);
    runtime_.queue().enqueueReadBuffer(b, CL_TRUE, 0, count * sizeof(T), out.data());
    return out;
  }

  // Runs kernel `name` over `items` work-items with the given arguments and waits. A SceneBuffers
  // argument stands for the WP_SCENE_PARAMS it sets (host/device/scene_buffers.h).
  template <class... Args>
  void run(const char* name, std::size_t items, const Args&... args) {
    cl::Kernel k(program_, name);
    cl_uint index = 0;
    (set_arg(k, index, args), ...);
    const std::size_t local = 64, global = (items + local - 1) / local * local;
    runtime_.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global),
                                          cl::NDRange(local));
    runtime_.queue().finish();
  }

 private:
  template <class T>
  static void set_arg(cl::Kernel& k, cl_uint& index, const T& arg) {
    k.setArg(index++, arg);
  }
  static void set_arg(cl::Kernel& k, cl_uint& index, const SceneBuffers& scene) {
    index = set_scene_args(k, index, scene);
  }

  ClRuntime runtime_;
  cl::Program program_;
};

}  // namespace wp::test
