// What a glTF node carries besides meshes: its transform, a camera, a KHR_lights_punctual light.
// Internal to the glTF loader; everything throws wp::Error (without the file name) on malformed
// values.
#pragma once

#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include "host/scene/scene.h"

namespace wp::gltf {

// The node's local transform: `matrix` (column-major, as glTF stores it) or T x R x S.
glm::dmat4 local_transform(const tinygltf::Node& node, int index);

// Camera `index` placed by `world`: position = world origin, forward = world -Z, up = world +Y
// made orthogonal to forward (both unit; scale does not matter).
Camera make_camera(const tinygltf::Model& model, int index, const glm::dmat4& world);

// The KHR_lights_punctual light index the node refers to, or -1 when it has none.
int node_light(const tinygltf::Node& node, int index);

// Light `index` placed by `world`: position = world origin, direction = world -Z (unit),
// intensity = colour x intensity.
// Colour x intensity beyond scene.h's kMaxRadiance is clamped, with a warning into `warnings`
// (may be null).
PunctualLight make_light(const tinygltf::Model& model, int index, const glm::dmat4& world,
                         std::vector<std::string>* warnings = nullptr);

}  // namespace wp::gltf
