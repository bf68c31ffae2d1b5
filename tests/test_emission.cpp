// Emissive textures in the light table (host/lights/emission.h): triangles that emit nothing
// anywhere are not lights, the others are weighted by the emission integrated over them. Host
// units; the whole-render check that this changes no answer (NEE, BSDF sampling and MIS still
// agree) is LightTransport.TexturedLampStrategiesAgree.
#include <cmath>

#include <gtest/gtest.h>

#include "host/lights/emission.h"
#include "host/scene/gltf_loader.h"
#include "host/lights/light_table.h"
#include "tests/scene_factory.h"
#include "tests/test_assets.h"

namespace {

using glm::vec3;

// A w x h image, black where x < black_columns, white elsewhere.
wp::Image half_black(int w, int h, int black_columns) {
  wp::Image img;
  img.width = w, img.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (std::uint8_t c :
           {std::uint8_t(x < black_columns ? 0 : 255), std::uint8_t(x < black_columns ? 0 : 255),
            std::uint8_t(x < black_columns ? 0 : 255), std::uint8_t(255)})
        img.rgba.push_back(c);
  return img;
}

// A scene with one emissive material (factor `emission`) textured with `img`, no triangles yet.
wp::Scene textured_emitter_scene(const wp::Image& img, vec3 emission, bool nearest) {
  wp::Scene s;
  s.images.push_back(img);
  wp::TextureRef t;
  t.image = 0;
  t.srgb = true;
  t.nearest = nearest;
  t.wrap_s = t.wrap_t = wp::Wrap::kClampToEdge;
  s.textures.push_back(t);
  wp::Material m = wp::test::diffuse_material(vec3(0.0f));
  m.emission = emission;
  m.emissive_texture = 0;
  s.materials.push_back(m);
  return s;
}

// A cells x cells grid of quads over [0,1]^2 in the x-y plane, uv = (x, y).
void add_uv_grid(wp::Scene& s, int cells) {
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const float x0 = float(i) / float(cells), x1 = float(i + 1) / float(cells);
      const float y0 = float(j) / float(cells), y1 = float(j + 1) / float(cells);
      const auto first = s.positions.size();
      wp::test::add_quad(s, {x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}, 0);
      for (std::size_t k = first; k < s.positions.size(); ++k)
        s.uv0[k] = {s.positions[k].x, s.positions[k].y};
    }
  wp::test::finish_bounds(s);
}

// 16 x 16 texels, columns 0-7 black; an 8 x 8 grid of cells, cell column i covering texel
// columns [2i, 2i + 2). Bilinear filtering reaches one texel beyond a point's own, so a cell's
// light can come from columns 2i - 1 to 2i + 2: cells 0-2 are black everywhere (no light), cell 3
// reaches white column 8 (a light, dim), cell 4 reaches black column 7 (a light, less than full),
// cells 5-7 are white everywhere (mean = factor exactly).
TEST(Emission, BlackPartsOfATextureAreNotLights) {
  const vec3 factor(2.0f, 3.0f, 4.0f);
  wp::Scene s = textured_emitter_scene(half_black(16, 16, 8), factor, /*nearest=*/false);
  add_uv_grid(s, 8);
  const wp::LightTable t =
      wp::build_light_table(s, nullptr, vec3(0.0f), 1.0f, wp::LightSelect::kPower);
  std::size_t lights = 0;
  for (std::size_t tri = 0; tri < s.triangle_count(); ++tri) {
    const int column = static_cast<int>(tri / 2 % 8);
    const wp::TriangleEmission e = wp::triangle_emission(s, tri);
    SCOPED_TRACE("triangle " + std::to_string(tri) + ", cell column " + std::to_string(column));
    if (column <= 2) {
      EXPECT_TRUE(e.zero());
      EXPECT_EQ(t.tri_light[tri], WP_NO_LIGHT);
      continue;
    }
    ++lights;
    EXPECT_NE(t.tri_light[tri], WP_NO_LIGHT);
    EXPECT_FLOAT_EQ(e.peak, 4.0f);
    if (column >= 5) {
      EXPECT_FLOAT_EQ(e.mean.x, factor.x);  // white everywhere: the factor, exactly
      EXPECT_FLOAT_EQ(e.mean.z, factor.z);
    } else if (column == 4) {
      EXPECT_GT(e.mean.x, 0.5f * factor.x);
      EXPECT_LT(e.mean.x, factor.x);
    } else {
      EXPECT_GT(e.mean.x, 0.0f);
      EXPECT_LT(e.mean.x, 0.5f * factor.x);
    }
  }
  EXPECT_EQ(t.emissive_triangles, lights);
  EXPECT_EQ(lights, 2u * 8u * 5u);
}

// The mean is the area average: a triangle with uv corners (0,0), (1,0), (0,1) over a 256 x 1
// image whose left half is black (NEAREST: a step at u = 1/2) has a quarter of its area at
// u > 1/2 (the corner triangle (1/2,0), (1,0), (1/2,1/2)), so its mean is factor / 4. The midpoint
// rule on the 16 x 16 grid (the least the function uses) errs only in the cells the step cuts:
// the step is a monotone curve in the grid's square (sqrt(s)(1 - t) = 1/2), which crosses at most
// 2 x 16 of its 256 cells, each off by at most one cell's weight: |error| <= 1/8 of factor.
TEST(Emission, MeanIsTheAreaAverage) {
  const vec3 factor(1.0f);
  wp::Scene s = textured_emitter_scene(half_black(256, 1, 128), factor, /*nearest=*/true);
  wp::test::add_mesh(s, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}},
                     {0, 1, 2}, 0);
  s.uv0 = {{0, 0}, {1, 0}, {0, 1}};
  const wp::TriangleEmission e = wp::triangle_emission(s, 0);
  EXPECT_NEAR(e.mean.x, 0.25, 0.125);
  EXPECT_FLOAT_EQ(e.peak, 1.0f);
}

// An untextured emitter is a light of its factor; a black one is none.
TEST(Emission, UntexturedFactor) {
  wp::Scene s;
  wp::Material lit = wp::test::diffuse_material(vec3(0.0f));
  lit.emission = {0.5f, 1.0f, 2.0f};
  s.materials = {lit, wp::test::diffuse_material(vec3(1.0f))};
  wp::test::add_quad(s, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, 0);
  wp::test::add_quad(s, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, 1);
  for (std::size_t tri : {0u, 1u}) {
    const wp::TriangleEmission e = wp::triangle_emission(s, tri);
    EXPECT_EQ(e.mean, lit.emission);
    EXPECT_FLOAT_EQ(e.peak, 2.0f);
  }
  EXPECT_TRUE(wp::triangle_emission(s, 2).zero());
}

// DamagedHelmet: 15,452 triangles use the emissive material, most of them on black parts of the
// emissive map. Those become no lights; every triangle that stays a light has a texel it can
// reach that is not black, and every dropped one is black at its corners (checked here directly
// on the decoded image, nearest texel, independently of the bounding-box walk).
TEST(Emission, DamagedHelmetDropsItsBlackTriangles) {
  WP_REQUIRE_MODEL(path, "DamagedHelmet/DamagedHelmet.glb");
  const wp::Scene s = wp::load_gltf(path);
  std::size_t emissive_material = 0;
  for (std::size_t tri = 0; tri < s.triangle_count(); ++tri) {
    const wp::Material& m = s.materials[s.triangle_material[tri]];
    emissive_material += m.emission.x + m.emission.y + m.emission.z > 0.0f;
  }
  const wp::LightTable t =
      wp::build_light_table(s, nullptr, vec3(0.0f), 1.0f, wp::LightSelect::kPower);
  std::printf("DamagedHelmet: %zu triangles with an emissive material, %zu lights\n",
              emissive_material, t.emissive_triangles);
  EXPECT_GT(emissive_material, 10000u);
  EXPECT_LT(t.emissive_triangles, emissive_material / 4);
  EXPECT_GT(t.emissive_triangles, 0u);
  for (std::size_t tri = 0; tri < s.triangle_count(); ++tri) {
    const wp::Material& m = s.materials[s.triangle_material[tri]];
    if (t.tri_light[tri] != WP_NO_LIGHT || m.emissive_texture < 0) continue;
    const wp::TextureRef& ref = s.textures[static_cast<std::size_t>(m.emissive_texture)];
    const wp::Image& img = s.images[static_cast<std::size_t>(ref.image)];
    const auto& uvs = ref.texcoord == 1 ? s.uv1 : s.uv0;
    for (int k = 0; k < 3; ++k) {
      const glm::vec2 uv = uvs[s.indices[3 * tri + k]];
      const float u = ref.row_u.x * uv.x + ref.row_u.y * uv.y + ref.row_u.z;
      const float v = ref.row_v.x * uv.x + ref.row_v.y * uv.y + ref.row_v.z;
      const int x = std::clamp(static_cast<int>(std::floor((u - std::floor(u)) * float(img.width))),
                               0, img.width - 1);
      const int y = std::clamp(
          static_cast<int>(std::floor((v - std::floor(v)) * float(img.height))), 0, img.height - 1);
      const std::uint8_t* p = &img.rgba[4 * (static_cast<std::size_t>(y) * img.width + x)];
      ASSERT_EQ(p[0] | p[1] | p[2], 0) << "dropped triangle " << tri << " is lit at corner " << k;
    }
  }
}

}  // namespace
