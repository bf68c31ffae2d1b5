// kernel tier: texture sampling (kernels/texture/textures.h), alpha (kernels/traversal/alpha.h) and
// material resolution (kernels/geom/material.h) on the OpenCL device, against host references
// written here from the glTF 2.0 specification (its samplers follow OpenGL: texel centres at (i +
// 0.5) / size, wrap modes on texel indices, NEAREST or bilinear LINEAR magnification) and the sRGB
// standard, over scenes packed by host/device/device_scene.cpp exactly as renders are. The
// references compute in double.
//
// Tolerances are float rounding bounds, derived where they are used (texture_bound()). Bilinear
// filtering is 1-Lipschitz in the texel-space position per axis (texel values lie in [0, 1]), so
// an error dx in the position moves the result by at most dx; NEAREST filtering is not continuous,
// so samples closer than that bound to a texel border are left out (and counted: under 1%).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <stdexcept>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "host/device/device_scene.h"
#include "host/lights/light_table.h"
#include "host/scene/mipmap.h"
#include "host/scene/srgb.h"
#include "tests/kernel_harness.h"

namespace {

using wp::dev::float4;
using wp::dev::uint4;
using Rgba = std::array<double, 4>;

wp::test::KernelHarness& harness() {
  static wp::test::KernelHarness h({"texture_kernels.cl"});
  return h;
}

// s packed as renders pack it, with mip chains (SceneExtras::mipmaps) or without.
wp::SceneBuffers upload(const wp::Scene& s, wp::test::KernelHarness& h = harness(),
                        bool mipmaps = false, const wp::dev::Camera& camera = {}) {
  const wp::LightTable lights;
  wp::SceneExtras extras;
  extras.lights = &lights;
  extras.mipmaps = mipmaps;
  extras.camera = camera;
  const wp::PackedScene p = wp::pack_scene(s, wp::bvh::Bvh{}, extras);
  // The test program is built without WP_SCENE_BUFFER_MAP: everything in buffer 0.
  if (p.buffers.size() != 1) throw std::logic_error("test scene split over several buffers");
  return wp::upload_scene(h.runtime().context(), p);
}

float4 f4(glm::vec4 v) {
  return {v.x, v.y, v.z, v.w};
}

wp::Image image_of(int w, int h, std::vector<std::uint8_t> rgba) {
  wp::Image img;
  img.width = w;
  img.height = h;
  img.rgba = std::move(rgba);
  return img;
}

wp::Image random_image(int w, int h, std::mt19937& rng) {
  std::vector<std::uint8_t> rgba(std::size_t(4 * w * h));
  for (std::uint8_t& c : rgba) c = static_cast<std::uint8_t>(rng() & 0xffu);
  return image_of(w, h, rgba);
}

// A unit square in the z = 0 plane facing +z: corners (0,0), (1,0), (1,1), (0,1) as triangles
// (0,1,2) and (0,2,3). TEXCOORD_0 = (x, 1 - y) (glTF's v runs down the image: seen from +z the
// image is upright), TEXCOORD_1 = (2x, y); tangent +x with handedness w. A point (x, y) with
// x >= y lies on the first triangle at barycentrics u = x - y, v = y.
void add_square(wp::Scene& s, std::uint32_t material, float w = 1.0f,
                glm::vec4 color = glm::vec4(1.0f)) {
  const auto base = static_cast<std::uint32_t>(s.positions.size());
  for (const glm::vec2 p : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)}) {
    s.positions.emplace_back(p, 0.0f);
    s.normals.emplace_back(0.0f, 0.0f, 1.0f);
    s.uv0.emplace_back(p.x, 1.0f - p.y);
    s.uv1.emplace_back(2.0f * p.x, p.y);
    s.color0.push_back(color);
    s.tangents.emplace_back(1.0f, 0.0f, 0.0f, w);
  }
  for (const std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) s.indices.push_back(base + i);
  s.triangle_material.insert(s.triangle_material.end(), {material, material});
}

int add_texture(wp::Scene& s, wp::Image image, bool srgb, bool nearest = true) {
  s.images.push_back(std::move(image));
  wp::TextureRef t;
  t.image = static_cast<int>(s.images.size() - 1);
  t.srgb = srgb;
  t.nearest = nearest;
  s.textures.push_back(t);
  return static_cast<int>(s.textures.size() - 1);
}

// ---------------------------------------------------------------------------------------------
// Host reference (glTF 2.0 / OpenGL sampling, sRGB EOTF of IEC 61966-2-1)

double srgb_eotf(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// OpenGL's wrap of texel index i into [0, n).
long long wrap_index(long long i, long long n, wp::Wrap mode) {
  const auto mod = [](long long a, long long m) { return ((a % m) + m) % m; };
  const auto mirror = [](long long a) { return a >= 0 ? a : -(1 + a); };
  switch (mode) {
    case wp::Wrap::kClampToEdge:
      return std::clamp(i, 0LL, n - 1);
    case wp::Wrap::kMirroredRepeat:
      return (n - 1) - mirror(mod(i, 2 * n) - n);
    default:
      return mod(i, n);
  }
}

Rgba texel(const wp::Image& img, long long i, long long j, bool srgb) {
  Rgba c{};
  for (int k = 0; k < 4; ++k) c[k] = img.rgba[std::size_t(4 * (j * img.width + i) + k)] / 255.0;
  if (srgb)
    for (int k = 0; k < 3; ++k) c[k] = srgb_eotf(c[k]);
  return c;
}

// The transformed coordinates (u', v') of texture t at uv01, in double.
glm::dvec2 transformed(const wp::TextureRef& t, glm::vec4 uv01) {
  const glm::dvec2 uv = t.texcoord == 1 ? glm::dvec2(uv01.z, uv01.w) : glm::dvec2(uv01.x, uv01.y);
  return {t.row_u.x * uv.x + t.row_u.y * uv.y + double(t.row_u.z),
          t.row_v.x * uv.x + t.row_v.y * uv.y + double(t.row_v.z)};
}

// Texture t at uv01 as if its image were `img` (a mip level of it, for the trilinear references).
Rgba reference_sample_image(const wp::Image& img, const wp::TextureRef& t, glm::vec4 uv01,
                            bool nearest) {
  const glm::dvec2 p = transformed(t, uv01) * glm::dvec2(img.width, img.height);
  if (nearest)
    return texel(img, wrap_index(std::llround(std::floor(p.x)), img.width, t.wrap_s),
                 wrap_index(std::llround(std::floor(p.y)), img.height, t.wrap_t), t.srgb);
  const glm::dvec2 q = p - 0.5, q0 = glm::floor(q), a = q - q0;
  const long long i0 = std::llround(q0.x), j0 = std::llround(q0.y);
  Rgba out{};
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) {
      const Rgba c = texel(img, wrap_index(i0 + di, img.width, t.wrap_s),
                           wrap_index(j0 + dj, img.height, t.wrap_t), t.srgb);
      const double w = (di ? a.x : 1.0 - a.x) * (dj ? a.y : 1.0 - a.y);
      for (int k = 0; k < 4; ++k) out[k] += w * c[k];
    }
  return out;
}

Rgba reference_sample(const wp::Scene& s, const wp::TextureRef& t, glm::vec4 uv01) {
  return reference_sample_image(s.images[std::size_t(t.image)], t, uv01, t.nearest);
}

// Bound on the device's error in the texel-space position (x, y), from its float arithmetic:
// u' = a u + b v + c rounds three times (relative 2^-24 each, of partial sums at most
// |a u| + |b v| + |c|); moving u' by whole wrap periods costs at most 2^-23 (half an ulp of 2);
// scaling by the width and subtracting 0.5 another 2^-23 of the width. Per axis, in texels.
glm::dvec2 position_bound(const wp::Scene& s, const wp::TextureRef& t, glm::vec4 uv01) {
  const wp::Image& img = s.images[std::size_t(t.image)];
  const glm::dvec2 uv = t.texcoord == 1 ? glm::dvec2(uv01.z, uv01.w) : glm::dvec2(uv01.x, uv01.y);
  const double su = std::abs(t.row_u.x * uv.x) + std::abs(t.row_u.y * uv.y) + std::abs(t.row_u.z);
  const double sv = std::abs(t.row_v.x * uv.x) + std::abs(t.row_v.y * uv.y) + std::abs(t.row_v.z);
  const double e = std::ldexp(1.0, -22);
  return {img.width * (e * su + e), img.height * (e * sv + e)};
}

// texture_sample's tolerance at a sample: the position bound (1-Lipschitz filtering) plus 8e-6
// for the texel arithmetic (bilinear weights: a few ulp of 1) and the sRGB decode (pow: at most
// 16 ulp in OpenCL, about 1e-6, amplified by 2.4 for the rounding of its argument).
double texture_bound(const glm::dvec2& position_error, bool nearest) {
  return (nearest ? 0.0 : position_error.x + position_error.y) + 8e-6;
}

// Whether NEAREST sampling at p (texel space) is ambiguous within the position bound.
bool near_border(const glm::dvec2& p, const glm::dvec2& bound) {
  return std::abs(p.x - std::round(p.x)) <= bound.x || std::abs(p.y - std::round(p.y)) <= bound.y;
}

std::vector<float4> sample(const wp::SceneBuffers& d, const std::vector<int>& refs,
                           const std::vector<float4>& uvs) {
  auto& h = harness();
  const cl::Buffer r = h.buffer(refs), u = h.buffer(uvs), out = h.buffer<float4>(uvs.size());
  h.run("sample_textures", uvs.size(), d, r, u, cl_uint(uvs.size()), out);
  return h.read<float4>(out, uvs.size());
}

// ---------------------------------------------------------------------------------------------
// texture_sample

struct Transform {
  glm::vec3 u, v;
  int texcoord;
};

// A texture of each of s's images for every wrap pair, magnification filter, encoding and
// transform.
void add_every_sampler(wp::Scene& s, const std::vector<Transform>& transforms) {
  const wp::Wrap wraps[] = {wp::Wrap::kRepeat, wp::Wrap::kClampToEdge, wp::Wrap::kMirroredRepeat};
  for (int image = 0; image < int(s.images.size()); ++image)
    for (const wp::Wrap ws : wraps)
      for (const wp::Wrap wt : wraps)
        for (const bool nearest : {false, true})
          for (const bool srgb : {false, true})
            for (const Transform& x : transforms)
              s.textures.push_back({image, ws, wt, nearest, srgb, x.texcoord, x.u, x.v});
}

// Every wrap pair, both filters, both encodings and three transforms (identity; a general affine
// map; another on TEXCOORD_1) on three images (7x5, 1x1, 2x3), at uvs in [-2, 3] and, for half of
// them, in [-100, 100].
TEST(TextureSample, MatchesReference) {
  std::mt19937 rng(11);
  wp::Scene s;
  s.images = {random_image(7, 5, rng), random_image(1, 1, rng), random_image(2, 3, rng)};
  add_every_sampler(s, {{{1, 0, 0}, {0, 1, 0}, 0},
                        {{0.8f, -1.3f, 0.25f}, {1.1f, 0.6f, -0.4f}, 0},
                        {{-2.5f, 0.3f, 1.5f}, {0.2f, 3.0f, 0.75f}, 1}});

  constexpr int kPerRef = 600;
  std::uniform_real_distribution<float> near_range(-2.0f, 3.0f), far_range(-100.0f, 100.0f);
  std::vector<int> refs;
  std::vector<float4> uvs;
  for (std::size_t r = 0; r < s.textures.size(); ++r)
    for (int k = 0; k < kPerRef; ++k) {
      auto& d = k % 2 ? far_range : near_range;
      refs.push_back(static_cast<int>(r));
      uvs.push_back({d(rng), d(rng), d(rng), d(rng)});
    }
  const std::vector<float4> got = sample(upload(s), refs, uvs);

  std::size_t failures = 0, skipped = 0, nearest_count = 0;
  for (std::size_t i = 0; i < uvs.size(); ++i) {
    const wp::TextureRef& t = s.textures[std::size_t(refs[i])];
    const glm::vec4 uv(uvs[i].x, uvs[i].y, uvs[i].z, uvs[i].w);
    const glm::dvec2 bound = position_bound(s, t, uv);
    if (t.nearest) {
      ++nearest_count;
      const wp::Image& img = s.images[std::size_t(t.image)];
      if (near_border(transformed(t, uv) * glm::dvec2(img.width, img.height), bound)) {
        ++skipped;
        continue;
      }
    }
    const Rgba want = reference_sample(s, t, uv);
    const float* g = &got[i].x;
    const double tol = texture_bound(bound, t.nearest);
    for (int k = 0; k < 4; ++k) {
      if (std::abs(g[k] - want[k]) <= tol) continue;
      if (++failures <= 10)
        ADD_FAILURE() << "ref " << refs[i] << " uv (" << uv.x << ", " << uv.y << ", " << uv.z
                      << ", " << uv.w << ") channel " << k << ": " << g[k] << " vs " << want[k]
                      << " (tolerance " << tol << ")";
      break;
    }
  }
  EXPECT_EQ(failures, 0u) << "of " << uvs.size() << " samples";
  EXPECT_LT(skipped, nearest_count / 100) << "NEAREST samples too close to a texel border";
}

// All 256 sRGB-encoded values through the sampler (NEAREST at texel centres of a 256 x 1 image):
// the exact EOTF, not a gamma curve, within 3e-6 relative (OpenCL's pow: 16 ulp, plus the
// rounding of its argument); alpha and linear textures pass through as value / 255.
TEST(TextureSample, SrgbDecodeIsExact) {
  std::vector<std::uint8_t> rgba;
  for (int i = 0; i < 256; ++i)
    rgba.insert(rgba.end(),
                {std::uint8_t(i), std::uint8_t(255 - i), std::uint8_t(i), std::uint8_t(i)});
  wp::Scene s;
  const int srgb = add_texture(s, image_of(256, 1, rgba), true);
  wp::TextureRef linear = s.textures[std::size_t(srgb)];
  linear.srgb = false;
  s.textures.push_back(linear);
  std::vector<int> refs;
  std::vector<float4> uvs;
  for (int r = 0; r < 2; ++r)
    for (int i = 0; i < 256; ++i) {
      refs.push_back(r);
      uvs.push_back({(static_cast<float>(i) + 0.5f) / 256.0f, 0.5f, 0.0f, 0.0f});
    }
  const std::vector<float4> got = sample(upload(s), refs, uvs);
  for (int i = 0; i < 256; ++i) {
    const float4 e = got[std::size_t(i)], l = got[std::size_t(256 + i)];
    const double c = i / 255.0, c2 = (255 - i) / 255.0;
    EXPECT_NEAR(e.x, srgb_eotf(c), 3e-6 * srgb_eotf(c)) << i;
    EXPECT_NEAR(e.y, srgb_eotf(c2), 3e-6 * srgb_eotf(c2)) << i;
    EXPECT_NEAR(e.w, c, 1e-7) << i;
    EXPECT_NEAR(l.x, c, 1e-7) << i;
    EXPECT_NEAR(l.y, c2, 1e-7) << i;
  }
  // Spot values of the standard: 0.5 encoded is 0.21404 linear; 10/255 is on the linear segment.
  EXPECT_NEAR(srgb_eotf(0.5), 0.214041, 1e-6);
  EXPECT_NEAR(got[10].x, 10.0 / 255.0 / 12.92, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Alpha (alpha.h)

struct AlphaResult {
  float alpha;
  bool passes;
};

std::vector<AlphaResult> alpha_queries(const wp::SceneBuffers& d,
                                       const std::vector<uint4>& queries) {
  auto& h = harness();
  const cl::Buffer q = h.buffer(queries), out = h.buffer<float4>(queries.size());
  h.run("alpha_queries", queries.size(), d, q, cl_uint(queries.size()), out);
  std::vector<AlphaResult> r;
  for (const float4& f : h.read<float4>(out, queries.size())) r.push_back({f.x, f.y != 0.0f});
  return r;
}

uint4 alpha_query(std::uint32_t tri, float u, float v, std::uint32_t key = 0) {
  std::uint32_t bu, bv;
  std::memcpy(&bu, &u, 4);
  std::memcpy(&bv, &v, 4);
  return {tri, bu, bv, key};
}

wp::Material alpha_material(wp::AlphaMode mode, float alpha, float cutoff = 0.5f) {
  wp::Material m;
  m.alpha_mode = mode;
  m.base_color.a = alpha;
  m.alpha_cutoff = cutoff;
  return m;
}

// MASK: present exactly where alpha >= alphaCutoff, alpha = factor x texture x vertex alpha.
// Square 0: factor 0.8 x texture alpha 159|160 (left|right half, NEAREST) x vertex alpha 1,
// cutoff 0.5: 0.8 x 159/255 = 0.4988 is cut away, 0.8 x 160/255 = 0.5020 stays. Square 1: factor
// alpha exactly the cutoff 0.3 at a vertex (alpha is exactly 0.3 there): present; square 2: the
// same with the cutoff one float above: absent. Square 3: vertex alpha 0.25 under factor 1,
// cutoff 0.25: present. Square 4: OPAQUE with alpha 0: always present.
TEST(Alpha, MaskIsExact) {
  wp::Scene s;
  s.materials = {alpha_material(wp::AlphaMode::kMask, 0.8f),
                 alpha_material(wp::AlphaMode::kMask, 0.3f, 0.3f),
                 alpha_material(wp::AlphaMode::kMask, 0.3f, std::nextafter(0.3f, 1.0f)),
                 alpha_material(wp::AlphaMode::kMask, 1.0f, 0.25f),
                 alpha_material(wp::AlphaMode::kOpaque, 0.0f)};
  s.materials[0].base_color_texture =
      add_texture(s, image_of(2, 1, {255, 255, 255, 159, 255, 255, 255, 160}), true);
  for (std::uint32_t m = 0; m < 5; ++m)
    add_square(s, m, 1.0f, glm::vec4(1, 1, 1, m == 3 ? 0.25f : 1));
  const std::vector<AlphaResult> r =
      alpha_queries(upload(s), {alpha_query(0, 0.2f, 0.1f), alpha_query(0, 0.6f, 0.3f),
                                alpha_query(2, 0.0f, 0.0f), alpha_query(4, 0.0f, 0.0f),
                                alpha_query(6, 0.3f, 0.2f), alpha_query(8, 0.3f, 0.2f)});
  EXPECT_NEAR(r[0].alpha, 0.8 * 159 / 255, 1e-6);  // x = 0.3: left texel
  EXPECT_FALSE(r[0].passes);
  EXPECT_NEAR(r[1].alpha, 0.8 * 160 / 255, 1e-6);  // x = 0.9: right texel
  EXPECT_TRUE(r[1].passes);
  EXPECT_EQ(r[2].alpha, 0.3f);
  EXPECT_TRUE(r[2].passes);
  EXPECT_FALSE(r[3].passes);
  EXPECT_NEAR(r[4].alpha, 0.25f, 1e-7);
  EXPECT_EQ(r[4].passes, r[4].alpha >= 0.25f);
  EXPECT_TRUE(r[5].passes);
}

// BLEND: over N keys a triangle of alpha a is present k ~ Binomial(N, a) times; |k - N a| must
// stay within 5 standard deviations sqrt(N a (1 - a)) (a false alarm about 6e-7 per check).
// a = 0 and a = 1 are exact (never, always). Along one ray (same key) two layers must be
// independent, both present with probability a x 0.5, or compositing would be wrong.
TEST(Alpha, BlendFrequency) {
  const float alphas[] = {0.0f, 0.1f, 0.37f, 0.5f, 0.9f, 1.0f};
  wp::Scene s;
  for (std::uint32_t m = 0; m < 6; ++m) {
    s.materials.push_back(alpha_material(wp::AlphaMode::kBlend, alphas[m]));
    add_square(s, m);
  }
  s.materials.push_back(alpha_material(wp::AlphaMode::kBlend, 0.5f));
  add_square(s, 6);
  const wp::SceneBuffers d = upload(s);
  auto& h = harness();
  constexpr std::uint32_t kN = 1u << 20;
  for (std::uint32_t m = 0; m < 6; ++m) {
    const cl::Buffer counts = h.buffer(std::vector<cl_uint>{0, 0});
    h.run("alpha_frequency", kN, d, cl_uint(2 * m), cl_uint(12), cl_uint(kN), counts);
    const std::vector<cl_uint> c = h.read<cl_uint>(counts, 2);
    const double a = alphas[m], n = kN;
    EXPECT_NEAR(c[0], n * a, 5.0 * std::sqrt(n * a * (1.0 - a))) << "alpha " << a;
    EXPECT_NEAR(c[1], n * a * 0.5, 5.0 * std::sqrt(n * a * 0.5 * (1.0 - a * 0.5)))
        << "joint, alpha " << a;
  }
}

// ---------------------------------------------------------------------------------------------
// Material resolution (material.h)

struct Resolved {
  glm::vec3 ns, color, emission;
  bool front;
  float metallic, roughness, transmission;
};

// resolve_surface on triangle `tri` at the point (x, y) of its square (x >= y: the first
// triangle), hit by a ray with direction d.
struct SurfaceQuery {
  std::uint32_t tri;
  glm::vec2 point;
  glm::vec3 d;
};

std::vector<Resolved> resolve(const wp::SceneBuffers& d, const std::vector<SurfaceQuery>& queries,
                              wp::test::KernelHarness& h = harness()) {
  std::vector<float4> q, rays;
  for (const SurfaceQuery& x : queries) {
    float tri;
    std::memcpy(&tri, &x.tri, 4);
    q.push_back({tri, x.point.x - x.point.y, x.point.y, 0.0f});
    rays.push_back(f4(glm::vec4(glm::normalize(x.d), 0.0f)));
  }
  const cl::Buffer qb = h.buffer(q), rb = h.buffer(rays), out = h.buffer<float4>(4 * q.size());
  h.run("resolve_surfaces", q.size(), d, qb, rb, cl_uint(q.size()), out);
  const std::vector<float4> o = h.read<float4>(out, 4 * q.size());
  std::vector<Resolved> r;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const float4 *a = &o[4 * i], *b = a + 1, *c = a + 2, *e = a + 3;
    r.push_back({{a->x, a->y, a->z},
                 {b->x, b->y, b->z},
                 {e->x, e->y, e->z},
                 a->w != 0.0f,
                 b->w,
                 c->x,
                 c->y});
  }
  return r;
}

::testing::AssertionResult near3(glm::dvec3 a, glm::dvec3 b, double tol) {
  if (glm::length(a - b) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") vs ("
                                       << b.x << ", " << b.y << ", " << b.z << ")";
}

// Square 0: every texture times its factor, times the vertex colour (0.9, 0.8, 0.7). Base colour
// sRGB (200, 100, 50) x (0.5, 1, 0.8); metallic-roughness (B = 64: metallic, G = 128: roughness)
// x (0.5, 0.8); emissive sRGB (255, 128, 0) x (2, 3, 4); transmission R = 51 x 0.5. Square 1: the
// same factors, no textures. Tolerance 1e-5: the sRGB decode (3e-6 relative) and a few roundings.
wp::Scene textured_scene() {
  wp::Scene s;
  wp::Material m;
  m.base_color = glm::vec4(0.5f, 1.0f, 0.8f, 1.0f);
  m.metallic = 0.5f;
  m.roughness = 0.8f;
  m.emission = glm::vec3(2, 3, 4);
  m.transmission = 0.5f;
  s.materials = {m, m};
  wp::Material& t = s.materials[0];
  t.base_color_texture = add_texture(s, image_of(1, 1, {200, 100, 50, 255}), true);
  t.metallic_roughness_texture = add_texture(s, image_of(1, 1, {0, 128, 64, 255}), false);
  t.emissive_texture = add_texture(s, image_of(1, 1, {255, 128, 0, 255}), true);
  t.transmission_texture = add_texture(s, image_of(1, 1, {51, 0, 0, 255}), false);
  for (std::uint32_t i = 0; i < 2; ++i) add_square(s, i, 1.0f, glm::vec4(0.9f, 0.8f, 0.7f, 1.0f));
  return s;
}

TEST(Material, TexturesMultiplyFactors) {
  const std::vector<Resolved> r = resolve(
      upload(textured_scene()), {{0, {0.6f, 0.3f}, {0, 0, -1}}, {2, {0.6f, 0.3f}, {0, 0, -1}}});
  const glm::dvec3 vertex(0.9, 0.8, 0.7), factor(0.5, 1.0, 0.8);
  const glm::dvec3 tex(srgb_eotf(200 / 255.0), srgb_eotf(100 / 255.0), srgb_eotf(50 / 255.0));
  EXPECT_TRUE(near3(r[0].color, factor * tex * vertex, 1e-5));
  EXPECT_NEAR(r[0].metallic, 0.5 * 64 / 255, 1e-6);
  EXPECT_NEAR(r[0].roughness, 0.8 * 128 / 255, 1e-6);
  EXPECT_NEAR(r[0].transmission, 0.5 * 51 / 255, 1e-6);
  EXPECT_TRUE(near3(r[0].emission, glm::dvec3(2, 3 * srgb_eotf(128 / 255.0), 0), 1e-5));
  EXPECT_TRUE(near3(r[1].color, factor * vertex, 1e-6));
  EXPECT_EQ(r[1].metallic, 0.5f);
  EXPECT_EQ(r[1].roughness, 0.8f);
  EXPECT_EQ(r[1].transmission, 0.5f);
  EXPECT_TRUE(near3(r[1].emission, glm::dvec3(2, 3, 4), 1e-6));
}

// Built without texture support (a scene without textures), the same program resolves factors
// only: the texture code is compiled out, the rest unchanged.
TEST(Material, WithoutTextureFeatures) {
  wp::test::KernelHarness h({"texture_kernels.cl"},
                            "-D WP_FEATURE_TEXTURES=0 -D WP_FEATURE_NORMAL_MAPS=0");
  const std::vector<Resolved> r =
      resolve(upload(textured_scene(), h), {{0, {0.6f, 0.3f}, {0, 0, -1}}}, h);
  EXPECT_TRUE(near3(r[0].color, glm::dvec3(0.45, 0.8, 0.56), 1e-6));
  EXPECT_EQ(r[0].metallic, 0.5f);
  EXPECT_TRUE(near3(r[0].emission, glm::dvec3(2, 3, 4), 1e-6));
  EXPECT_TRUE(near3(r[0].ns, glm::dvec3(0, 0, 1), 1e-6));
}

// Normal maps. The square's frame: tangent +x, normal +z, bitangent cross(n, t) w = w (+y); its
// TEXCOORD_0 runs v down the image, so with w = +1 the map's green (+Y) points to the image's up,
// +y, as glTF requires. Expected: normalize(t x s + b y s + n z), (x, y, z) = texel * 2 / 255 - 1,
// s the normal scale; on the back of a double-sided square, the negation of the front's.
glm::dvec3 mapped(glm::ivec3 texel, double scale, double w) {
  const glm::dvec3 c = glm::dvec3(texel) * (2.0 / 255.0) - 1.0;
  return glm::normalize(glm::dvec3(c.x * scale, c.y * scale * w, c.z));
}

TEST(Material, NormalMapping) {
  struct Case {
    glm::ivec3 texel;
    float w, scale;
  };
  const Case cases[] = {{{128, 128, 255}, 1, 1},  {{128, 128, 255}, -1, 1},
                        {{128, 218, 218}, 1, 1},  {{128, 218, 218}, -1, 1},
                        {{218, 128, 218}, -1, 1}, {{128, 218, 218}, 1, 0.5f}};
  wp::Scene s;
  for (std::uint32_t i = 0; i < 6; ++i) {
    wp::Material m;
    m.double_sided = true;
    m.normal_scale = cases[i].scale;
    const glm::ivec3 c = cases[i].texel;
    m.normal_texture = add_texture(
        s, image_of(1, 1, {std::uint8_t(c.x), std::uint8_t(c.y), std::uint8_t(c.z), 255}), false);
    s.materials.push_back(m);
    add_square(s, i, cases[i].w);
  }
  // Seen roughly along the mapped normal, from the front and from the back, so that the mirror
  // reflection stays above the surface and keep_reflection_above leaves the normal alone.
  std::vector<SurfaceQuery> q;
  for (std::uint32_t i = 0; i < 6; ++i) {
    const glm::vec3 n(mapped(cases[i].texel, cases[i].scale, cases[i].w));
    q.push_back({2 * i, {0.6f, 0.3f}, -n + glm::vec3(0.05f, 0.03f, 0.0f)});
    q.push_back({2 * i, {0.6f, 0.3f}, n + glm::vec3(0.05f, 0.03f, 0.0f)});
  }
  const std::vector<Resolved> r = resolve(upload(s), q);
  for (std::size_t i = 0; i < 6; ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    const glm::dvec3 want = mapped(cases[i].texel, cases[i].scale, cases[i].w);
    EXPECT_TRUE(r[2 * i].front);
    EXPECT_TRUE(near3(r[2 * i].ns, want, 1e-5));
    EXPECT_FALSE(r[2 * i + 1].front);
    EXPECT_TRUE(near3(r[2 * i + 1].ns, -want, 1e-5));
  }
  // Flat (128, 128, 255) is unchanged up to 8-bit quantisation: 128 encodes 1/255, not 0, a tilt
  // of atan(sqrt(2) / 254) = 0.319 degrees.
  for (const std::size_t i : {0u, 1u}) EXPECT_LT(std::acos(std::min(1.0f, r[i * 2].ns.z)), 0.00557);
  // (128, 218, 218) tilts by atan(0.7098 / 0.7098) = 45 degrees toward +y with w = +1 and toward
  // -y with w = -1; (218, 128, 218) toward +x whatever w.
  const double tilt = std::atan2(2.0 * 218 / 255 - 1, 2.0 * 218 / 255 - 1);
  EXPECT_NEAR(std::acos(r[4].ns.z), tilt, 1e-3);
  EXPECT_GT(r[4].ns.y, 0.7f);
  EXPECT_LT(r[6].ns.y, -0.7f);
  EXPECT_GT(r[8].ns.x, 0.7f);
}

// A 45-degree tilt toward +y seen from the -y side: the mirror reflection about the mapped normal
// would point below the surface. The normal is bent toward the geometric normal until the
// reflection is 0.01 above the tangent plane.
TEST(Material, NormalMapKeepsReflectionAboveSurface) {
  wp::Scene s;
  wp::Material m;
  m.normal_texture = add_texture(s, image_of(1, 1, {128, 218, 218, 255}), false);
  s.materials.push_back(m);
  add_square(s, 0);
  const glm::vec3 d = glm::normalize(glm::vec3(0.0f, 0.5f, -1.0f));
  const Resolved r = resolve(upload(s), {{0, {0.6f, 0.3f}, d}})[0];
  const glm::dvec3 wo(-d), ns(r.ns);
  const glm::dvec3 reflected = 2.0 * glm::dot(wo, ns) * ns - wo;
  EXPECT_NEAR(reflected.z, 0.01, 1e-5);
  EXPECT_NEAR(glm::length(ns), 1.0, 1e-6);
  EXPECT_LT(std::abs(ns.x), 0.005);  // the tilt stays in the y-z plane, bent toward +z
  EXPECT_GT(ns.y, 0.0);
  EXPECT_LT(ns.y, mapped({128, 218, 218}, 1, 1).y);
}

// ---------------------------------------------------------------------------------------------
// Mip chains (host/scene/mipmap.cpp) and lookups through them (kernels/texture/textures.h)

// Level k of `image` as an Image, from mip_chain's output (level 0: the image).
wp::Image mip_image(const wp::Image& image, const std::vector<std::uint8_t>& chain, int level) {
  if (level == 0) return image;
  std::size_t offset = 0;
  for (int k = 1; k < level; ++k)
    offset += 4 * std::size_t(wp::mip_size(image.width, k)) * wp::mip_size(image.height, k);
  const int w = wp::mip_size(image.width, level), h = wp::mip_size(image.height, level);
  const auto first = chain.begin() + std::ptrdiff_t(offset);
  return image_of(w, h, std::vector<std::uint8_t>(first, first + 4 * std::ptrdiff_t(w) * h));
}

// The box filter of level 0 over texel (i, j) of level k, computed directly in double: the mean
// of the piecewise-constant image over [i W / w_k, (i + 1) W / w_k) x [j H / h_k, (j + 1) H / h_k),
// each channel decoded first (sRGB colour: the EOTF; alpha linear).
Rgba box_of_level0(const wp::Image& img, int level, int i, int j, bool srgb) {
  const int w = wp::mip_size(img.width, level), h = wp::mip_size(img.height, level);
  const double x0 = double(i) * img.width / w, x1 = double(i + 1) * img.width / w;
  const double y0 = double(j) * img.height / h, y1 = double(j + 1) * img.height / h;
  Rgba sum{};
  for (int y = int(std::floor(y0)); y < int(std::ceil(y1)); ++y)
    for (int x = int(std::floor(x0)); x < int(std::ceil(x1)); ++x) {
      const double cover = (std::min(x1, x + 1.0) - std::max(x0, double(x))) *
                           (std::min(y1, y + 1.0) - std::max(y0, double(y)));
      const Rgba c = texel(img, x, y, srgb);
      for (int k = 0; k < 4; ++k) sum[k] += cover * c[k];
    }
  for (double& c : sum) c /= (x1 - x0) * (y1 - y0);
  return sum;
}

// The chains' colour encoding from its table (encode_srgb8) against the pow form it replaces
// (encode_srgb8_pow): the same code for one float in 256 across [0, 1] by bit pattern (every
// binade), for the 16 floats around each code's first value (where the table's bisection
// decides), and outside [0, 1] (clamped).
TEST(MipChain, ColourEncodingMatchesThePowForm) {
  const auto bits_to_float = [](std::uint32_t b) {
    float f;
    std::memcpy(&f, &b, sizeof f);
    return f;
  };
  std::size_t checked = 0, mismatches = 0;
  const auto check = [&](float v) {
    ++checked;
    if (wp::encode_srgb8(v) != wp::encode_srgb8_pow(v) && ++mismatches <= 10)
      ADD_FAILURE() << "v " << v << ": table " << int(wp::encode_srgb8(v)) << ", pow "
                    << int(wp::encode_srgb8_pow(v));
  };
  for (std::uint32_t b = 0; b <= 0x3f800000u; b += 256) check(bits_to_float(b));
  for (int c = 0; c < 255; ++c) {  // each code's first value, by bisection on the pow form
    std::uint32_t lo = 0, hi = 0x3f800000u;
    while (hi - lo > 1) {
      const std::uint32_t mid = lo + (hi - lo) / 2;
      (wp::encode_srgb8_pow(bits_to_float(mid)) > c ? hi : lo) = mid;
    }
    for (std::uint32_t b = hi - 8; b < hi + 8; ++b) check(bits_to_float(b));
  }
  for (float v : {-1.0f, -0.0f, 1.0f, 1.5f, 1e30f}) check(v);
  EXPECT_EQ(mismatches, 0u) << "of " << checked;
  EXPECT_EQ(wp::encode_srgb8(0.5f), 188);  // the standard's 0.5 linear: 0.7354 encoded
}

// Every texel of every level, for odd, even, square and strip sizes, colour and data: each is the
// 8-bit encoding, rounded to nearest, of the box filter of level 0 over its footprint, computed
// here in double from level 0. The chain is made in float (each level from the previous one,
// never from its 8-bit copy), so its value before rounding is within a few float ulps (far below
// 1e-4 of a code) of the exact box: the stored code is within 0.5 + 1e-4 of 255 x exact, which
// leaves it a choice only at ties (common: the mean of two or four codes often ends in .5). Also:
// the number of levels, and the third of the image's texels the chain adds at most.
TEST(MipChain, EachLevelIsTheBoxFilterOfLevelZero) {
  std::mt19937 rng(5);
  const std::pair<int, int> sizes[] = {{16, 16}, {13, 7}, {7, 13}, {6, 10}, {5, 5},
                                       {33, 2},  {2, 33}, {1, 9},  {3, 1},  {64, 17}};
  std::size_t checked = 0, ties = 0;
  for (const auto& [w, h] : sizes)
    for (const bool srgb : {false, true}) {
      const wp::Image img = random_image(w, h, rng);
      const std::vector<std::uint8_t> chain = wp::mip_chain(img, srgb);
      const int levels = wp::mip_levels(w, h);
      EXPECT_EQ(levels, 1 + int(std::floor(std::log2(std::min(w, h))))) << w << "x" << h;
      EXPECT_EQ(wp::mip_size(std::min(w, h), levels - 1), 1);
      std::size_t expected_bytes = 0;
      for (int k = 1; k < levels; ++k)
        expected_bytes += 4 * std::size_t(wp::mip_size(w, k)) * wp::mip_size(h, k);
      ASSERT_EQ(chain.size(), expected_bytes) << w << "x" << h;
      EXPECT_LE(3 * chain.size(), img.rgba.size()) << "more than a third added, " << w << "x" << h;
      for (int k = 1; k < levels; ++k) {
        const wp::Image level = mip_image(img, chain, k);
        for (int j = 0; j < level.height; ++j)
          for (int i = 0; i < level.width; ++i) {
            const Rgba want = box_of_level0(img, k, i, j, srgb);
            for (int c = 0; c < 4; ++c) {
              const double exact = 255.0 * (srgb && c < 3 ? wp::linear_to_srgb(want[c]) : want[c]);
              const int got = level.rgba[4 * (std::size_t(j) * level.width + i) + c];
              ++checked;
              ties += got != int(std::lround(exact));
              if (std::abs(got - exact) > 0.5 + 1e-4)
                ADD_FAILURE() << w << "x" << h << (srgb ? " srgb" : "") << " level " << k
                              << " texel (" << i << ", " << j << ") channel " << c << ": " << got
                              << " vs " << exact;
            }
          }
      }
    }
  EXPECT_GT(checked, 4000u);
  std::printf("%zu codes checked, %zu ties rounded the other way\n", checked, ties);
}

// The texture's own term of its level (device_scene.cpp's lod_term), as the device adds it: in
// float.
float lod_term(const wp::Image& img, const wp::TextureRef& t) {
  const double det = double(t.row_u.x) * t.row_v.y - double(t.row_u.y) * t.row_v.x;
  return static_cast<float>(0.5 * std::log2(double(img.width) * img.height * std::abs(det)));
}

// texture_sample_lod against a trilinear reference on the host's levels (whose filtering the test
// above checks): OpenGL's rule, the magnification filter at level 0 where lambda <= 0, else
// bilinear in levels floor(lambda) and floor(lambda) + 1 mixed by the fraction (the last level
// alone past it). Every wrap pair, both magnification filters, both encodings, a transform with
// an area scale, on odd and even sizes; footprints swept densely around 0 (the switch between the
// filters) and each integer level (the switch between level pairs), and past the last level.
// lambda is formed in float as the device forms it (footprint + the texture's term), so both
// sides pick the same levels. Tolerance: texture_bound's at level 0 (the coarser levels' position
// errors are smaller), plus 1e-6 for the mix.
TEST(TextureSample, LevelsMatchTrilinearReference) {
  std::mt19937 rng(17);
  wp::Scene s;
  s.images = {random_image(13, 7, rng), random_image(8, 8, rng)};
  add_every_sampler(s, {{{0.8f, -1.3f, 0.25f}, {1.1f, 0.6f, -0.4f}, 0}});
  std::vector<float> footprints;
  for (const float l : {0.0f, 1.0f, 2.0f, 3.0f})
    for (const float e : {-0.01f, -1e-4f, 0.0f, 1e-4f, 0.01f, 0.25f, 0.5f, 0.75f})
      footprints.push_back(l + e);
  footprints.insert(footprints.end(), {-3.0f, 4.5f, 9.0f});

  std::vector<int> refs;
  std::vector<float4> uvs;
  std::vector<float> lods;
  std::uniform_real_distribution<float> range(-3.0f, 4.0f);
  for (std::size_t r = 0; r < s.textures.size(); ++r) {
    const wp::Image& img = s.images[std::size_t(s.textures[r].image)];
    const float term = lod_term(img, s.textures[r]);
    for (const float lambda : footprints)
      for (int k = 0; k < 12; ++k) {
        refs.push_back(int(r));
        uvs.push_back({range(rng), range(rng), range(rng), range(rng)});
        lods.push_back(lambda - term); /* the footprint that gives level lambda */
      }
  }
  auto& h = harness();
  const cl::Buffer rb = h.buffer(refs), ub = h.buffer(uvs), lb = h.buffer(lods);
  const cl::Buffer out = h.buffer<float4>(uvs.size());
  const wp::SceneBuffers scene = upload(s, h, true);
  h.run("sample_textures_lod", uvs.size(), scene, rb, ub, lb, cl_uint(uvs.size()), out);
  const std::vector<float4> got = h.read<float4>(out, uvs.size());

  // Each image is filtered as colour, since a texture uses it as colour (device_scene.cpp).
  std::vector<std::vector<std::uint8_t>> chains;
  for (const wp::Image& img : s.images) chains.push_back(wp::mip_chain(img, true));
  std::size_t failures = 0, skipped = 0;
  for (std::size_t i = 0; i < uvs.size(); ++i) {
    const wp::TextureRef& t = s.textures[std::size_t(refs[i])];
    const wp::Image& img = s.images[std::size_t(t.image)];
    const std::vector<std::uint8_t>& chain = chains[std::size_t(t.image)];
    const float lambda = lods[i] + lod_term(img, t);
    const glm::vec4 uv(uvs[i].x, uvs[i].y, uvs[i].z, uvs[i].w);
    const glm::dvec2 bound = position_bound(s, t, uv);
    Rgba want;
    if (!(lambda > 0.0f)) {
      if (t.nearest && near_border(transformed(t, uv) * glm::dvec2(img.width, img.height), bound)) {
        ++skipped;
        continue;
      }
      want = reference_sample_image(img, t, uv, t.nearest);
    } else {
      const int last = wp::mip_levels(img.width, img.height) - 1;
      const float l = std::min(lambda, float(last));
      const int l0 = int(std::floor(l));
      want = reference_sample_image(mip_image(img, chain, l0), t, uv, false);
      if (l0 < last) {
        const Rgba b = reference_sample_image(mip_image(img, chain, l0 + 1), t, uv, false);
        for (int c = 0; c < 4; ++c) want[c] += double(l - float(l0)) * (b[c] - want[c]);
      }
    }
    const float* g = &got[i].x;
    const double tol = texture_bound(bound, false) + 1e-6;
    for (int c = 0; c < 4; ++c) {
      if (std::abs(g[c] - want[c]) <= tol) continue;
      if (++failures <= 10)
        ADD_FAILURE() << "ref " << refs[i] << " lambda " << lambda << " channel " << c << ": "
                      << g[c] << " vs " << want[c] << " (tolerance " << tol << ")";
      break;
    }
  }
  EXPECT_EQ(failures, 0u) << "of " << uvs.size() << " lookups";
  EXPECT_LT(skipped, uvs.size() / 100);
}

// ---------------------------------------------------------------------------------------------
// Ray cones (kernels/texture/ray_cone.h)

// kernels/texture/ray_cone.h's WP_CONE_SCALE: cones are an eighth of a sample's footprint.
constexpr double kConeScale = 0.125;

// The level a camera ray's cone picks on a plane at a known distance and angle, against the
// analytic footprint: a pinhole's cone spreads by an eighth of the pixel's angle, g = 1/8 x
// 2 tan(yfov / 2) / height, so at distance t along the ray it is g t across, the minor axis of its
// footprint on a plane the ray meets at any angle (the major axis, g t / cos, does not count:
// kernels/texture/ray_cone.h); a texture of W x H texels spread over the plane with texel density
// sqrt(W H |det T| A_uv / A_world) per unit length sees that footprint as log2 of (its length x
// the density) texels: lambda. An orthographic camera's cone is an eighth of the pixel's height,
// 1/8 x 2 ymag / height, at any distance. Checked for several pixels of tilted views (from
// head-on to about cos 0.15) on both coordinate sets (TEXCOORD_1 of the square covers twice the
// area of TEXCOORD_0) with a scaling transform; tolerance 1e-4 (float log2 and the cone's
// arithmetic: relative errors of a few 1e-7).
TEST(RayCone, CameraRayLevelIsTheAnalyticFootprint) {
  wp::Scene s;
  wp::Material m;
  m.base_color_texture =
      add_texture(s, image_of(64, 32, std::vector<std::uint8_t>(64 * 32 * 4)), true, false);
  s.textures.push_back(s.textures[0]);
  s.textures[1].texcoord = 1;
  s.textures[1].row_u = {3.0f, 0.5f, 0.0f};
  s.textures[1].row_v = {0.0f, 0.5f, 0.2f};
  s.materials.push_back(m);
  add_square(s, 0);
  constexpr int kHeight = 120;
  struct View {
    glm::dvec3 eye, target;
    bool ortho;
  };
  const View views[] = {{{0.5, 0.5, 3.0}, {0.5, 0.5, 0.0}, false},
                        {{-1.5, 0.3, 1.2}, {0.6, 0.5, 0.0}, false},
                        {{0.5, -4.0, 0.7}, {0.5, 0.6, 0.0}, false},
                        {{2.0, 1.5, 2.5}, {0.4, 0.4, 0.0}, true}};
  for (const View& v : views) {
    wp::Camera cam;
    cam.position = glm::vec3(v.eye);
    cam.forward = glm::vec3(glm::normalize(v.target - v.eye));
    cam.up = std::abs(cam.forward.z) > 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1);
    cam.yfov = 0.4f;
    cam.type = v.ortho ? wp::CameraType::kOrthographic : wp::CameraType::kPerspective;
    cam.ymag = 0.4f;
    const wp::dev::Camera dc = wp::device_camera(cam, 160, kHeight);
    std::vector<float4> queries, rays;
    std::vector<double> want;
    for (const glm::dvec2 ndc :
         {glm::dvec2(0, 0), glm::dvec2(0.15, -0.1), glm::dvec2(-0.1, 0.05)}) {
      const glm::dvec3 fwd(dc.forward.x, dc.forward.y, dc.forward.z);
      const glm::dvec3 plane = ndc.x * glm::dvec3(dc.right.x, dc.right.y, dc.right.z) +
                               ndc.y * glm::dvec3(dc.up.x, dc.up.y, dc.up.z);
      const glm::dvec3 o = v.ortho ? v.eye + plane : v.eye;
      const glm::dvec3 d = v.ortho ? fwd : glm::normalize(fwd + plane);
      const double t = -o.z / d.z;
      const glm::dvec3 p = o + t * d;
      ASSERT_TRUE(p.x > 0 && p.x < 1 && p.y > 0 && p.y < 1) << "the ray misses the square";
      // Triangle 0 holds x >= y at barycentrics (x - y, y); triangle 1, (0, 2, 3), the rest at
      // (x, y - x).
      const bool first = p.x >= p.y;
      const glm::dvec2 bary = first ? glm::dvec2(p.x - p.y, p.y) : glm::dvec2(p.x, p.y - p.x);
      const double length =
          kConeScale *
          (v.ortho ? 2.0 * 0.4 / kHeight : 2.0 * std::tan(0.5 * double(cam.yfov)) / kHeight * t);
      for (std::uint32_t ref = 0; ref < 2; ++ref) {
        const wp::TextureRef& tr = s.textures[ref];
        const double det = double(tr.row_u.x) * tr.row_v.y - double(tr.row_u.y) * tr.row_v.x;
        const double uv_area = ref == 1 ? 2.0 : 1.0;  // per unit area of the square
        want.push_back(std::log2(length * std::sqrt(64.0 * 32.0 * std::abs(det) * uv_area)));
        std::uint32_t tri = first ? 0u : 1u;
        float4 q;
        std::memcpy(&q.x, &tri, 4);
        std::memcpy(&q.y, &ref, 4);
        q.z = float(bary.x);
        q.w = float(bary.y);
        queries.push_back(q);
        rays.push_back({float(d.x), float(d.y), float(d.z), float(t)});
      }
    }
    auto& h = harness();
    const cl::Buffer qb = h.buffer(queries), rb = h.buffer(rays);
    const cl::Buffer out = h.buffer<float4>(queries.size());
    h.run("camera_ray_levels", queries.size(), upload(s, h, true, dc), qb, rb, cl_uint(kHeight),
          cl_uint(queries.size()), out);
    const std::vector<float4> got = h.read<float4>(out, queries.size());
    for (std::size_t i = 0; i < got.size(); ++i)
      EXPECT_NEAR(got[i].x, want[i], 1e-4)
          << "view from (" << v.eye.x << ", " << v.eye.y << ", " << v.eye.z << ") query " << i;
  }
}

// The cone through bounces as the stages carry it, against the ray-cone recurrence in double: at
// a hit at distance t the width grows by spread x t; leaving it, the spread grows by 2 k |width|
// (curvature k) and, for a sample that is not a delta lobe, by an eighth of 2 / sqrt(pi pdf), the
// full angle of the cone of solid angle 1 / pdf, at most pi: 0.25 rad for a Lambertian sample at
// normal incidence (pdf 1/pi), pi / 8 for one at cos 0.25.
// Width and spread pass through the path state's bfloat16 halves between bounces (8 significant
// bits: 2^-9 relative per rounding, a few roundings per value: 1% relative). The footprint, and so
// the level, grows at every rough bounce; a mirror (pdf 0) on a flat surface adds no spread.
TEST(RayCone, GrowsAtEachRoughBounce) {
  const double pixel = 2.0 * std::tan(0.3) / 120.0;
  // (t, curvature, pdf): Lambertian at normal incidence, glossy, a mirror on a flat surface, a
  // mirror on a sphere of radius 2 seen from outside, Lambertian at cos 0.25.
  const std::vector<float4> bounces = {{2.0f, 0.0f, float(1.0 / M_PI), 0.0f},
                                       {1.5f, 0.0f, 40.0f, 0.0f},
                                       {0.5f, 0.0f, 0.0f, 0.0f},
                                       {0.7f, 0.5f, 0.0f, 0.0f},
                                       {1.0f, 0.0f, float(0.25 / M_PI), 0.0f}};
  auto& h = harness();
  const cl::Buffer b = h.buffer(bounces), out = h.buffer<float4>(bounces.size());
  h.run("cone_bounces", 1, cl_float2{{0.0f, float(pixel)}}, b, cl_uint(bounces.size()), out);
  const std::vector<float4> got = h.read<float4>(out, bounces.size());
  double width = 0.0, spread = pixel;
  for (std::size_t i = 0; i < bounces.size(); ++i) {
    const float4& x = bounces[i];
    width += spread * x.x;
    spread += 2.0 * x.y * std::abs(width) +
              (x.z > 0 ? kConeScale * std::min(2.0 / std::sqrt(M_PI * x.z), M_PI) : 0.0);
    EXPECT_NEAR(got[i].x, width, 0.01 * width) << "bounce " << i;
    EXPECT_NEAR(got[i].y, spread, 0.01 * spread) << "bounce " << i;
    if (i > 0) {
      EXPECT_GT(got[i].x, got[i - 1].x) << "the footprint grows at bounce " << i;
    }
  }
  EXPECT_NEAR(got[0].y - pixel, 0.25, 0.0025) << "a Lambertian sample at normal incidence";
  EXPECT_EQ(got[2].y, got[1].y) << "a flat mirror adds no spread";
  EXPECT_GT(got[3].y, got[2].y) << "a convex mirror spreads the cone";
}

// triangle_curvature: 1/R for any triangle of points on a sphere of radius R with its radial
// normals (dn . dp / |dp|^2 = (dp / R) . dp / |dp|^2 exactly), -1/R with the normals inward (the
// sphere seen from inside), 0 for a flat triangle; within float rounding (1e-5 relative).
TEST(RayCone, CurvatureOfSphereAndPlane) {
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  std::vector<float4> tris;
  std::vector<double> want;
  for (int k = 0; k < 60; ++k) {
    const float r = 0.1f + 0.2f * float(k);
    const glm::vec3 c(g(rng), g(rng), g(rng));
    glm::vec3 n[3];
    for (glm::vec3& x : n) {
      x = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)) * 0.2f + glm::vec3(0, 0, 1));
    }
    const float sign = k % 2 ? -1.0f : 1.0f;
    for (const glm::vec3& x : n) tris.push_back({c.x + r * x.x, c.y + r * x.y, c.z + r * x.z, 0});
    for (const glm::vec3& x : n) tris.push_back({sign * x.x, sign * x.y, sign * x.z, 0});
    want.push_back(sign / r);
  }
  for (int k = 0; k < 10; ++k) {  // flat, with one normal
    for (int v = 0; v < 3; ++v) tris.push_back({g(rng), g(rng), 0.0f, 0});
    for (int v = 0; v < 3; ++v) tris.push_back({0, 0, 1, 0});
    want.push_back(0.0);
  }
  auto& h = harness();
  const cl::Buffer tb = h.buffer(tris), out = h.buffer<float>(want.size());
  h.run("curvatures", want.size(), tb, cl_uint(want.size()), out);
  const std::vector<float> got = h.read<float>(out, want.size());
  for (std::size_t i = 0; i < want.size(); ++i)
    EXPECT_NEAR(got[i], want[i], 1e-5 * std::max(1.0, std::abs(want[i])) + 1e-6) << i;
}

}  // namespace
