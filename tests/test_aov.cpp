// AOVs (--aov: albedo, normal, depth) against what a scene built for it must show, and the film
// that holds them: the image unchanged by recording them, parts merged bit for bit, the .wpfilm
// file, and the command line's outputs.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "host/device/cl_runtime.h"
#include "host/film/film.h"
#include "host/film/image_io.h"
#include "host/render/render.h"
#include "tests/device_test.h"
#include "tests/cli_run.h"
#include "tests/scene_factory.h"
#include "tests/test_assets.h"

namespace {

using glm::vec3;

constexpr int kSize = 16;
const vec3 kWall(0.2f, 0.5f, 0.8f);
const vec3 kBackground(0.3f, 0.6f, 2.0f);  // the albedo AOV clamps it: (0.3, 0.6, 1)

// An orthographic camera at z = 5 looking down -z over [-1, 1]^2 (16 x 16 pixels of 0.125). Below
// y = 0.5 (rows 4 to 15) a diffuse wall of colour kWall at z = 0 fills x < 0 (columns 0-7) and a
// smooth white mirror facing the camera fills x > 0 (columns 8-15); above, nothing. The
// boundaries fall on pixel edges, so every sample of a pixel sees the same thing.
wp::Scene aov_scene() {
  wp::Scene s;
  s.materials.push_back(wp::test::diffuse_material(kWall));
  wp::Material mirror;
  mirror.base_color = glm::vec4(1.0f);
  mirror.metallic = 1.0f;
  mirror.roughness = 0.0f;
  s.materials.push_back(mirror);
  wp::test::add_quad(s, {-1, -1, 0}, {0, -1, 0}, {0, 0.5f, 0}, {-1, 0.5f, 0}, 0);
  wp::test::add_quad(s, {0, -1, 0}, {1, -1, 0}, {1, 0.5f, 0}, {0, 0.5f, 0}, 1);
  wp::Camera c = wp::test::look_at({0, 0, 5}, {0, 0, 0}, 0.8f);
  c.type = wp::CameraType::kOrthographic;
  c.xmag = c.ymag = 1.0f;
  s.cameras.push_back(c);
  wp::test::finish_bounds(s);
  return s;
}

wp::RenderSettings aov_settings(int spp) {
  wp::RenderSettings st;
  st.width = st.height = kSize;
  st.spp = spp;
  st.background = kBackground;
  st.aov = true;
  return st;
}

class Aov : public wp::test::DeviceTest {};

// Every sample of a pixel records the same values, so the means are those values up to the
// film's fixed point (2^-32) and float rounding: 1e-6.
TEST_F(Aov, KnownAnswersForWallMirrorAndBackground) {
  const wp::Rendered r = wp::render(*runtime_, aov_scene(), aov_settings(4));
  const wp::FilmImages img = r.film.images();
  ASSERT_EQ(img.albedo.size(), 3u * kSize * kSize);
  ASSERT_EQ(img.depth.size(), std::size_t(kSize) * kSize);
  const vec3 sky = glm::min(kBackground, vec3(1.0f));
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const std::size_t p = std::size_t(y) * kSize + x;
      const bool empty = y < 4, wall = !empty && x < 8;
      // The wall shows its colour and faces the camera; the mirror is delta lobes alone, so its
      // pixels show what it reflects: the background (normal 0) seen 5 m away; empty pixels the
      // background at depth 0.
      const vec3 albedo = wall ? kWall : sky, normal = wall ? vec3(0, 0, 1) : vec3(0);
      const float depth = empty ? 0.0f : 5.0f;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(img.albedo[3 * p + c], albedo[c], 1e-6) << x << "," << y << " channel " << c;
        EXPECT_NEAR(img.normal[3 * p + c], normal[c], 1e-6) << x << "," << y << " channel " << c;
      }
      EXPECT_NEAR(img.depth[p], depth, 1e-5) << x << "," << y;
    }
}

// Recording AOVs changes no random number and no radiance: the image sums are the same words.
TEST_F(Aov, TheImageDoesNotChange) {
  wp::Scene s = aov_scene();
  s.materials[0].roughness = 0.4f;  // some glossy scattering, so paths go on bouncing
  wp::RenderSettings with = aov_settings(5), without = with;
  without.aov = false;
  const wp::Film a = wp::render(*runtime_, s, with).film,
                 b = wp::render(*runtime_, s, without).film;
  ASSERT_EQ(a.info().words_per_pixel(), WP_FILM_WORDS(1));
  ASSERT_EQ(b.info().words_per_pixel(), WP_FILM_WORDS(0));
  for (std::size_t p = 0; p < a.pixels(); ++p)
    for (std::size_t w = 0; w < WP_FILM_WORDS_PER_PIXEL; ++w)
      ASSERT_EQ(a.words()[p * WP_FILM_WORDS(1) + w], b.words()[p * WP_FILM_WORDS(0) + w])
          << "pixel " << p << " word " << w;
  EXPECT_NE(a.info().key, b.info().key);  // and the films do not merge
  EXPECT_NE(wp::film_identity_problem(a.info(), b.info()), "");
}

// Sample ranges with AOVs merge to the single render, bit for bit, also through a .wpfilm file.
TEST_F(Aov, PartsMergeBitForBitThroughFiles) {
  const wp::Scene s = aov_scene();
  wp::RenderSettings st = aov_settings(6);
  const wp::Film whole = wp::render(*runtime_, s, st).film;
  st.spp = 2;
  wp::Film merged = wp::render(*runtime_, s, st).film;
  st.sample_begin = 2;
  st.spp = 4;
  const std::string file = (std::filesystem::temp_directory_path() /
                            ("wavepath_aov_" + std::to_string(::getpid()) + ".wpfilm"))
                               .string();
  wp::render(*runtime_, s, st).film.write(file);
  const wp::Film part = wp::Film::read(file);
  std::filesystem::remove(file);
  EXPECT_TRUE(part.info().aov);
  merged.add(part);
  EXPECT_TRUE(merged.words() == whole.words());
}

class AovCli : public wp::test::FolderTest {};

// The command line: EXR layers and PFM companions, only those asked for; merge writes them from
// films that hold them and refuses films that do not.
TEST_F(AovCli, LayersAndCompanionFiles) {
  const std::string scene = "'" + wp::test::source_path("scenes/cornell_box.gltf") + "'";
  const auto run = [&](const std::string& args) { return wp::test::run_wavepath(dir_, args); };
  const wp::test::CliRun r = run("render " + scene +
                                 " --width 12 --height 8 --spp 3 -q --aov depth,albedo -o a.exr "
                                 "-o a.pfm -o a.wpfilm");
  ASSERT_EQ(r.status, 0) << r.err;
  const wp::ImageRgb albedo = wp::read_exr(path("a.exr"), "albedo");
  EXPECT_EQ(albedo.width, 12);
  EXPECT_TRUE(std::filesystem::exists(path("a.albedo.pfm")));
  EXPECT_TRUE(std::filesystem::exists(path("a.depth.pfm")));
  EXPECT_FALSE(std::filesystem::exists(path("a.normal.pfm")));
  const std::string depth = wp::test::slurp(path("a.depth.pfm"));
  EXPECT_EQ(depth.rfind("Pf\n12 8\n", 0), 0u);
  EXPECT_EQ(depth.size(), std::string("Pf\n12 8\n-1.0\n").size() + 12 * 8 * 4);
  // The albedo the EXR holds is the film's.
  const wp::FilmImages film = wp::Film::read(path("a.wpfilm")).images();
  EXPECT_EQ(albedo.rgb, film.albedo);

  const wp::test::CliRun m = run("merge a.wpfilm --aov normal -q -o m.pfm");
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_TRUE(std::filesystem::exists(path("m.normal.pfm")));
  ASSERT_EQ(run("render " + scene + " --width 12 --height 8 --spp 3 -q -o plain.wpfilm").status, 0);
  const wp::test::CliRun none = run("merge plain.wpfilm --aov normal -q -o n.pfm");
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.err.find("holds no AOVs"), std::string::npos) << none.err;
  EXPECT_FALSE(std::filesystem::exists(path("n.pfm")));
  const wp::test::CliRun bad = run("render " + scene + " --aov albedo,motion -o b.exr");
  EXPECT_EQ(bad.status, 1);
  EXPECT_FALSE(std::filesystem::exists(path("b.exr")));
}

}  // namespace
