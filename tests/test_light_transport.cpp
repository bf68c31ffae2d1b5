// scene tier (its furnaces: energy): the light transport as a whole - energy conservation,
// agreement of the sampling strategies, and a closed-form area-light answer - on the default
// OpenCL device.
//
// Tolerances come from the renderer's own variance estimate: every render returns, per pixel,
// the sample variance of its samples divided by the sample count (the variance of the pixel's
// estimate). Differences are turned into z-scores with it; a test fails when the mean of z^2 is
// not 1 within 5 sqrt(2/N) (the spread of a chi-square mean over N independent values), or when
// one |z| exceeds 6 (N <= ~3000 values: a false alarm has probability < 1e-5). Where a pixel's
// estimate has heavy tails (BSDF sampling that finds a light rarely), values are summed over
// pixel blocks first, which brings them close to Gaussian.
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "host/device/cl_runtime.h"
#include "host/device/device_scene.h"
#include "host/lights/environment.h"
#include "host/film/image_io.h"
#include "host/lights/light_table.h"
#include "host/render/render.h"
#include "host/device/scene_features.h"
#include "tests/device_test.h"
#include "tests/scene_factory.h"

namespace {

using glm::dvec3;
using glm::vec3;

class LightTransport : public wp::test::DeviceTest {
 public:  // render is used by the free helpers below too
  static wp::Rendered render(const wp::Scene& s, const wp::RenderSettings& st) {
    wp::Rendered r = wp::render(*runtime_, s, st);
    EXPECT_EQ(r.report.nonfinite_samples, 0u) << "NaN/Inf reached the film";
    return r;
  }
};

struct ZStats {
  double mean_z2 = 0.0, worst = 0.0;
  int n = 0;
};

// z-scores of a - b over pixel blocks of `block` x `block`, from both renders' variances.
ZStats compare(const wp::Rendered& a, const wp::Rendered& b, int block) {
  ZStats z;
  const int w = a.image.width, h = a.image.height;
  for (int by = 0; by + block <= h; by += block)
    for (int bx = 0; bx + block <= w; bx += block)
      for (int c = 0; c < 3; ++c) {
        double d = 0.0, var = 0.0;
        for (int y = by; y < by + block; ++y)
          for (int x = bx; x < bx + block; ++x) {
            const std::size_t i = 3 * (std::size_t(y) * w + x) + c;
            d += a.image.rgb[i] - b.image.rgb[i];
            var += a.variance.rgb[i] + b.variance.rgb[i];
          }
        if (var <= 0.0) {
          EXPECT_EQ(d, 0.0) << "block (" << bx << "," << by << ") differs with zero variance";
          continue;
        }
        const double zz = d / std::sqrt(var);
        z.mean_z2 += zz * zz;
        z.worst = std::max(z.worst, std::fabs(zz));
        ++z.n;
      }
  if (z.n) z.mean_z2 /= z.n;
  return z;
}

void expect_agree(const wp::Rendered& a, const wp::Rendered& b, int block, const char* what) {
  if (std::getenv("WP_DEBUG")) {
    wp::write_images({std::string("/tmp/dbg/") + what + "_a.exr"}, a.image, {});
    wp::write_images({std::string("/tmp/dbg/") + what + "_b.exr"}, b.image, {});
  }
  const ZStats z = compare(a, b, block);
  ASSERT_GT(z.n, 50) << what;
  EXPECT_NEAR(z.mean_z2, 1.0, 5.0 * std::sqrt(2.0 / z.n)) << what << ", worst |z| " << z.worst;
  EXPECT_LT(z.worst, 6.0) << what;
}

// Renders s with MIS, NEE alone and BSDF sampling alone (different seeds) and expects every pair
// to agree within their standard errors, over 4 x 4 pixel blocks.
void expect_strategies_agree(const wp::Scene& s, wp::RenderSettings st, const std::string& what) {
  const wp::Strategy strategies[3] = {wp::Strategy::kMis, wp::Strategy::kNee, wp::Strategy::kBsdf};
  const char* names[3] = {"MIS", "NEE", "BSDF"};
  std::vector<wp::Rendered> r;
  for (int k = 0; k < 3; ++k) {
    st.strategy = strategies[k];
    st.seed = static_cast<std::uint32_t>(k);
    r.push_back(LightTransport::render(s, st));
  }
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      expect_agree(r[a], r[b], 4, (what + names[a] + " vs " + names[b]).c_str());
}

struct FurnaceCase {
  const char* name;
  bool cube, volume;
};
void PrintTo(const FurnaceCase& c, std::ostream* os) {
  *os << c.name;
}

class Furnace : public LightTransport, public ::testing::WithParamInterface<FurnaceCase> {};

// Smooth glass (transmission 1, ior 1.5, base colour 1) in a constant background of 1: every path
// carries weight exactly 1 (reflection F / F, refraction (1 - F) / (1 - F) with the radiance
// scaling 1/eta^2 undone on the way out), so without Russian roulette every pixel is 1 up to float
// rounding. Two shapes, with flat normals so shading and geometry agree:
// - a cube: inside it, reflection keeps the direction cosines, so a ray meets the faces parallel
//   to its entry face below the critical angle and leaves within a few bounces: exact;
// - a faceted sphere: a facet can tilt a ray inside past the critical angle, and total internal
//   reflection can then keep it circling for hundreds of bounces. At max_depth 1000 such paths
//   are cut: measured, 3 of 55296 samples (5e-5) in this view. The test allows 1e-4 of the image.
// With roulette the image stays exact (see below).
TEST_P(Furnace, SmoothGlassIsInvisible) {
  const FurnaceCase& fc = GetParam();
  wp::Scene s;
  s.materials.push_back(wp::test::glass_material(fc.volume));
  if (fc.cube)
    wp::test::add_cube(s, {0, 0, 0}, 0.7f, 0.6f, 0);
  else
    wp::test::add_sphere(s, {0, 0, 0}, 1.0f, 48, 96, 0, /*flat=*/true);
  wp::test::finish_bounds(s);
  s.cameras.push_back(wp::test::look_at({0, 0, 3.5f}, {0, 0, 0}, 0.8f));
  wp::RenderSettings st;
  st.width = 48;
  st.height = 36;
  st.spp = 32;
  st.background = vec3(1.0f);
  st.max_depth = 1000;
  st.rr_depth = 1000;  // no roulette
  const wp::Rendered exact = render(s, st);
  double sum = 0.0;
  for (float v : exact.image.rgb) {
    ASSERT_LE(v, 1.0f + 1e-4f);
    if (fc.cube || !fc.volume) {
      ASSERT_NEAR(v, 1.0f, 1e-4f);
    }
    sum += v;
  }
  EXPECT_GE(sum / static_cast<double>(exact.image.rgb.size()), 1.0 - 1e-4);

  // Roulette from the first bounce on: survival is max(throughput) x eta scale (the 1/eta^2 of
  // refraction divided out), which is 1 for white smooth glass, thin or with a volume, so roulette
  // never ends a path and the image is the exact one up to float rounding. (Before the eta scale,
  // paths inside volume glass were ended for the 1/eta^2 they carried: unbiased, but noisy.)
  st.rr_depth = 1;
  const wp::Rendered rr = render(s, st);
  for (std::size_t i = 0; i < rr.image.rgb.size(); ++i)
    ASSERT_NEAR(rr.image.rgb[i], exact.image.rgb[i], 1e-4f) << "value " << i;
}

INSTANTIATE_TEST_SUITE_P(Glass, Furnace,
                         ::testing::Values(FurnaceCase{"ThinWalledCube", true, false},
                                           FurnaceCase{"VolumeCube", true, true},
                                           FurnaceCase{"ThinWalledSphere", false, false},
                                           FurnaceCase{"VolumeSphere", false, true}),
                         [](const auto& p) { return std::string(p.param.name); });

// A glossy floor, a diffuse sphere and an emissive quad under a constant sky: both lights can be
// found by both strategies, so MIS, NEE-only and BSDF-only must agree, and roulette must not
// change the answer.
wp::Scene agreement_scene() {
  wp::Scene s;
  wp::Material floor;
  floor.base_color = glm::vec4(0.8f, 0.7f, 0.6f, 1.0f);
  floor.metallic = 0.3f;
  floor.roughness = 0.35f;
  s.materials.push_back(floor);
  s.materials.push_back(wp::test::diffuse_material(vec3(0.3f, 0.5f, 0.8f)));
  wp::Material lamp = wp::test::diffuse_material(vec3(0.0f), false);
  lamp.emission = {4.0f, 3.5f, 3.0f};
  s.materials.push_back(lamp);
  wp::test::add_quad(s, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, 0);
  wp::test::add_sphere(s, {-0.4f, 0.5f, 0.0f}, 0.5f, 24, 48, 1);
  // Facing down: counter-clockwise seen from below.
  wp::test::add_quad(s, {0.0f, 1.4f, -0.6f}, {1.0f, 1.4f, -0.6f}, {1.0f, 1.4f, 0.4f},
                     {0.0f, 1.4f, 0.4f}, 2);
  wp::test::finish_bounds(s);
  s.cameras.push_back(wp::test::look_at({0.5f, 1.8f, 3.5f}, {0.0f, 0.4f, 0.0f}, 0.9f));
  return s;
}

wp::RenderSettings agreement_settings() {
  wp::RenderSettings st;
  // The z-scores below take each pixel's error variance from the film's variance image, which is
  // what it is for independent samples only; the Sobol' pattern is tested in tests/test_rng.cpp
  // and against known answers in tests/test_render_known.cpp.
  st.sampler = wp::Sampler::kIndependent;
  st.width = 48;
  st.height = 36;
  st.spp = 256;
  st.background = {0.2f, 0.25f, 0.3f};
  st.max_depth = 8;
  return st;
}

// A small equirectangular sky (host/lights/environment.h's convention): a gradient from 0.1 at the
// horizon to 0.4 at the zenith, dark below, and a broad bright "sun" (15 degrees, radiance 6)
// that BSDF sampling still finds often enough for its estimate to be close to Gaussian per block.
std::shared_ptr<const wp::EnvironmentMap> test_sky() {
  auto env = std::make_shared<wp::EnvironmentMap>();
  env->width = 64;
  env->height = 32;
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.6, 0.7, -0.4));
  for (int y = 0; y < env->height; ++y)
    for (int x = 0; x < env->width; ++x) {
      const double theta = M_PI * (y + 0.5) / env->height;
      const double phi = 2.0 * M_PI * (x + 0.5) / env->width - M_PI;
      const glm::dvec3 d(std::sin(theta) * std::sin(phi), std::cos(theta),
                         -std::sin(theta) * std::cos(phi));
      double l = d.y > 0.0 ? 0.1 + 0.3 * d.y : 0.02;
      if (glm::dot(d, sun) > std::cos(15.0 * M_PI / 180.0)) l += 6.0;
      env->texels.emplace_back(static_cast<float>(l), static_cast<float>(0.9 * l),
                               static_cast<float>(0.8 * l), 0.0f);
    }
  wp::build_environment_tables(*env);
  return env;
}

// A scene whose materials have no specular layer (metallic 0, KHR_materials_specular factor 0)
// builds the Lambert-only BSDF (WP_FEATURE_GLOSSY 0, kernels/bsdf/bsdf.h). It must render what the
// general BSDF renders with the same random numbers: the values agree up to float rounding (1e-4
// relative; a path can take another turn where a roulette or lobe decision sits within rounding
// of its threshold, about once per 10^6 decisions, so up to 0.5% of pixels may differ more), and
// both renders agree within their standard errors (z-scores over 4 x 4 blocks).
TEST_F(LightTransport, LambertOnlyBuildRendersAsTheGeneralBsdf) {
  wp::Scene s = agreement_scene();
  EXPECT_TRUE(wp::SceneFeatures::of(s, false).glossy);  // the floor is partly metal
  for (wp::Material& m : s.materials) m.metallic = 0.0f, m.specular = 0.0f;
  ASSERT_FALSE(wp::SceneFeatures::of(s, false).glossy);
  wp::RenderSettings st = agreement_settings();
  st.spp = 64;
  const wp::Rendered lambert = render(s, st);
  st.all_features = true;
  const wp::Rendered general = render(s, st);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < lambert.image.rgb.size(); ++i) {
    const float a = lambert.image.rgb[i], b = general.image.rgb[i];
    differ += std::fabs(a - b) > 1e-4f * std::max(std::fabs(b), 1e-3f);
  }
  EXPECT_LE(differ, lambert.image.rgb.size() / 200) << differ << " values differ";
  st.seed = 1;
  expect_agree(lambert, render(s, st), 4, "lambert-only vs general, other seed");
}

// 0: the constant sky; 1, 2: the environment map looked up nearest, bilinear.
class StrategiesAgree : public LightTransport, public ::testing::WithParamInterface<int> {};

// With the constant sky and with an environment map (the scene: an emissive quad, a glossy
// surface and an environment map), under either lookup of the map.
TEST_P(StrategiesAgree, MisNeeAndBsdf) {
  const wp::Scene s = agreement_scene();
  wp::RenderSettings st = agreement_settings();
  if (GetParam() > 0) st.environment = test_sky();
  st.env_filter = GetParam() == 1 ? wp::EnvFilter::kNearest : wp::EnvFilter::kBilinear;
  expect_strategies_agree(s, st, "");
}

INSTANTIATE_TEST_SUITE_P(Sky, StrategiesAgree, ::testing::Values(0, 1, 2), [](const auto& p) {
  return std::string(p.param == 0   ? "ConstantSky"
                     : p.param == 1 ? "EnvironmentMapNearest"
                                    : "EnvironmentMapBilinear");
});

// Irradiance from a small map with a known answer. A white-ish Lambertian plane (albedo a, no
// specular layer: the Lambert-only BSDF, a / pi) facing +Y, seen from straight above so every
// pixel sees it, direct light only (max_depth 1): each pixel is a / pi x E with
// E = the integral over the upper hemisphere of L(w) cos(theta). In map coordinates
// (d omega = 2 pi^2 sin(pi v) du dv, cos(theta) = cos(pi v)) and integrated over u first:
// E = 2 pi^2 times the integral over v in [0, 1/2] of R(v) sin(pi v) cos(pi v), R(v) the mean over
// u of the lookup. Nearest: R is the row mean on each row. Bilinear: a full period of the linear
// interpolation in u integrates to the row mean, so R blends the two row means linearly between
// row centres and is constant within half a row of the poles. E is invariant under rotation
// about +Y. Composite Simpson on each piece where R is smooth (64 panels) makes E exact to ~1e-10.
// The map (8 x 4) is bright in row 1 and black in row 2, below the horizon: bilinear lookup
// spreads row 1's light across the horizon, so the two filters' answers differ by 4.7%, ~30
// standard errors, and a render with the wrong lookup, or tables that missed a texel, fails.
double known_irradiance(const wp::EnvironmentMap& env, wp::EnvFilter filter, int channel) {
  const int w = env.width, h = env.height;
  std::vector<double> row(std::size_t(h), 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      row[std::size_t(y)] += env.texels[std::size_t(y * w + x)][channel] / double(w);
  const auto r_of = [&](double v) {
    if (filter == wp::EnvFilter::kNearest) return row[std::size_t(std::min(int(v * h), h - 1))];
    const double fy = v * h - 0.5, y0 = std::floor(fy), t = fy - y0;
    const auto at = [&](double y) { return row[std::size_t(std::clamp(int(y), 0, h - 1))]; };
    return (1 - t) * at(y0) + t * at(y0 + 1);
  };
  // Piece edges: row edges (nearest) or row centres (bilinear), and the horizon v = 1/2.
  std::vector<double> edges = {0.0, 0.5};
  for (int k = 0; k <= h; ++k) {
    const double e = filter == wp::EnvFilter::kNearest ? double(k) / h : (k + 0.5) / h;
    if (e > 0.0 && e < 0.5) edges.push_back(e);
  }
  std::sort(edges.begin(), edges.end());
  double sum = 0.0;
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    const int n = 64;
    const double a = edges[k], step = (edges[k + 1] - a) / n;
    for (int i = 0; i <= n; ++i) {
      // Inside the piece: nudged off its edges so that nearest lookup takes the piece's row.
      const double v = std::clamp(a + i * step, a + 1e-12, edges[k + 1] - 1e-12);
      const double c = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
      sum += c * step / 3.0 * r_of(v) * std::sin(M_PI * v) * std::cos(M_PI * v);
    }
  }
  return 2.0 * M_PI * M_PI * sum;
}

// Each strategy alone (and MIS), each filter: the mean over the image against a / pi x E within 5
// standard errors of that mean. The film's variance image holds each pixel's variance of its
// mean over its samples (tests above use it the same way); pixels are independent (independent
// sampler), so the image mean's variance is their sum over N^2. 32 x 32 pixels x 128 samples:
// 0.15% standard error of the mean per strategy (measured), against the 4.7% between the filters.
TEST_F(LightTransport, EnvironmentIrradianceKnownAnswer) {
  auto env = std::make_shared<wp::EnvironmentMap>();
  env->width = 8;
  env->height = 4;
  const float rows[4] = {0.3f, 4.0f, 0.0f, 0.7f};
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      const float l = rows[y] * (x == 0 ? 6.0f : x == 7 ? 0.0f : 1.0f);  // a bright seam column
      env->texels.emplace_back(l, 0.8f * l, 0.6f * l, 0.0f);
    }
  wp::build_environment_tables(*env);
  wp::Scene s;
  wp::Material plane = wp::test::diffuse_material(vec3(0.7f));
  plane.specular = 0.0f;
  s.materials.push_back(plane);
  wp::test::add_quad(s, {-100, 0, -100}, {-100, 0, 100}, {100, 0, 100}, {100, 0, -100}, 0);
  wp::test::finish_bounds(s);
  s.cameras.push_back(wp::test::look_at({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.5f, {0, 0, -1}));
  wp::RenderSettings st;
  st.sampler = wp::Sampler::kIndependent;
  st.width = st.height = 32;
  st.spp = 128;
  st.max_depth = 1;
  st.environment = env;
  st.env_rotation = 30.0f;
  for (const wp::EnvFilter filter : {wp::EnvFilter::kNearest, wp::EnvFilter::kBilinear}) {
    st.env_filter = filter;
    for (const wp::Strategy strategy :
         {wp::Strategy::kMis, wp::Strategy::kNee, wp::Strategy::kBsdf}) {
      st.strategy = strategy;
      const wp::Rendered r = render(s, st);
      const std::size_t n = r.image.rgb.size() / 3;
      for (int c = 0; c < 3; ++c) {
        double mean = 0.0, var = 0.0;
        for (std::size_t p = 0; p < n; ++p) {
          mean += r.image.rgb[3 * p + std::size_t(c)] / double(n);
          var += r.variance.rgb[3 * p + std::size_t(c)] / (double(n) * double(n));
        }
        const double expected = 0.7 / M_PI * known_irradiance(*env, filter, c);
        const double se = std::sqrt(var);
        const std::string what = std::string(wp::env_filter_name(filter)) + " strategy " +
                                 std::to_string(int(strategy)) + " channel " + std::to_string(c);
        EXPECT_NEAR(mean, expected, 5.0 * se) << what << " (standard error " << se << ")";
        if (c == 0)
          std::cout << "  " << what << ": " << mean << " vs " << expected << " ("
                    << (mean - expected) / se << " standard errors; the other filter's answer "
                    << 0.7 / M_PI *
                           known_irradiance(*env,
                                            filter == wp::EnvFilter::kNearest
                                                ? wp::EnvFilter::kBilinear
                                                : wp::EnvFilter::kNearest,
                                            c)
                    << ")\n";
      }
    }
  }
}

// An emitter with alpha: BSDF-sampled rays see it only where the traversal accepts it (MASK: where
// alpha >= cutoff; BLEND: with probability alpha), so NEE must scale its light by the same
// coverage. The lamp of the agreement scene as BLEND with alpha 0.5, and as MASK cut out
// everywhere (alpha 0.2 < cutoff 0.5): NEE and BSDF sampling agree. Before NEE looked at alpha,
// it lit the scene with the whole lamp in both cases.
TEST_F(LightTransport, AlphaEmittersAgree) {
  for (const wp::AlphaMode mode : {wp::AlphaMode::kBlend, wp::AlphaMode::kMask}) {
    wp::Scene s = agreement_scene();
    wp::Material& lamp = s.materials[2];
    ASSERT_GT(lamp.emission.x, 0.0f);
    lamp.alpha_mode = mode;
    lamp.base_color.a = mode == wp::AlphaMode::kBlend ? 0.5f : 0.2f;
    wp::RenderSettings st = agreement_settings();
    st.strategy = wp::Strategy::kNee;
    const wp::Rendered nee = render(s, st);
    st.strategy = wp::Strategy::kBsdf;
    st.seed = 2;
    const wp::Rendered bsdf = render(s, st);
    expect_agree(nee, bsdf, 4, mode == wp::AlphaMode::kBlend ? "blend lamp" : "mask lamp");
  }
}

// A lamp with an emissive texture that is black on its left half (host/lights/emission.h): the lamp
// is an 8 x 8 grid of quads, and the triangles on the black half are no lights at all. Light
// sampling, BSDF sampling and MIS still agree (a triangle that is not in the light table shows
// its emission to BSDF-sampled rays with weight 1).
TEST_F(LightTransport, TexturedLampStrategiesAgree) {
  wp::Scene s = agreement_scene();
  const std::size_t lamp_first = s.triangle_count() - 2;  // the agreement scene's lamp: last quad
  wp::Image img;
  img.width = img.height = 16;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 4; ++c) img.rgba.push_back(c == 3 || x >= 8 ? 255 : 0);
  s.images.push_back(img);
  wp::TextureRef t;
  t.image = 0;
  t.srgb = true;
  t.wrap_s = t.wrap_t = wp::Wrap::kClampToEdge;
  s.textures.push_back(t);
  s.materials[2].emissive_texture = 0;
  s.materials[2].emission *= 2.0f;
  // Replace the lamp quad by a grid over the same rectangle (facing down), uv = its x-z position.
  s.indices.resize(3 * lamp_first);
  s.triangle_material.resize(lamp_first);
  constexpr int kCells = 8;
  for (int j = 0; j < kCells; ++j)
    for (int i = 0; i < kCells; ++i) {
      const float x0 = float(i) / kCells, x1 = float(i + 1) / kCells;
      const float z0 = -0.6f + float(j) / kCells, z1 = -0.6f + float(j + 1) / kCells;
      const std::size_t first = s.positions.size();
      wp::test::add_quad(s, {x0, 1.4f, z0}, {x1, 1.4f, z0}, {x1, 1.4f, z1}, {x0, 1.4f, z1}, 2);
      for (std::size_t k = first; k < s.positions.size(); ++k)
        s.uv0[k] = {s.positions[k].x, s.positions[k].z + 0.6f};
    }
  wp::test::finish_bounds(s);
  wp::RenderSettings st = agreement_settings();
  const wp::LightTable table =
      wp::build_light_table(s, nullptr, st.background, 1.0f, wp::LightSelect::kPower);
  EXPECT_EQ(table.emissive_triangles, std::size_t{kCells * kCells + 2 * kCells})
      << "the lamp's black half (columns 0-2 wholly, by the filter's reach) is no light";
  expect_strategies_agree(s, st, "textured lamp: ");
}

// A smooth thin glass pane (double-sided, transmission 1, ior 1.5) between the lamp and the floor
// of the agreement scene: NEE's shadow rays pass it with (1 - F) (trace_shadow.cl), BSDF-sampled
// paths pass it as a delta transmission that keeps the previous vertex's pdf and distance for
// MIS (sample_bsdf.cl). The three strategies agree only if both sides weigh the light behind the
// pane alike: with a pane that blocked shadow rays, or a BSDF path that lost its pdf there, NEE
// or MIS would miss or double the lamp's light on the floor.
TEST_F(LightTransport, StrategiesAgreeThroughThinGlass) {
  wp::Scene s = agreement_scene();
  wp::Material pane = wp::test::glass_material(/*volume=*/false);
  pane.double_sided = true;
  s.materials.push_back(pane);
  const auto material = static_cast<std::uint32_t>(s.materials.size() - 1);
  wp::test::add_quad(s, {-1.2f, 1.1f, -1.5f}, {-1.2f, 1.1f, 1.5f}, {0.6f, 1.1f, 1.5f},
                     {0.6f, 1.1f, -1.5f}, material);
  wp::test::finish_bounds(s);
  expect_strategies_agree(s, agreement_settings(), "through a pane: ");
}

TEST_F(LightTransport, HeuristicsAndLightSelectionAgree) {
  const wp::Scene s = agreement_scene();
  wp::RenderSettings st = agreement_settings();
  const wp::Rendered power = render(s, st);
  st.mis_heuristic = wp::MisHeuristic::kBalance;
  st.light_select = wp::LightSelect::kUniform;
  st.seed = 3;
  const wp::Rendered balance = render(s, st);
  expect_agree(power, balance, 4, "power heuristic + power selection vs balance + uniform");
}

TEST_F(LightTransport, RouletteOnAndOffAgree) {
  const wp::Scene s = agreement_scene();
  wp::RenderSettings st = agreement_settings();
  st.rr_depth = 1000;
  const wp::Rendered off = render(s, st);
  st.rr_depth = 1;
  st.seed = 4;
  const wp::Rendered on = render(s, st);
  expect_agree(off, on, 4, "roulette off vs on");
  st.rr_threshold = 1.0f;  // pbrt's rule, the most roulette a threshold allows
  st.seed = 5;
  const wp::Rendered strict = render(s, st);
  expect_agree(off, strict, 4, "roulette off vs on at threshold 1");
}

// Irradiance at x (normal n) from a uniformly emitting polygon of radiance 1 (Lambert's formula):
// E = 1/2 |sum_i theta_i n . normalize(r_i x r_i+1)|, r_i = v_i - x, theta_i the angle between
// r_i and r_i+1.
double polygon_irradiance(const std::vector<dvec3>& poly, dvec3 x, dvec3 n) {
  double sum = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const dvec3 a = glm::normalize(poly[i] - x),
                b = glm::normalize(poly[(i + 1) % poly.size()] - x);
    const double theta = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
    sum += theta * glm::dot(n, glm::normalize(glm::cross(a, b)));
  }
  return 0.5 * std::fabs(sum);
}

class EmissiveQuad : public LightTransport, public ::testing::WithParamInterface<wp::Strategy> {};

// A Lambertian plane (specular factor 0) under an emissive quad in a black world: each pixel is
// (albedo / pi) L E(x), E from Lambert's formula, nothing else (the quad absorbs what reaches it).
TEST_P(EmissiveQuad, MatchesLambertsFormula) {
  wp::Scene s;
  wp::Material plane = wp::test::diffuse_material(vec3(0.8f, 0.6f, 0.4f));
  plane.specular = 0.0f;
  s.materials.push_back(plane);
  wp::Material lamp = wp::test::diffuse_material(vec3(0.0f), false);
  lamp.specular = 0.0f;
  lamp.emission = {2.0f, 2.0f, 2.0f};
  s.materials.push_back(lamp);
  // Large enough that every camera ray meets it (its edge, a discontinuity, stays out of view).
  wp::test::add_quad(s, {-8, 0, -8}, {-8, 0, 8}, {8, 0, 8}, {8, 0, -8}, 0);
  const std::vector<dvec3> quad = {
      {-0.5, 0.6, -0.5}, {0.5, 0.6, -0.5}, {0.5, 0.6, 0.5}, {-0.5, 0.6, 0.5}};
  wp::test::add_quad(s, quad[0], quad[1], quad[2], quad[3], 1);  // front faces down
  wp::test::finish_bounds(s);
  const vec3 eye(0.0f, 2.5f, 2.5f);
  s.cameras.push_back(wp::test::look_at(eye, {0.0f, 0.0f, 0.0f}, 0.7f));
  wp::RenderSettings st;
  st.sampler = wp::Sampler::kIndependent;  // z-scores from variance images: see agreement_settings
  st.width = 40;
  st.height = 30;
  st.spp = 1024;
  st.strategy = GetParam();
  const wp::Rendered r = render(s, st);
  if (std::getenv("WP_DEBUG")) wp::write_images({"/tmp/dbg/quad.png"}, r.image, {});

  // Expected pixel values: the average over the pixel's footprint (8 x 8 midpoint grid) of the
  // plane's radiance where the camera ray meets it (the quad, seen from above, is culled).
  const wp::dev::Camera cam = wp::device_camera(s.cameras[0], st.width, st.height);
  const dvec3 fwd(cam.forward.x, cam.forward.y, cam.forward.z),
      right(cam.right.x, cam.right.y, cam.right.z), up(cam.up.x, cam.up.y, cam.up.z);
  ZStats z;
  for (int py = 0; py < st.height; ++py)
    for (int px = 0; px < st.width; ++px) {
      double e = 0.0, hit_probability = 0.0;
      constexpr int kGrid = 8;
      for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
          const double nx = 2.0 * (px + (i + 0.5) / kGrid) / st.width - 1.0;
          const double ny = 1.0 - 2.0 * (py + (j + 0.5) / kGrid) / st.height;
          const dvec3 d = glm::normalize(fwd + nx * right + ny * up);
          const dvec3 x = dvec3(eye) + (-double(eye.y) / d.y) * d;
          EXPECT_TRUE(d.y < 0.0 && std::fabs(x.x) < 8.0 && std::fabs(x.z) < 8.0);
          const double unit = polygon_irradiance(quad, x, {0, 1, 0});
          e += 2.0 * unit / M_PI;
          hit_probability += unit / M_PI;  // cosine sampling finds the quad this often
        }
      e /= kGrid * kGrid;
      hit_probability /= kGrid * kGrid;
      // BSDF sampling's estimate is a rare-event count where it seldom finds the quad: there the
      // sample variance is unreliable (often 0). Compare only where >= 100 hits are expected.
      if (GetParam() == wp::Strategy::kBsdf && hit_probability * st.spp < 100.0) continue;
      const double albedo[3] = {0.8, 0.6, 0.4};
      for (int c = 0; c < 3; ++c) {
        const std::size_t idx = 3 * (std::size_t(py) * st.width + px) + c;
        const double want = albedo[c] * e;
        // Monte Carlo variance + the footprint integration error (< 1e-4 relative: E is smooth).
        const double se = std::sqrt(r.variance.rgb[idx] + (1e-4 * want) * (1e-4 * want));
        const double zz = (r.image.rgb[idx] - want) / se;
        z.mean_z2 += zz * zz;
        z.worst = std::max(z.worst, std::fabs(zz));
        ++z.n;
      }
    }
  ASSERT_GT(z.n, 300);
  z.mean_z2 /= z.n;
  EXPECT_NEAR(z.mean_z2, 1.0, 5.0 * std::sqrt(2.0 / z.n)) << "worst |z| " << z.worst;
  EXPECT_LT(z.worst, 6.0);
}

INSTANTIATE_TEST_SUITE_P(Strategies, EmissiveQuad,
                         ::testing::Values(wp::Strategy::kMis, wp::Strategy::kNee,
                                           wp::Strategy::kBsdf),
                         [](const auto& p) {
                           return std::string(p.param == wp::Strategy::kMis   ? "Mis"
                                              : p.param == wp::Strategy::kNee ? "Nee"
                                                                              : "Bsdf");
                         });

}  // namespace
