// Bounds-checked reading of glTF accessors from a tinygltf model. Internal to the glTF loader.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <tiny_gltf.h>

namespace wp::gltf {

// Bit for a TINYGLTF_COMPONENT_TYPE_* value (5120..5126) in AccessorSpec::component_types; 0 for
// any other value a file may hold (a shift by it would be undefined: found by fuzzing).
constexpr unsigned component_bit(int component_type) {
  return component_type >= 5120 && component_type <= 5126 ? 1u << (component_type - 5120) : 0u;
}

constexpr unsigned kFloatBit = component_bit(TINYGLTF_COMPONENT_TYPE_FLOAT);
constexpr unsigned kIntegerBits = component_bit(TINYGLTF_COMPONENT_TYPE_BYTE) |
                                  component_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                                  component_bit(TINYGLTF_COMPONENT_TYPE_SHORT) |
                                  component_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
constexpr unsigned kIndexBits = component_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                                component_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) |
                                component_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);

// Components of an accessor `type` (SCALAR 1, VECn n); 0 for matrices and unknown types.
int component_count(int type);

// What a caller accepts from an accessor.
struct AccessorSpec {
  const char* what;    // role named in messages: "POSITION", "indices", ...
  int min_components;  // SCALAR = 1, VECn = n; matrices are never accepted
  int max_components;
  unsigned component_types;  // component_bit() of each accepted component type
};

// One accessor, validated once: its type against an AccessorSpec, and every byte it can read
// (bufferView and buffer ranges, stride, sparse indices and values) against the buffers, so
// that read() and read_indices() never leave them. Throws wp::Error naming the accessor and the
// cause (the loader adds the file name). Sparse accessors are resolved into a dense copy.
class AccessorReader {
 public:
  AccessorReader(const tinygltf::Model& model, int accessor, const AccessorSpec& spec);

  std::size_t count() const { return count_; }
  int components() const { return components_; }

  // Element i (< count()) into out[0, components()): floats as stored; normalized integers
  // mapped to [0, 1] (unsigned) or [-1, 1] (signed) as glTF specifies; other integers converted.
  void read(std::size_t i, float* out) const;

  // All elements of an unsigned integer accessor (indices), in order.
  std::vector<std::uint32_t> read_indices() const;

 private:
  void resolve_sparse(const tinygltf::Model& model, const tinygltf::Accessor& accessor);

  // Element 0: data_ in the buffer, or dense_ once a sparse accessor is resolved; null when there
  // is no data (all zeros).
  const unsigned char* base() const { return sparse_ ? dense_.data() : data_; }

  const unsigned char* data_ = nullptr;
  std::size_t stride_ = 0;  // bytes from one element to the next
  std::size_t count_ = 0;
  std::size_t element_size_ = 0;
  int components_ = 0;
  int component_type_ = 0;
  int component_size_ = 0;
  bool normalized_ = false;
  bool sparse_ = false;
  int index_ = -1;
  const char* what_ = "";
  std::vector<unsigned char> dense_;  // sparse accessors: base data with the sparse values applied
};

// The element count of accessor `accessor` when the bytes it spans lie in its bufferView and
// buffer, else 0 (also without a bufferView: such an accessor is zeros, whatever its count).
// Checks no type and reads nothing: for counting a scene before it is loaded, where a count that
// no bytes of the file hold must not size anything.
std::size_t readable_count(const tinygltf::Model& model, int accessor);

}  // namespace wp::gltf
