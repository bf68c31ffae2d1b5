#include "host/film/image_io.h"

#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <optional>
#include <random>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <stb_image_write.h>

#include "host/util/error.h"

namespace wp {

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

namespace {

// Adds img's R, G, B as channels `prefix`R/G/B to the header and the frame buffer.
void add_rgb(Imf::Header& header, Imf::FrameBuffer& fb, const ImageRgb& img,
             const std::string& prefix) {
  const std::size_t xs = 3 * sizeof(float), ys = xs * static_cast<std::size_t>(img.width);
  char* base = reinterpret_cast<char*>(const_cast<float*>(img.rgb.data()));
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    header.channels().insert(prefix + names[c], Imf::Channel(Imf::FLOAT));
    fb.insert(prefix + names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
  }
}

void write_exr(const std::string& path, const ImageRgb& img,
               const std::map<std::string, std::string>& attributes,
               const std::vector<ImageLayer>& layers) {
  Imf::Header header(img.width, img.height);
  for (const auto& [key, value] : attributes) header.insert(key, Imf::StringAttribute(value));
  Imf::FrameBuffer fb;
  add_rgb(header, fb, img, "");
  for (const ImageLayer& layer : layers) {
    const std::size_t n = layer.channels.size(), xs = n * sizeof(float),
                      ys = xs * static_cast<std::size_t>(img.width);
    char* base = reinterpret_cast<char*>(const_cast<float*>(layer.data.data()));
    for (std::size_t c = 0; c < n; ++c) {
      const std::string name = layer.name + "." + layer.channels[c];
      header.channels().insert(name, Imf::Channel(Imf::FLOAT));
      fb.insert(name, Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
    }
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(fb);
  file.writePixels(img.height);
}

void write_png(const std::string& path, const ImageRgb& img, const PngOptions& png) {
  std::vector<unsigned char> bytes(img.rgb.size());
  for (std::size_t i = 0; i + 2 < img.rgb.size(); i += 3) {
    const std::array<unsigned char, 3> code =
        png_encode({img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]}, png);
    std::copy(code.begin(), code.end(), bytes.begin() + std::ptrdiff_t(i));
  }
  if (!stbi_write_png(path.c_str(), img.width, img.height, 3, bytes.data(), img.width * 3))
    throw Error("cannot write " + path);
}

// Portable FloatMap: "PF", size, -1 (little-endian), then float RGB rows from the bottom up.
// A PFM of `channels` (3: colour "PF", 1: greyscale "Pf") floats per pixel, rows from the top
// in `data` (PFM stores them from the bottom).
void write_pfm(const std::string& path, int width, int height, std::size_t channels,
               const std::vector<float>& data) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw Error("cannot write " + path);
  std::fprintf(f, "%s\n%d %d\n-1.0\n", channels == 3 ? "PF" : "Pf", width, height);
  const std::size_t row = channels * std::size_t(width);
  bool ok = true;
  for (int y = height - 1; y >= 0; --y)
    ok &= std::fwrite(data.data() + row * std::size_t(y), sizeof(float), row, f) == row;
  ok &= std::fclose(f) == 0;
  if (!ok) throw Error("cannot write " + path);
}

std::string layer_path(const std::string& pfm, const std::string& layer) {
  return pfm.substr(0, pfm.size() - 4) + "." + layer + ".pfm";
}

std::string temporary_name(const std::string& path) {
  static std::mt19937_64 rng{std::random_device{}()};
  const std::filesystem::path p(path);
  // Keep the extension last: OpenEXR and stb do not care, but it keeps temp files recognisable.
  return (p.parent_path() / ("." + p.stem().string() + ".tmp" + std::to_string(rng() % 1000000) +
                             p.extension().string()))
      .string();
}

// Temporary files on disk while write_images runs, for the SIGINT/SIGTERM handler below: a fixed
// array of pointers into strings that outlive the registration, since a handler may not allocate
// or take locks. A count is published only after its entries are written.
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
const char* g_temp_paths[64];
volatile std::sig_atomic_t g_temp_count = 0;

// Removes the temporary files (unlink is async-signal-safe; a name not yet created or already
// renamed fails harmlessly), then dies of the same signal with its default action.
extern "C" void remove_temps_and_reraise(int sig) {
  for (int i = 0; i < g_temp_count; ++i) ::unlink(g_temp_paths[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);  // delivered when the handler returns (the signal is blocked inside it)
}

// While alive: `paths` are removed if the process is interrupted (SIGINT, SIGTERM, SIGHUP) and the
// previous handlers are restored afterwards. One at a time (write_images is not reentrant).
class TempFileGuard {
 public:
  explicit TempFileGuard(const std::vector<std::string>& paths) {
    if (paths.size() > std::size(g_temp_paths))
      throw Error("too many output files (" + std::to_string(paths.size()) + ")");
    for (std::size_t i = 0; i < paths.size(); ++i) g_temp_paths[i] = paths[i].c_str();
    std::atomic_signal_fence(std::memory_order_seq_cst);
    g_temp_count = static_cast<std::sig_atomic_t>(paths.size());
    struct sigaction action {};
    action.sa_handler = remove_temps_and_reraise;
    sigemptyset(&action.sa_mask);
    for (const int sig : kSignals) sigaddset(&action.sa_mask, sig);  // one handler at a time
    for (std::size_t i = 0; i < std::size(kSignals); ++i)
      sigaction(kSignals[i], &action, &previous_[i]);
  }
  ~TempFileGuard() {
    for (std::size_t i = 0; i < std::size(kSignals); ++i)
      sigaction(kSignals[i], &previous_[i], nullptr);
    g_temp_count = 0;
  }
  TempFileGuard(const TempFileGuard&) = delete;
  TempFileGuard& operator=(const TempFileGuard&) = delete;

 private:
  struct sigaction previous_[std::size(kSignals)]{};
};

// Blocks the guarded signals while alive: the renames that publish a set of outputs then complete
// as a whole, and a signal that came meanwhile is handled just after.
class BlockSignals {
 public:
  BlockSignals() {
    sigset_t set;
    sigemptyset(&set);
    for (const int sig : kSignals) sigaddset(&set, sig);
    pthread_sigmask(SIG_BLOCK, &set, &previous_);
  }
  ~BlockSignals() { pthread_sigmask(SIG_SETMASK, &previous_, nullptr); }
  BlockSignals(const BlockSignals&) = delete;
  BlockSignals& operator=(const BlockSignals&) = delete;

 private:
  sigset_t previous_;
};

}  // namespace

std::vector<OutputFile> image_files(const std::vector<std::string>& paths, const ImageRgb& image,
                                    const std::map<std::string, std::string>& exr_attributes,
                                    const PngOptions& png, const std::vector<ImageLayer>& layers) {
  // The lambdas refer to the caller's image, attributes and options, which outlive write_files.
  std::vector<OutputFile> files;
  for (const auto& path : paths) {
    const std::string ext = extension_of(path);
    if (ext == ".exr")
      files.push_back({path, [&image, &exr_attributes, &layers](const std::string& temp) {
                         write_exr(temp, image, exr_attributes, layers);
                       }});
    else if (ext == ".png")
      files.push_back(
          {path, [&image, &png](const std::string& temp) { write_png(temp, image, png); }});
    else if (ext == ".pfm")
      files.push_back({path, [&image](const std::string& temp) {
                         write_pfm(temp, image.width, image.height, 3, image.rgb);
                       }});
    else
      throw Error(path + ": unsupported output format (use .exr, .png or .pfm)");
    if (ext == ".pfm")
      for (const ImageLayer& layer : layers)
        files.push_back({layer_path(path, layer.name), [&image, &layer](const std::string& temp) {
                           write_pfm(temp, image.width, image.height, layer.channels.size(),
                                     layer.data);
                         }});
  }
  return files;
}

void write_files(const std::vector<OutputFile>& files, bool signals_remove_and_exit) {
  // Every temporary name is chosen before the first is created, so that an interruption at any
  // point finds all of them registered with the signal handler.
  std::vector<std::string> temps;
  for (const auto& file : files) temps.push_back(temporary_name(file.path));
  std::optional<TempFileGuard> guard;
  if (signals_remove_and_exit) guard.emplace(temps);
  std::size_t current = 0;  // the file being written, for messages
  try {
    for (; current < files.size(); ++current) files[current].write(temps[current]);
    const BlockSignals block;
    for (current = 0; current < files.size(); ++current)
      std::filesystem::rename(temps[current], files[current].path);
  } catch (const std::exception& e) {
    for (const auto& t : temps) std::remove(t.c_str());  // also those not (yet) created: harmless
    if (dynamic_cast<const Error*>(&e)) throw;
    throw Error("cannot write " + files[std::min(current, files.size() - 1)].path + ": " +
                e.what());
  }
}

void write_images(const std::vector<std::string>& paths, const ImageRgb& image,
                  const std::map<std::string, std::string>& exr_attributes, const PngOptions& png,
                  const std::vector<ImageLayer>& layers) {
  write_files(image_files(paths, image, exr_attributes, png, layers));
}

ImageRgb read_exr(const std::string& path, const std::string& layer) {
  const std::string prefix = layer.empty() ? "" : layer + ".";
  try {
    Imf::InputFile file(path.c_str());
    for (const char* c : {"R", "G", "B"})
      if (!file.header().channels().findChannel(prefix + c))
        throw Error("cannot read " + path + ": no channel " + prefix + c);
    const Imath::Box2i dw = file.header().dataWindow();
    ImageRgb img;
    img.width = dw.max.x - dw.min.x + 1;
    img.height = dw.max.y - dw.min.y + 1;
    img.rgb.assign(3 * std::size_t(img.width) * std::size_t(img.height), 0.0f);
    const std::size_t xs = 3 * sizeof(float), ys = xs * static_cast<std::size_t>(img.width);
    char* base = reinterpret_cast<char*>(img.rgb.data()) - dw.min.x * std::ptrdiff_t(xs) -
                 dw.min.y * std::ptrdiff_t(ys);
    Imf::FrameBuffer fb;
    fb.insert(prefix + "R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert(prefix + "G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
    fb.insert(prefix + "B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return img;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error("cannot read " + path + ": " + e.what());
  }
}

std::map<std::string, std::string> read_exr_attributes(const std::string& path) {
  std::map<std::string, std::string> out;
  try {
    Imf::InputFile file(path.c_str());
    for (auto it = file.header().begin(); it != file.header().end(); ++it)
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        out[it.name()] = s->value();
  } catch (const std::exception& e) {
    throw Error("cannot read " + path + ": " + e.what());
  }
  return out;
}

}  // namespace wp
