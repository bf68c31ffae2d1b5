#include "host/scene/view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "host/scene/gltf_loader.h"
#include "host/util/error.h"

namespace wp {

namespace {

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::string text(const glm::vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%g,%g,%g", double(v.x), double(v.y), double(v.z));
  return buf;
}

// The scene's bounding sphere, with the framing camera's fallbacks for an empty or broken scene:
// the origin and one scene unit.
struct Sphere {
  glm::vec3 centre;
  float radius;
};
Sphere bounding_sphere(const Scene& scene) {
  Sphere s{0.5f * (scene.bounds_lo + scene.bounds_hi),
           0.5f * glm::length(scene.bounds_hi - scene.bounds_lo)};
  if (!finite(s.centre)) s.centre = glm::vec3(0.0f);
  if (!(s.radius > 0.0f) || !std::isfinite(s.radius)) s.radius = 1.0f;
  return s;
}

// Unit image +y for a camera looking along `forward`: `up` without its part along forward.
glm::vec3 image_up(const glm::vec3& forward, const glm::vec3& up) {
  const glm::vec3 u = up - glm::dot(up, forward) * forward;
  const float length = glm::length(u);
  // Below ~1e-3 of a radian between them, the image's roll is set by rounding: refuse.
  if (!(length > 1e-3f * glm::length(up)))
    throw Error("--up " + text(up) + " is (nearly) parallel to the view direction " +
                text(forward) + "; give another --up");
  return u / length;
}

// The camera --look-from/--look-at or --orbit places (perspective, znear 0).
Camera placed_camera(const Scene& scene, const View& view, float yfov, float aspect) {
  Camera c;
  c.name = "command line";
  c.type = CameraType::kPerspective;
  c.yfov = yfov;
  c.znear = 0.0f;
  if (view.look_from) {
    const glm::vec3 towards = *view.look_at - *view.look_from;
    const float distance = glm::length(towards);
    if (!(distance > 0.0f) || !std::isfinite(distance))
      throw Error("--look-from " + text(*view.look_from) + " and --look-at " + text(*view.look_at) +
                  " must be two different points");
    c.position = *view.look_from;
    c.forward = towards / distance;
    c.up = image_up(c.forward, view.up.value_or(glm::vec3(0.0f, 1.0f, 0.0f)));
    return c;
  }
  const Sphere sphere = bounding_sphere(scene);
  const float theta = glm::radians(view.orbit->x), phi = glm::radians(view.orbit->y);
  const float r = view.orbit->z > 0.0f ? view.orbit->z : fit_distance(sphere.radius, yfov, aspect);
  const glm::vec3 out(std::sin(phi) * std::sin(theta), std::cos(phi),
                      std::sin(phi) * std::cos(theta));
  c.position = sphere.centre + r * out;
  c.forward = -out;
  // Towards +Y on the orbit's sphere (minus the derivative of `out` by phi): the world's up
  // projected onto the image plane, and at the poles (phi 0 or 180) its limit, so the view turns
  // continuously through them.
  const glm::vec3 pole_up(-std::cos(phi) * std::sin(theta), std::sin(phi),
                          -std::cos(phi) * std::cos(theta));
  c.up = view.up ? image_up(c.forward, *view.up) : glm::normalize(pole_up);
  return c;
}

// Where the lens focuses, along the view direction: the options' choice, or the look-at point,
// the orbit's centre, else the centre of the bounds.
float focus_distance(const Scene& scene, const View& view, const Camera& c) {
  if (view.focus_distance) return *view.focus_distance;
  glm::vec3 target = bounding_sphere(scene).centre;
  const char* what = "the centre of the scene's bounds";
  if (view.focus_on) {
    target = *view.focus_on;
    what = "the --focus-on point";
  } else if (view.look_at) {
    target = *view.look_at;
    what = "the --look-at point";
  }
  const float d = glm::dot(target - c.position, glm::normalize(c.forward));
  if (!(d > 0.0f) || !std::isfinite(d))
    throw Error(std::string("--aperture: ") + what + " " + text(target) +
                " is not in front of the camera; give --focus-distance or --focus-on");
  return d;
}

}  // namespace

std::string view_text(const View& v) {
  std::string out;
  const auto add = [&](const char* name, const std::string& value) {
    out += (out.empty() ? "" : " ") + std::string(name) + "=" + value;
  };
  const auto number = [](float x) {  // 9 significant digits: every float reads back exactly
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", double(x));
    return std::string(buf);
  };
  const auto vec = [&](const glm::vec3& p) {
    return number(p.x) + "," + number(p.y) + "," + number(p.z);
  };
  if (v.look_from) add("look_from", vec(*v.look_from));
  if (v.look_at) add("look_at", vec(*v.look_at));
  if (v.up) add("up", vec(*v.up));
  if (v.orbit) add("orbit", vec(*v.orbit));
  if (v.fov) add("fov", number(*v.fov));
  if (v.aperture > 0.0f) add("aperture", number(v.aperture));
  if (v.focus_distance) add("focus_distance", number(*v.focus_distance));
  if (v.focus_on) add("focus_on", vec(*v.focus_on));
  return out;
}

float fit_distance(float radius, float yfov, float aspect) {
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) aspect = 1.0f;
  const float half_v = 0.5f * yfov;
  const float half = std::min(half_v, std::atan(std::tan(half_v) * aspect));
  return radius / std::sin(half);
}

void check_view(const View& v, bool camera_index_given) {
  const auto check = [](bool ok, const std::string& what) {
    if (!ok) throw Error(what);
  };
  for (const auto& [p, name] : {std::pair{&v.look_from, "--look-from"},
                                {&v.look_at, "--look-at"},
                                {&v.up, "--up"},
                                {&v.orbit, "--orbit"},
                                {&v.focus_on, "--focus-on"}})
    check(!*p || finite(**p), std::string(name) + " must be three finite numbers");
  check(!(v.look_from && v.orbit), "--look-from and --orbit place the camera twice; give one");
  check(v.look_from.has_value() == v.look_at.has_value(),
        "--look-from and --look-at go together (the eye and the point it looks at)");
  check(!v.up || v.places_camera(), "--up needs --look-from/--look-at or --orbit");
  check(!(camera_index_given && v.places_camera()),
        "--camera and --look-from/--orbit both choose the camera; give one");
  check(!v.up || glm::length(*v.up) > 0.0f, "--up must not be the zero vector");
  check(!v.orbit || v.orbit->z >= 0.0f,
        "--orbit THETA,PHI,DISTANCE: the distance must be >= 0 (0: fit the scene)");
  check(!v.fov || (*v.fov > 0.0f && *v.fov < 180.0f),
        "--fov must be a vertical field of view in degrees, between 0 and 180 (exclusive)");
  check(std::isfinite(v.aperture) && v.aperture >= 0.0f,
        "--aperture must be a lens radius >= 0 (scene units; 0: a pinhole)");
  check(!v.focus_distance || (std::isfinite(*v.focus_distance) && *v.focus_distance > 0.0f),
        "--focus-distance must be a distance > 0 (scene units)");
  check(!(v.focus_distance && v.focus_on), "--focus-distance and --focus-on both set the focus");
  check(v.aperture > 0.0f || !(v.focus_distance || v.focus_on),
        "--focus-distance and --focus-on need --aperture (a pinhole is sharp at every depth)");
}

Camera choose_camera(const Scene& scene, int index, const View& view, float aspect) {
  const float yfov = glm::radians(view.fov.value_or(45.0f));
  Camera c;
  if (view.places_camera()) {
    c = placed_camera(scene, view, yfov, aspect);
  } else if (index >= 0 || !scene.cameras.empty()) {
    const std::size_t i = index >= 0 ? std::size_t(index) : 0;
    if (i >= scene.cameras.size())
      throw Error("--camera " + std::to_string(index) + ": the scene has " +
                  std::to_string(scene.cameras.size()) + " camera(s)");
    c = scene.cameras[i];
    if (c.type == CameraType::kOrthographic && view.fov)
      throw Error("--fov: camera " + std::to_string(i) +
                  " is orthographic (its view has a size, not an angle)");
    if (view.fov) c.yfov = yfov;
  } else {
    c = framing_camera(scene, aspect);
    if (view.fov) {  // the same view direction, moved to fit the bounds at this angle
      c.yfov = yfov;
      const Sphere sphere = bounding_sphere(scene);
      c.position = sphere.centre - fit_distance(sphere.radius, yfov, aspect) * c.forward;
    }
  }
  if (view.aperture > 0.0f) {
    if (c.type == CameraType::kOrthographic)
      throw Error("--aperture: the camera is orthographic; a thin lens needs a perspective one");
    c.lens_radius = view.aperture;
    c.focus_distance = focus_distance(scene, view, c);
  }
  return c;
}

}  // namespace wp
