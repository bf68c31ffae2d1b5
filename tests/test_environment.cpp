// Environment maps: loading (.hdr, .exr and the refusals), the sampling tables, the direction
// convention on the device (host/lights/environment.h), and env_sample against env_pdf: chi-square
// on equal-area sphere bins, pdf agreement per sample, normalisation, and an unbiased estimator of
// the map's integral over the sphere.
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iostream>
#include <iterator>
#include <memory>
#include <random>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <stb_image_write.h>
#include <gtest/gtest.h>

#include "host/lights/environment.h"
#include "host/util/error.h"
#include "host/lights/light_table.h"
#include "tests/chi2.h"
#include "tests/kernel_harness.h"
#include "tests/test_assets.h"

namespace {

using wp::dev::float4;
constexpr double kPi = 3.14159265358979323846;

std::string temp_file(const std::string& name) {
  static const std::string tag = std::to_string(std::random_device{}() % 1000000u);
  return (std::filesystem::temp_directory_path() / ("wp_env_" + tag + "_" + name)).string();
}

wp::EnvironmentMap make_map(int w, int h, const std::function<glm::vec3(int, int)>& f,
                            wp::EnvFilter filter = wp::EnvFilter::kNearest) {
  wp::EnvironmentMap env;
  env.source = "synthetic";
  env.width = w;
  env.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) env.texels.emplace_back(f(x, y), 0.0f);
  wp::build_environment_tables(env, filter);
  return env;
}

// Host reference of the convention: map coordinates (u, v) of world direction d for a map turned
// by `degrees` about +Y (the map frame is the world turned back by the rotation).
glm::dvec2 map_uv(glm::dvec3 d, double degrees) {
  const double r = degrees * kPi / 180.0, c = std::cos(r), s = std::sin(r);
  const glm::dvec3 m(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
  return {(std::atan2(m.x, -m.z) + kPi) / (2.0 * kPi), std::acos(m.y / glm::length(m)) / kPi};
}

// The texel solid angle (2 pi / W)(cos theta_y - cos theta_{y+1}).
double texel_solid_angle(const wp::EnvironmentMap& env, int y) {
  const double h = env.height;
  return 2.0 * kPi / env.width * (std::cos(kPi * y / h) - std::cos(kPi * (y + 1) / h));
}

// Host reference of the bilinear lookup (kernels/lights/environment.h), written from the convention
// in float64: texel centres at ((x + 0.5) / W, (y + 0.5) / H), columns wrapped, rows clamped.
glm::dvec3 bilinear_at(const wp::EnvironmentMap& env, double u, double v) {
  const int w = env.width, h = env.height;
  const double fx = u * w - 0.5, fy = v * h - 0.5;
  const double x0 = std::floor(fx), y0 = std::floor(fy), tx = fx - x0, ty = fy - y0;
  const auto texel = [&](double x, double y) {
    const int xi = ((int(x) % w) + w) % w, yi = std::clamp(int(y), 0, h - 1);
    return glm::dvec3(env.texels[std::size_t(yi * w + xi)]);
  };
  return (1 - ty) * ((1 - tx) * texel(x0, y0) + tx * texel(x0 + 1, y0)) +
         ty * ((1 - tx) * texel(x0, y0 + 1) + tx * texel(x0 + 1, y0 + 1));
}

// The integral over the sphere of the bilinear map: 2 pi^2 times the integral over v of
// sin(pi v) R(v), where R(v), the integral over u of the map, is the mean of the two blended rows
// (a full period of the linear interpolation in u integrates to the row mean). R is linear between
// row centres and constant within half a row of the poles, so composite Simpson on each of those
// H + 1 pieces (sin(pi v) smooth, 64 panels) is exact up to ~1e-10 relative.
glm::dvec3 bilinear_integral(const wp::EnvironmentMap& env) {
  const int w = env.width, h = env.height;
  std::vector<glm::dvec3> row_mean(std::size_t(h), glm::dvec3(0.0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      row_mean[std::size_t(y)] += glm::dvec3(env.texels[std::size_t(y * w + x)]) / double(w);
  const auto r_of = [&](double v) {
    const double fy = v * h - 0.5, y0 = std::floor(fy), t = fy - y0;
    const auto row = [&](double y) { return row_mean[std::size_t(std::clamp(int(y), 0, h - 1))]; };
    return (1 - t) * row(y0) + t * row(y0 + 1);
  };
  glm::dvec3 sum(0.0);
  for (int k = 0; k <= h; ++k) {
    const double a = k == 0 ? 0.0 : (k - 0.5) / h, b = k == h ? 1.0 : (k + 0.5) / h;
    const int n = 64;
    const double step = (b - a) / n;
    for (int i = 0; i <= n; ++i) {
      const double v = a + i * step, c = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
      sum += c * step / 3.0 * std::sin(kPi * v) * r_of(v);
    }
  }
  return 2.0 * kPi * kPi * sum;
}

// The kernels, built once per test process: nearest lookup, and bilinear (-D WP_ENV_BILINEAR=1).
class Environment : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    kernels_ = std::make_unique<wp::test::KernelHarness>(
        std::vector<std::string>{"environment_kernels.cl"});
    bilinear_ = std::make_unique<wp::test::KernelHarness>(
        std::vector<std::string>{"environment_kernels.cl"}, "-D WP_ENV_BILINEAR=1");
  }
  static void TearDownTestSuite() {
    kernels_.reset();
    bilinear_.reset();
  }
  static std::unique_ptr<wp::test::KernelHarness> kernels_, bilinear_;
};
std::unique_ptr<wp::test::KernelHarness> Environment::kernels_, Environment::bilinear_;

// A map on the device: the SceneDesc fields the environment reads, and its three arrays.
struct DeviceEnv {
  wp::dev::SceneDesc desc{};
  cl::Buffer texels, marginal, conditional;
  DeviceEnv(wp::test::KernelHarness& k, const wp::EnvironmentMap* env, float intensity,
            double degrees) {
    const double r = degrees * kPi / 180.0;
    desc.env_params = {intensity, float(std::cos(r)), float(std::sin(r)), 0.0f};
    desc.background = {0.25f, 0.5f, 0.75f, 0.0f};
    const wp::EnvironmentMap none;
    const wp::EnvironmentMap& e = env ? *env : none;
    desc.env_width = static_cast<wp::dev::uint>(e.width);
    desc.env_height = static_cast<wp::dev::uint>(e.height);
    // A buffer cannot be empty: without a map, one unused element each.
    texels = k.buffer(e.texels.empty() ? std::vector<glm::vec4>(1) : e.texels);
    marginal = k.buffer(e.marginal.empty() ? std::vector<float>(1) : e.marginal);
    conditional = k.buffer(e.conditional.empty() ? std::vector<float>(1) : e.conditional);
  }
};

// (env_radiance, env_pdf) of each direction on the device. Every call also checks that
// env_radiance_pdf without the pdf (a camera ray's escape) gives the same radiance, bit for bit,
// and pdf 0.
std::vector<float4> eval(wp::test::KernelHarness& k, DeviceEnv& e,
                         const std::vector<glm::vec3>& dirs) {
  std::vector<float4> in;
  for (const glm::vec3& d : dirs) in.push_back({d.x, d.y, d.z, 0.0f});
  cl::Buffer din = k.buffer(in), out = k.buffer<float4>(2 * in.size());
  const auto n = static_cast<std::uint32_t>(in.size());
  k.run("env_eval", n, e.desc, e.texels, e.marginal, e.conditional, din, n, out);
  const std::vector<float4> both = k.read<float4>(out, 2 * in.size());
  std::vector<float4> result;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const float4 &r = both[2 * i], &radiance_only = both[2 * i + 1];
    EXPECT_TRUE(r.x == radiance_only.x && r.y == radiance_only.y && r.z == radiance_only.z)
        << "env_radiance_pdf without the pdf, direction " << i;
    EXPECT_EQ(radiance_only.w, 0.0f) << "direction " << i;
    result.push_back(r);
  }
  return result;
}

// ---- Loading ----------------------------------------------------------------------------------

TEST(EnvironmentLoad, HdrRoundTrip) {
  const int w = 7, h = 3;
  std::vector<float> rgb;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (float c : {float(x + 1), 0.5f * float(y + 1), 0.125f}) rgb.push_back(c);
  const std::string path = temp_file("round_trip.hdr");
  ASSERT_TRUE(stbi_write_hdr(path.c_str(), w, h, 3, rgb.data()));
  const wp::EnvironmentMap env = wp::load_environment(path);
  std::filesystem::remove(path);
  ASSERT_EQ(env.width, w);
  ASSERT_EQ(env.height, h);
  for (std::size_t i = 0; i < env.texels.size(); ++i) {
    const float max = std::max({rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]});
    for (int c = 0; c < 3; ++c)  // RGBE keeps 8 mantissa bits of the largest component
      EXPECT_NEAR(env.texels[i][c], rgb[3 * i + std::size_t(c)], max / 128.0f) << i << " " << c;
  }
  EXPECT_EQ(env.marginal.size(), std::size_t(h + 1));
  EXPECT_EQ(env.conditional.size(), std::size_t(h * (w + 1)));
  EXPECT_GT(env.mean_luminance, 0.0);
}

// Writes an EXR of 32-bit float channels (R, G, B unless told) with a data window that does not
// start at (0, 0): at `origin`.
void write_exr(const std::string& path, int w, int h, const std::function<float(int, int, int)>& f,
               const std::vector<std::string>& channels = {"R", "G", "B"},
               Imath::V2i origin = {-3, 5}) {
  const Imath::Box2i display({0, 0}, {w - 1, h - 1}),
      data(origin, {origin.x + w - 1, origin.y + h - 1});
  Imf::Header header(display, data);
  for (const auto& c : channels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  std::vector<float> px(std::size_t(w) * std::size_t(h) * channels.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (std::size_t c = 0; c < channels.size(); ++c)
        px[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * channels.size() + c] =
            f(x, y, int(c));
  const std::size_t xs = channels.size() * sizeof(float), ys = xs * std::size_t(w);
  // OpenEXR's slice base: the pixels less the origin's offset, on the integer address (the
  // pointer itself may lie outside any object; see host/lights/environment.cpp, read_exr).
  char* base = reinterpret_cast<char*>(reinterpret_cast<std::uintptr_t>(px.data()) -
                                       std::uintptr_t(std::intptr_t(origin.x)) * xs -
                                       std::uintptr_t(std::intptr_t(origin.y)) * ys);
  Imf::FrameBuffer fb;
  for (std::size_t c = 0; c < channels.size(); ++c)
    fb.insert(channels[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(fb);
  file.writePixels(h);
}

// The data window's origin anywhere, also a billion pixels from (0, 0) (OpenEXR's limit is about
// 2^30). Its fuzz finding, that the loader's slice base for such a window was undefined pointer
// arithmetic (UBSan), is a seed of tools/fuzz.sh (tests/fuzz/make_seeds.py,
// builtin_far_origin.exr); without UBSan, the test below can only check that such a file is an
// error, not a crash.
TEST(EnvironmentLoad, ExrDataWindow) {
  const std::string path = temp_file("window.exr");
  const auto value = [](int x, int y, int c) {
    return float(x) + 10.0f * float(y) + 0.25f * float(c);
  };
  for (const Imath::V2i& origin : {Imath::V2i(-3, 5), Imath::V2i(1000000000, 1000000000),
                                   Imath::V2i(-1000000000, 500000000)}) {
    write_exr(path, 6, 4, value, {"R", "G", "B"}, origin);
    const wp::EnvironmentMap env = wp::load_environment(path);
    std::filesystem::remove(path);
    ASSERT_EQ(env.width, 6);
    ASSERT_EQ(env.height, 4);
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 6; ++x)
        for (int c = 0; c < 3; ++c)
          EXPECT_EQ(env.texels[std::size_t(y * 6 + x)][c], value(x, y, c))
              << x << " " << y << " origin " << origin.x << "," << origin.y;
  }
}

// An EXR whose header declares a data window far larger than the file holds, in the form the
// fuzzer found (tests/fuzz): a 6 x 2 RGB float image, one scanline per chunk (RLE), whose
// dataWindow attribute (box2i xMin, yMin, xMax, yMax, little-endian int32) is then patched to a
// wide x range; OpenEXR opens it, and the loader used to allocate width x 2 x 16 bytes (4 GiB
// for 2^28 texels, 537 MB for 2^25) before reading failed. Refused now before any allocation.
void write_wide_exr(const std::string& path, std::int32_t x_min, std::int32_t x_max,
                    std::int32_t y_min = 0, std::int32_t y_max = 1) {
  {
    Imf::Header header(6, 2);
    header.compression() = Imf::RLE_COMPRESSION;
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    std::vector<float> px(6 * 2 * 3, 1.0f);
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c)
      fb.insert(std::string(1, "RGB"[c]),
                Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px.data() + c), 12, 72));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(2);
  }
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
  const std::size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const std::size_t box = at + key.size() + 4;  // after the attribute's size field
  f.clear();
  f.seekp(static_cast<std::streamoff>(box));
  f.write(reinterpret_cast<const char*>(&x_min), 4);
  f.write(reinterpret_cast<const char*>(&y_min), 4);
  f.write(reinterpret_cast<const char*>(&x_max), 4);
  f.write(reinterpret_cast<const char*>(&y_max), 4);
}

TEST(EnvironmentLoad, ExrHugeDataWindowIsAnError) {
  for (const auto& [x_min, x_max] :
       {std::pair<std::int32_t, std::int32_t>{-(1 << 26), 1 << 26}, {-(1 << 24), 2}}) {
    const std::string path = temp_file("huge_window.exr");
    write_wide_exr(path, x_min, x_max);
    try {
      wp::load_environment(path);
      ADD_FAILURE() << "window columns " << x_min << ".." << x_max << " accepted";
    } catch (const wp::Error& e) {
      EXPECT_NE(std::string(e.what()).find("pixels"), std::string::npos) << e.what();
      std::cout << "  refused: " << e.what() << "\n";
    }
    std::filesystem::remove(path);
  }
}

// The fuzz finding of ExrDataWindow's comment in the form a test can write: a window 2 million
// pixels wide (allowed for a file this size: the header may be honest about a file cut short) at
// y = 10^9, over a file that holds 6 x 2 pixels. The loader allocates the row, sets OpenEXR's slice
// base (before the fix, pointer arithmetic far outside the row) and reports OpenEXR's failure to
// read it: one error, no crash.
TEST(EnvironmentLoad, ExrFarWindowOverMissingPixelsIsAnError) {
  const std::string path = temp_file("far_window.exr");
  write_wide_exr(path, 0, 1999999, 1000000000, 1000000000);
  try {
    wp::load_environment(path);
    ADD_FAILURE() << "accepted";
  } catch (const wp::Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read the EXR image"), std::string::npos)
        << e.what();
    std::cout << "  refused: " << e.what() << "\n";
  }
  std::filesystem::remove(path);
}

// An attribute stating more bytes than the file has (fuzzing: 1.6 GB in a 202-byte file, which
// OpenEXR allocated before reading) is refused by the header walk before OpenEXR sees the file.
TEST(EnvironmentLoad, ExrAttributeLongerThanTheFileIsAnError) {
  const std::string path = temp_file("long_attribute.exr");
  std::string bytes("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
  bytes += std::string("junk\0opaqueType\0", 16);
  bytes += std::string("\x00\x00\x00\x64", 4);  // 1677721600, little-endian
  bytes += std::string(85, 'x');
  std::ofstream(path, std::ios::binary) << bytes;
  try {
    wp::load_environment(path);
    ADD_FAILURE() << "accepted";
  } catch (const wp::Error& e) {
    EXPECT_EQ(std::string(e.what()), path +
                                         ": the EXR header is corrupt (an attribute states "
                                         "1677721600 bytes, 85 follow)");
  }
  // OpenEXR reads known types by their type, not their stated size: a channel list longer than
  // stated (fuzzing: then OpenEXR met a 1.9 GB attribute the walk never saw) and a fixed-size
  // value of another size are refused, so the walk and OpenEXR agree.
  const std::string head("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
  for (const auto& [attribute, cause] : std::vector<std::pair<std::string, std::string>>{
           {std::string("channels\0chlist\0\x12\0\0\0R\0", 21) + std::string(17, '\0'),
            "a channel list that does not end where its size says"},
           {std::string("compression\0compression\0\x02\0\0\0\0\0", 30),
            "a compression attribute of 2 bytes, not 1"}}) {
    std::ofstream(path, std::ios::binary) << head + attribute + std::string(64, '\0');
    try {
      wp::load_environment(path);
      ADD_FAILURE() << cause << ": accepted";
    } catch (const wp::Error& e) {
      EXPECT_NE(std::string(e.what()).find(cause), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove(path);
}

void expect_refused(const std::string& path, const std::string& why) {
  try {
    wp::load_environment(path);
    ADD_FAILURE() << why << ": " << path << " was accepted";
  } catch (const wp::Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    std::cout << "  refused (" << why << "): " << e.what() << "\n";
  }
}

TEST(EnvironmentLoad, Refusals) {
  expect_refused(temp_file("missing.hdr"), "missing .hdr");
  expect_refused(temp_file("missing.exr"), "missing .exr");
  const std::string text = temp_file("not_an_image.hdr"), text_exr = temp_file("not.exr");
  const std::string png = temp_file("image.png");
  for (const std::string& p : {text, text_exr, png}) std::ofstream(p) << "not an image\n";
  expect_refused(text, "garbage .hdr");
  expect_refused(text_exr, "garbage .exr");
  expect_refused(png, "unsupported extension");
  const std::string bad = temp_file("bad.exr");
  for (float v : {-1.0f, std::nanf(""), INFINITY}) {
    write_exr(bad, 4, 2,
              [v](int x, int y, int c) { return x == 2 && y == 1 && c == 1 ? v : 1.0f; });
    expect_refused(bad, "value " + std::to_string(v));
  }
  write_exr(bad, 4, 2, [](int, int, int) { return 1.0f; }, {"Y"});
  expect_refused(bad, "no RGB channels");
  for (const std::string& p : {text, text_exr, png, bad}) std::filesystem::remove(p);
  wp::EnvironmentMap empty;
  EXPECT_THROW(wp::build_environment_tables(empty), wp::Error);
}

// ---- Radiance RGBE: the bounded reader ---------------------------------------------------------

using Rgbe = std::array<unsigned char, 4>;

// The floats the loader must give for one RGBE pixel: m * 2^(e - 136), 0 when e = 0 (stb_image's
// convention, scenes/rgbe.py's decode). Exact in float: 8 mantissa bits times a power of two.
glm::vec3 rgbe_value(const Rgbe& p) {
  if (p[3] == 0) return glm::vec3(0.0f);
  const auto f = [&](int c) { return static_cast<float>(std::ldexp(double(p[c]), p[3] - 136)); };
  return {f(0), f(1), f(2)};
}

std::string hdr_header(int w, int h) {
  return "#?RADIANCE\n# made by test_environment\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n-Y " +
         std::to_string(h) + " +X " + std::to_string(w) + "\n";
}

// One new-style run-length scanline: 2, 2, width, then each channel as runs (3 or more equal
// bytes, count 128 + n) and literals (count n <= 128) between them.
std::string rle_scanline(const std::vector<Rgbe>& px) {
  const std::size_t w = px.size();
  std::string out = {2, 2, char(w >> 8), char(w & 255)};
  for (std::size_t c = 0; c < 4; ++c) {
    const auto run_at = [&](std::size_t x) {
      std::size_t n = 1;
      while (x + n < w && n < 127 && px[x + n][c] == px[x][c]) ++n;
      return n;
    };
    for (std::size_t x = 0; x < w;) {
      if (const std::size_t n = run_at(x); n >= 3) {
        out += char(128 + n);
        out += char(px[x][c]);
        x += n;
        continue;
      }
      const std::size_t start = x;
      while (x < w && x - start < 128 && run_at(x) < 3) ++x;
      out += char(x - start);
      for (std::size_t k = start; k < x; ++k) out += char(px[k][c]);
    }
  }
  return out;
}

// A 16 x 3 image with runs and literals in every channel, and a pixel with e = 0.
std::vector<Rgbe> rle_pixels(int w, int h) {
  std::vector<Rgbe> px;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      px.push_back({static_cast<unsigned char>(128 + (x / 4) * 8),
                    static_cast<unsigned char>((x * 37 + y * 11) % 256), 200,
                    static_cast<unsigned char>(x == 5 && y == 1 ? 0 : 120 + 4 * y)});
  return px;
}

std::string rle_file(int w, int h, const std::vector<Rgbe>& px) {
  std::string bytes = hdr_header(w, h);
  for (int y = 0; y < h; ++y)
    bytes += rle_scanline(std::vector<Rgbe>(px.begin() + y * w, px.begin() + (y + 1) * w));
  return bytes;
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void expect_exact(const wp::EnvironmentMap& env, int w, int h, const std::vector<Rgbe>& px) {
  ASSERT_EQ(env.width, w);
  ASSERT_EQ(env.height, h);
  ASSERT_EQ(env.texels.size(), px.size());
  for (std::size_t i = 0; i < px.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(env.texels[i][c], rgbe_value(px[i])[c]) << i << " " << c;
}

TEST(EnvironmentLoad, HdrRunLengthAndFlatDecodeExactly) {
  const std::string path = temp_file("exact.hdr");
  const std::vector<Rgbe> rle = rle_pixels(16, 3);
  write_file(path, rle_file(16, 3, rle));
  expect_exact(wp::load_environment(path), 16, 3, rle);
  // Flat scanlines: required below 8 pixels wide, and what scenes/rgbe.py writes at any width.
  for (const int w : {5, 12}) {
    const std::vector<Rgbe> flat = rle_pixels(w, 2);
    std::string bytes = hdr_header(w, 2);
    for (const Rgbe& p : flat) bytes.append(p.begin(), p.end());
    write_file(path, bytes);
    expect_exact(wp::load_environment(path), w, 2, flat);
  }
  std::filesystem::remove(path);
}

// Runs `body` on a thread and fails the whole test program if it takes more than a minute: the
// reader it checks used to loop forever, and a hang must show as a failure, not a stuck test.
void within_a_minute(const std::function<void()>& body) {
  auto done = std::async(std::launch::async, body);
  if (done.wait_for(std::chrono::seconds(60)) == std::future_status::timeout) {
    std::fprintf(stderr, "FAILED: the HDR reader hangs\n");
    std::_Exit(1);
  }
  done.get();
}

// Expects load_environment to throw wp::Error naming the file and `needle`, all on one line.
void expect_hdr_error(const std::string& path, const std::string& bytes, const std::string& needle,
                      const std::string& what) {
  write_file(path, bytes);
  try {
    wp::load_environment(path);
    ADD_FAILURE() << what << ": accepted";
  } catch (const wp::Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << what << ": " << message;
    EXPECT_NE(message.find(needle), std::string::npos) << what << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << what << ": " << message;
  }
}

TEST(EnvironmentLoad, HdrTruncatedAtEveryByteIsAnError) {
  const std::string path = temp_file("truncated.hdr");
  const std::string bytes = rle_file(16, 3, rle_pixels(16, 3));
  within_a_minute([&] {
    for (std::size_t n = 0; n < bytes.size(); ++n)
      expect_hdr_error(path, bytes.substr(0, n), "", "truncated to " + std::to_string(n));
    // Cut inside the second scanline's run-length data: the message names it.
    expect_hdr_error(path, bytes.substr(0, bytes.size() - 30), "truncated in scanline 2 of 3",
                     "cut in scanline 2");
  });
  std::filesystem::remove(path);
}

TEST(EnvironmentLoad, HdrCorruptRunsAndHeadersAreErrors) {
  const std::string path = temp_file("corrupt.hdr");
  const std::string good = rle_file(16, 3, rle_pixels(16, 3));
  const std::size_t data = hdr_header(16, 3).size();  // scanline 0: 2, 2, 0, 16, then channel R
  const auto patched = [&](std::size_t at, char value) {
    std::string b = good;
    b[at] = value;
    return b;
  };
  within_a_minute([&] {
    expect_hdr_error(path, patched(data + 4, char(128 + 17)), "scanline 0: run of 17",
                     "run past the width");
    expect_hdr_error(path, patched(data + 4, 17), "scanline 0: literal of 17", "literal past");
    expect_hdr_error(path, patched(data + 4, 0), "scanline 0: zero-length run", "zero run");
    expect_hdr_error(path, patched(data + 3, 15), "run-length width 15", "width mismatch");
    const std::string pixels = good.substr(data);
    const std::vector<std::pair<std::string, std::string>> headers = {
        {"#?JPEG\nFORMAT=32-bit_rle_rgbe\n\n-Y 3 +X 16\n", "signature"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 3 +X 16\n", "FORMAT=32-bit_rle_xyze"},
        {"#?RADIANCE\n\n-Y 3 +X 16\n", "no FORMAT"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", "truncated in the header"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n", "truncated in the resolution line"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 3 +X 16\n", "resolution line"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 16\n", "resolution line"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 3 +X -16\n", "resolution line"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 3 +X 16x\n", "resolution line"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 99999 +X 99999\n", "more than the 2^28"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 9999999999 +X 9999999999\n", "2^28"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16384 +X 16384\n", "too short"}};
    for (const auto& [header, needle] : headers)  // a truncated header ends the file
      expect_hdr_error(path, header + (needle.rfind("truncated", 0) == 0 ? "" : pixels), needle,
                       header);
  });
  std::filesystem::remove(path);
}

// ---- Tables -----------------------------------------------------------------------------------

TEST(EnvironmentTables, ConstantMapMeanAndCdfs) {
  const glm::vec3 c(1.0f, 2.0f, 4.0f);
  const wp::EnvironmentMap env = make_map(8, 4, [&](int, int) { return c; });
  EXPECT_NEAR(env.mean_luminance, 0.2126 * 1 + 0.7152 * 2 + 0.0722 * 4, 1e-12);
  EXPECT_EQ(env.marginal.front(), 0.0f);
  EXPECT_EQ(env.marginal.back(), 1.0f);
  // Rows weigh with sin(theta_c): the marginal is symmetric about the equator.
  EXPECT_NEAR(env.marginal[2], 0.5f, 1e-7f);
  const double s1 = std::sin(kPi / 8), s2 = std::sin(3 * kPi / 8);
  EXPECT_NEAR(env.marginal[1], s1 / (2 * (s1 + s2)), 1e-7);
  for (int x = 0; x <= 8; ++x) EXPECT_NEAR(env.conditional[std::size_t(9 + x)], x / 8.0, 1e-7);
}

TEST(EnvironmentTables, BlackRowsAndBlackMap) {
  const wp::EnvironmentMap rows =
      make_map(4, 4, [](int x, int y) { return glm::vec3(y == 1 ? 0.0f : float(x + 1)); });
  EXPECT_EQ(rows.marginal[1], rows.marginal[2]);  // the black row is never chosen
  EXPECT_EQ(rows.conditional[5 + 4], 1.0f);       // ... but its row table is well-defined
  const wp::EnvironmentMap black = make_map(4, 2, [](int, int) { return glm::vec3(0.0f); });
  EXPECT_EQ(black.mean_luminance, 0.0);
  for (float m : black.marginal) EXPECT_EQ(m, 0.0f);
  // The light table then gives the environment no light at all (no power, never picked).
  wp::Scene scene;
  const wp::LightTable none =
      wp::build_light_table(scene, &black, glm::vec3(1.0f), 1.0f, wp::LightSelect::kPower);
  EXPECT_EQ(none.env_light, WP_NO_LIGHT);
  const wp::LightTable some =
      wp::build_light_table(scene, &rows, glm::vec3(0.0f), 1.0f, wp::LightSelect::kPower);
  EXPECT_NE(some.env_light, WP_NO_LIGHT);
}

// ---- Device: the direction convention ---------------------------------------------------------

// A 9 x 5 map whose texel (x, y) holds (x, y, 1): odd sizes put -Z and the equator at texel
// centres.
wp::EnvironmentMap index_map() {
  return make_map(9, 5, [](int x, int y) { return glm::vec3(float(x), float(y), 1.0f); });
}

TEST_F(Environment, NamedDirections) {
  const wp::EnvironmentMap env = index_map();
  struct Case {
    double degrees;
    glm::vec3 dir;
    int x, y;  // x < 0: any column (a pole)
  };
  // u = (atan2(x, -z) + pi) / (2 pi): -Z -> 0.5 (column 4), +X -> 0.75 (6), -X -> 0.25 (2);
  // v = theta / pi: the equator is row 2, +Y row 0, -Y row 4. Turned by 90 degrees
  // (counter-clockwise seen from above), the map shows at -X what it showed at -Z, at -Z what it
  // showed at +X, and at +Z what it showed at -X.
  const std::vector<Case> cases = {
      {0, {0, 0, -1}, 4, 2},  {0, {1, 0, 0}, 6, 2},   {0, {-1, 0, 0}, 2, 2},
      {0, {0, 1, 0}, -1, 0},  {0, {0, -1, 0}, -1, 4}, {90, {-1, 0, 0}, 4, 2},
      {90, {0, 0, -1}, 6, 2}, {90, {0, 0, 1}, 2, 2},  {90, {0, 1, 0}, -1, 0}};
  for (const Case& c : cases) {
    DeviceEnv e(*kernels_, &env, 2.0f, c.degrees);
    const float4 r = eval(*kernels_, e, {c.dir})[0];
    const std::string where = "rotation " + std::to_string(c.degrees) + " dir " +
                              std::to_string(c.dir.x) + "," + std::to_string(c.dir.y) + "," +
                              std::to_string(c.dir.z);
    if (c.x >= 0) {
      EXPECT_EQ(r.x, 2.0f * float(c.x)) << where;
    }
    EXPECT_EQ(r.y, 2.0f * float(c.y)) << where;
    EXPECT_EQ(r.z, 2.0f) << where;
  }
}

// Random directions against the host reference: radiance = intensity x the texel of map_uv, and
// env_pdf = P(row) P(column | row) W H / (2 pi^2 sin theta) from the tables.
TEST_F(Environment, RandomDirectionsMatchHostReference) {
  const wp::EnvironmentMap env = make_map(23, 11, [](int x, int y) {
    return glm::vec3(float(x + 1), float(y * y), float((x * y) % 5));
  });
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  std::vector<glm::vec3> dirs(4096);
  for (auto& d : dirs) d = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
  for (double degrees : {0.0, 37.0, -150.0}) {
    DeviceEnv e(*kernels_, &env, 0.5f, degrees);
    const std::vector<float4> out = eval(*kernels_, e, dirs);
    int checked = 0;
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      const glm::dvec2 uv = map_uv(dirs[i], degrees);
      const double fx = uv.x * env.width, fy = uv.y * env.height;
      if (std::fabs(fx - std::round(fx)) < 1e-4 || std::fabs(fy - std::round(fy)) < 1e-4) continue;
      const int x = std::min(int(fx), env.width - 1), y = std::min(int(fy), env.height - 1);
      const glm::vec4 t = env.texels[std::size_t(y * env.width + x)] * 0.5f;
      EXPECT_EQ(glm::vec3(out[i].x, out[i].y, out[i].z), glm::vec3(t)) << i << " at " << degrees;
      const std::size_t row = std::size_t(y) * std::size_t(env.width + 1) + std::size_t(x);
      const double p = double(env.marginal[std::size_t(y) + 1] - env.marginal[std::size_t(y)]) *
                       double(env.conditional[row + 1] - env.conditional[row]);
      const double pdf = p * env.width * env.height / (2 * kPi * kPi * std::sin(kPi * uv.y));
      EXPECT_NEAR(out[i].w, pdf, 1e-5 * pdf) << i << " at " << degrees;
      ++checked;
    }
    EXPECT_GT(checked, 4000);
  }
}

struct Draws {
  std::vector<float4> dir_pdf, radiance_pdf;
};

Draws draw(wp::test::KernelHarness& k, DeviceEnv& e, std::uint32_t n, std::uint32_t seed) {
  cl::Buffer a = k.buffer<float4>(n), b = k.buffer<float4>(n);
  k.run("env_draw", n, e.desc, e.texels, e.marginal, e.conditional, n, seed, a, b);
  return {k.read<float4>(a, n), k.read<float4>(b, n)};
}

TEST_F(Environment, ConstantBackgroundAndFeatureOff) {
  const std::vector<glm::vec3> dirs = {{0, 0, -1}, {0, 1, 0}, {0.6f, 0, 0.8f}};
  DeviceEnv none(*kernels_, nullptr, 1.0f, 0.0);
  const wp::EnvironmentMap env = index_map();
  wp::test::KernelHarness off({"environment_kernels.cl"}, "-D WP_FEATURE_ENVIRONMENT=0");
  DeviceEnv ignored(off, &env, 2.0f, 0.0);  // compiled out: the map is not looked at
  for (const auto& out : {eval(*kernels_, none, dirs), eval(off, ignored, dirs)})
    for (const float4& r : out) {
      EXPECT_EQ(r.x, 0.25f);
      EXPECT_EQ(r.y, 0.5f);
      EXPECT_EQ(r.z, 0.75f);
      EXPECT_FLOAT_EQ(r.w, float(1.0 / (4.0 * kPi)));
    }
}

TEST_F(Environment, BlackMapSamplesNothing) {
  const wp::EnvironmentMap black = make_map(8, 4, [](int, int) { return glm::vec3(0.0f); });
  DeviceEnv e(*kernels_, &black, 1.0f, 0.0);
  const Draws s = draw(*kernels_, e, 1024, 1);
  for (std::size_t i = 0; i < s.dir_pdf.size(); ++i) {
    EXPECT_EQ(s.dir_pdf[i].w, 0.0f);
    EXPECT_EQ(s.radiance_pdf[i].x + s.radiance_pdf[i].y + s.radiance_pdf[i].z, 0.0f);
  }
  for (const float4& r : eval(*kernels_, e, {{0, 0, -1}, {0.6f, 0, 0.8f}})) EXPECT_EQ(r.w, 0.0f);
}

// ---- Device: sampling -------------------------------------------------------------------------

constexpr std::uint32_t kBinsZ = 32, kBinsPhi = 64;

std::size_t bin_of(const float4& d) {
  const double z = std::clamp(double(d.y), -1.0, 1.0);
  const double phi = std::atan2(double(d.x), -double(d.z));
  const auto iz = std::min<std::size_t>(kBinsZ - 1, std::size_t((1.0 - z) / 2.0 * kBinsZ));
  const auto ip =
      std::min<std::size_t>(kBinsPhi - 1, std::size_t((phi + kPi) / (2 * kPi) * kBinsPhi));
  return iz * kBinsPhi + ip;
}

// env_pdf integrated over each bin on the device (exact for the piecewise-constant density, see
// the kernel). Their sum is 1 up to float rounding: each piece carries a few float operations of
// relative error ~1e-7 and the per-bin sums are compensated, so 1e-5 is 10x that bound.
std::vector<double> bin_probabilities(wp::test::KernelHarness& k, DeviceEnv& e) {
  const std::uint32_t bins = kBinsZ * kBinsPhi;
  cl::Buffer out = k.buffer<float>(bins);
  k.run("env_integrate_bins", bins, e.desc, e.texels, e.marginal, e.conditional, kBinsZ, kBinsPhi,
        out);
  const std::vector<float> f = k.read<float>(out, bins);
  std::vector<double> p(f.begin(), f.end());
  double total = 0.0;
  for (double x : p) total += x;
  EXPECT_NEAR(total, 1.0, 1e-5) << "env_pdf does not integrate to 1";
  std::cout << "  integral of env_pdf over the sphere: 1 " << std::showpos << total - 1.0
            << std::noshowpos << "\n";
  return p;
}

// env_pdf(dir) must equal the pdf env_sample returned. A direction's round trip through
// sin/cos/atan2 (and the rotation) can move it across a texel edge by ~1e-7 in u or v (more near
// a pole, where u is ill-conditioned); only such samples may differ.
void check_pdf_agreement(const wp::EnvironmentMap& env, double degrees, const Draws& s) {
  std::size_t differ = 0, off_edge = 0;
  for (std::size_t i = 0; i < s.dir_pdf.size(); ++i) {
    const float pdf = s.dir_pdf[i].w, again = s.radiance_pdf[i].w;
    if (!(pdf > 0.0f) || std::fabs(again - pdf) <= 1e-4f * pdf) continue;
    ++differ;
    const glm::dvec3 d(s.dir_pdf[i].x, s.dir_pdf[i].y, s.dir_pdf[i].z);
    const glm::dvec2 uv = map_uv(d, degrees);
    const double sin_theta = std::max(1e-6, std::sin(kPi * uv.y));
    const double du = std::fabs(uv.x * env.width - std::round(uv.x * env.width)) / env.width;
    const double dv = std::fabs(uv.y * env.height - std::round(uv.y * env.height)) / env.height;
    if (du > 2e-6 / sin_theta && dv > 2e-6) ++off_edge;
  }
  EXPECT_EQ(off_edge, 0u) << "env_pdf disagrees with env_sample away from texel edges";
  EXPECT_LT(double(differ), 1e-3 * double(s.dir_pdf.size()));
  std::cout << "  pdf agreement: " << differ << " of " << s.dir_pdf.size()
            << " samples differ, all at texel edges\n";
}

// The mean of radiance / pdf estimates the integral of the radiance over the sphere, which for
// the nearest-texel map is the sum of texel x intensity x texel solid angle, and for the bilinear
// map bilinear_integral (the known answer of the bilinear tests). The tolerance is 5 standard
// errors of the mean, the standard error estimated from the samples' own variance (2^21 samples:
// the estimate of it is good to ~0.1%, the normal approximation holds).
void check_estimator(const wp::EnvironmentMap& env, float intensity, const Draws& s) {
  glm::dvec3 exact(0.0);
  if (env.filter == wp::EnvFilter::kBilinear)
    exact = bilinear_integral(env);
  else
    for (int y = 0; y < env.height; ++y)
      for (int x = 0; x < env.width; ++x)
        exact += glm::dvec3(env.texels[std::size_t(y * env.width + x)]) * texel_solid_angle(env, y);
  exact *= double(intensity);
  glm::dvec3 sum(0.0), sum2(0.0);
  for (std::size_t i = 0; i < s.dir_pdf.size(); ++i) {
    const double pdf = s.dir_pdf[i].w;
    const glm::dvec3 l(s.radiance_pdf[i].x, s.radiance_pdf[i].y, s.radiance_pdf[i].z);
    const glm::dvec3 v = pdf > 0.0 ? l / pdf : glm::dvec3(0.0);
    sum += v;
    sum2 += v * v;
  }
  const double n = double(s.dir_pdf.size());
  for (int c = 0; c < 3; ++c) {
    const double mean = sum[c] / n, se = std::sqrt(std::max(0.0, sum2[c] / n - mean * mean) / n);
    EXPECT_NEAR(mean, exact[c], 5.0 * se) << "channel " << c << " (standard error " << se << ")";
    std::cout << "  estimator channel " << c << ": " << mean << " vs " << exact[c] << " ("
              << (mean - exact[c]) / se << " standard errors)\n";
  }
}

void check_sampling(wp::test::KernelHarness& k, const wp::EnvironmentMap& env, float intensity,
                    double degrees, std::uint32_t n) {
  DeviceEnv e(k, &env, intensity, degrees);
  const std::vector<double> p = bin_probabilities(k, e);
  const Draws s = draw(k, e, n, 12345u);
  std::vector<double> observed(p.size(), 0.0), expected(p.size());
  for (const float4& d : s.dir_pdf) observed[bin_of(d)] += 1.0;
  for (std::size_t b = 0; b < p.size(); ++b) expected[b] = p[b] * double(n);
  const wp::test::Chi2Result r = wp::test::chi2_test(observed, expected);
  EXPECT_GT(r.p_value, 1e-4) << r.detail;
  std::cout << "  chi-square: " << r.detail << "\n";
  check_pdf_agreement(env, degrees, s);
  check_estimator(env, intensity, s);
}

// A sky gradient (brighter up and toward +u) with a 2 x 2 texel sun about 10^4 times brighter.
TEST_F(Environment, SamplingSunAndGradient) {
  const wp::EnvironmentMap env = make_map(64, 32, [](int x, int y) {
    if ((x == 40 || x == 41) && (y == 9 || y == 10)) return glm::vec3(2000.0f, 1800.0f, 1500.0f);
    const float g = (1.2f - float(y) / 32.0f) * (0.5f + float(x) / 64.0f);
    return glm::vec3(0.4f * g, 0.6f * g, g);
  });
  check_sampling(*kernels_, env, 1.5f, 0.0, 1u << 21);
}

// Odd sizes, a rotation, a black band at the bottom and a black row in the middle, a one-texel
// sun next to the pole.
TEST_F(Environment, SamplingRotatedWithBlackRows) {
  const wp::EnvironmentMap env = make_map(90, 45, [](int x, int y) {
    if (y >= 40 || y == 20) return glm::vec3(0.0f);
    if (x == 70 && y == 2) return glm::vec3(1e4f);
    return glm::vec3(0.1f + float(x % 9), 1.0f, 0.5f + float(y) / 45.0f);
  });
  check_sampling(*kernels_, env, 0.7f, 123.0, 1u << 21);
}

TEST_F(Environment, SamplingRealMap) {
  const std::filesystem::path path =
      std::filesystem::path(wp::test::assets_dir()) / "env" / "spiaggia_di_mondello_1k.hdr";
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << "asset not found: " << path;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const wp::EnvironmentMap env = wp::load_environment(path.string());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "  loaded " << env.width << " x " << env.height << " with tables in " << seconds
            << " s\n";
  check_sampling(*kernels_, env, 1.0f, 30.0, 1u << 21);
}

// ---- Bilinear lookup (--env-filter bilinear) --------------------------------------------------

// Random directions, directions across the u seam (u near 0 and 1: looking down +Z, x of either
// sign) and near both poles, against bilinear_at. The kernel works in float: u and v carry a
// relative error of a few 1e-7, i.e. fx, fy within ~1e-5 of a texel for these sizes, so the
// lookup may differ from the float64 one by that times the largest step between neighbours
// (< 30 here), times the intensity: 1e-3 absolute is ~3x that bound.
TEST_F(Environment, BilinearMatchesHostReference) {
  const wp::EnvironmentMap env = make_map(
      23, 11,
      [](int x, int y) { return glm::vec3(float(x + 1), float(y * y), float((x * y) % 5)); },
      wp::EnvFilter::kBilinear);
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec3> dirs(4096);
  for (auto& d : dirs) d = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
  for (int i = 0; i < 512; ++i) {  // the seam: x of either sign close to 0, z > 0
    const float y = unit(rng), x = 1e-3f * unit(rng);
    dirs.push_back(glm::normalize(glm::vec3(x, y, 1.0f)));
  }
  for (int i = 0; i < 512; ++i) {  // within a texel of either pole (a row spans 16 degrees)
    const float r = 0.2f * std::fabs(unit(rng)), a = 3.1415926f * unit(rng);
    dirs.push_back(
        glm::normalize(glm::vec3(r * std::cos(a), i % 2 ? 1.0f : -1.0f, r * std::sin(a))));
  }
  for (double degrees : {0.0, 37.0, -150.0}) {
    DeviceEnv e(*bilinear_, &env, 0.5f, degrees);
    const std::vector<float4> out = eval(*bilinear_, e, dirs);
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      const glm::dvec2 uv = map_uv(dirs[i], degrees);
      const glm::dvec3 ref = 0.5 * bilinear_at(env, uv.x, uv.y);
      EXPECT_NEAR(out[i].x, ref.x, 1e-3) << i << " at " << degrees;
      EXPECT_NEAR(out[i].y, ref.y, 1e-3) << i << " at " << degrees;
      EXPECT_NEAR(out[i].z, ref.z, 1e-3) << i << " at " << degrees;
    }
  }
}

// The bilinear tables: a black texel whose 3 x 3 neighbourhood holds a bright one has the bright
// one's weight (it sees some of its light), a texel two away from any light has none.
TEST(EnvironmentTables, BilinearTablesCoverNeighbours) {
  const wp::EnvironmentMap env = make_map(
      8, 4, [](int x, int y) { return glm::vec3(x == 0 && y == 1 ? 1.0f : 0.0f); },
      wp::EnvFilter::kBilinear);
  const auto p = [&](int x, int y) {
    const std::size_t r = std::size_t(y) * 9 + std::size_t(x);
    return (env.marginal[std::size_t(y) + 1] - env.marginal[std::size_t(y)]) *
           (env.conditional[r + 1] - env.conditional[r]);
  };
  for (int y : {0, 1, 2})
    for (int x : {7, 0, 1}) EXPECT_GT(p(x, y), 0.0f) << x << ", " << y;  // across the seam too
  EXPECT_EQ(p(2, 1), 0.0f);
  EXPECT_EQ(p(0, 3), 0.0f);
}

// Sampling with the bilinear tables: chi-square of the directions against env_pdf, env_pdf against
// the pdf returned, and the estimator against the bilinear map's integral (check_estimator).
TEST_F(Environment, BilinearSamplingSunAndGradient) {
  const wp::EnvironmentMap env = make_map(
      64, 32,
      [](int x, int y) {
        if ((x == 40 || x == 41) && (y == 9 || y == 10))
          return glm::vec3(2000.0f, 1800.0f, 1500.0f);
        const float g = (1.2f - float(y) / 32.0f) * (0.5f + float(x) / 64.0f);
        return glm::vec3(0.4f * g, 0.6f * g, g);
      },
      wp::EnvFilter::kBilinear);
  check_sampling(*bilinear_, env, 1.5f, 0.0, 1u << 21);
}

// Black bands and rows, a one-texel sun next to the pole and on the seam: the texels next to them
// must be sampled (else the estimator would miss their light and fail the known integral).
TEST_F(Environment, BilinearSamplingBlackRowsSeamAndPole) {
  const wp::EnvironmentMap env = make_map(
      90, 45,
      [](int x, int y) {
        if (y >= 40 || y == 20) return glm::vec3(0.0f);
        if ((x == 70 || x == 0) && y == 0) return glm::vec3(1e4f);
        if (x == 89 && y == 30) return glm::vec3(3e3f);
        return glm::vec3(0.1f + float(x % 9), 1.0f, 0.5f + float(y) / 45.0f);
      },
      wp::EnvFilter::kBilinear);
  check_sampling(*bilinear_, env, 0.7f, 123.0, 1u << 21);
}

// Single bright texels on black (on the seam, on the top row, in the middle): bilinear lookup
// spreads each over a 2 x 2 texel area, and only (3/4)^2 = 56% of its light falls on its own
// texel. Tables that gave the black neighbours no probability would miss the other 44% (the
// estimator check fails by ~2000 standard errors then: measured by building nearest tables
// for the bilinear kernel); the 3 x 3 tables sample all of it.
TEST_F(Environment, BilinearSamplingIsolatedTexels) {
  const wp::EnvironmentMap env = make_map(
      32, 16,
      [](int x, int y) {
        if (x == 0 && y == 7) return glm::vec3(50.0f, 40.0f, 30.0f);
        if (x == 13 && y == 0) return glm::vec3(20.0f);
        if (x == 20 && y == 10) return glm::vec3(5.0f, 10.0f, 15.0f);
        return glm::vec3(0.0f);
      },
      wp::EnvFilter::kBilinear);
  check_sampling(*bilinear_, env, 1.0f, 10.0, 1u << 20);
}

}  // namespace
