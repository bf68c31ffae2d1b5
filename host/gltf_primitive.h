// Triangle primitives into the scene's flat arrays. Internal to the glTF loader.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include "host/scene.h"

namespace wp::gltf {

// True for the modes that become triangles: TRIANGLES (also mode absent), TRIANGLE_STRIP and
// TRIANGLE_FAN.
bool is_triangle_mode(int mode);

// Appends the triangles of `primitive` (a triangle mode, with POSITION) placed by `world`, all
// with `material`: positions by `world`, normals by its inverse transpose (renormalised), winding
// swapped when `world` mirrors so fronts stay counter-clockwise. Triangles without usable normals
// (NORMAL absent or zero at one of its corners) get unshared vertices carrying the face normal.
// Only vertices that some triangle uses are appended. Throws wp::Error (without the file name)
// for out-of-range accessors or indices and for non-finite positions. Returns how many trailing
// indices did not make a whole triangle (TRIANGLES mode; normally 0).
std::size_t append_primitive(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                             const glm::dmat4& world, std::uint32_t material, Scene& scene);

}  // namespace wp::gltf
