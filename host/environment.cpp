// Loading equirectangular environment maps and building their sampling tables. The table layout
// is documented once, in kernels/environment.h, which reads it.
#include "host/environment.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <system_error>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <stb_image.h>

#include "host/error.h"

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

// Radiance RGBE through stb_image. stbi_is_hdr first: stbi_loadf would also decode an LDR image
// (a PNG renamed .hdr) and invent radiance from it by undoing a guessed gamma.
void read_hdr(const std::string& path, EnvironmentMap& env) {
  if (!stbi_is_hdr(path.c_str())) throw Error(path + ": not a Radiance HDR (RGBE) file");
  int w = 0, h = 0, channels = 0;
  std::unique_ptr<float, void (*)(void*)> data(stbi_loadf(path.c_str(), &w, &h, &channels, 3),
                                               stbi_image_free);
  if (!data) {
    const char* why = stbi_failure_reason();
    throw Error(path + ": cannot decode the HDR image (" + (why ? why : "unknown error") + ")");
  }
  if (w <= 0 || h <= 0) throw Error(path + ": the image is empty");
  env.width = w;
  env.height = h;
  const std::size_t n = std::size_t(w) * std::size_t(h);
  env.texels.resize(n);
  const float* p = data.get();
  for (std::size_t i = 0; i < n; ++i) env.texels[i] = {p[3 * i], p[3 * i + 1], p[3 * i + 2], 0.0f};
}

// OpenEXR: R, G and B of the data window (which may start anywhere), as 32-bit floats whatever
// their stored type. Row 0 of the data window is the top of the map.
void read_exr(const std::string& path, EnvironmentMap& env) {
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    for (const char* c : {"R", "G", "B"})
      if (!header.channels().findChannel(c))
        throw Error(path + ": the EXR image has no " + c + " channel (RGB is required)");
    const Imath::Box2i dw = header.dataWindow();
    const long long w = 1LL + dw.max.x - dw.min.x, h = 1LL + dw.max.y - dw.min.y;
    if (w <= 0 || h <= 0) throw Error(path + ": the image is empty");
    env.width = static_cast<int>(w);
    env.height = static_cast<int>(h);
    env.texels.assign(std::size_t(w) * std::size_t(h), glm::vec4(0.0f));
    const std::size_t xs = sizeof(glm::vec4), ys = xs * std::size_t(w);
    char* base = reinterpret_cast<char*>(env.texels.data()) - dw.min.x * std::ptrdiff_t(xs) -
                 dw.min.y * std::ptrdiff_t(ys);
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

EnvironmentMap load_environment(const std::string& path) {
  EnvironmentMap env;
  env.source = path;
  const std::string ext = lower_extension(path);
  if (ext != ".hdr" && ext != ".exr")
    throw Error(path + ": unsupported environment map format (use .hdr or .exr)");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": no such file");
  if (ext == ".hdr")
    read_hdr(path, env);
  else
    read_exr(path, env);
  build_environment_tables(env);
  return env;
}

// Texel (x, y) covers u in [x, x+1) / W and v in [y, y+1) / H, i.e. a solid angle of
// (2 pi / W) (cos theta_y - cos theta_{y+1}) = (2 pi / W) 2 sin(theta_c) sin(pi / 2H) with
// theta_c its centre. Weights luminance x sin(theta_c) are therefore proportional to luminance x
// solid angle, the piecewise-constant density over (u, v) that matches radiance x Jacobian.
void build_environment_tables(EnvironmentMap& env) {
  validate(env);
  const std::size_t w = std::size_t(env.width), h = std::size_t(env.height);
  env.marginal.assign(h + 1, 0.0f);
  env.conditional.assign(h * (w + 1), 0.0f);
  std::vector<double> row_weight(h), texel_weight(w);
  double weighted = 0.0;  // sum of luminance x solid angle
  const double row_half_height = std::sin(0.5 * kPi / double(h));
  for (std::size_t y = 0; y < h; ++y) {
    const double sin_theta = std::sin(kPi * (double(y) + 0.5) / double(h));
    double row = 0.0;
    for (std::size_t x = 0; x < w; ++x) {
      texel_weight[x] = luminance(env.texels[y * w + x]) * sin_theta;
      row += texel_weight[x];
    }
    row_weight[y] = row;
    weighted += row * (2.0 * kPi / double(w)) * 2.0 * row_half_height;
    write_cdf(texel_weight, env.conditional.data() + y * (w + 1), false);
  }
  write_cdf(row_weight, env.marginal.data(), true);
  env.mean_luminance = weighted / (4.0 * kPi);
}

}  // namespace wp
