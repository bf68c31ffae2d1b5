#include "host/scene/gltf_accessor.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "host/util/error.h"

namespace wp::gltf {
namespace {

// Accessors without a bufferView read as zeros (or sparse values over zeros); their count is not
// bounded by any buffer, so cap it to keep a malformed count from allocating without limit.
constexpr std::size_t kMaxCountWithoutData = std::size_t{1} << 26;

int component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

template <typename T>
T load(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));  // buffers carry no alignment guarantee
  return value;
}

// One component as float, with glTF's normalisation (e.g. signed: max(c / 127, -1)).
float to_float(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return load<float>(p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const float v = load<std::int8_t>(p);
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const float v = load<std::uint8_t>(p);
      return normalized ? v / 255.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const float v = load<std::int16_t>(p);
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const float v = load<std::uint16_t>(p);
      return normalized ? v / 65535.0f : v;
    }
    default: {  // UNSIGNED_INT, the only other type a spec can admit
      const double v = load<std::uint32_t>(p);
      return static_cast<float>(normalized ? v / 4294967295.0 : v);
    }
  }
}

std::uint32_t to_index(const unsigned char* p, int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return load<std::uint8_t>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return load<std::uint16_t>(p);
    default:
      return load<std::uint32_t>(p);
  }
}

// Start of bytes [offset, offset + size) of bufferView `view`, after checking that the view lies
// inside its buffer and the range inside the view.
const unsigned char* view_range(const tinygltf::Model& model, int view, std::size_t offset,
                                std::size_t size, const std::string& where) {
  if (view < 0 || static_cast<std::size_t>(view) >= model.bufferViews.size())
    throw Error(where + ": bufferView " + std::to_string(view) + " does not exist");
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(view)];
  if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size())
    throw Error(where + ": bufferView " + std::to_string(view) + " refers to missing buffer " +
                std::to_string(bv.buffer));
  const std::vector<unsigned char>& buffer =
      model.buffers[static_cast<std::size_t>(bv.buffer)].data;
  if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset)
    throw Error(where + ": bufferView " + std::to_string(view) + " (offset " +
                std::to_string(bv.byteOffset) + ", length " + std::to_string(bv.byteLength) +
                ") exceeds buffer " + std::to_string(bv.buffer) + " (" +
                std::to_string(buffer.size()) + " bytes)");
  if (offset > bv.byteLength || size > bv.byteLength - offset)
    throw Error(where + ": needs " + std::to_string(size) + " bytes at offset " +
                std::to_string(offset) + " of bufferView " + std::to_string(view) + " (" +
                std::to_string(bv.byteLength) + " bytes)");
  return buffer.data() + bv.byteOffset + offset;
}

// Bytes spanned by `count` elements of `element` bytes, `stride` apart; throws on overflow.
std::size_t span_bytes(std::size_t count, std::size_t stride, std::size_t element,
                       const std::string& where) {
  if (count == 0) return 0;
  if (count - 1 > (std::numeric_limits<std::size_t>::max() - element) / stride)
    throw Error(where + ": count " + std::to_string(count) + " is too large");
  return (count - 1) * stride + element;
}

}  // namespace

int component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    default:
      return 0;  // matrices and unknown types
  }
}

std::size_t readable_count(const tinygltf::Model& model, int accessor) {
  if (accessor < 0 || static_cast<std::size_t>(accessor) >= model.accessors.size()) return 0;
  const tinygltf::Accessor& a = model.accessors[static_cast<std::size_t>(accessor)];
  const std::size_t element = static_cast<std::size_t>(component_size(a.componentType)) *
                              static_cast<std::size_t>(component_count(a.type));
  if (element == 0) return 0;
  if (a.bufferView < 0 || static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size())
    return 0;
  const std::size_t stride = model.bufferViews[static_cast<std::size_t>(a.bufferView)].byteStride;
  try {
    view_range(model, a.bufferView, a.byteOffset,
               span_bytes(a.count, std::max(stride, element), element, ""), "");
  } catch (const Error&) {
    return 0;
  }
  return a.count;
}

AccessorReader::AccessorReader(const tinygltf::Model& model, int accessor, const AccessorSpec& spec)
    : index_(accessor), what_(spec.what) {
  const std::string where = "accessor " + std::to_string(accessor) + " (" + spec.what + ")";
  if (accessor < 0 || static_cast<std::size_t>(accessor) >= model.accessors.size())
    throw Error(where + " does not exist");
  const tinygltf::Accessor& a = model.accessors[static_cast<std::size_t>(accessor)];

  components_ = component_count(a.type);
  if (components_ < spec.min_components || components_ > spec.max_components)
    throw Error(where + ": unsupported accessor type " + std::to_string(a.type));
  component_type_ = a.componentType;
  component_size_ = component_size(a.componentType);
  if (component_size_ == 0 || (spec.component_types & component_bit(a.componentType)) == 0)
    throw Error(where + ": unsupported component type " + std::to_string(a.componentType));
  normalized_ = a.normalized && a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT;
  element_size_ = static_cast<std::size_t>(component_size_) * static_cast<std::size_t>(components_);
  count_ = a.count;

  if (a.bufferView >= 0) {
    stride_ = element_size_;  // tightly packed unless the view says otherwise
    if (static_cast<std::size_t>(a.bufferView) < model.bufferViews.size()) {
      const std::size_t stride =
          model.bufferViews[static_cast<std::size_t>(a.bufferView)].byteStride;
      // Elements would overlap; the validator refuses it and no writer means it.
      if (stride != 0 && stride < element_size_)
        throw Error(where + ": bufferView " + std::to_string(a.bufferView) + " byteStride " +
                    std::to_string(stride) + " is smaller than the element size " +
                    std::to_string(element_size_));
      if (stride != 0) stride_ = stride;
    }
    // view_range rejects a missing bufferView, so the stride above is always the view's.
    data_ = view_range(model, a.bufferView, a.byteOffset,
                       span_bytes(count_, stride_, element_size_, where), where);
  } else if (count_ > kMaxCountWithoutData) {
    throw Error(where + ": count " + std::to_string(count_) + " without a bufferView");
  }
  if (a.sparse.isSparse) resolve_sparse(model, a);
}

void AccessorReader::resolve_sparse(const tinygltf::Model& model, const tinygltf::Accessor& a) {
  const std::string where = "accessor " + std::to_string(index_) + " (" + what_ + ") sparse";
  const auto& sparse = a.sparse;
  if (sparse.count < 0 || static_cast<std::size_t>(sparse.count) > count_)
    throw Error(where + ": count " + std::to_string(sparse.count) + " exceeds the accessor's " +
                std::to_string(count_));
  const int index_size = component_size(sparse.indices.componentType);
  if ((kIndexBits & component_bit(sparse.indices.componentType)) == 0 || index_size == 0)
    throw Error(where + ": unsupported index component type " +
                std::to_string(sparse.indices.componentType));
  if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0)
    throw Error(where + ": negative byteOffset");

  const auto n = static_cast<std::size_t>(sparse.count);
  const unsigned char* indices = view_range(model, sparse.indices.bufferView,
                                            static_cast<std::size_t>(sparse.indices.byteOffset),
                                            span_bytes(n, static_cast<std::size_t>(index_size),
                                                       static_cast<std::size_t>(index_size), where),
                                            where + " indices");
  const unsigned char* values = view_range(
      model, sparse.values.bufferView, static_cast<std::size_t>(sparse.values.byteOffset),
      span_bytes(n, element_size_, element_size_, where), where + " values");

  dense_.assign(count_ * element_size_, 0);  // no bufferView: the base is zeros
  if (data_ != nullptr)
    for (std::size_t i = 0; i < count_; ++i)
      std::memcpy(&dense_[i * element_size_], data_ + i * stride_, element_size_);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t target =
        to_index(indices + k * static_cast<std::size_t>(index_size), sparse.indices.componentType);
    if (target >= count_)
      throw Error(where + ": index " + std::to_string(target) + " out of range (count " +
                  std::to_string(count_) + ")");
    std::memcpy(&dense_[target * element_size_], values + k * element_size_, element_size_);
  }
  sparse_ = true;
  stride_ = element_size_;
}

void AccessorReader::read(std::size_t i, float* out) const {
  if (i >= count_)
    throw Error("accessor " + std::to_string(index_) + " (" + what_ + "): element " +
                std::to_string(i) + " out of range (count " + std::to_string(count_) + ")");
  const unsigned char* p = base();
  if (p == nullptr) {
    std::fill(out, out + components_, 0.0f);
    return;
  }
  p += i * stride_;
  for (int c = 0; c < components_; ++c)
    out[c] = to_float(p + c * component_size_, component_type_, normalized_);
  // NaN or Inf in a float attribute would poison the BVH, the shading or the texture lookups.
  if (component_type_ == TINYGLTF_COMPONENT_TYPE_FLOAT)
    for (int c = 0; c < components_; ++c)
      if (!std::isfinite(out[c]))
        throw Error("accessor " + std::to_string(index_) + " (" + what_ + "): element " +
                    std::to_string(i) + " is not finite");
}

std::vector<std::uint32_t> AccessorReader::read_indices() const {
  std::vector<std::uint32_t> out(count_, 0);
  const unsigned char* p = base();
  if (p == nullptr) return out;
  // One loop per type: index lists are the bulk of a large mesh's data.
  const auto copy = [&](auto type_tag) {
    using T = decltype(type_tag);
    for (std::size_t i = 0; i < count_; ++i) out[i] = load<T>(p + i * stride_);
  };
  switch (component_type_) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      copy(std::uint8_t{});
      break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      copy(std::uint16_t{});
      break;
    default:
      copy(std::uint32_t{});
      break;
  }
  return out;
}

}  // namespace wp::gltf
