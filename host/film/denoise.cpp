#include "host/film/denoise.h"

#include <dlfcn.h>
#include <glob.h>

#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <utility>

#include "host/util/error.h"

namespace wp {

const char* const kOidnHint =
    "--denoise needs Intel Open Image Denoise 2.x: run tools/setup.sh --denoise, or set "
    "WAVEPATH_OIDN to libOpenImageDenoise.so.2 or its folder";

namespace {

constexpr const char* kLibraryName = "libOpenImageDenoise.so.2";

// The values of OIDN's C enums that are used (OIDNDeviceType, OIDNFormat, OIDNError), as the API
// documentation lists them; C enums are passed as int.
constexpr int kDeviceTypeDefault = 0;  // OIDN_DEVICE_TYPE_DEFAULT: the likely fastest device
constexpr int kFormatFloat3 = 3;       // OIDN_FORMAT_FLOAT3
constexpr int kErrorNone = 0;          // OIDN_ERROR_NONE

// OIDN's objects are opaque handles (OIDNDevice, OIDNBuffer, OIDNFilter).
using Handle = void*;

// The folder of the running binary, or "" when /proc/self/exe cannot be read.
std::filesystem::path binary_folder() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

// The library that tools/setup.sh --denoise installs beside the binary (pyoidn in a venv), or "".
std::string installed_beside_binary() {
  const std::filesystem::path folder = binary_folder();
  if (folder.empty()) return "";
  const std::string pattern =
      (folder / "oidn-venv/lib/python3.*/site-packages/pyoidn/oidn/lib/" / kLibraryName).string();
  glob_t found{};
  std::string path;
  if (glob(pattern.c_str(), 0, nullptr, &found) == 0 && found.gl_pathc > 0)
    path = found.gl_pathv[found.gl_pathc - 1];  // the newest Python's, should there be several
  globfree(&found);
  return path;
}

// dlopen's last error as text.
std::string dl_reason() {
  const char* e = dlerror();
  return e ? e : "unknown reason";
}

// Opens the library (Denoiser::load's search order); `where` is set to what was opened.
void* open_library(std::string& where) {
  if (const char* env = std::getenv("WAVEPATH_OIDN"); env && *env) {
    const std::filesystem::path given(env);
    const bool folder = std::filesystem::is_directory(given);
    const std::filesystem::path p = folder ? given / kLibraryName : given;
    where = p.string();
    if (!std::filesystem::exists(p))
      throw Error("Open Image Denoise not found: WAVEPATH_OIDN=" + given.string() + " is " +
                  (folder ? "a folder without " + std::string(kLibraryName) : "no file") + "; " +
                  kOidnHint);
    void* lib = dlopen(where.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib)
      throw Error("Open Image Denoise could not be loaded from WAVEPATH_OIDN (" + dl_reason() +
                  "); " + kOidnHint);
    return lib;
  }
  where = installed_beside_binary();
  if (!where.empty()) {
    void* lib = dlopen(where.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib)
      throw Error("Open Image Denoise could not be loaded from " + where + " (" + dl_reason() +
                  "); " + kOidnHint);
    return lib;
  }
  where = kLibraryName;
  void* lib = dlopen(kLibraryName, RTLD_NOW | RTLD_LOCAL);
  if (!lib)
    throw Error("Open Image Denoise not found (WAVEPATH_OIDN is not set, no " +
                (binary_folder() / "oidn-venv").string() + ", and " + dl_reason() + "); " +
                kOidnHint);
  return lib;
}

}  // namespace

// The C functions of OIDN 2.x that wavepath calls, with the signatures of its API documentation.
struct Denoiser::Api {
  Handle (*newDevice)(int type);
  void (*commitDevice)(Handle device);
  int (*getDeviceError)(Handle device, const char** message);
  int (*getDeviceInt)(Handle device, const char* name);
  void (*releaseDevice)(Handle device);
  Handle (*newBuffer)(Handle device, std::size_t bytes);
  void (*writeBuffer)(Handle buffer, std::size_t offset, std::size_t bytes, const void* source);
  void (*readBuffer)(Handle buffer, std::size_t offset, std::size_t bytes, void* destination);
  void (*releaseBuffer)(Handle buffer);
  Handle (*newFilter)(Handle device, const char* type);
  void (*setFilterImage)(Handle filter, const char* name, Handle buffer, int format,
                         std::size_t width, std::size_t height, std::size_t byte_offset,
                         std::size_t pixel_stride, std::size_t row_stride);
  void (*setFilterBool)(Handle filter, const char* name, bool value);
  void (*commitFilter)(Handle filter);
  void (*executeFilter)(Handle filter);
  void (*releaseFilter)(Handle filter);

  // Throws when OIDN has recorded an error on `device` (nullptr: a device that failed to be
  // created); `doing` says what was being done.
  void check(Handle device, const char* doing) const {
    const char* message = nullptr;
    if (getDeviceError(device, &message) != kErrorNone)
      throw Error(std::string("Open Image Denoise: ") + doing + ": " +
                  (message && *message ? message : "unknown error"));
  }
};

namespace {

// Resolves every function of Denoiser::Api from `lib`, or throws naming the first one missing
// (an OIDN 1.x library, or not OIDN at all).
template <typename F>
void resolve(void* lib, const std::string& where, const char* name, F& fn) {
  fn = reinterpret_cast<F>(dlsym(lib, name));
  if (!fn)
    throw Error(where + " is not Open Image Denoise 2.x (it has no " + name + "); " + kOidnHint);
}

}  // namespace

Denoiser Denoiser::load() {
  std::string where;
  // Never closed: OIDN's CPU device keeps worker threads (TBB) that may outlive its release.
  void* lib = open_library(where);
  auto api = std::make_unique<Api>();
  resolve(lib, where, "oidnNewDevice", api->newDevice);
  resolve(lib, where, "oidnCommitDevice", api->commitDevice);
  resolve(lib, where, "oidnGetDeviceError", api->getDeviceError);
  resolve(lib, where, "oidnGetDeviceInt", api->getDeviceInt);
  resolve(lib, where, "oidnReleaseDevice", api->releaseDevice);
  resolve(lib, where, "oidnNewBuffer", api->newBuffer);
  resolve(lib, where, "oidnWriteBuffer", api->writeBuffer);
  resolve(lib, where, "oidnReadBuffer", api->readBuffer);
  resolve(lib, where, "oidnReleaseBuffer", api->releaseBuffer);
  resolve(lib, where, "oidnNewFilter", api->newFilter);
  resolve(lib, where, "oidnSetFilterImage", api->setFilterImage);
  resolve(lib, where, "oidnSetFilterBool", api->setFilterBool);
  resolve(lib, where, "oidnCommitFilter", api->commitFilter);
  resolve(lib, where, "oidnExecuteFilter", api->executeFilter);
  resolve(lib, where, "oidnReleaseFilter", api->releaseFilter);

  Denoiser d;
  d.device_ = api->newDevice(kDeviceTypeDefault);
  if (!d.device_) {
    api->check(nullptr, "creating a device");
    throw Error("Open Image Denoise: creating a device failed");
  }
  d.api_ = api.release();  // from here the destructor releases the device
  d.api_->commitDevice(d.device_);
  d.api_->check(d.device_, "committing the device");
  const int v = d.api_->getDeviceInt(d.device_, "version");  // major * 10000 + minor * 100 + patch
  d.description_ = "Open Image Denoise " + std::to_string(v / 10000) + "." +
                   std::to_string(v / 100 % 100) + "." + std::to_string(v % 100) + " (" + where +
                   ")";
  return d;
}

Denoiser::Denoiser(Denoiser&& other) noexcept {
  *this = std::move(other);
}

Denoiser& Denoiser::operator=(Denoiser&& other) noexcept {
  std::swap(api_, other.api_);
  std::swap(device_, other.device_);
  std::swap(description_, other.description_);
  return *this;
}

Denoiser::~Denoiser() {
  if (api_ && device_) api_->releaseDevice(device_);
  delete api_;
}

std::vector<float> Denoiser::denoise(int width, int height, const std::vector<float>& color,
                                     const std::vector<float>& albedo,
                                     const std::vector<float>& normal) const {
  const std::size_t w = std::size_t(width), h = std::size_t(height), floats = 3 * w * h,
                    bytes = floats * sizeof(float);
  if (color.size() != floats || albedo.size() != floats || normal.size() != floats)
    throw Error("denoise: the colour, albedo and normal images differ in size");
  const Api& api = *api_;
  // Buffers (not the host's pointers): OIDN's default device may be a GPU, which cannot read
  // memory allocated by the system.
  const auto release_buffer = [&api](Handle b) {
    if (b) api.releaseBuffer(b);
  };
  const auto release_filter = [&api](Handle f) {
    if (f) api.releaseFilter(f);
  };
  using Buffer = std::unique_ptr<void, decltype(release_buffer)>;
  using Filter = std::unique_ptr<void, decltype(release_filter)>;
  const auto buffer = [&](const std::vector<float>* data) {
    Buffer b(api.newBuffer(device_, bytes), release_buffer);
    api.check(device_, "allocating a buffer");
    if (data) api.writeBuffer(b.get(), 0, bytes, data->data());
    api.check(device_, "copying an image to the device");
    return b;
  };
  const Buffer color_buf = buffer(&color), albedo_buf = buffer(&albedo),
               normal_buf = buffer(&normal), output_buf = buffer(nullptr);

  // An RT filter with `inputs` (name, buffer), its output in `output`, and the bools given.
  const auto run = [&](std::initializer_list<std::pair<const char*, Handle>> inputs, Handle output,
                       bool hdr_clean_aux, const char* doing) {
    Filter f(api.newFilter(device_, "RT"), release_filter);
    api.check(device_, doing);
    for (const auto& [name, b] : inputs)
      api.setFilterImage(f.get(), name, b, kFormatFloat3, w, h, 0, 0, 0);
    api.setFilterImage(f.get(), "output", output, kFormatFloat3, w, h, 0, 0, 0);
    if (hdr_clean_aux) {
      api.setFilterBool(f.get(), "hdr", true);
      api.setFilterBool(f.get(), "cleanAux", true);
    }
    api.commitFilter(f.get());
    api.check(device_, doing);
    api.executeFilter(f.get());
    api.check(device_, doing);
  };
  // Prefiltering, in place (OIDN's "Denoising with Prefiltering" example), then the beauty.
  run({{"albedo", albedo_buf.get()}}, albedo_buf.get(), false, "prefiltering the albedo");
  run({{"normal", normal_buf.get()}}, normal_buf.get(), false, "prefiltering the normal");
  run({{"color", color_buf.get()}, {"albedo", albedo_buf.get()}, {"normal", normal_buf.get()}},
      output_buf.get(), true, "denoising the image");
  std::vector<float> out(floats);
  api.readBuffer(output_buf.get(), 0, bytes, out.data());
  api.check(device_, "copying the denoised image back");
  return out;
}

std::string denoised_path(const std::string& path) {
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + ".denoised" + p.extension().string())).string();
}

}  // namespace wp
