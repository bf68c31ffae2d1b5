// What tinygltf 2.7.0 cannot parse in compressed glTF files, rewritten in the JSON before it does.
// Internal to the glTF loader.
//
//   EXT_meshopt_compression: a buffer without data (a "fallback" or placeholder buffer, only a
//     byteLength) is refused by tinygltf (a .gltf's buffer needs a uri; a .glb's gets the binary
//     chunk copied in, or fails when byteLength exceeds it). Each becomes a one-byte data: URI and
//     is listed, so that gltf_meshopt.cpp knows it has no data and how large it claims to be.
//   KHR_draco_mesh_compression: the indices accessor of a Draco primitive has no bufferView (the
//     data are in the Draco stream), which tinygltf refuses for indices. It is given the Draco
//     bufferView, which gltf_draco.cpp replaces with the decoded indices.
#pragma once

#include <string>

#include "host/scene/gltf_meshopt.h"

namespace wp::gltf {

// Rewrites the JSON document `json` (a .gltf, or a .glb's JSON chunk; `glb`: its buffer 0 is the
// binary chunk) as above when it uses either extension; the placeholder buffers go to
// `placeholders`. Returns whether `json` changed. Anything else is left as it is, and JSON that
// does not parse too (tinygltf reports it). Cheap for files that use neither extension: a text
// search.
bool prepare_compressed_json(std::string& json, bool glb, PlaceholderBuffers* placeholders);

// Whether `text` mentions either extension (the test the loader makes before copying a file).
bool mentions_compression(const char* text, std::size_t size);

}  // namespace wp::gltf
