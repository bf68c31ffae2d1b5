// Loading equirectangular environment maps and building their sampling tables. The table layout
// is documented once, in kernels/lights/environment.h, which reads it.
#include "host/lights/environment.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include "host/scene/scene.h"
#include "host/util/error.h"
#include "host/util/files.h"

namespace wp {

namespace {

constexpr double kPi = 3.14159265358979323846;

double luminance(const glm::vec4& c) {
  return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// Radiance RGBE (.hdr), read here and not by stb_image: stbi_loadf loops forever on a truncated
// run-length scanline or a zero-length run. Every count below is checked against the scanline
// width and the bytes left, so any input ends in pixels or in one wp::Error naming the cause.
//
// Layout: "#?RADIANCE" (or "#?RGBE"), header lines up to an empty line (FORMAT=32-bit_rle_rgbe
// required), the resolution line "-Y H +X W" (rows from the top, the only orientation read),
// then H scanlines. A scanline starting 2, 2, hi, lo (hi < 128) is new-style run-length encoded:
// hi * 256 + lo = W, then each of the 4 channels in turn as runs (count > 128: count - 128 copies
// of the next byte) and literals (count 1..128: that many bytes). Any other scanline is W flat
// RGBE pixels. Old-style runs (pixel 1, 1, 1, n) are read as pixels, as stb_image did.
constexpr std::uint64_t kMaxMapPixels = std::uint64_t{1} << 28;  // 4 GiB of texels (any format)

class RgbeReader {
 public:
  RgbeReader(const std::string& path, std::vector<unsigned char> bytes)
      : path_(path), b_(std::move(bytes)) {}

  void read(EnvironmentMap& env) {
    read_header();
    const auto [w, h] = read_resolution();
    env.width = w;
    env.height = h;
    env.texels.assign(std::size_t(w) * std::size_t(h), glm::vec4(0.0f));
    std::vector<unsigned char> line(4 * std::size_t(w));
    for (int y = 0; y < h; ++y) {
      read_scanline(y, h, line);
      for (int x = 0; x < w; ++x) {
        const unsigned char* p = &line[4 * std::size_t(x)];
        // stb_image's convention (scenes/rgbe.py's decode): m * 2^(e - 136), no half-step.
        const float f = p[3] == 0 ? 0.0f : std::ldexp(1.0f, int(p[3]) - 136);
        env.texels[std::size_t(y) * std::size_t(w) + std::size_t(x)] = {
            float(p[0]) * f, float(p[1]) * f, float(p[2]) * f, 0.0f};
      }
    }
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw Error(path_ + ": not a valid Radiance HDR file: " + why);
  }

  // The next line without its '\n'; a file that ends first is truncated.
  std::string next_line(const char* where) {
    const auto begin = b_.begin() + std::ptrdiff_t(pos_);
    const auto end = std::find(begin, b_.end(), '\n');
    if (end == b_.end()) fail(std::string("truncated in the ") + where);
    pos_ = std::size_t(end - b_.begin()) + 1;
    return std::string(begin, end);
  }

  void read_header() {
    const std::string magic = next_line("header");
    if (magic != "#?RADIANCE" && magic != "#?RGBE")
      fail("no #?RADIANCE or #?RGBE signature on the first line");
    bool format = false;
    for (std::string line = next_line("header"); !line.empty(); line = next_line("header")) {
      if (line.rfind("FORMAT=", 0) != 0) continue;  // EXPOSURE, comments, ...: not needed
      if (line != "FORMAT=32-bit_rle_rgbe")
        fail("unsupported " + line.substr(0, 64) + " (only FORMAT=32-bit_rle_rgbe is read)");
      format = true;
    }
    if (!format) fail("no FORMAT=32-bit_rle_rgbe line in the header");
  }

  // "-Y H +X W" with 0 < W * H <= kMaxMapPixels; checked before anything is allocated.
  std::pair<int, int> read_resolution() {
    const std::string line = next_line("resolution line");
    const auto number = [&](std::size_t& at) {
      std::uint64_t v = 0;
      const std::size_t start = at;
      while (at < line.size() && std::isdigit(static_cast<unsigned char>(line[at])) &&
             at - start < 10)
        v = v * 10 + std::uint64_t(line[at++] - '0');
      return at == start ? 0 : v;  // 0: missing, and also refused below
    };
    std::size_t at = 3;
    std::uint64_t h = 0, w = 0;
    const bool shape = line.rfind("-Y ", 0) == 0 && (h = number(at)) > 0 &&
                       line.compare(at, 4, " +X ") == 0 && (at += 4, (w = number(at)) > 0) &&
                       at == line.size();
    if (!shape)
      fail("resolution line '" + line.substr(0, 64) + "' is not '-Y <height> +X <width>'");
    if (w > kMaxMapPixels || h > kMaxMapPixels || w * h > kMaxMapPixels)
      fail(std::to_string(w) + " x " + std::to_string(h) + " pixels is more than the 2^28 read");
    // Cheapest possible scanline: 4 flat bytes a pixel, or 4 + 4 channels x 2 bytes a run of 127.
    const std::uint64_t least = std::min<std::uint64_t>(4 * w, 4 + 8 * ((w + 126) / 127));
    if (least * h > b_.size() - pos_)
      fail("the file is too short for " + std::to_string(w) + " x " + std::to_string(h) +
           " pixels");
    return {int(w), int(h)};
  }

  const unsigned char* take(std::size_t n, int y, int h) {
    if (n > b_.size() - pos_)
      fail("truncated in scanline " + std::to_string(y) + " of " + std::to_string(h));
    pos_ += n;
    return &b_[pos_ - n];
  }

  void read_scanline(int y, int h, std::vector<unsigned char>& line) {
    const std::size_t w = line.size() / 4;
    const std::string at = "scanline " + std::to_string(y) + ": ";
    const bool rle = w >= 8 && w < 32768 && b_.size() - pos_ >= 4 && b_[pos_] == 2 &&
                     b_[pos_ + 1] == 2 && b_[pos_ + 2] < 128;
    if (!rle) {
      std::memcpy(line.data(), take(4 * w, y, h), 4 * w);
      return;
    }
    const unsigned char* head = take(4, y, h);
    const std::size_t declared = std::size_t(head[2]) << 8 | head[3];
    if (declared != w)
      fail(at + "run-length width " + std::to_string(declared) + " is not the image width " +
           std::to_string(w));
    for (std::size_t c = 0; c < 4; ++c) {
      for (std::size_t x = 0; x < w;) {
        const std::size_t count = *take(1, y, h);
        const bool run = count > 128;
        const std::size_t n = run ? count - 128 : count;
        if (n == 0) fail(at + "zero-length run");
        if (n > w - x)
          fail(at + (run ? "run" : "literal") + " of " + std::to_string(n) + " at x " +
               std::to_string(x) + " overruns the width " + std::to_string(w));
        if (run) {
          const unsigned char value = *take(1, y, h);
          for (std::size_t k = 0; k < n; ++k) line[4 * (x + k) + c] = value;
        } else {
          const unsigned char* p = take(n, y, h);
          for (std::size_t k = 0; k < n; ++k) line[4 * (x + k) + c] = p[k];
        }
        x += n;
      }
    }
  }

  const std::string& path_;
  std::vector<unsigned char> b_;
  std::size_t pos_ = 0;
};

void read_hdr(const std::string& path, EnvironmentMap& env) {
  RgbeReader(path, read_regular_file(path)).read(env);
}

// A data window of w x h pixels, checked before anything is allocated for it: a 417-byte file can
// declare a 2^28-pixel window (found by tests/fuzz). Besides the texel limit of .hdr maps, the file
// must be able to hold the window: at 6 bytes per pixel (half RGB), no EXR compression (zlib: at
// most ~1000:1) packs more than 2048 x its size, and maps up to 16 MiB of pixels are never refused
// on this count.
void check_exr_window(const std::string& path, long long w, long long h, std::uint64_t file_bytes) {
  const std::uint64_t pixels = std::uint64_t(w) * std::uint64_t(h);
  if (std::uint64_t(w) > kMaxMapPixels || std::uint64_t(h) > kMaxMapPixels ||
      pixels > kMaxMapPixels)
    throw Error(path + ": " + std::to_string(w) + " x " + std::to_string(h) +
                " pixels is more than the 2^28 read");
  if (6 * pixels > 2048 * file_bytes + (std::uint64_t{16} << 20))
    throw Error(path + ": " + std::to_string(w) + " x " + std::to_string(h) +
                " pixels in a file of " + std::to_string(file_bytes) +
                " bytes: the EXR header is corrupt");
}

// The bytes a value of EXR attribute type `type` takes (OpenEXR reads that many whatever the
// stated size), or 0 for types of variable size (strings, channel lists, previews, unknown ones).
std::size_t exr_fixed_size(const std::string& type) {
  static const std::pair<const char*, std::size_t> kSizes[] = {{"box2i", 16},
                                                               {"box2f", 16},
                                                               {"compression", 1},
                                                               {"lineOrder", 1},
                                                               {"envmap", 1},
                                                               {"int", 4},
                                                               {"float", 4},
                                                               {"double", 8},
                                                               {"v2i", 8},
                                                               {"v2f", 8},
                                                               {"v2d", 16},
                                                               {"v3i", 12},
                                                               {"v3f", 12},
                                                               {"v3d", 24},
                                                               {"m33f", 36},
                                                               {"m33d", 72},
                                                               {"m44f", 64},
                                                               {"m44d", 128},
                                                               {"rational", 8},
                                                               {"timecode", 8},
                                                               {"keycode", 28},
                                                               {"tiledesc", 9},
                                                               {"chromaticities", 32},
                                                               {"deepImageState", 1}};
  for (const auto& [name, bytes] : kSizes)
    if (type == name) return bytes;
  return 0;
}

// The attributes of an EXR file's header(s), walked before OpenEXR reads them: each attribute's
// size must fit in the bytes that follow it. OpenEXR allocates an unknown ("opaque") attribute's
// stated size before reading it, so a 202-byte file stating 1.6 GB made it allocate that much
// (fuzzing: with the sanitizers' bookkeeping, seconds per input). Names and types are
// NUL-terminated strings of at most 255 bytes; a header ends with an empty name, a multi-part
// file's headers with an empty header. A dataWindow is checked here too (check_exr_window): for a
// window millions of pixels wide OpenEXR allocates line buffers before read_exr could look.
void check_exr_attributes(const std::string& path) {
  const std::vector<unsigned char> b = read_regular_file(path);
  const auto fail = [&](const std::string& what) {
    return Error(path + ": the EXR header is corrupt (" + what + ")");
  };
  if (b.size() < 8) throw fail("shorter than its magic number and version");
  const bool multipart = (b[5] & 0x10) != 0;  // version bit 12
  std::size_t at = 8;
  const auto text = [&](const char* what) {
    const std::size_t start = at;
    while (at < b.size() && b[at] != 0 && at - start < 256) ++at;
    if (at >= b.size() || b[at] != 0) throw fail(std::string("unterminated ") + what);
    return at++ - start;  // its length; `at` past the NUL
  };
  for (int headers = 0;; ++headers) {
    bool empty = true;
    std::size_t name_at = at;
    while (text("attribute name") > 0) {
      empty = false;
      const bool window =
          std::strcmp(reinterpret_cast<const char*>(&b[name_at]), "dataWindow") == 0;
      const std::size_t type_at = at;
      text("attribute type");
      const std::string type(reinterpret_cast<const char*>(&b[type_at]));
      if (b.size() - at < 4) throw fail("truncated attribute size");
      const std::uint32_t size = std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 |
                                 std::uint32_t(b[at + 2]) << 16 | std::uint32_t(b[at + 3]) << 24;
      at += 4;
      if (size > b.size() - at)
        throw fail("an attribute states " + std::to_string(size) + " bytes, " +
                   std::to_string(b.size() - at) + " follow");
      // OpenEXR reads a value of a known type by its type, not by the stated size (fuzzing: a
      // channel list one byte longer than stated put OpenEXR, but not this walk, on an attribute
      // stating 1.9 GB). Valid files state exactly what their types take; anything else is
      // refused here, so that this walk and OpenEXR see the same attributes.
      if (const std::size_t fixed = exr_fixed_size(type); fixed && fixed != size)
        throw fail("a " + type + " attribute of " + std::to_string(size) + " bytes, not " +
                   std::to_string(fixed));
      if (type == "chlist") {  // entries: a name, then 16 bytes; an empty name ends the list
        std::size_t c = at;
        const std::size_t end = at + size;
        while (c < end && b[c] != 0) {
          while (c < end && b[c] != 0) ++c;
          c += 1 + 16;
        }
        if (c + 1 != end) throw fail("a channel list that does not end where its size says");
      }
      if (window && size == 16) {  // box2i: xMin, yMin, xMax, yMax
        std::int32_t v[4];
        for (int i = 0; i < 4; ++i)
          v[i] = static_cast<std::int32_t>(
              std::uint32_t(b[at + 4 * i]) | std::uint32_t(b[at + 4 * i + 1]) << 8 |
              std::uint32_t(b[at + 4 * i + 2]) << 16 | std::uint32_t(b[at + 4 * i + 3]) << 24);
        const long long w = 1LL + v[2] - v[0], h = 1LL + v[3] - v[1];
        if (w > 0 && h > 0) check_exr_window(path, w, h, b.size());
      }
      at += size;
      name_at = at;
    }
    if (!multipart || (empty && headers > 0)) return;
  }
}

// OpenEXR: R, G and B of the data window (which may start anywhere), as 32-bit floats whatever
// their stored type. Row 0 of the data window is the top of the map.
void read_exr(const std::string& path, EnvironmentMap& env) {
  check_exr_attributes(path);
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    for (const char* c : {"R", "G", "B"})
      if (!header.channels().findChannel(c))
        throw Error(path + ": the EXR image has no " + c + " channel (RGB is required)");
    const Imath::Box2i dw = header.dataWindow();
    const long long w = 1LL + dw.max.x - dw.min.x, h = 1LL + dw.max.y - dw.min.y;
    if (w <= 0 || h <= 0) throw Error(path + ": the image is empty");
    // Again as OpenEXR read it (the walk above checked the first dataWindow it met).
    check_exr_window(path, w, h, std::filesystem::file_size(path));
    env.width = static_cast<int>(w);
    env.height = static_cast<int>(h);
    env.texels.assign(std::size_t(w) * std::size_t(h), glm::vec4(0.0f));
    const std::size_t xs = sizeof(glm::vec4), ys = xs * std::size_t(w);
    // OpenEXR addresses pixel (x, y) of a slice at base + x * xs + y * ys, so the base lies the
    // window's origin before the texels: for an origin far from (0, 0) outside any object, even
    // below address 0. Computed on the integer address (unsigned, wrapping as defined), since
    // pointer arithmetic that leaves the array is undefined (UBSan, a fuzz finding: a window at
    // y = 690 million).
    const std::uintptr_t first = reinterpret_cast<std::uintptr_t>(env.texels.data());
    char* base = reinterpret_cast<char*>(first - std::uintptr_t(std::intptr_t(dw.min.x)) * xs -
                                         std::uintptr_t(std::intptr_t(dw.min.y)) * ys);
    Imf::FrameBuffer fb;
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(path + ": cannot read the EXR image (" + e.what() + ")");
  }
}

// Texels brighter than float32 carries through the transport (scene.h: kMaxRadiance) are clamped
// to it, all three channels scaled alike; one warning says how many and the brightest.
void clamp_radiance(EnvironmentMap& env) {
  std::size_t count = 0;
  float brightest = 0.0f;
  for (glm::vec4& t : env.texels) {
    const float m = std::max({t.x, t.y, t.z});
    if (!std::isfinite(m) || m <= float(kMaxRadiance)) continue;  // NaN, Inf: validate's errors
    ++count;
    brightest = std::max(brightest, m);
    t = glm::vec4(glm::vec3(t) * (float(kMaxRadiance) / m), t.w);
  }
  if (count == 0) return;
  char text[160];
  std::snprintf(text, sizeof text,
                ": %zu texel%s above %g (the brightest %g) clamped to it, the most radiance "
                "wavepath carries",
                count, count == 1 ? "" : "s", kMaxRadiance, double(brightest));
  env.warnings.push_back(env.source + text);
}

// Refuses what would poison the tables or the image: wrong sizes, NaN, infinities, negatives.
void validate(const EnvironmentMap& env) {
  const std::string name = env.source.empty() ? std::string("environment map") : env.source;
  if (env.width <= 0 || env.height <= 0) throw Error(name + ": the image is empty");
  if (env.texels.size() != std::size_t(env.width) * std::size_t(env.height))
    throw Error(name + ": texel count does not match " + std::to_string(env.width) + " x " +
                std::to_string(env.height));
  for (std::size_t i = 0; i < env.texels.size(); ++i) {
    const glm::vec4& t = env.texels[i];
    for (int k = 0; k < 3; ++k) {
      if (std::isfinite(t[k]) && t[k] >= 0.0f) continue;
      const std::size_t x = i % std::size_t(env.width), y = i / std::size_t(env.width);
      throw Error(name + ": texel (" + std::to_string(x) + ", " + std::to_string(y) + ") has " +
                  (std::isfinite(t[k]) ? "a negative" : "a non-finite") +
                  " value (radiance must be finite and >= 0)");
    }
  }
}

// Writes the CDF of `weights` (n + 1 entries: 0, ..., 1) to out[0..n]. Cumulated and normalised
// in double, so entries after the last positive weight are exactly 1.0f and the rounding to float
// is monotone. All weights zero: an all-zero CDF when `zero_if_empty` (nothing to sample, the
// kernels test cdf[n] > 0), else the uniform one (a black row is never chosen, but keeps a
// well-defined table).
void write_cdf(const std::vector<double>& weights, float* out, bool zero_if_empty) {
  const std::size_t n = weights.size();
  double total = 0.0;
  for (double w : weights) total += w;
  out[0] = 0.0f;
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += weights[i];
    if (total > 0.0)
      out[i + 1] = static_cast<float>(sum / total);
    else
      out[i + 1] = zero_if_empty ? 0.0f : static_cast<float>(double(i + 1) / double(n));
  }
  if (total > 0.0 || !zero_if_empty) out[n] = 1.0f;
}

}  // namespace

const char* env_filter_name(EnvFilter f) {
  return f == EnvFilter::kBilinear ? "bilinear" : "nearest";
}

EnvironmentMap load_environment(const std::string& path, EnvFilter filter) {
  EnvironmentMap env;
  env.source = path;
  const std::string ext = lower_extension(path);
  if (ext != ".hdr" && ext != ".exr")
    throw Error(path + ": unsupported environment map format (use .hdr or .exr)");
  require_regular_file(path);  // a FIFO must not block OpenEXR's open
  if (ext == ".hdr")
    read_hdr(path, env);
  else
    read_exr(path, env);
  clamp_radiance(env);
  build_environment_tables(env, filter);
  return env;
}

// Texel (x, y) covers u in [x, x+1) / W and v in [y, y+1) / H, i.e. a solid angle of
// (2 pi / W) (cos theta_y - cos theta_{y+1}) = (2 pi / W) 2 sin(theta_c) sin(pi / 2H) with
// theta_c its centre. Weights luminance x sin(theta_c) are therefore proportional to luminance x
// solid angle, the piecewise-constant density over (u, v) that matches radiance x Jacobian.
// Bilinear tables use f(x, y) = the largest luminance of the 3 x 3 texels around (x, y) instead,
// which bounds the interpolated luminance over the texel (kernels/lights/environment.h says why).
void build_environment_tables(EnvironmentMap& env, EnvFilter filter) {
  validate(env);
  env.filter = filter;
  const std::size_t w = std::size_t(env.width), h = std::size_t(env.height);
  std::vector<double> lum(w * h);
  env.max_radiance = 0.0;
  for (std::size_t i = 0; i < w * h; ++i) {
    lum[i] = luminance(env.texels[i]);
    const glm::vec4& t = env.texels[i];
    env.max_radiance = std::max({env.max_radiance, double(t.x), double(t.y), double(t.z)});
  }
  std::vector<double> bound = lum;
  if (filter == EnvFilter::kBilinear)
    for (std::size_t y = 0; y < h; ++y)
      for (std::size_t x = 0; x < w; ++x) {
        double m = 0.0;
        for (std::size_t ry : {y == 0 ? 0 : y - 1, y, std::min(y + 1, h - 1)})
          for (std::size_t rx : {(x + w - 1) % w, x, (x + 1) % w})
            m = std::max(m, lum[ry * w + rx]);
        bound[y * w + x] = m;
      }
  env.marginal.assign(h + 1, 0.0f);
  env.conditional.assign(h * (w + 1), 0.0f);
  std::vector<double> row_weight(h), texel_weight(w);
  double weighted = 0.0;  // sum of luminance x solid angle (the map's own, whatever the filter)
  const double row_half_height = std::sin(0.5 * kPi / double(h));
  for (std::size_t y = 0; y < h; ++y) {
    const double sin_theta = std::sin(kPi * (double(y) + 0.5) / double(h));
    double row = 0.0, row_luminance = 0.0;
    for (std::size_t x = 0; x < w; ++x) {
      texel_weight[x] = bound[y * w + x] * sin_theta;
      row += texel_weight[x];
      row_luminance += lum[y * w + x] * sin_theta;
    }
    row_weight[y] = row;
    weighted += row_luminance * (2.0 * kPi / double(w)) * 2.0 * row_half_height;
    write_cdf(texel_weight, env.conditional.data() + y * (w + 1), false);
  }
  write_cdf(row_weight, env.marginal.data(), true);
  env.mean_luminance = weighted / (4.0 * kPi);
}

}  // namespace wp
