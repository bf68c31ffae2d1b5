// The OpenCL host runtime: device discovery and selection, one context + in-order profiling queue,
// program building with its log, and the translation of OpenCL errors into wp::Error.
#pragma once

#include <string>
#include <vector>

#include <CL/opencl.hpp>

namespace wp {

struct DeviceEntry {
  int index = 0;  // position in enumerate_devices(), stable for a given machine
  cl::Platform platform;
  cl::Device device;
  std::string platform_name;
  std::string name;
  std::string type;       // "GPU", "CPU", "ACCELERATOR", ...
  std::string version;    // CL_DEVICE_VERSION
  std::string c_version;  // CL_DEVICE_OPENCL_C_VERSION
  bool gpu = false;
  unsigned compute_units = 0;
  unsigned long long global_memory = 0;  // bytes
  unsigned long long max_alloc = 0;      // bytes
  unsigned long long cache_bytes = 0;    // CL_DEVICE_GLOBAL_MEM_CACHE_SIZE (PoCL: the last level)
};

// Every device of every platform, numbered in platform order. Empty when there is no OpenCL
// implementation at all (no ICD loader entries).
std::vector<DeviceEntry> enumerate_devices();

// `spec` empty: the first GPU, else the first CPU device, else the first device; with `nth`, the
// nth of those (modulo their number), so that processes sharing a machine (MPI ranks,
// host/cli/distributed.h) spread over its devices of one kind. Otherwise an index into
// enumerate_devices() or a case-insensitive substring of "platform device name".
// Throws wp::Error when nothing matches or there is no device.
DeviceEntry select_device(const std::string& spec, int nth = 0);

// The name of an OpenCL error code ("CL_OUT_OF_RESOURCES").
std::string cl_error_name(cl_int code);

// Rethrows a cl::Error as wp::Error("<what> failed: CL_...") with `context` prepended.
[[noreturn]] void rethrow_cl(const cl::Error& e, const std::string& context);

class ClRuntime {
 public:
  explicit ClRuntime(const DeviceEntry& device);

  const DeviceEntry& device() const { return device_; }
  const cl::Context& context() const { return context_; }
  cl::CommandQueue& queue() { return queue_; }

  // Builds `source` with `options` for this device. On failure throws wp::Error naming the device
  // and the first error line, with the whole build log as details. The time spent is added to
  // build_seconds(). With a `cache_dir` the program is built from the binary cached there when
  // there is one the device accepts (host/device/program_cache.h), and its binary is stored there
  // after a build from source; cached_build() tells which happened last.
  cl::Program build(const std::string& source, const std::string& options,
                    const std::string& cache_dir = {});
  double build_seconds() const { return build_seconds_; }
  bool cached_build() const { return cached_build_; }

 private:
  DeviceEntry device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  double build_seconds_ = 0.0;
  bool cached_build_ = false;
};

}  // namespace wp
