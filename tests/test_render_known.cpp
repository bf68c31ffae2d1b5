// scene tier: whole-pipeline renders with answers known in closed form, computed here, plus
// determinism. All on the default OpenCL device (PoCL in CI).
//
// Every known-answer scene here has no randomness but the pixel jitter (box filter): one bounce
// to a delta lobe or to punctual lights, the rest escaping to a constant background. So each
// pixel's expectation is the average of a smooth function over the pixel's footprint, which the
// test integrates on a 16x16 midpoint grid (its error is far below the tolerance for smooth
// functions, so no scene here has an edge or a shadow boundary in view), and the
// estimator's standard error is sigma_pixel / sqrt(spp), sigma_pixel the spread of that function
// over the footprint. A pixel fails when it is more than 6 standard errors away (after adding
// float rounding, 2e-5 relative, in quadrature); with ~9000 values and Gaussian errors the chance
// of a false alarm is ~2e-5. Where the Monte Carlo error dominates, the mean of z^2 must also be
// that of a chi-square variable with one degree of freedom: 1 +- 5 sqrt(2/N) (this catches a
// wrong variance, i.e. correlated or non-uniform jitter, that a per-pixel bound would miss).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "host/device/cl_runtime.h"
#include "host/device/device_scene.h"
#include "host/lights/environment.h"
#include "host/render/render.h"
#include "host/scene/srgb.h"
#include "tests/device_test.h"
#include "tests/scene_factory.h"

namespace {

using glm::dvec3;
using glm::vec3;

class RenderKnown : public wp::test::DeviceTest {};

constexpr int kWidth = 64, kHeight = 48, kSpp = 16;

// The direction of the camera ray through image point (x, y) in pixels (y down), computed as the
// kernel does (kernels/camera/camera.h) but in double precision.
dvec3 camera_dir(const wp::dev::Camera& c, double x, double y) {
  const double nx = 2.0 * x / kWidth - 1.0, ny = 1.0 - 2.0 * y / kHeight;
  const dvec3 f(c.forward.x, c.forward.y, c.forward.z), r(c.right.x, c.right.y, c.right.z),
      u(c.up.x, c.up.y, c.up.z);
  return glm::normalize(f + nx * r + ny * u);
}

// Mean and standard deviation of `value(dir)` over each pixel's footprint.
struct PixelMoments {
  std::vector<dvec3> mean, sigma;
};
PixelMoments integrate(const wp::dev::Camera& cam, const std::function<dvec3(dvec3)>& value) {
  constexpr int kGrid = 16;
  PixelMoments m;
  for (int py = 0; py < kHeight; ++py)
    for (int px = 0; px < kWidth; ++px) {
      dvec3 s(0.0), s2(0.0);
      for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
          const dvec3 v = value(camera_dir(cam, px + (i + 0.5) / kGrid, py + (j + 0.5) / kGrid));
          s += v;
          s2 += v * v;
        }
      const dvec3 mean = s / double(kGrid * kGrid);
      m.mean.push_back(mean);
      m.sigma.push_back(glm::sqrt(glm::max(s2 / double(kGrid * kGrid) - mean * mean, dvec3(0.0))));
    }
  return m;
}

// Checks a render against the known pixel means. z = (got - expected) / sigma, sigma the standard
// error kSpp independent samples would have (from the known per-pixel spread) plus a rounding
// floor. Independent samples: every |z| < 6 and mean z^2 = 1 within 5 of its standard errors
// (sqrt(2 / n)), a two-sided test of both the value and the error model. Sobol' samples have
// less error than that model, so: every |z| < 6, mean z^2 <= 1 + 5 sqrt(2 / n) (no noisier than
// independent samples), and unbiasedness by the self-normalised sum over pixels: with D_p the
// pixel's error summed over channels, independent across pixels (independent scrambles) with
// mean 0 for an unbiased render, |sum D_p| / sqrt(sum D_p^2) ~ |N(0, 1)| < 5.
void expect_matches(const wp::Rendered& r, const PixelMoments& expected,
                    wp::Sampler sampler = wp::Sampler::kIndependent) {
  EXPECT_EQ(r.report.nonfinite_samples, 0u);
  double z2 = 0.0, worst = 0.0, sum_d = 0.0, sum_d2 = 0.0;
  int n = 0;
  for (std::size_t p = 0; p < expected.mean.size(); ++p) {
    double d_pixel = 0.0;
    bool noisy = false;
    for (int c = 0; c < 3; ++c) {
      const double e = expected.mean[p][c], got = r.image.rgb[3 * p + c];
      const double mc = expected.sigma[p][c] * expected.sigma[p][c] / kSpp;
      const double rounding = (2e-5 * e) * (2e-5 * e) + 1e-14;
      const double z = (got - e) / std::sqrt(mc + rounding);
      worst = std::max(worst, std::fabs(z));
      ASSERT_LT(std::fabs(z), 6.0) << "pixel " << p << " channel " << c << ": got " << got
                                   << ", expected " << e << " +- " << std::sqrt(mc + rounding);
      // The chi-square check only where the Monte Carlo error dominates the rounding floor
      // (elsewhere z is mostly rounding, whose spread the floor overstates).
      if (mc > 100.0 * rounding) {
        z2 += z * z;
        ++n;
        d_pixel += got - e;
        noisy = true;
      }
    }
    if (noisy) {
      sum_d += d_pixel;
      sum_d2 += d_pixel * d_pixel;
    }
  }
  if (n < 100) return;
  if (sampler == wp::Sampler::kIndependent) {
    EXPECT_NEAR(z2 / n, 1.0, 5.0 * std::sqrt(2.0 / n)) << n << " pixels, worst |z| " << worst;
  } else {
    EXPECT_LE(z2 / n, 1.0 + 5.0 * std::sqrt(2.0 / n)) << n << " pixels, worst |z| " << worst;
    EXPECT_LT(std::fabs(sum_d), 5.0 * std::sqrt(sum_d2)) << "sum of errors " << sum_d;
  }
}

// Renders s with each sample pattern and checks both against the known answer.
void expect_matches_with_each_sampler(wp::ClRuntime& runtime, const wp::Scene& s,
                                      wp::RenderSettings st, const PixelMoments& expected) {
  for (wp::Sampler sampler : {wp::Sampler::kIndependent, wp::Sampler::kSobol}) {
    SCOPED_TRACE(sampler == wp::Sampler::kSobol ? "sobol" : "independent");
    st.sampler = sampler;
    expect_matches(wp::render(runtime, s, st), expected, sampler);
  }
}

// A 200 x 200 quad in the plane y = 0, front face up.
wp::Scene plane_scene(const wp::Material& m) {
  wp::Scene s;
  s.materials.push_back(m);
  wp::test::add_quad(s, {-100, 0, -100}, {-100, 0, 100}, {100, 0, 100}, {100, 0, -100}, 0);
  wp::test::finish_bounds(s);
  return s;
}

wp::RenderSettings settings_for(const wp::Scene& s, vec3 background) {
  wp::RenderSettings st;
  st.width = kWidth;
  st.height = kHeight;
  st.spp = kSpp;
  st.background = background;
  st.camera = 0;
  st.sampler = wp::Sampler::kIndependent;  // expect_matches_with_each_sampler tries both
  (void)s;
  return st;
}

// Where the ray from `eye` along d meets the plane y = 0, and whether that is on plane_scene's
// quad (a ray that passes beyond its edge sees the background).
bool plane_hit(vec3 eye, dvec3 d, dvec3* p) {
  if (d.y >= 0.0) return false;
  *p = dvec3(eye) + (-double(eye.y) / d.y) * d;
  return std::fabs(p->x) <= 100.0 && std::fabs(p->z) <= 100.0;
}

// A smooth metal (roughness 0, base colour 0.5) under a white sky shows exactly the Schlick
// Fresnel term of the metal: F = 0.5 + 0.5 (1 - cos theta)^5.
TEST_F(RenderKnown, SmoothMetalShowsSchlickFresnel) {
  wp::Material m;
  m.base_color = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  m.metallic = 1.0f;
  m.roughness = 0.0f;
  wp::Scene s = plane_scene(m);
  // Every pixel sees the plane, from cos(theta) = 0.17 (grazing) to 0.7: the quad's far edge,
  // a discontinuity the test's integration grid would not resolve, stays out of view.
  const vec3 eye(0.0f, 1.0f, 3.0f);
  s.cameras.push_back(wp::test::look_at(eye, {0.0f, 0.0f, 1.0f}, 0.9f));
  const wp::RenderSettings st = settings_for(s, vec3(1.0f));
  const wp::dev::Camera cam = wp::device_camera(s.cameras[0], kWidth, kHeight);
  const auto expected = integrate(cam, [&](dvec3 d) {
    dvec3 p;
    if (!plane_hit(eye, d, &p)) return dvec3(1.0);  // the sky itself
    const double c = -d.y;
    return dvec3(0.5 + 0.5 * std::pow(1.0 - c, 5.0));
  });
  expect_matches_with_each_sampler(*runtime_, s, st, expected);
}

// The glTF metallic-roughness BRDF (specification appendix B), written independently of the
// kernels, in double precision.
dvec3 gltf_brdf(dvec3 n, dvec3 v, dvec3 l, dvec3 base, double metallic, double roughness) {
  const double nl = glm::dot(n, l), nv = glm::dot(n, v);
  if (nl <= 0 || nv <= 0) return dvec3(0.0);
  const dvec3 h = glm::normalize(v + l);
  const double vh = glm::dot(v, h), nh = glm::dot(n, h), a = roughness * roughness, a2 = a * a;
  const double d = a2 / (M_PI * std::pow(nh * nh * (a2 - 1) + 1, 2));
  const double vis =
      0.5 / (nl * std::sqrt(nv * nv * (1 - a2) + a2) + nv * std::sqrt(nl * nl * (1 - a2) + a2));
  const double fd = 0.04 + 0.96 * std::pow(1 - vh, 5);
  const dvec3 fm = base + (dvec3(1.0) - base) * std::pow(1 - vh, 5);
  const dvec3 dielectric = (1 - fd) * base / M_PI + dvec3(fd * d * vis);
  const dvec3 metal = fm * d * vis;
  return (1 - metallic) * dielectric + metallic * metal;
}

struct LightCase {
  const char* name;
  wp::PunctualLight light;
  double metallic, roughness;
};

void PrintTo(const LightCase& c, std::ostream* os) {
  *os << c.name;
}

class RenderPunctual : public RenderKnown, public ::testing::WithParamInterface<LightCase> {};

// A plane lit by one punctual light in a black world: each pixel is f * E cos(theta), with
// E = I / d^2 (point, spot with the KHR falloff) or E (directional), and nothing else.
TEST_P(RenderPunctual, PlaneShowsBrdfTimesIrradiance) {
  const LightCase& lc = GetParam();
  wp::Material m;
  m.base_color = glm::vec4(0.8f, 0.6f, 0.4f, 1.0f);
  m.metallic = static_cast<float>(lc.metallic);
  m.roughness = static_cast<float>(lc.roughness);
  wp::Scene s = plane_scene(m);
  s.lights.push_back(lc.light);
  const vec3 eye(0.0f, 2.0f, 4.0f);
  s.cameras.push_back(wp::test::look_at(eye, {0.0f, 0.0f, 0.0f}, 0.8f));
  const wp::RenderSettings st = settings_for(s, vec3(0.0f));
  const wp::dev::Camera cam = wp::device_camera(s.cameras[0], kWidth, kHeight);
  const wp::PunctualLight& L = lc.light;
  const dvec3 base(0.8, 0.6, 0.4), n(0, 1, 0);
  const auto expected = integrate(cam, [&](dvec3 d) {
    dvec3 p;
    if (!plane_hit(eye, d, &p)) return dvec3(0.0);
    dvec3 wi, irradiance;
    if (L.type == wp::LightType::kDirectional) {
      wi = -glm::normalize(dvec3(L.direction));
      irradiance = dvec3(L.intensity);
    } else {
      const dvec3 to = dvec3(L.position) - p;
      wi = glm::normalize(to);
      irradiance = dvec3(L.intensity) / glm::dot(to, to);
      if (L.type == wp::LightType::kSpot) {
        const double co = std::cos(L.outer_cone), ci = std::cos(L.inner_cone);
        const double scale = 1.0 / std::max(0.001, ci - co);
        const double cd = glm::dot(glm::normalize(dvec3(L.direction)), -wi);
        const double att = std::clamp(cd * scale - co * scale, 0.0, 1.0);
        irradiance *= att * att;
      }
    }
    return gltf_brdf(n, -d, wi, base, lc.metallic, lc.roughness) * std::max(0.0, wi.y) * irradiance;
  });
  expect_matches_with_each_sampler(*runtime_, s, st, expected);
}

wp::PunctualLight point_light() {
  wp::PunctualLight l;
  l.type = wp::LightType::kPoint;
  l.position = {0.3f, 1.5f, 0.2f};
  l.intensity = {3.0f, 2.0f, 1.0f};
  return l;
}
wp::PunctualLight spot_light() {
  wp::PunctualLight l = point_light();
  l.type = wp::LightType::kSpot;
  l.direction = glm::normalize(vec3(0.1f, -1.0f, 0.3f));
  l.inner_cone = 0.2f;
  l.outer_cone = 0.6f;
  return l;
}
wp::PunctualLight sun_light() {
  wp::PunctualLight l;
  l.type = wp::LightType::kDirectional;
  l.direction = glm::normalize(vec3(0.3f, -1.0f, -0.5f));
  l.intensity = {1.5f, 1.0f, 0.5f};
  return l;
}

INSTANTIATE_TEST_SUITE_P(Lights, RenderPunctual,
                         ::testing::Values(LightCase{"PointDiffuse", point_light(), 0.0, 1.0},
                                           LightCase{"PointGlossy", point_light(), 0.0, 0.4},
                                           LightCase{"PointMetal", point_light(), 1.0, 0.5},
                                           LightCase{"SpotDiffuse", spot_light(), 0.0, 1.0},
                                           LightCase{"SunGlossy", sun_light(), 0.3, 0.6}),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

// The sun through a window: a smooth thin-walled glass pane (transmission 1, ior 1.5, white) at
// y = 1 over the plane; the camera is below it. Shadow rays pass the pane with its transmittance
// 1 - F(cos), F = 0.04 + 0.96 (1 - cos)^5 (Schlick, f0 of ior 1.5), cos the sun's angle to the
// pane: each pixel is f * E cos(theta) * (1 - F). Direct light only (max_depth 1), so light
// reflected between plane and pane does not add to the closed form. Before shadow rays passed
// such panes, the plane got nothing of the sun.
TEST_F(RenderKnown, SunThroughThinGlassPane) {
  wp::Material floor;
  floor.base_color = glm::vec4(0.8f, 0.6f, 0.4f, 1.0f);
  floor.metallic = 0.0f;
  floor.roughness = 1.0f;
  wp::Scene s = plane_scene(floor);
  wp::Material glass = wp::test::glass_material(/*volume=*/false);
  glass.double_sided = true;  // single-sided, its back face (toward the plane) would be culled
  s.materials.push_back(glass);
  wp::test::add_quad(s, {-100, 1, -100}, {-100, 1, 100}, {100, 1, 100}, {100, 1, -100}, 1);
  wp::test::finish_bounds(s);
  const wp::PunctualLight sun = sun_light();
  s.lights.push_back(sun);
  const vec3 eye(0.0f, 0.5f, 1.5f);
  s.cameras.push_back(wp::test::look_at(eye, {0.0f, 0.0f, 0.0f}, 0.8f));
  wp::RenderSettings st = settings_for(s, vec3(0.0f));
  st.max_depth = 1;
  const wp::dev::Camera cam = wp::device_camera(s.cameras[0], kWidth, kHeight);
  const dvec3 base(0.8, 0.6, 0.4), n(0, 1, 0), wi = -glm::normalize(dvec3(sun.direction));
  const double fresnel = 0.04 + 0.96 * std::pow(1.0 - wi.y, 5.0);
  const auto expected = integrate(cam, [&](dvec3 d) {
    dvec3 p;
    if (!plane_hit(eye, d, &p)) return dvec3(0.0);
    return gltf_brdf(n, -d, wi, base, 0.0, 1.0) * wi.y * dvec3(sun.intensity) * (1.0 - fresnel);
  });
  expect_matches_with_each_sampler(*runtime_, s, st, expected);
}

// An emissive quad facing the camera shows its radiance; seen from behind it is not there when
// single-sided (glTF back-face culling) and emits from both sides when double-sided.
TEST_F(RenderKnown, EmissionAndSidedness) {
  for (const bool double_sided : {false, true}) {
    for (const bool from_front : {true, false}) {
      wp::Material m = wp::test::diffuse_material(vec3(0.0f), double_sided);
      m.emission = {2.0f, 3.0f, 4.0f};
      wp::Scene s;
      s.materials.push_back(m);
      // Front faces +z.
      wp::test::add_quad(s, {-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}, 0);
      wp::test::finish_bounds(s);
      s.cameras.push_back(wp::test::look_at({0, 0, from_front ? 3.0f : -3.0f}, {0, 0, 0}, 0.5f));
      wp::RenderSettings st = settings_for(s, vec3(0.25f));
      st.max_depth = 0;  // emission only: the quad's own reflection would add to it otherwise
      const wp::Rendered r = wp::render(*runtime_, s, st);
      const bool visible = from_front || double_sided;
      const float want[3] = {visible ? 2.0f : 0.25f, visible ? 3.0f : 0.25f,
                             visible ? 4.0f : 0.25f};
      for (std::size_t p = 0; p < r.image.rgb.size() / 3; ++p)
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(r.image.rgb[3 * p + c], want[c])
              << "double_sided " << double_sided << " from_front " << from_front;
    }
  }
}

// A scene without triangles (valid glTF: no nodes, or only a camera) shows the background and
// nothing else: every camera ray escapes, so every pixel is the background radiance exactly, with
// both BVH layouts; its lights have nothing to light.
TEST_F(RenderKnown, EmptySceneShowsOnlyTheBackground) {
  wp::Scene s;
  s.lights.push_back(point_light());
  s.lights.push_back(sun_light());
  wp::test::finish_bounds(s);  // no positions: the bounds stay inverted
  s.cameras.push_back(wp::test::look_at({0.0f, 1.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.9f));
  const vec3 background(0.25f, 0.5f, 1.0f);
  for (const int width : {2, 8}) {
    wp::RenderSettings st = settings_for(s, background);
    st.bvh_width = width;
    st.spp = 4;
    const wp::Rendered r = wp::render(*runtime_, s, st);
    EXPECT_EQ(r.report.triangles, 0u);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    ASSERT_EQ(r.image.rgb.size(), std::size_t(3 * kWidth * kHeight));
    for (std::size_t p = 0; p < r.image.rgb.size() / 3; ++p)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(r.image.rgb[3 * p + c], background[c]) << "width " << width << " pixel " << p;
  }
}

// Adds a 64 x 64 texture of black and white texels (sRGB colour, magnification NEAREST, REPEAT),
// white where white(column, row) holds, as the scene's texture 0.
template <typename White>
void add_black_and_white_texture(wp::Scene& s, White white) {
  wp::Image img;
  img.width = img.height = 64;
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i) {
      const std::uint8_t v = white(i, j) ? 255 : 0;
      img.rgba.insert(img.rgba.end(), {v, v, v, 255});
    }
  s.images.push_back(img);
  wp::TextureRef t;
  t.image = 0;
  t.srgb = true;
  t.nearest = true;
  s.textures.push_back(t);
}

// A 2 x 2 square in the plane z = 0 facing +z, textured with a 64 x 64 checkerboard of black and
// white texels (sRGB colour, magnification NEAREST, REPEAT) repeated 32 times across: 1024
// texels per unit. Unlit (the image is the texture itself) or Lambertian.
wp::Scene checker_scene(bool unlit) {
  wp::Scene s;
  add_black_and_white_texture(s, [](int i, int j) { return (i + j) % 2 != 0; });
  wp::Material m = wp::test::diffuse_material(vec3(1.0f));
  m.unlit = unlit;
  m.specular = 0.0f;  // Lambert's BSDF alone: under a white sky its radiance is its albedo
  m.base_color_texture = 0;
  s.materials.push_back(m);
  wp::test::add_quad(s, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 0);
  for (std::size_t v = 0; v < 4; ++v)
    s.uv0[v] = 16.0f * glm::vec2(s.positions[v].x + 1.0f, 1.0f - s.positions[v].y);
  wp::test::finish_bounds(s);
  return s;
}

// The checkerboard seen from `distance` on its axis through a 0.5 rad field of view, 48 x 48.
wp::RenderSettings checker_view(wp::Scene& s, float distance, bool mipmaps, int spp) {
  s.cameras = {wp::test::look_at({0.1f, 0.05f, distance}, {0.1f, 0.05f, 0.0f}, 0.5f)};
  wp::RenderSettings st;
  st.width = st.height = 48;
  st.spp = spp;
  st.camera = 0;
  st.mipmaps = mipmaps;
  st.background = vec3(1.0f);
  st.sampler = wp::Sampler::kIndependent;  // the standard errors below assume independent samples
  return st;
}

// The mean of the checkerboard as its mip levels store it: every level from 1 on is exactly 0.5
// in linear light (a box over whole 2 x 2 blocks), encoded as 8-bit sRGB (code 188) and decoded.
double stored_half() {
  return wp::srgb_to_linear(std::round(255.0 * wp::linear_to_srgb(0.5)) / 255.0);
}

// Seen from 2.93 units the board spans 1.5 units (1536 texels) over 48 pixels: a pixel covers 32 x
// 32 texels, and each camera ray's cone (an eighth of the pixel) picks level 2 or a little more.
// With mip-maps every sample is the stored half (the unlit image is that constant within float
// rounding, 1e-6), variance 0; without, each sample is the texel under its jittered point, 0 or 1
// with probability 1/2: the image converges to 0.5, and each pixel's estimate has variance 0.25 /
// spp, which the mean of the renderer's per-pixel variance estimates over 2304 pixels matches
// within 10% (their own relative spread: sqrt(2 / 15) / 48 = 0.8%). Every mean over the 2304 pixels
// lies within 5 of its standard errors of its known value. Lit (Lambertian under a white sky:
// radiance = albedo a times the lighting estimate L, E[L] = 1, independent of a), the variance
// without mip-maps is E[a^2] E[L^2]
// - E[a]^2 and with them a_h^2 (E[L^2] - 1), a_h the stored half: their difference is at least
// var(a) = 0.25 per sample (the texture's share, which mip-maps remove), checked with 10% slack;
// the ratio is printed (docs/usage.md quotes it).
TEST_F(RenderKnown, DistantCheckerboardShowsItsMeanWithMipmaps) {
  const double half = stored_half();
  const auto mean_of = [](const wp::ImageRgb& im) {
    double sum = 0.0;
    for (const float v : im.rgb) sum += v;
    return sum / double(im.rgb.size());
  };
  for (const bool unlit : {true, false}) {
    SCOPED_TRACE(unlit ? "unlit" : "lambertian");
    wp::Scene s = checker_scene(unlit);
    const wp::Rendered on = wp::render(*runtime_, s, checker_view(s, 2.93f, true, 16));
    const wp::Rendered off = wp::render(*runtime_, s, checker_view(s, 2.93f, false, 16));
    EXPECT_EQ(on.report.nonfinite_samples + off.report.nonfinite_samples, 0u);
    const double var_on = mean_of(on.variance), var_off = mean_of(off.variance);
    const double n = double(off.image.rgb.size());
    // The standard error of a mean over pixels whose estimates each have variance var / 1.
    EXPECT_NEAR(mean_of(off.image), 0.5, 5.0 * std::sqrt(var_off / n));
    const double texture_share = 0.25 / 16.0;
    if (unlit) {
      for (const float v : on.image.rgb) ASSERT_NEAR(v, half, 1e-6);
      EXPECT_EQ(var_on, 0.0);
      EXPECT_NEAR(var_off, texture_share, 0.1 * texture_share);
    } else {
      EXPECT_NEAR(mean_of(on.image), half, 5.0 * std::sqrt(var_on / n));
      EXPECT_GT(var_off - var_on, 0.9 * texture_share);
      std::printf(
          "checkerboard at 32 texels per pixel, Lambertian, 16 spp: pixel variance "
          "%.3g with mip-maps, %.3g without (%.0fx)\n",
          var_on, var_off, var_off / var_on);
    }
  }
}

// Seen from 0.1 units the board spans 0.051 units (52 texels) over 48 pixels: magnified, each
// ray's level is below 0 (about -2.9), so mip-mapped lookups are the full-resolution ones: the
// same image bit for bit as without mip-maps, and the checks are sharp (NEAREST): pixels inside a
// texel are exactly 0 or 1.
TEST_F(RenderKnown, NearCheckerboardStaysSharpWithMipmaps) {
  wp::Scene s = checker_scene(true);
  const wp::Rendered on = wp::render(*runtime_, s, checker_view(s, 0.1f, true, 4));
  const wp::Rendered off = wp::render(*runtime_, s, checker_view(s, 0.1f, false, 4));
  ASSERT_EQ(on.image.rgb.size(), off.image.rgb.size());
  for (std::size_t i = 0; i < on.image.rgb.size(); ++i)
    ASSERT_EQ(on.image.rgb[i], off.image.rgb[i]) << "value " << i;
  const auto [lo, hi] = std::minmax_element(on.image.rgb.begin(), on.image.rgb.end());
  EXPECT_EQ(*lo, 0.0f);
  EXPECT_EQ(*hi, 1.0f);
}

// A floor seen at grazing angles keeps what runs along the view: stripes of white and black
// texels, constant along z, on an unlit floor (x in [-1, 1], z in [-8, 0], y = 0) under a white
// background, seen from 0.05 above it toward (0, 0, -5) through a 0.5 rad field of view, 48 x 48.
// The floor's texture coordinates run 2 periods of a 64-texel image per unit both ways (128 texels
// per unit, sRGB, NEAREST): columns 0-31 white, 32-63 black, u = 2x + 1/4, so the white stripe
// |x| < 1/8 lies under the image's two middle columns at every distance (a pixel is 0.0106 rad,
// 0.085 units wide at the floor's far edge). Every sample of those columns sees white, the
// floor's or the background's: each pixel is 1 (float rounding of the trilinear weights, 1e-6),
// with or without mip-maps. The rows near the horizon meet the floor at cos 0.01-0.04, where a cone
// an eighth of a pixel is 0.1-0.9 texel across (level 0-0.4) but 10-85 texels along the view; a
// level taken from that length (the isotropic footprint width / cos, wavepath's until 2026-11-27)
// averages whole periods there and renders those pixels 0.5-0.9.
TEST_F(RenderKnown, GrazingStripesKeepTheirContrastWithMipmaps) {
  wp::Scene s;
  add_black_and_white_texture(s, [](int i, int) { return i < 32; });
  wp::Material m = wp::test::diffuse_material(vec3(1.0f));
  m.unlit = true;
  m.base_color_texture = 0;
  s.materials.push_back(m);
  wp::test::add_quad(s, {-1, 0, 0}, {1, 0, 0}, {1, 0, -8}, {-1, 0, -8}, 0);
  for (std::size_t v = 0; v < 4; ++v)
    s.uv0[v] = glm::vec2(2.0f * s.positions[v].x + 0.25f, -2.0f * s.positions[v].z);
  wp::test::finish_bounds(s);
  s.cameras = {wp::test::look_at({0.0f, 0.05f, 0.0f}, {0.0f, 0.0f, -5.0f}, 0.5f)};
  wp::RenderSettings st;
  st.width = st.height = 48;
  st.spp = 4;
  st.camera = 0;
  st.background = vec3(1.0f);
  st.sampler = wp::Sampler::kIndependent;
  for (const bool mipmaps : {true, false}) {
    SCOPED_TRACE(mipmaps ? "mip-maps" : "full resolution");
    st.mipmaps = mipmaps;
    const wp::Rendered r = wp::render(*runtime_, s, st);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    for (int y = 0; y < 48; ++y)
      for (int x = 23; x <= 24; ++x)
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(r.image.rgb[3 * (48 * y + x) + c], 1.0f, 1e-6)
              << "pixel (" << x << ", " << y << ")";
    // The floor is seen and its black stripes resolved (the rows below the middle).
    EXPECT_EQ(*std::min_element(r.image.rgb.begin(), r.image.rgb.end()), 0.0f);
  }
}

// A small closed scene with every kind of randomness: diffuse, glossy and mirror surfaces, a
// point light, emission, roulette.
wp::Scene busy_scene() {
  wp::Scene s;
  s.materials.push_back(wp::test::diffuse_material(vec3(0.7f, 0.6f, 0.5f)));
  wp::Material glossy;
  glossy.base_color = glm::vec4(0.9f, 0.5f, 0.2f, 1.0f);
  glossy.metallic = 0.5f;
  glossy.roughness = 0.3f;
  s.materials.push_back(glossy);
  wp::Material mirror;
  mirror.metallic = 1.0f;
  mirror.roughness = 0.0f;
  s.materials.push_back(mirror);
  wp::Material lamp = wp::test::diffuse_material(vec3(0.0f));
  lamp.emission = {5.0f, 5.0f, 4.0f};
  s.materials.push_back(lamp);
  wp::test::add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
  wp::test::add_quad(s, {-2, 0, -2}, {2, 0, -2}, {2, 3, -2}, {-2, 3, -2}, 2);
  wp::test::add_sphere(s, {0.5f, 0.6f, 0.0f}, 0.6f, 24, 48, 1);
  wp::test::add_quad(s, {-0.5f, 2.5f, -0.5f}, {0.5f, 2.5f, -0.5f}, {0.5f, 2.5f, 0.5f},
                     {-0.5f, 2.5f, 0.5f}, 3);
  wp::PunctualLight l;
  l.position = {-1.0f, 1.5f, 1.0f};
  l.intensity = {2.0f, 2.0f, 2.0f};
  s.lights.push_back(l);
  wp::test::finish_bounds(s);
  s.cameras.push_back(wp::test::look_at({0.0f, 1.5f, 5.0f}, {0.0f, 0.8f, 0.0f}, 0.9f));
  return s;
}

// Same seed, same image, bit for bit, whatever the wave size and work-group size; another seed,
// another image. Each work-group size, and prefetch or packets off, is a program of its own: the
// default suite renders one of each change with Sobol' (DeterministicAcrossWaveAndGroupSizes),
// the slow tier every combination below with both samplers (...Exhaustive).
struct WaveShapeCase {
  std::size_t wave, local;
  bool prefetch, packets;
};

void expect_deterministic(wp::ClRuntime& runtime, const std::vector<wp::Sampler>& samplers,
                          const std::vector<WaveShapeCase>& cases) {
  const wp::Scene s = busy_scene();
  for (const wp::Sampler sampler : samplers) {
    SCOPED_TRACE(sampler == wp::Sampler::kSobol ? "sobol" : "independent");
    wp::RenderSettings st = settings_for(s, vec3(0.1f, 0.2f, 0.3f));
    st.sampler = sampler;
    st.spp = 4;
    st.seed = 11;
    // Shading one path per work-item: the shade packets' films are the single path's bit for bit
    // (ShadePacketsGiveTheSinglePathFilm), and each program here would build them too.
    st.shade_packets = false;
    const wp::Rendered first = wp::render(runtime, s, st);
    const auto& reference = first.image.rgb;
    // The scene has no instances, alpha or transmission, so on PoCL's CPU devices (the wide BVH)
    // the default traces shadow rays and closest-hit rays in packets: the comparisons below do
    // test both traversals. (Both take turns of packets and single rays per bounce until one is
    // found faster, Wavefront::packet_mode: a render of several waves uses both.)
    const wp::DeviceEntry& device = runtime.device();
    if (!device.gpu && device.platform_name == "Portable Computing Language") {
      EXPECT_NE(first.report.build_options.find("-D WP_SHADOW_PACKET=1"), std::string::npos)
          << first.report.build_options;
      EXPECT_NE(first.report.build_options.find("-D WP_CLOSEST_PACKET=1"), std::string::npos)
          << first.report.build_options;
    }
    double sum = 0.0;
    for (float v : reference) sum += v;
    EXPECT_GT(sum, 0.0);
    // ... and with the cache hints off (prefetch false; on PoCL they are on by default), and with
    // each shadow and closest-hit ray traced on its own (on PoCL's CPU devices they go eight to a
    // work-item by default, kernels/traversal/traverse8_packet.h, and the wave and group sizes
    // change which rays share a packet).
    for (const auto& [wave, local, prefetch, packets] : cases) {
      st.wave_size = wave;
      st.local_size = local;
      st.prefetch = prefetch;
      st.shadow_packets = st.closest_packets = packets;
      const wp::Rendered rendered = wp::render(runtime, s, st);
      const auto& image = rendered.image.rgb;
      if (!packets) {
        EXPECT_EQ(rendered.report.closest_packet, 1u);
        EXPECT_TRUE(rendered.report.closest_packets.empty());
        EXPECT_EQ(rendered.report.shadow_packet, 1u);
        EXPECT_TRUE(rendered.report.shadow_packets.empty());
      } else if (rendered.report.closest_packet > 1 && wave == 1000) {
        // Several waves (the image has more pixels x samples than 1000): the camera rays and the
        // first shadow rays of the waves after the first were timed both ways, and the report
        // says so.
        for (const auto* timing :
             {&rendered.report.closest_packets, &rendered.report.shadow_packets}) {
          ASSERT_FALSE(timing->empty());
          EXPECT_GT((*timing)[0].rays[0], 0u);
          EXPECT_GT((*timing)[0].rays[1], 0u);
        }
      }
      ASSERT_EQ(image.size(), reference.size());
      EXPECT_EQ(0, std::memcmp(image.data(), reference.data(), image.size() * sizeof(float)))
          << "wave " << wave << " local " << local << " prefetch " << prefetch << " packets "
          << packets;
    }
    st.shadow_packets = st.closest_packets = true;
    st.wave_size = 0;
    st.local_size = 0;
    st.prefetch = true;
    st.seed = 12;
    const auto other = wp::render(runtime, s, st).image.rgb;
    EXPECT_NE(0, std::memcmp(other.data(), reference.data(), other.size() * sizeof(float)));
  }
}

TEST_F(RenderKnown, DeterministicAcrossWaveAndGroupSizes) {
  expect_deterministic(
      *runtime_, {wp::Sampler::kSobol},
      {{1000, 0, true, true}, {777, 8, true, true}, {333, 1, false, true}, {0, 0, true, false}});
}

TEST_F(RenderKnown, DeterministicAcrossWaveAndGroupSizesExhaustive) {
  expect_deterministic(*runtime_, {wp::Sampler::kSobol, wp::Sampler::kIndependent},
                       {{0, 0, true, true},
                        {1000, 0, true, true},
                        {777, 8, true, true},
                        {0, 64, true, true},
                        {256, 32, true, true},
                        {333, 1, true, true},
                        {0, 256, true, true},
                        {0, 0, false, true},
                        {333, 1, false, true},
                        {0, 0, true, false},
                        {777, 8, true, false}});
}

// trace_shadow launched ahead of its queue's count (over an estimate from the wave before, then
// the rest from where that launch stopped once the count is read back: Wavefront::run_bounce)
// traces every shadow ray once: the same image bit for bit as launches over the exact count, with
// estimates far too low (the rest launched at every bounce), about right and too high to need a
// rest, with and without shadow packets, and with work-groups of 1, 32 and 64 items (the first
// launch has to stop exactly at its estimate, a whole number of work-groups).
TEST_F(RenderKnown, ShadowRaysLaunchedAheadAreEachTracedOnce) {
  const wp::Scene s = busy_scene();
  wp::RenderSettings st = settings_for(s, vec3(0.1f, 0.2f, 0.3f));
  st.sampler = wp::Sampler::kSobol;
  st.spp = 16;
  st.seed = 5;
  // Waves of two samples of the whole image (8 waves): estimates from the same pixels in the wave
  // before. A wave's first bounce queues ~920 shadow rays (counted), so an estimate of 0.3 of them
  // leaves a rest whether the launch unit is a work-group of single rays (64) or of packets
  // (64 x 8 = 512 rays), whichever the packet timing (Wavefront::time_packets, waves 2-5) picks on
  // the machine. (With waves of 1000 pixels the ~350 rays fitted one packet work-group: whether a
  // rest was launched hung on that timing.)
  st.wave_size = 2 * std::size_t(kWidth) * kHeight;
  st.shadow_ahead = 0.0f;
  st.shade_packets = false;  // shading one path per work-item, as in expect_deterministic
  const wp::Rendered exact = wp::render(*runtime_, s, st);
  EXPECT_EQ(exact.report.shadow_ahead_launches, 0u);
  const auto& reference = exact.image.rgb;
  for (const auto& [packets, local, ahead] :
       std::vector<std::tuple<bool, std::size_t, float>>{{true, 0, 0.3f},
                                                         {true, 1, 0.3f},
                                                         {false, 32, 0.3f},
                                                         {true, 0, 1.03f},
                                                         {false, 1, 1.03f},
                                                         {true, 0, 100.0f}}) {
    SCOPED_TRACE(::testing::Message()
                 << "packets " << packets << " local " << local << " ahead " << ahead);
    st.shadow_packets = packets;
    st.local_size = local;
    st.shadow_ahead = ahead;
    const wp::Rendered r = wp::render(*runtime_, s, st);
    EXPECT_GT(r.report.shadow_ahead_launches, 0u);
    if (ahead < 1.0f) {
      EXPECT_GT(r.report.shadow_rest_launches, 0u);
    } else if (ahead >= 100.0f) {
      EXPECT_EQ(r.report.shadow_rest_launches, 0u);  // over every ray
    }
    ASSERT_EQ(r.image.rgb.size(), reference.size());
    EXPECT_EQ(0,
              std::memcmp(r.image.rgb.data(), reference.data(), reference.size() * sizeof(float)));
  }
}

// The Lambertian busy scene of ShadePacketsGiveTheSinglePathFilm.
wp::Scene lambert_busy_scene() {
  wp::Scene s = busy_scene();
  s.materials[1] = wp::test::diffuse_material(vec3(0.9f, 0.5f, 0.2f));
  s.materials[2] = wp::test::diffuse_material(vec3(0.3f, 0.8f, 0.6f));
  // Lambert alone: glTF's default specular factor 1 is a dielectric layer (a glossy program).
  for (wp::Material& m : s.materials) m.specular = 0.0f;
  return s;
}

struct PacketCase {
  wp::Sampler sampler;
  wp::Strategy strategy;
  std::size_t wave;
};

// Renders `s` with shade packets and without for each case, under `env` where given (else a
// constant background), width x height pixels: the same film bit for bit.
void expect_packets_match_single_paths(
    wp::ClRuntime& runtime, const wp::Scene& s, const std::vector<PacketCase>& cases,
    const std::shared_ptr<const wp::EnvironmentMap>& env = nullptr, int width = kWidth,
    int height = kHeight) {
  for (const auto& [sampler, strategy, wave] : cases) {
    SCOPED_TRACE("sampler " + std::to_string(static_cast<int>(sampler)) + ", strategy " +
                 std::to_string(static_cast<int>(strategy)) + ", wave " + std::to_string(wave));
    wp::RenderSettings st = settings_for(s, vec3(0.1f, 0.2f, 0.3f));
    st.environment = env;
    st.width = width;
    st.height = height;
    st.sampler = sampler;
    st.strategy = strategy;
    st.wave_size = wave;
    st.spp = 4;
    const wp::Rendered packets = wp::render(runtime, s, st);
    const wp::DeviceEntry& device = runtime.device();
    if (!device.gpu && device.platform_name == "Portable Computing Language") {
      EXPECT_NE(packets.report.build_options.find("-D WP_SHADE_PACKET=1"), std::string::npos)
          << packets.report.build_options;
    }
    st.shade_packets = false;
    const wp::Rendered single = wp::render(runtime, s, st);
    EXPECT_EQ(single.report.build_options.find("WP_SHADE_PACKET"), std::string::npos);
    double sum = 0.0;
    for (float v : packets.image.rgb) sum += v;
    EXPECT_GT(sum, 0.0);
    EXPECT_TRUE(packets.film.words() == single.film.words()) << "films differ";
  }
}

// The busy scene with glTF's metallic-roughness BSDF everywhere (WP_BSDF_PLAIN): the glossy sphere
// (metallic 0.5, roughness 0.3), the smooth mirror (a delta lobe: its paths are shaded one at a
// time), a dielectric floor with specular factor 0.5 and ior 1 (F0 0), and small spheres of
// roughness just below and above the delta threshold (alpha = roughness^2 against WP_DELTA_ALPHA
// 1e-3: roughness 0.0316 and 0.0317) and of ior 3 with specular 1, so that the lanes mix every
// kind.
wp::Scene glossy_busy_scene() {
  wp::Scene s = busy_scene();
  s.materials[0].specular = 0.5f;
  s.materials[0].ior = 1.0f;
  const float roughness[] = {0.0316f, 0.0317f, 0.6f};
  for (int i = 0; i < 3; ++i) {
    wp::Material m;
    m.base_color = glm::vec4(0.3f + 0.2f * static_cast<float>(i), 0.6f, 0.4f, 1.0f);
    m.metallic = i == 2 ? 0.0f : 0.8f;
    m.roughness = roughness[i];
    m.ior = i == 2 ? 3.0f : 1.5f;
    s.materials.push_back(m);
    wp::test::add_sphere(s, {-1.2f + 0.7f * static_cast<float>(i), 0.3f, 1.0f}, 0.3f, 12, 24,
                         static_cast<std::uint32_t>(s.materials.size() - 1));
  }
  wp::test::finish_bounds(s);
  return s;
}

// The glossy busy scene textured (WP_FEATURE_TEXTURES, ray cones, normal maps, alpha: each hit is
// shade_hit's lane by lane, the light and BSDF samples in the lanes): a random 4 x 4 texture as
// the floor's base colour, the glossy sphere's metallic-roughness and normal map, and the lamp's
// emission (so that NEE toward a textured emitter is the one-path code's), and the lamp quad cut
// out where alpha < 0.5 (MASK). Every vertex takes its x-z position as uv.
wp::Scene textured_busy_scene() {
  wp::Scene s = glossy_busy_scene();
  std::vector<std::uint8_t> rgba(4 * 4 * 4);
  std::uint32_t state = 12345u;
  for (std::uint8_t& c : rgba)
    c = static_cast<std::uint8_t>((state = state * 1664525u + 1013904223u) >> 24);
  const auto add_texture = [&](bool srgb) {
    wp::Image img;
    img.width = img.height = 4;
    img.rgba = rgba;
    s.images.push_back(img);
    wp::TextureRef t;
    t.image = static_cast<int>(s.images.size() - 1);
    t.srgb = srgb;
    s.textures.push_back(t);
    return static_cast<int>(s.textures.size() - 1);
  };
  s.materials[0].base_color_texture = add_texture(true);
  s.materials[1].metallic_roughness_texture = add_texture(false);
  s.materials[1].normal_texture = add_texture(false);
  s.materials[3].emissive_texture = add_texture(true);
  s.materials[3].alpha_mode = wp::AlphaMode::kMask;
  s.materials[3].base_color_texture = add_texture(true);
  s.uv0.resize(s.positions.size());
  for (std::size_t k = 0; k < s.positions.size(); ++k)
    s.uv0[k] = {s.positions[k].x, s.positions[k].z};
  wp::test::finish_bounds(s);
  return s;
}

// A 16 x 8 environment map: a sky brighter toward the zenith, a dark ground and one bright texel,
// so that its sampling table is far from uniform (the light samples' binary searches and the
// bilinear lookups in lanes, kernels/lights/env_map.def).
std::shared_ptr<const wp::EnvironmentMap> packet_sky() {
  auto env = std::make_shared<wp::EnvironmentMap>();
  env->width = 16;
  env->height = 8;
  for (int y = 0; y < env->height; ++y)
    for (int x = 0; x < env->width; ++x) {
      const float l = (y == 2 && x == 5) ? 40.0f : y < 4 ? 0.2f + 0.1f * float(4 - y) : 0.02f;
      env->texels.emplace_back(l, 0.8f * l + 0.01f * float(x), 0.6f * l, 0.0f);
    }
  wp::build_environment_tables(*env);
  return env;
}

// In a scene of Lambertian or plain glTF surfaces (WP_BSDF_PLAIN: bsdf/glossy.def in lanes, delta
// lobes lane by lane), textured or not, the fused kernel shades eight paths per work-item on PoCL's
// CPU devices (kernels/integrator/shade_packet.h): the film must be the single-path kernel's bit
// for bit, with every kind of light sample (the lamp's triangles, the constant background and an
// environment map in SIMD lanes, the point light by the single-path function), each sampler and
// strategy, and several waves of different sizes (which paths share a packet changes nothing). The
// default suite takes the textured scene under the map with Sobol' and MIS (two programs, which
// the suite's time allows); ...Exhaustive (slow) the Lambertian scene's cases below, the textured
// scene under a constant background, the untextured glossy scene (whose surfaces the lanes
// resolve) and each sampler and strategy.
TEST_F(RenderKnown, ShadePacketsGiveTheSinglePathFilm) {
  using wp::Sampler, wp::Strategy;
  // Rows not a multiple of eight pixels, so that camera-ray packets span two rows (start_paths8
  // counts pixels on from the first one's), and waves of two samples of the image (a packet across
  // the samples' boundary), of 1000 and of 8 paths.
  expect_packets_match_single_paths(*runtime_, textured_busy_scene(),
                                    {{Sampler::kSobol, Strategy::kMis, 2 * 61 * 37},
                                     {Sampler::kSobol, Strategy::kMis, 1000},
                                     {Sampler::kSobol, Strategy::kMis, 8}},
                                    packet_sky(), 61, 37);
}

// The Lambertian cases of the shade packets (ShadePacketsGiveTheSinglePathFilmExhaustive).
void expect_lambert_packets_match_single_paths(wp::ClRuntime& runtime) {
  wp::Scene s = lambert_busy_scene();
  // Rows not a multiple of eight pixels, so that camera-ray packets span two rows (start_paths8
  // counts pixels on from the first one's), and waves of two samples of the image (a packet across
  // the samples' boundary), of 1000 and of 8 paths: 61 x 37, with a wall behind everything, a
  // light before it and a black background, so that every pixel, and those just past the image's
  // edges, sees a surface whose light depends on where it is (a ray into another pixel changes
  // the film; under a constant sky a plane's points all look alike for the same numbers).
  wp::Scene walled = s;
  wp::test::add_quad(walled, {-50, -50, -3}, {50, -50, -3}, {50, 50, -3}, {-50, 50, -3}, 0);
  wp::PunctualLight front;
  front.position = {0.0f, 1.5f, 4.0f};
  front.intensity = {3.0f, 3.0f, 3.0f};
  walled.lights.push_back(front);
  wp::test::finish_bounds(walled);
  for (const std::size_t wave : {std::size_t(2 * 61 * 37), std::size_t(1000), std::size_t(8)}) {
    SCOPED_TRACE("61 x 37, wave " + std::to_string(wave));
    wp::RenderSettings st = settings_for(walled, vec3(0.0f));
    st.sampler = wp::Sampler::kSobol;  // camera packets draw the Sobol' jitter in the lanes
    st.width = 61;
    st.height = 37;
    st.spp = 2;
    st.wave_size = wave;
    const wp::Rendered packets = wp::render(runtime, walled, st);
    st.shade_packets = false;
    const wp::Rendered single = wp::render(runtime, walled, st);
    EXPECT_TRUE(packets.film.words() == single.film.words()) << "films differ";
  }
  // Past WP_LIGHT_PICK_REUSE_MAX (64) lights the pick takes a number of its own (lights.h), which
  // the lanes otherwise leave out: 40 more lamp quads, 80 triangles.
  for (int i = 0; i < 40; ++i) {
    const float x = -1.9f + 0.095f * static_cast<float>(i);
    wp::test::add_quad(s, {x, 2.9f, -1.9f}, {x + 0.05f, 2.9f, -1.9f}, {x + 0.05f, 2.9f, -1.8f},
                       {x, 2.9f, -1.8f}, 3);
  }
  wp::test::finish_bounds(s);
  wp::RenderSettings st = settings_for(s, vec3(0.1f, 0.2f, 0.3f));
  st.sampler = wp::Sampler::kSobol;  // the lanes' numbers (the independent sampler's are per path)
  st.spp = 4;
  st.wave_size = 1000;
  const wp::Rendered packets = wp::render(runtime, s, st);
  st.shade_packets = false;
  const wp::Rendered single = wp::render(runtime, s, st);
  EXPECT_TRUE(packets.film.words() == single.film.words()) << "films differ, many lights";
}

TEST_F(RenderKnown, ShadePacketsGiveTheSinglePathFilmExhaustive) {
  using wp::Sampler, wp::Strategy;
  expect_lambert_packets_match_single_paths(*runtime_);
  expect_packets_match_single_paths(
      *runtime_, textured_busy_scene(),
      {{Sampler::kIndependent, Strategy::kMis, 0}, {Sampler::kSobol, Strategy::kMis, 1000}});
  expect_packets_match_single_paths(*runtime_, glossy_busy_scene(),
                                    {{Sampler::kSobol, Strategy::kMis, 1000},
                                     {Sampler::kSobol, Strategy::kNee, 0},
                                     {Sampler::kSobol, Strategy::kBsdf, 1000},
                                     {Sampler::kSobolPadded, Strategy::kMis, 1000},
                                     {Sampler::kIndependent, Strategy::kMis, 0}});
  expect_packets_match_single_paths(*runtime_, lambert_busy_scene(),
                                    {{Sampler::kSobol, Strategy::kMis, 1000},
                                     {Sampler::kSobol, Strategy::kNee, 0},
                                     {Sampler::kSobol, Strategy::kBsdf, 1000},
                                     {Sampler::kSobolPadded, Strategy::kMis, 1000},
                                     {Sampler::kIndependent, Strategy::kMis, 0}});
}

// The fused shading kernel (kernels/shade.cl) runs the split stages' functions in the same order
// per path with the same random numbers, so it must give their image bit for bit: with every
// feature built, AOVs on and off, each sampler, and a thin glass pane (transmission's shadow-ray
// path) added to the busy scene. Each case is two programs with every feature: the default suite
// renders one (Sobol', AOVs on), ...Exhaustive (slow) all four.
void expect_fused_equals_split(wp::ClRuntime& runtime,
                               const std::vector<std::pair<wp::Sampler, bool>>& cases) {
  wp::Scene s = busy_scene();
  s.materials.push_back(wp::test::glass_material(false));
  wp::test::add_quad(s, {-1.5f, 0.2f, 1.0f}, {-0.2f, 0.2f, 1.0f}, {-0.2f, 1.6f, 1.0f},
                     {-1.5f, 1.6f, 1.0f}, static_cast<std::uint32_t>(s.materials.size() - 1));
  wp::test::finish_bounds(s);
  for (const auto& [sampler, aov] : cases) {
    SCOPED_TRACE(std::string(sampler == wp::Sampler::kSobol ? "sobol" : "independent") +
                 (aov ? ", aov" : ""));
    wp::RenderSettings st = settings_for(s, vec3(0.1f, 0.2f, 0.3f));
    st.sampler = sampler;
    st.aov = aov;
    st.all_features = true;
    st.spp = 4;
    const wp::Rendered fused = wp::render(runtime, s, st);
    st.fused = false;
    const wp::Rendered split = wp::render(runtime, s, st);
    double sum = 0.0;
    for (float v : fused.image.rgb) sum += v;
    EXPECT_GT(sum, 0.0);
    ASSERT_EQ(fused.image.rgb.size(), split.image.rgb.size());
    EXPECT_EQ(0, std::memcmp(fused.image.rgb.data(), split.image.rgb.data(),
                             fused.image.rgb.size() * sizeof(float)));
    EXPECT_TRUE(fused.film.words() == split.film.words()) << "films differ";
  }
}

TEST_F(RenderKnown, FusedAndSplitShadingAreBitIdentical) {
  expect_fused_equals_split(*runtime_, {{wp::Sampler::kSobol, true}});
}

TEST_F(RenderKnown, FusedAndSplitShadingAreBitIdenticalExhaustive) {
  expect_fused_equals_split(*runtime_, {{wp::Sampler::kSobol, false},
                                        {wp::Sampler::kSobol, true},
                                        {wp::Sampler::kIndependent, false},
                                        {wp::Sampler::kIndependent, true}});
}

}  // namespace
