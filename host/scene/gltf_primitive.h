// Triangle primitives into the scene's flat arrays. Internal to the glTF loader.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include "host/scene/scene.h"

namespace wp::gltf {

// What the scene keeps per vertex beyond position, normal, TEXCOORD_0 and COLOR_0. The loader
// decides once per file, so that Scene::uv0, color0, uv1 and tangents are each either empty or as
// long as Scene::positions.
struct VertexNeeds {
  bool uv0 = true;        // keep TEXCOORD_0 (some primitive has it, or tangents are kept); (0, 0)
  bool color0 = true;     // keep COLOR_0 (some primitive has it); (1, 1, 1, 1) where absent
  bool uv1 = false;       // keep TEXCOORD_1 (some texture reads it); (0, 0) where absent
  bool tangents = false;  // keep tangents (some material needs a tangent frame: gltf_loader.cpp)
  // The TEXCOORD set this primitive's normal texture reads (else its clearcoat normal or
  // anisotropy texture; 0 without any): when tangents are kept and the primitive has no TANGENT,
  // they are generated from that set.
  int tangent_uv = 0;
};

// True for the modes that become triangles: TRIANGLES (also mode absent), TRIANGLE_STRIP and
// TRIANGLE_FAN.
bool is_triangle_mode(int mode);

// Appends the triangles of `primitive` (a triangle mode, with POSITION) placed by `world`, all
// with `material`: positions by `world`, normals by its inverse transpose (renormalised), winding
// swapped when `world` mirrors so fronts stay counter-clockwise. Triangles without usable normals
// (NORMAL absent or zero at one of its corners) get unshared vertices carrying the face normal.
// Only vertices that some triangle uses are appended. With `needs`: TEXCOORD_1, and TANGENT with
// xyz by the upper 3x3 of `world` (renormalised) and w flipped when `world` mirrors, or, where the
// primitive has none, tangents from generate_tangents() (every vertex gets a usable tangent).
// Throws wp::Error (without the file name) for out-of-range accessors or indices and for non-finite
// positions. Returns how many trailing indices did not make a whole triangle (TRIANGLES mode;
// normally 0).
std::size_t append_primitive(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                             const glm::dmat4& world, std::uint32_t material,
                             const VertexNeeds& needs, Scene& scene);

// Per-vertex tangents for the triangles [first_triangle, triangle_count()) from their positions,
// normals and TEXCOORD set `uv_set` (0 or 1), written to Scene::tangents (which must be as long
// as Scene::positions). This approximates MikkTSpace, the algorithm glTF recommends: per-triangle
// UV tangents (dP/du) and bitangents (the image's up, -dP/dv: glTF's v runs down the image),
// normalised and accumulated per vertex weighted by the corner angle, the tangent made
// orthogonal to the vertex normal (Gram-Schmidt). w is the handedness of the vertex's triangles:
// +1 where cross(face normal, dP/du) points to the image's up, -1 where UVs are mirrored, so
// that glTF's bitangent cross(normal, tangent) * w points to the image's up (the +Y of a normal
// texture). A vertex shared by triangles of both handednesses (a mirrored UV seam) is split in
// two, as MikkTSpace does. MikkTSpace also splits
// vertices whose triangles' tangents diverge strongly and weights differently; results agree on
// smooth, consistently mapped meshes. Vertices of triangles without a usable UV mapping get an
// arbitrary tangent orthogonal to the normal.
void generate_tangents(Scene& scene, std::size_t first_triangle, int uv_set);

}  // namespace wp::gltf
