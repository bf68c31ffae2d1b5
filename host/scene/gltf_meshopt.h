// EXT_meshopt_compression: buffer views whose bytes are stored compressed (meshoptimizer's codecs),
// decoded before anything reads them. Internal to the glTF loader.
//
// A compressed view's extension names the compressed bytes (buffer, byteOffset, byteLength), their
// layout (count elements of byteStride bytes), the codec (mode ATTRIBUTES, TRIANGLES or INDICES)
// and a filter applied after it (NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL). The view's own buffer
// is often a placeholder without data (a "fallback" buffer: only byteLength), which tinygltf
// cannot parse: the loader finds those first (gltf_prepass.h). Every
// compressed view is decoded into one new buffer of the model, the view pointed at it: accessors
// and images then read decoded bytes as they read any view.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include <tiny_gltf.h>

namespace wp::gltf {

// Buffers without data for this extension: buffer index -> the byteLength the file declares.
using PlaceholderBuffers = std::map<int, std::uint64_t>;

enum class MeshoptMode { kAttributes, kTriangles, kIndices };
enum class MeshoptFilter { kNone, kOctahedral, kQuaternion, kExponential };

// One compressed stream as the extension describes it.
struct MeshoptStream {
  std::size_t count = 0;   // elements
  std::size_t stride = 0;  // bytes per element
  MeshoptMode mode = MeshoptMode::kAttributes;
  MeshoptFilter filter = MeshoptFilter::kNone;
};

// Checks `s` against the extension's rules (stride by mode and filter, count a multiple of 3 for
// TRIANGLES) and `compressed_bytes` against what the codecs can expand to (below); throws
// wp::Error naming `where`. Every check the decoder functions would assert on is made here.
void check_meshopt_stream(const MeshoptStream& s, std::uint64_t compressed_bytes,
                          const std::string& where);

// Decodes `size` compressed bytes into `out` (s.count * s.stride bytes) and applies the filter;
// `s` must have passed check_meshopt_stream. Throws wp::Error naming `where` when the stream is
// corrupt (the decoders return an error; they never read or write outside the two ranges).
void decode_meshopt_stream(const MeshoptStream& s, const unsigned char* data, std::size_t size,
                           unsigned char* out, const std::string& where);

// Decodes every compressed buffer view of `model` into one new buffer appended to it, pointing the
// views there; `placeholders` from mark_meshopt_placeholders (their data is dropped). Throws
// wp::Error naming the bufferView for a malformed extension, a range outside its buffer, a stream
// larger than its compressed bytes can hold, or a corrupt stream; nothing is allocated for the
// decoded data before every view has passed.
void decode_meshopt(tinygltf::Model& model, const PlaceholderBuffers& placeholders);

}  // namespace wp::gltf
