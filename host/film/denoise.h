// Denoising with Intel Open Image Denoise (OIDN 2.x), loaded at run time: wavepath neither builds
// nor links against it (Debian 12 does not package it), so a binary without it still runs, and
// only `--denoise` needs it. The few C functions used are declared in denoise.cpp from OIDN's
// API documentation and resolved with dlsym.
#pragma once

#include <string>
#include <vector>

namespace wp {

// What tells a user how to get OIDN; ends every "not found" error.
extern const char* const kOidnHint;

class Denoiser {
 public:
  // Loads the library and creates and commits an OIDN device, so that a missing or unusable
  // library fails before any rendering. Looked for, in order (the first place that applies is the
  // only one tried):
  //   1. $WAVEPATH_OIDN, when set and not empty: the library file itself, or a folder holding
  //      libOpenImageDenoise.so.2;
  //   2. what `tools/setup.sh --denoise` installs beside the binary: <binary's folder>/oidn-venv/
  //      lib/python3.*/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2;
  //   3. libOpenImageDenoise.so.2 on the system's library path (ld.so's search).
  // Throws wp::Error (one line: where it looked, dlopen's reason, and kOidnHint) on failure.
  static Denoiser load();

  Denoiser(Denoiser&& other) noexcept;
  Denoiser& operator=(Denoiser&& other) noexcept;
  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;
  ~Denoiser();

  // "Open Image Denoise 2.5.1 (PATH)": the version the device reports and the file loaded.
  const std::string& description() const { return description_; }

  // OIDN's RT filter on a linear HDR image (`hdr`), with the albedo and normal AOVs as auxiliary
  // images: these are first denoised by the RT filter of their own (OIDN's "prefiltering"), then
  // passed as clean (`cleanAux`). wavepath's AOVs are means over the pixel's samples, so they
  // still hold noise where a pixel's samples see different surfaces or texels (edges, fine
  // texture, what smooth glass shows); OIDN's documentation asks for cleanAux only with
  // noise-free auxiliary images and recommends prefiltering noisy ones for final frames.
  // Every image: 3 floats per pixel, rows from the top, width * height pixels. Returns the
  // denoised colour. Throws wp::Error ("Open Image Denoise: ...") on any OIDN error.
  std::vector<float> denoise(int width, int height, const std::vector<float>& color,
                             const std::vector<float>& albedo,
                             const std::vector<float>& normal) const;

 private:
  struct Api;  // the resolved functions
  Denoiser() = default;

  const Api* api_ = nullptr;  // owned; the library itself stays loaded (see load())
  void* device_ = nullptr;    // OIDNDevice
  std::string description_;
};

// The path of a denoised output beside `path`: X.exr -> X.denoised.exr (likewise .png, .pfm).
std::string denoised_path(const std::string& path);

}  // namespace wp
