#include "host/device/cl_runtime.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <sstream>

#include "host/util/error.h"
#include "host/device/program_cache.h"

namespace wp {

namespace {

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back()))))
    s.pop_back();
  const auto first = s.find_first_not_of(" \t");
  return first == std::string::npos ? std::string() : s.substr(first);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "ACCELERATOR";
  return "OTHER";
}

// The first line of a build log that reports an error, for the one-line message.
std::string first_error_line(const std::string& log) {
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line))
    if (line.find("error") != std::string::npos) return trim(line);
  return "see the build log";
}

// Holds what is written to stderr (fd 2) while it lives: some OpenCL compilers (PoCL's clang)
// print diagnostics there themselves, which would break the one-line error contract. The build log
// carries the same text.
class StderrCapture {
 public:
  StderrCapture() {
    std::fflush(stderr);
    file_ = std::tmpfile();
    saved_ = dup(STDERR_FILENO);
    if (file_ && saved_ >= 0) dup2(fileno(file_), STDERR_FILENO);
  }
  ~StderrCapture() {
    std::fflush(stderr);
    if (saved_ >= 0) {
      dup2(saved_, STDERR_FILENO);
      close(saved_);
    }
    if (file_) std::fclose(file_);
  }
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;

 private:
  std::FILE* file_ = nullptr;
  int saved_ = -1;
};

}  // namespace

std::vector<DeviceEntry> enumerate_devices() {
  std::vector<DeviceEntry> out;
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return out;  // no ICD: CL_PLATFORM_NOT_FOUND_KHR
  }
  for (const cl::Platform& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform without devices
    }
    for (const cl::Device& d : devices) {
      DeviceEntry e;
      e.index = static_cast<int>(out.size());
      e.platform = p;
      e.device = d;
      e.platform_name = trim(p.getInfo<CL_PLATFORM_NAME>());
      e.name = trim(d.getInfo<CL_DEVICE_NAME>());
      const cl_device_type type = d.getInfo<CL_DEVICE_TYPE>();
      e.type = type_name(type);
      e.gpu = (type & CL_DEVICE_TYPE_GPU) != 0;
      e.version = trim(d.getInfo<CL_DEVICE_VERSION>());
      e.c_version = trim(d.getInfo<CL_DEVICE_OPENCL_C_VERSION>());
      e.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      e.global_memory = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      e.max_alloc = d.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
      e.cache_bytes = d.getInfo<CL_DEVICE_GLOBAL_MEM_CACHE_SIZE>();
      out.push_back(std::move(e));
    }
  }
  return out;
}

DeviceEntry select_device(const std::string& spec, int nth) {
  const std::vector<DeviceEntry> all = enumerate_devices();
  if (all.empty())
    throw Error("no OpenCL device found (is an OpenCL driver such as pocl-opencl-icd installed?)");
  if (spec.empty()) {
    // One kind only: a CPU device beside GPUs would take another BVH layout (bvh_width), hence
    // another render key, and its part could not be merged with theirs.
    using Kind = bool (*)(const DeviceEntry&);
    const Kind kinds[] = {[](const DeviceEntry& e) { return e.gpu; },
                          [](const DeviceEntry& e) { return e.type == "CPU"; }};
    for (const Kind kind : kinds) {
      std::vector<const DeviceEntry*> matching;
      for (const auto& e : all)
        if (kind(e)) matching.push_back(&e);
      if (!matching.empty()) return *matching[std::size_t(nth) % matching.size()];
    }
    return all[std::size_t(nth) % all.size()];
  }
  if (std::all_of(spec.begin(), spec.end(), [](unsigned char c) { return std::isdigit(c); })) {
    const unsigned long i = std::stoul(spec);
    if (i < all.size()) return all[i];
    throw Error("--device " + spec + ": no such device index (there are " +
                std::to_string(all.size()) + "; see `wavepath devices`)");
  }
  for (const auto& e : all)
    if (lower(e.platform_name + " " + e.name).find(lower(spec)) != std::string::npos) return e;
  throw Error("--device " + spec + ": no device name matches (see `wavepath devices`)");
}

std::string cl_error_name(cl_int code) {
  switch (code) {
#define WP_CL_CASE(x) \
  case x:             \
    return #x;
    WP_CL_CASE(CL_DEVICE_NOT_FOUND)
    WP_CL_CASE(CL_DEVICE_NOT_AVAILABLE)
    WP_CL_CASE(CL_COMPILER_NOT_AVAILABLE)
    WP_CL_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    WP_CL_CASE(CL_OUT_OF_RESOURCES)
    WP_CL_CASE(CL_OUT_OF_HOST_MEMORY)
    WP_CL_CASE(CL_BUILD_PROGRAM_FAILURE)
    WP_CL_CASE(CL_INVALID_VALUE)
    WP_CL_CASE(CL_INVALID_DEVICE)
    WP_CL_CASE(CL_INVALID_CONTEXT)
    WP_CL_CASE(CL_INVALID_COMMAND_QUEUE)
    WP_CL_CASE(CL_INVALID_MEM_OBJECT)
    WP_CL_CASE(CL_INVALID_BUFFER_SIZE)
    WP_CL_CASE(CL_INVALID_PROGRAM)
    WP_CL_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    WP_CL_CASE(CL_INVALID_KERNEL_NAME)
    WP_CL_CASE(CL_INVALID_KERNEL)
    WP_CL_CASE(CL_INVALID_ARG_INDEX)
    WP_CL_CASE(CL_INVALID_ARG_VALUE)
    WP_CL_CASE(CL_INVALID_ARG_SIZE)
    WP_CL_CASE(CL_INVALID_KERNEL_ARGS)
    WP_CL_CASE(CL_INVALID_WORK_DIMENSION)
    WP_CL_CASE(CL_INVALID_WORK_GROUP_SIZE)
    WP_CL_CASE(CL_INVALID_WORK_ITEM_SIZE)
    WP_CL_CASE(CL_INVALID_GLOBAL_OFFSET)
    WP_CL_CASE(CL_INVALID_EVENT)
    WP_CL_CASE(CL_INVALID_OPERATION)
    WP_CL_CASE(CL_INVALID_BUILD_OPTIONS)
    WP_CL_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
#undef WP_CL_CASE
    default:
      return "OpenCL error " + std::to_string(code);
  }
}

void rethrow_cl(const cl::Error& e, const std::string& context) {
  throw Error(context + ": " + e.what() + " failed with " + cl_error_name(e.err()));
}

ClRuntime::ClRuntime(const DeviceEntry& device) : device_(device) {
  try {
    context_ = cl::Context(device_.device);
    queue_ = cl::CommandQueue(context_, device_.device, CL_QUEUE_PROFILING_ENABLE);
  } catch (const cl::Error& e) {
    rethrow_cl(e, "cannot open OpenCL device " + device_.name);
  }
}

cl::Program ClRuntime::build(const std::string& source, const std::string& options,
                             const std::string& cache_dir) {
  const auto start = std::chrono::steady_clock::now();
  const auto add_time = [&] {
    build_seconds_ +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  cached_build_ = false;
  std::uint64_t key = 0;
  if (!cache_dir.empty()) {
    std::string driver;
    try {
      driver = device_.device.getInfo<CL_DRIVER_VERSION>();
    } catch (const cl::Error&) {
    }
    key = program_cache_key(device_, driver, source, options);
    if (auto binary = program_cache_load(cache_dir, key)) {
      try {
        StderrCapture quiet;
        cl::Program cached(context_, {device_.device}, cl::Program::Binaries{std::move(*binary)});
        cached.build({device_.device}, options.c_str());
        cached_build_ = true;
        add_time();
        return cached;
      } catch (const cl::Error&) {
        // Refused (another driver build, say): built from source below, and the entry replaced.
      }
    }
  }
  cl::Program program(context_, source);
  try {
    StderrCapture quiet;
    program.build({device_.device}, options.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_.device);
    } catch (const cl::Error&) {
    }
    throw Error("kernel build failed on " + device_.name + ": " + first_error_line(log),
                "OpenCL build log (options: " + options + "):\n" + trim(log));
  }
  if (!cache_dir.empty()) {
    try {
      const auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
      if (binaries.size() == 1) program_cache_store(cache_dir, key, binaries[0]);
    } catch (const cl::Error&) {
      // An implementation without binaries: nothing to cache.
    }
  }
  add_time();
  return program;
}

}  // namespace wp
