// The view a render is seen from: one of the file's cameras, or one placed from the command line
// (--look-from/--look-at, --orbit), with an optional thin lens (--aperture). Lengths in scene
// units (glTF: metres), angles in degrees, world space with +Y up as in glTF.
#pragma once

#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "host/scene/scene.h"

namespace wp {

// What the command line says about the camera; every field is optional, and a View with none set
// leaves the file's camera (or the framing camera) as it is.
struct View {
  // --look-from EYE --look-at TARGET [--up UP]: a perspective camera at EYE looking at TARGET,
  // image +y towards UP (projected onto the image plane).
  std::optional<glm::vec3> look_from, look_at;
  std::optional<glm::vec3> up;
  // --orbit THETA,PHI[,DISTANCE] about the centre of the scene's bounding sphere, the convention
  // of the Khronos glTF Render Fidelity scenarios: position = centre + r (sin phi sin theta,
  // cos phi, sin phi cos theta), theta the azimuth from +Z towards +X, phi the angle from +Y;
  // r = DISTANCE, or where it is 0 or missing the distance at which the bounding sphere fits the
  // view (as the framing camera does).
  std::optional<glm::vec3> orbit;  // (theta, phi, distance)
  std::optional<float> fov;        // --fov: vertical field of view, degrees, (0, 180)
  // Thin lens: --aperture RADIUS (the lens radius; 0: a pinhole) focused at --focus-distance D
  // (along the view direction) or on the point --focus-on P. With neither, the focus is the
  // look-at point or the orbit's centre, else the centre of the scene's bounds.
  float aperture = 0.0f;
  std::optional<float> focus_distance;
  std::optional<glm::vec3> focus_on;

  bool places_camera() const { return look_from.has_value() || orbit.has_value(); }
};

// The options set, as text that tells two views apart ("" for a View with none set): part of the
// render key (films of two views never merge) and of the EXR header.
std::string view_text(const View& view);

// The distance from the centre of a sphere of `radius` at which it just fits a perspective view
// of vertical field of view `yfov` (radians) and `aspect` (width / height): the tighter half-angle
// of the view subtends the radius.
float fit_distance(float radius, float yfov, float aspect);

// Checks what can be checked without the scene (finite values, ranges, options that exclude one
// another); throws wp::Error naming the option.
void check_view(const View& view, bool camera_index_given);

// The camera to render: `index` (-1: the file's first camera, else the framing camera), or the one
// `view` places, with `view`'s field of view and lens. Throws wp::Error for a view that the scene
// makes impossible (an orthographic camera with a lens or a field of view, a focus behind the
// camera, an index past the file's cameras).
Camera choose_camera(const Scene& scene, int index, const View& view, float aspect);

}  // namespace wp
