// The view from the command line (host/scene/view.h): cameras placed by --look-from/--look-at and
// --orbit, --fov, and the thin lens (--aperture, kernels/camera/camera.h).
//
// Known pixels: the expected image positions come from GLM's own view and projection matrices
// (glm::lookAt, glm::perspective), not from wavepath's camera code. The scenes are black but for
// small emissive squares ("markers") seen with --max-depth 0 (camera rays only: no light is
// reflected), so every pixel value is exactly the marker radiance times the fraction of the
// pixel's samples that hit a marker.
//
// Thin lens: an image-plane point q (in units of the plane at distance 1 that the camera's
// right/up span) of a ray from lens point a (|a| <= aperture A) through a point at depth z (along
// the view direction) is q = p + a (1/F - 1/z), p its pinhole image and F the focus distance. So a
// flat marker at depth z images as its pinhole image convolved with a uniform disc of radius
// R = A |1/F - 1/z|, and on the plane of focus (z = F) exactly as through a pinhole.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "host/device/cl_runtime.h"
#include "host/render/render.h"
#include "host/scene/view.h"
#include "host/util/error.h"
#include "tests/device_test.h"
#include "tests/scene_factory.h"

namespace {

using glm::dvec3;
using glm::vec3;

constexpr double kPi = 3.14159265358979323846;

// ---- host: the cameras placed ------------------------------------------------------------------

wp::Scene bounds_scene(vec3 lo, vec3 hi) {
  wp::Scene s;
  s.bounds_lo = lo;
  s.bounds_hi = hi;
  return s;
}

TEST(View, LookAtGivesAnOrthonormalFrameWithTheRequestedUp) {
  wp::View v;
  v.look_from = vec3(1, 2, 5);
  v.look_at = vec3(0, 0.5f, 0);
  v.up = vec3(1, 1, 0);
  v.fov = 30.0f;
  const wp::Camera c = wp::choose_camera(bounds_scene(vec3(-1), vec3(1)), -1, v, 1.5f);
  EXPECT_EQ(c.type, wp::CameraType::kPerspective);
  EXPECT_FLOAT_EQ(c.yfov, float(30.0 * kPi / 180.0));
  const vec3 f = glm::normalize(*v.look_at - *v.look_from);
  EXPECT_NEAR(glm::length(c.forward - f), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(c.up, c.forward), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(c.up), 1.0f, 1e-6f);
  // up lies in the plane of the requested up and the view direction, on the requested side.
  EXPECT_NEAR(glm::dot(glm::cross(*v.up, f), c.up), 0.0f, 1e-6f);
  EXPECT_GT(glm::dot(c.up, *v.up), 0.0f);
  EXPECT_EQ(c.position, *v.look_from);
  EXPECT_EQ(c.lens_radius, 0.0f);
}

// position = centre + r (sin phi sin theta, cos phi, sin phi cos theta), in double here; with no
// distance, the bounding sphere (radius |hi - lo| / 2) just fits the tighter half-angle.
TEST(View, OrbitFollowsTheRenderFidelityConvention) {
  const vec3 lo(-1, 0, -3), hi(3, 2, 1);
  const dvec3 centre(1, 1, -1);
  const double radius = 0.5 * std::sqrt(16.0 + 4.0 + 16.0);
  for (const float aspect : {0.5f, 1.0f, 2.0f})
    for (const float theta : {0.0f, 35.0f, 90.0f, 200.0f, -60.0f})
      for (const float phi : {0.0f, 10.0f, 60.0f, 90.0f, 135.0f, 180.0f})
        for (const float distance : {0.0f, 7.5f}) {
          wp::View v;
          v.orbit = vec3(theta, phi, distance);
          const wp::Camera c = wp::choose_camera(bounds_scene(lo, hi), -1, v, aspect);
          const double t = theta * kPi / 180, p = phi * kPi / 180;
          const dvec3 out(std::sin(p) * std::sin(t), std::cos(p), std::sin(p) * std::cos(t));
          const double half =
              std::min(kPi / 8, std::atan(std::tan(kPi / 8) * double(aspect)));  // 45 deg fov
          const double r = distance > 0 ? distance : radius / std::sin(half);
          const dvec3 want = centre + r * out;
          SCOPED_TRACE(testing::Message()
                       << theta << "," << phi << "," << distance << " aspect " << aspect);
          EXPECT_NEAR(glm::length(dvec3(c.position) - want), 0.0, 2e-6 * r);
          EXPECT_NEAR(glm::length(dvec3(c.forward) + out), 0.0, 1e-6);
          EXPECT_NEAR(glm::dot(c.up, c.forward), 0.0f, 1e-6f);
          EXPECT_NEAR(glm::length(c.up), 1.0f, 1e-6f);
          // Image up is the world's +Y projected where that is defined; at the poles it is the
          // limit from the equator's side, -d(out)/d(phi) there: (-sin theta, 0, -cos theta) at
          // phi 0.
          const dvec3 limit(-std::cos(p) * std::sin(t), std::sin(p), -std::cos(p) * std::cos(t));
          EXPECT_NEAR(glm::length(dvec3(c.up) - limit), 0.0, 2e-6);
        }
}

// The framing camera with --fov keeps its direction and moves to fit the bounds at that angle.
TEST(View, FieldOfViewRefitsTheFramingCamera) {
  const wp::Scene s = bounds_scene(vec3(-1), vec3(1));
  wp::View v;
  v.fov = 20.0f;
  const wp::Camera narrow = wp::choose_camera(s, -1, v, 1.0f);
  const wp::Camera wide = wp::choose_camera(s, -1, {}, 1.0f);
  EXPECT_NEAR(glm::length(narrow.forward - wide.forward), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(narrow.position) * std::sin(10.0 * kPi / 180), std::sqrt(3.0), 1e-5);
}

TEST(View, ImpossibleViewsAreErrorsNamingTheOption) {
  const auto error = [](const wp::View& v, bool index_given = false) -> std::string {
    try {
      wp::check_view(v, index_given);
      wp::Scene s = bounds_scene(vec3(-1), vec3(1));
      wp::Camera ortho;  // the file's camera, for --camera 0
      ortho.type = wp::CameraType::kOrthographic;
      if (index_given) s.cameras.push_back(ortho);
      (void)wp::choose_camera(s, index_given ? 0 : -1, v, 1.0f);
    } catch (const wp::Error& e) {
      return e.what();
    }
    return "";
  };
  wp::View v;
  v.look_from = vec3(0, 0, 1);
  EXPECT_NE(error(v).find("--look-from and --look-at go together"), std::string::npos);
  v.look_at = vec3(0, 0, 1);
  EXPECT_NE(error(v).find("must be two different points"), std::string::npos);
  v.look_at = vec3(0, 0, 0);
  v.up = vec3(0, 0, 2);
  EXPECT_NE(error(v).find("--up 0,0,2 is (nearly) parallel"), std::string::npos);
  v.up.reset();
  EXPECT_NE(error(v, true).find("--camera and --look-from/--orbit"), std::string::npos);
  v.orbit = vec3(0, 90, 0);
  EXPECT_NE(error(v).find("--look-from and --orbit"), std::string::npos);
  v.look_from = vec3(NAN, 0, 0);
  EXPECT_NE(error(v).find("--look-from must be three finite numbers"), std::string::npos);

  wp::View o;
  o.orbit = vec3(0, 90, -1);
  EXPECT_NE(error(o).find("the distance must be >= 0"), std::string::npos);
  for (const float fov : {0.0f, 180.0f, -5.0f, NAN}) {
    wp::View f;
    f.fov = fov;
    EXPECT_NE(error(f).find("--fov must be"), std::string::npos) << fov;
  }
  wp::View ortho_fov;
  ortho_fov.fov = 30.0f;
  EXPECT_NE(error(ortho_fov, true).find("is orthographic"), std::string::npos);
  wp::View lens;
  lens.aperture = 0.1f;
  EXPECT_NE(error(lens, true).find("a thin lens needs a perspective one"), std::string::npos);
  lens.aperture = -1.0f;
  EXPECT_NE(error(lens).find("--aperture must be"), std::string::npos);
  wp::View focus;
  focus.focus_distance = 2.0f;
  EXPECT_NE(error(focus).find("need --aperture"), std::string::npos);
  focus.aperture = 0.1f;
  focus.focus_distance = 0.0f;
  EXPECT_NE(error(focus).find("--focus-distance must be"), std::string::npos);
  wp::View behind;  // the framing camera looks along -Z from +Z: a point at z = +100 is behind
  behind.aperture = 0.1f;
  behind.focus_on = vec3(0, 0, 100);
  EXPECT_NE(error(behind).find("is not in front of the camera"), std::string::npos);
}

// ---- device: renders of markers -----------------------------------------------------------------

class ViewRender : public wp::test::DeviceTest {};

constexpr int kWidth = 64, kHeight = 48;

// A scene of emissive squares (radiance 1, both sides) whose bounds are the box [-10, 10]^3 (centre
// 0): two black triangles at its corners, unseen with max depth 0.
struct Markers {
  wp::Scene scene;
  Markers() {
    wp::Material black;
    black.base_color = glm::vec4(0, 0, 0, 1);
    wp::Material light = black;
    light.emission = vec3(1.0f);
    light.double_sided = true;
    scene.materials = {black, light};
    const std::vector<vec3> n(3, vec3(1, 0, 0));
    wp::test::add_mesh(scene, {vec3(-10), vec3(-10, -10, -9.9f), vec3(-10, -9.9f, -10)}, n,
                       {0, 1, 2}, 0);
    wp::test::add_mesh(scene, {vec3(10), vec3(10, 10, 9.9f), vec3(10, 9.9f, 10)}, n, {0, 1, 2}, 0);
  }
  // A square of side `side` about `centre`, perpendicular to `forward`.
  void add(vec3 centre, vec3 forward, float side) {
    const vec3 a = glm::normalize(
        glm::cross(forward, std::abs(forward.y) < 0.9f ? vec3(0, 1, 0) : vec3(1, 0, 0)));
    const vec3 b = glm::cross(forward, a);
    const float h = 0.5f * side;
    wp::test::add_quad(scene, centre - h * a - h * b, centre + h * a - h * b,
                       centre + h * a + h * b, centre - h * a + h * b, 1);
  }
  wp::Scene done() {
    wp::test::finish_bounds(scene);
    return scene;
  }
};

wp::RenderSettings marker_settings(const wp::View& view, int spp) {
  wp::RenderSettings st;
  st.width = kWidth;
  st.height = kHeight;
  st.spp = spp;
  st.max_depth = 0;  // camera rays only
  st.view = view;
  return st;
}

// The camera GLM's matrices describe: world point -> continuous pixel coordinates (x right, y
// down, the pixel (i, j) covering [i, i + 1) x [j, j + 1)), and back at a depth along the view.
struct GlmCamera {
  glm::dmat4 view, proj;
  dvec3 eye, forward;
  GlmCamera(dvec3 eye_, dvec3 target, dvec3 up, double fov_deg)
      : view(glm::lookAt(eye_, target, up)),
        proj(glm::perspective(fov_deg * kPi / 180, double(kWidth) / kHeight, 0.01, 100.0)),
        eye(eye_),
        forward(glm::normalize(target - eye_)) {}
  glm::dvec2 pixel(dvec3 p) const {
    const glm::dvec4 c = proj * view * glm::dvec4(p, 1.0);
    return {(c.x / c.w + 1) * 0.5 * kWidth, (1 - c.y / c.w) * 0.5 * kHeight};
  }
  // The world point at image position (x, y) (pixels) and `depth` along the view direction.
  dvec3 point(double x, double y, double depth) const {
    const glm::dvec4 ndc(2 * x / kWidth - 1, 1 - 2 * y / kHeight, 0.5, 1.0);
    glm::dvec4 w = glm::inverse(proj * view) * ndc;
    const dvec3 onray = dvec3(w) / w.w;
    const dvec3 d = glm::normalize(onray - eye);
    return eye + d * (depth / glm::dot(d, forward));
  }
  // World size of one pixel at `depth`.
  double pixel_size(double depth, double fov_deg) const {
    return 2 * depth * std::tan(0.5 * fov_deg * kPi / 180) / kHeight;
  }
};

std::vector<float> luminance(const wp::Rendered& r) {
  const std::vector<float> rgb = r.film.images().mean;
  std::vector<float> y(rgb.size() / 3);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] = rgb[3 * i];  // markers are white
  return y;
}

// Every marker lights exactly its own pixel: a half-pixel square about the centre of pixel (i, j),
// placed by GLM's inverse projection, so 0.15 px from the pixel's edges at least.
void expect_markers_on_pixels(wp::ClRuntime& rt, const wp::View& view, const GlmCamera& glm_cam,
                              double fov) {
  const std::vector<std::pair<int, int>> pixels = {{3, 4}, {60, 2}, {31, 23}, {10, 40}, {50, 44}};
  Markers m;
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const double depth = 3.0 + 0.5 * double(k);
    const dvec3 p = glm_cam.point(pixels[k].first + 0.5, pixels[k].second + 0.5, depth);
    const glm::dvec2 back = glm_cam.pixel(p);
    ASSERT_NEAR(back.x, pixels[k].first + 0.5, 1e-9);  // GLM's two directions agree
    ASSERT_NEAR(back.y, pixels[k].second + 0.5, 1e-9);
    m.add(vec3(p), vec3(glm_cam.forward), float(0.5 * glm_cam.pixel_size(depth, fov)));
  }
  const wp::Scene s = m.done();
  const std::vector<float> y = luminance(wp::render(rt, s, marker_settings(view, 64)));
  std::vector<float> want(y.size(), 0.0f);
  for (const auto& [i, j] : pixels) want[std::size_t(j) * kWidth + i] = 1.0f;
  for (int j = 0; j < kHeight; ++j)
    for (int i = 0; i < kWidth; ++i) {
      const float v = y[std::size_t(j) * kWidth + i];
      if (want[std::size_t(j) * kWidth + i] > 0)  // about a quarter of the samples hit it
        EXPECT_GT(v, 0.05f) << "marker pixel " << i << "," << j;
      else
        EXPECT_EQ(v, 0.0f) << "pixel " << i << "," << j << " has light";
    }
}

TEST_F(ViewRender, LookAtPutsKnownPointsOnTheirPixels) {
  for (const vec3 up : {vec3(0, 1, 0), vec3(1, 1, 0)}) {
    wp::View v;
    v.look_from = vec3(1, 2, 5);
    v.look_at = vec3(0, 0.5f, 0);
    v.up = up;
    v.fov = 40.0f;
    SCOPED_TRACE(testing::Message() << "up " << up.x << "," << up.y);
    expect_markers_on_pixels(*runtime_, v, GlmCamera(dvec3(1, 2, 5), dvec3(0, 0.5, 0), up, 40.0),
                             40.0);
  }
}

TEST_F(ViewRender, OrbitPutsKnownPointsOnTheirPixels) {
  // About the bounds' centre (0, 0, 0), at 6 units; and looking straight down (phi 0), where image
  // up is (-sin theta, 0, -cos theta).
  for (const vec3 orbit : {vec3(35, 60, 6), vec3(120, 0, 6)}) {
    wp::View v;
    v.orbit = orbit;
    const double t = orbit.x * kPi / 180, p = orbit.y * kPi / 180;
    const dvec3 eye =
        6.0 * dvec3(std::sin(p) * std::sin(t), std::cos(p), std::sin(p) * std::cos(t));
    const dvec3 up = orbit.y == 0 ? dvec3(-std::sin(t), 0, -std::cos(t)) : dvec3(0, 1, 0);
    SCOPED_TRACE(testing::Message() << "orbit " << orbit.x << "," << orbit.y);
    expect_markers_on_pixels(*runtime_, v, GlmCamera(eye, dvec3(0), up, 45.0), 45.0);
  }
}

// Markers on the plane of focus image as through a pinhole: the same pixels, the same values
// (a sample hits a marker on that plane exactly when its pinhole ray does; the pixel jitter takes
// the same numbers, the lens two of its own) up to float rounding at a marker's edge.
TEST_F(ViewRender, ThePlaneOfFocusStaysSharp) {
  const GlmCamera cam(dvec3(0, 0, 6), dvec3(0), dvec3(0, 1, 0), 45.0);
  Markers m;
  std::vector<int> lit;
  for (const auto& [i, j] : std::vector<std::pair<int, int>>{{5, 5}, {32, 24}, {58, 40}}) {
    m.add(vec3(cam.point(i + 0.5, j + 0.5, 6.0)), vec3(0, 0, -1),
          float(0.5 * cam.pixel_size(6.0, 45.0)));
    lit.push_back(j * kWidth + i);
  }
  const wp::Scene s = m.done();
  wp::View pinhole;
  pinhole.look_from = vec3(0, 0, 6);
  pinhole.look_at = vec3(0);
  wp::View lens = pinhole;
  lens.aperture = 0.3f;  // off the plane, at depth 3 or 12, a blur disc of 9.7 or 4.8 px radius
  lens.focus_distance = 6.0f;
  const std::vector<float> a = luminance(wp::render(*runtime_, s, marker_settings(pinhole, 64)));
  const std::vector<float> b = luminance(wp::render(*runtime_, s, marker_settings(lens, 64)));
  for (std::size_t k = 0; k < a.size(); ++k) {
    const bool marker = std::find(lit.begin(), lit.end(), int(k)) != lit.end();
    if (!marker) {
      EXPECT_EQ(b[k], 0.0f) << "pixel " << k;
      continue;
    }
    EXPECT_GT(a[k], 0.05f);
    // At most one of 64 samples decided differently by rounding at the marker's edge.
    EXPECT_NEAR(b[k], a[k], 1.0f / 64 + 1e-6f) << "pixel " << k;
  }
}

// A marker off the plane of focus spreads into a disc of radius R = A |1/F - 1/z| (image-plane
// units; x (H/2) / tan(fov/2) in pixels), centred on its pinhole image. Measured by the image's
// second moment about its centroid: a uniform disc gives R^2 / 2, to which the marker's own
// square (side s px: s^2/6) and the pixel grid (1/12 per axis, Sheppard) add. The independent
// sampler makes the ~n marker hits independent: with n >= 10^4 the relative standard error of
// the moment is below sqrt(Var(r^2)) / (E r^2 sqrt(n)) = 0.58 / 100, so 3% is 5 standard errors.
TEST_F(ViewRender, BlurDiscHasTheThinLensDiameter) {
  const double fov = 45.0, F = 6.0, A = 1.5;  // radius 10.3 px at depth 3.5, 7.2 px at 12
  const double to_px = 0.5 * kHeight / std::tan(0.5 * fov * kPi / 180);
  const GlmCamera cam(dvec3(0, 0, 6), dvec3(0), dvec3(0, 1, 0), fov);
  for (const double z : {3.5, 12.0}) {  // nearer and farther than the focus
    const double side_px = 3.0;
    Markers m;
    const dvec3 centre = cam.point(30.5, 22.5, z);
    m.add(vec3(centre), vec3(0, 0, -1), float(side_px * cam.pixel_size(z, fov)));
    const wp::Scene s = m.done();
    wp::View v;
    v.look_from = vec3(0, 0, 6);
    v.look_at = vec3(0);
    v.aperture = float(A);
    v.focus_distance = float(F);
    wp::RenderSettings st = marker_settings(v, 2048);
    st.sampler = wp::Sampler::kIndependent;
    const std::vector<float> y = luminance(wp::render(*runtime_, s, st));
    double sum = 0, sx = 0, sy = 0;
    for (int j = 0; j < kHeight; ++j)
      for (int i = 0; i < kWidth; ++i) {
        const double w = y[std::size_t(j) * kWidth + i];
        sum += w, sx += w * (i + 0.5), sy += w * (j + 0.5);
      }
    ASSERT_GT(sum, 0.0);
    const double cx = sx / sum, cy = sy / sum;
    double m2 = 0;
    for (int j = 0; j < kHeight; ++j)
      for (int i = 0; i < kWidth; ++i)
        m2 += y[std::size_t(j) * kWidth + i] *
              (std::pow(i + 0.5 - cx, 2) + std::pow(j + 0.5 - cy, 2));
    m2 /= sum;
    const double radius = std::sqrt(2 * (m2 - side_px * side_px / 6 - 1.0 / 6));
    const double want = A * std::abs(1 / F - 1 / z) * to_px;
    SCOPED_TRACE(testing::Message()
                 << "depth " << z << ": radius " << radius << " px, thin lens " << want << " px");
    EXPECT_NEAR(radius, want, 0.03 * want);
    EXPECT_NEAR(cx, 30.5, 0.05 * want);  // the disc is centred on the pinhole image
    EXPECT_NEAR(cy, 22.5, 0.05 * want);
    // Total light is kept: the marker's pinhole pixel sum is its area in pixels (side^2, radiance
    // 1); the disc spreads the same. Relative standard error ~1/sqrt(n) <= 1%: 5% bound.
    EXPECT_NEAR(sum, side_px * side_px, 0.05 * side_px * side_px);
  }
}

// The lens takes two numbers of the pixel's own Sobol' order: images stay the same bit for bit
// whatever the wave size, and sample ranges rendered apart merge into the whole.
TEST_F(ViewRender, LensImagesDoNotDependOnWavesOrSampleSplits) {
  const GlmCamera cam(dvec3(0, 0, 6), dvec3(0), dvec3(0, 1, 0), 45.0);
  Markers m;
  m.add(vec3(cam.point(20.5, 20.5, 4.0)), vec3(0, 0, -1), 0.3f);
  m.add(vec3(cam.point(40.5, 30.5, 9.0)), vec3(0, 0, -1), 0.5f);
  const wp::Scene s = m.done();
  wp::View v;
  v.look_from = vec3(0, 0, 6);
  v.look_at = vec3(0);
  v.aperture = 0.2f;
  wp::RenderSettings st = marker_settings(v, 8);
  const wp::Film whole = wp::render(*runtime_, s, st).film;
  st.wave_size = kWidth * kHeight / 2;  // two waves a sample
  EXPECT_TRUE(wp::render(*runtime_, s, st).film.words() == whole.words()) << "wave size";
  st.wave_size = 0;
  st.spp = 3;
  wp::Film parts = wp::render(*runtime_, s, st).film;
  st.sample_begin = 3;
  st.spp = 5;
  parts.add(wp::render(*runtime_, s, st).film);
  EXPECT_TRUE(parts.words() == whole.words()) << "samples 0:3 + 3:8";
}

}  // namespace
