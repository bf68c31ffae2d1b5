// What a glTF node carries besides meshes: its transform, a camera, a KHR_lights_punctual light.
// Internal to the glTF loader; everything throws wp::Error (without the file name) on malformed
// values.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include "host/scene/scene.h"

namespace wp::gltf {

// The node's local transform: `matrix` (column-major, as glTF stores it) or T x R x S.
glm::dmat4 local_transform(const tinygltf::Node& node, int index);

// EXT_mesh_gpu_instancing: the transforms of node `index`'s instances, T x R x S each from the
// extension's TRANSLATION (VEC3 float), ROTATION (VEC4 float, or normalized byte or short: an
// x, y, z, w quaternion, renormalised) and SCALE (VEC3 float) accessors, an absent one the
// identity; none (std::nullopt) when the node does not have the extension. The node places its
// mesh once per instance, at world x instance (the extension's "NodeWorldXform * InstanceXform").
// Every attribute accessor, custom ones ("_ID") included, must have the same count.
std::optional<std::vector<glm::dmat4>> instance_transforms(const tinygltf::Model& model,
                                                           const tinygltf::Node& node, int index);

// How many times node `node` places its mesh: its EXT_mesh_gpu_instancing instances (the count of
// the first attribute accessor whose data lies in the file, 0 when none does), else 1. Reads no
// data (for counting a scene before loading it).
std::size_t placements(const tinygltf::Model& model, const tinygltf::Node& node);

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
