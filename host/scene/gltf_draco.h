// KHR_draco_mesh_compression: a primitive's attributes and indices stored as one Draco-compressed
// mesh in a bufferView, decoded before anything reads them. Internal to the glTF loader.
//
// Each Draco primitive's mesh is decoded (Draco, libdraco), then the accessors its `attributes`
// and `indices` name are given the decoded data: a new buffer holds it, each accessor points at a
// view of it (the extension says loaders must ignore their own bufferView), so the primitive reads
// as any other. The accessors' counts must match the decoded mesh, as the extension requires.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace wp::gltf {

// One decoded attribute: `components` values of glTF component type `component_type` per point,
// point after point.
struct DracoAttribute {
  int component_type = 0;
  int components = 0;
  std::vector<unsigned char> bytes;
};

// A decoded Draco mesh: its point count, its faces as a triangle list of point indices (each below
// `points`), and every attribute by its unique id.
struct DracoMesh {
  std::size_t points = 0;
  std::vector<std::uint32_t> indices;
  std::map<std::uint32_t, DracoAttribute> attributes;
};

// Decodes `size` bytes of a Draco triangle mesh. Throws wp::Error naming `where` for anything but a
// triangle mesh Draco decodes, more points or indices than 32-bit indices address, a face or an
// attribute mapping outside the mesh, or an attribute of a type glTF has not (64-bit, bool).
DracoMesh decode_draco_mesh(const unsigned char* data, std::size_t size, const std::string& where);

// Decodes the KHR_draco_mesh_compression of every primitive of `meshes` (the meshes the scene
// places; others are never read) and points its accessors at the decoded data (primitives of
// TRIANGLE_STRIP mode become TRIANGLES: Draco stores faces). Before Draco decodes anything, the
// counts its header announces are checked against the primitive's accessors (the Draco bitstream
// must be version 2.2, the extension's): Draco allocates from them, so the loader counts the
// accessors' claims against the device before calling this (gltf_loader.cpp). Throws wp::Error
// naming the mesh and primitive for a malformed extension, a header announcing more faces or
// points than the accessors hold (or more points than its faces' corners), an attribute it lists
// that the primitive has not or the data has not, an accessor whose count, component count or use
// disagrees with the decoded mesh, and the errors of decode_draco_mesh.
void decode_draco(tinygltf::Model& model, const std::set<int>& meshes);

}  // namespace wp::gltf
