#include "host/scene/gltf_draco.h"

#include <cstring>
#include <limits>
#include <set>
#include <memory>
#include <utility>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include "host/scene/gltf_accessor.h"
#include "host/scene/gltf_json.h"
#include "host/util/error.h"

namespace wp::gltf {
namespace {

constexpr const char* kName = "KHR_draco_mesh_compression";

// Points and indices a Scene can address with 32-bit indices (the all-ones index is reserved).
constexpr std::uint64_t kMaxIndex = std::numeric_limits<std::uint32_t>::max() - 1;

// glTF's component type for a Draco data type; 0 for the types glTF has not.
int gltf_component_type(draco::DataType type) {
  switch (type) {
    case draco::DT_INT8:
      return TINYGLTF_COMPONENT_TYPE_BYTE;
    case draco::DT_UINT8:
      return TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    case draco::DT_INT16:
      return TINYGLTF_COMPONENT_TYPE_SHORT;
    case draco::DT_UINT16:
      return TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    case draco::DT_UINT32:
      return TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    case draco::DT_FLOAT32:
      return TINYGLTF_COMPONENT_TYPE_FLOAT;
    default:
      return 0;
  }
}

// Draco's messages as one line.
std::string one_line(const std::string& text) {
  std::string out = text.substr(0, 200);
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  return out.empty() ? "no reason given" : out;
}

// The values of attribute `att` for every point, checked against its storage first.
DracoAttribute extract(const draco::PointAttribute& att, std::size_t points,
                       const std::string& where) {
  DracoAttribute out;
  out.component_type = gltf_component_type(att.data_type());
  if (out.component_type == 0)
    throw Error(where + ": data type " + std::to_string(int(att.data_type())) +
                " has no glTF component type");
  out.components = att.num_components();
  if (out.components < 1 || out.components > 4)
    throw Error(where + ": " + std::to_string(out.components) + " components (glTF has 1 to 4)");
  const std::size_t element = std::size_t(out.components) * draco::DataTypeLength(att.data_type());
  const draco::DataBuffer* buffer = att.buffer();
  if (!att.is_mapping_identity() && att.indices_map_size() < points)
    throw Error(where + ": maps " + std::to_string(att.indices_map_size()) + " of " +
                std::to_string(points) + " points");
  if (buffer == nullptr || att.byte_stride() < std::int64_t(element) || att.byte_offset() < 0)
    throw Error(where + ": no data");
  out.bytes.resize(points * element);
  for (std::size_t p = 0; p < points; ++p) {
    const auto value = att.mapped_index(draco::PointIndex(static_cast<std::uint32_t>(p))).value();
    const std::uint64_t at =
        std::uint64_t(att.byte_offset()) + std::uint64_t(att.byte_stride()) * value;
    if (value >= att.size() || at + element > buffer->data_size())
      throw Error(where + ": point " + std::to_string(p) + " maps to value " +
                  std::to_string(value) + " outside the attribute's " + std::to_string(att.size()));
    std::memcpy(&out.bytes[p * element], buffer->data() + at, element);
  }
  return out;
}

// Where a Draco primitive's data go: a buffer appended to the model at the end, views of it, and
// which accessor each decoded array went to (an accessor two primitives share must get the same).
class Writer {
 public:
  explicit Writer(tinygltf::Model& model)
      : model_(model), buffer_(static_cast<int>(model.buffers.size())) {}

  // Points accessor `index` at `bytes` (`count` elements of `type` components); `source` names the
  // decoded array, so that an accessor two Draco primitives share is given the same array once.
  void assign(int index, const std::string& source, int component_type, bool normalized,
              std::size_t count, const std::vector<unsigned char>& bytes,
              const std::string& where) {
    const auto claimed = claims_.find(index);
    if (claimed != claims_.end()) {
      if (claimed->second != source)
        throw Error(where + ": accessor " + std::to_string(index) + " is also " + claimed->second);
      return;
    }
    claims_[index] = source;
    while (data_.size() % 4) data_.push_back(0);
    tinygltf::BufferView view;
    view.buffer = buffer_;
    view.byteOffset = data_.size();
    view.byteLength = bytes.size();
    data_.insert(data_.end(), bytes.begin(), bytes.end());
    model_.bufferViews.push_back(view);
    tinygltf::Accessor& a = model_.accessors[static_cast<std::size_t>(index)];
    a.bufferView = static_cast<int>(model_.bufferViews.size()) - 1;
    a.byteOffset = 0;
    a.componentType = component_type;
    a.normalized = normalized && component_type != TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = count;
    a.sparse.isSparse = false;
  }

  void finish() {
    if (claims_.empty()) return;
    tinygltf::Buffer b;
    b.name = std::string(kName) + " (decoded)";
    b.data = std::move(data_);
    model_.buffers.push_back(std::move(b));
  }

 private:
  tinygltf::Model& model_;
  int buffer_;
  std::vector<unsigned char> data_;
  std::map<int, std::string> claims_;
};

const tinygltf::Accessor& accessor(const tinygltf::Model& model, int index,
                                   const std::string& where) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
    throw Error(where + ": accessor " + std::to_string(index) + " does not exist");
  return model.accessors[static_cast<std::size_t>(index)];
}

// The bytes of bufferView `index`, checked against its buffer.
std::pair<const unsigned char*, std::size_t> view_bytes(const tinygltf::Model& model,
                                                        std::uint64_t index,
                                                        const std::string& where) {
  if (index >= model.bufferViews.size())
    throw Error(where + ": bufferView " + std::to_string(index) + " does not exist");
  const tinygltf::BufferView& v = model.bufferViews[index];
  if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= model.buffers.size())
    throw Error(where + ": bufferView " + std::to_string(index) + " refers to missing buffer " +
                std::to_string(v.buffer));
  const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(v.buffer)].data;
  if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
    throw Error(where + ": bufferView " + std::to_string(index) + " exceeds buffer " +
                std::to_string(v.buffer));
  return {data.data() + v.byteOffset, v.byteLength};
}

// Reads the Draco bitstream's header (the Draco bitstream specification, version 2.2: header,
// metadata, connectivity) up to the counts the decoder allocates from.
class HeaderReader {
 public:
  HeaderReader(const unsigned char* data, std::size_t size, std::string at)
      : p_(data), end_(data + size), at_(std::move(at)) {}

  std::uint32_t u8() {
    need(1);
    return *p_++;
  }
  std::uint32_t u16() {
    const std::uint32_t lo = u8();
    return lo | u8() << 8;
  }
  std::uint32_t var_u32() {  // LEB128, at most 5 bytes
    std::uint64_t v = 0;
    for (int shift = 0; shift < 35; shift += 7) {
      const std::uint32_t b = u8();
      v |= std::uint64_t(b & 0x7f) << shift;
      if (!(b & 0x80)) {
        if (v > std::numeric_limits<std::uint32_t>::max()) break;
        return static_cast<std::uint32_t>(v);
      }
    }
    throw Error(at_ + ": a malformed number in the Draco header");
  }
  void skip(std::size_t n) {
    need(n);
    p_ += n;
  }
  // DecodeMetadataElement: its entries, then its sub-elements, nested at most kMaxDepth deep.
  void metadata_element(int depth) {
    constexpr int kMaxDepth = 32;
    if (depth > kMaxDepth) throw Error(at_ + ": Draco metadata nested too deep");
    for (std::uint32_t n = var_u32(); n > 0; --n) {
      skip(u8());  // key
      skip(u8());  // value
    }
    for (std::uint32_t n = var_u32(); n > 0; --n) {
      skip(u8());  // sub-metadata key
      metadata_element(depth + 1);
    }
  }
  const std::string& at() const { return at_; }

 private:
  void need(std::size_t n) {
    if (static_cast<std::size_t>(end_ - p_) < n) throw Error(at_ + ": the Draco data end early");
  }
  const unsigned char* p_;
  const unsigned char* end_;
  std::string at_;
};

// What the header of a Draco mesh announces, before anything is decoded.
struct DracoCounts {
  std::uint64_t faces = 0;
  // Sequential encoding: its points; edgebreaker: its encoded vertices (the points before any
  // attribute seam splits them).
  std::uint64_t points = 0;
};

DracoCounts read_draco_header(const unsigned char* data, std::size_t size, const std::string& at) {
  HeaderReader r(data, size, at);
  static const unsigned char kMagic[5] = {'D', 'R', 'A', 'C', 'O'};
  for (const unsigned char c : kMagic)
    if (r.u8() != c) throw Error(at + ": not Draco data (no DRACO signature)");
  const std::uint32_t major = r.u8(), minor = r.u8();
  // The extension specifies Draco bitstream 2.2; older streams lay the counts out differently.
  if (major != 2 || minor != 2)
    throw Error(at + ": Draco bitstream version " + std::to_string(major) + "." +
                std::to_string(minor) + " (KHR_draco_mesh_compression uses 2.2)");
  if (r.u8() != 1) throw Error(at + ": not a Draco triangle mesh");
  const std::uint32_t method = r.u8();
  const std::uint32_t flags = r.u16();
  if (flags & 0x8000) {  // metadata: per attribute, then the file's
    for (std::uint32_t n = r.var_u32(); n > 0; --n) {
      r.var_u32();  // the attribute's id
      r.metadata_element(0);
    }
    r.metadata_element(0);
  }
  DracoCounts h;
  if (method == 0) {  // sequential
    h.faces = r.var_u32();
    h.points = r.var_u32();
  } else if (method == 1) {  // edgebreaker
    r.u8();                  // traversal type
    h.points = r.var_u32();  // encoded vertices
    h.faces = r.var_u32();
  } else {
    throw Error(at + ": Draco encoder method " + std::to_string(method) + " is not 0 or 1");
  }
  return h;
}

// The counts the header of a primitive's Draco data announces, against what its accessors claim
// (which the loader has counted against the device's memory before decoding: gltf_loader.cpp):
// no more faces than its indices give triangles, no more points than any of its attributes has,
// and no more points than its faces' corners. Draco allocates from these counts before it has
// decoded anything (a 232-byte payload of the fuzzer's asked for 2.56 GB); checked here, what it
// allocates is bounded by what the file claims and the loader accepted.
void check_draco_header(const tinygltf::Model& model, const tinygltf::Primitive& p,
                        const tinygltf::Value& ext, const unsigned char* data, std::size_t size,
                        const std::string& where) {
  const std::string at = where;
  const DracoCounts h = read_draco_header(data, size, at);
  const auto position = p.attributes.find("POSITION");
  const std::uint64_t corners = p.indices >= 0 ? accessor(model, p.indices, at).count
                                : position != p.attributes.end()
                                    ? accessor(model, position->second, at).count
                                    : 0;
  // A strip of n indices has n - 2 triangles: at most n faces either way.
  const std::uint64_t max_faces = p.mode == TINYGLTF_MODE_TRIANGLE_STRIP ? corners : corners / 3;
  if (h.faces > max_faces)
    throw Error(at + ": the Draco header announces " + std::to_string(h.faces) +
                " faces, more than the primitive's accessors hold (" + std::to_string(max_faces) +
                ")");
  if (h.points > 3 * h.faces)
    throw Error(at + ": the Draco header announces " + std::to_string(h.points) +
                " points, more than its " + std::to_string(h.faces) + " faces use");
  const tinygltf::Value& attributes = ext.Get("attributes");
  for (const std::string& name : attributes.Keys()) {
    const auto attribute = p.attributes.find(name);
    if (attribute == p.attributes.end()) continue;  // an error once decoded
    const std::uint64_t count = accessor(model, attribute->second, at).count;
    if (h.points > count)
      throw Error(at + ": the Draco header announces " + std::to_string(h.points) +
                  " points, more than accessor " + std::to_string(attribute->second) + " (" +
                  name.substr(0, 32) + ") holds (" + std::to_string(count) + ")");
  }
}

// One Draco primitive: its extension read, its mesh decoded (once per bufferView, in `decoded`),
// its accessors given the data.
void decode_primitive(tinygltf::Model& model, tinygltf::Primitive& p, const tinygltf::Value& ext,
                      std::map<std::uint64_t, DracoMesh>& decoded, Writer& writer,
                      const std::string& where) {
  const std::uint64_t view = count_member(ext, "bufferView", where, true);
  if (!ext.Has("attributes") || !ext.Get("attributes").IsObject())
    throw Error(where + ": attributes is not an object");
  if (p.mode != TINYGLTF_MODE_TRIANGLES && p.mode != TINYGLTF_MODE_TRIANGLE_STRIP && p.mode >= 0)
    throw Error(where + ": mode " + std::to_string(p.mode) +
                " (Draco primitives are TRIANGLES or " + "TRIANGLE_STRIP)");
  auto it = decoded.find(view);
  if (it == decoded.end()) {
    const auto [data, size] = view_bytes(model, view, where);
    check_draco_header(model, p, ext, data, size, where);
    it = decoded.emplace(view, decode_draco_mesh(data, size, where)).first;
  }
  const DracoMesh& mesh = it->second;
  const std::string source = "bufferView " + std::to_string(view) + "'s Draco ";

  // Indices: the decoded faces, a triangle list whatever the file's mode.
  const std::size_t index_count = mesh.indices.size();
  if (p.indices >= 0) {
    const tinygltf::Accessor& a = accessor(model, p.indices, where);
    if (p.mode != TINYGLTF_MODE_TRIANGLE_STRIP && a.count != index_count)
      throw Error(where + ": indices accessor " + std::to_string(p.indices) + " count " +
                  std::to_string(a.count) + " differs from the decoded " +
                  std::to_string(index_count) + " (" + std::to_string(index_count / 3) + " faces)");
  } else {
    model.accessors.emplace_back();
    model.accessors.back().type = TINYGLTF_TYPE_SCALAR;
    p.indices = static_cast<int>(model.accessors.size()) - 1;
  }
  std::vector<unsigned char> bytes(index_count * 4);
  if (index_count) std::memcpy(bytes.data(), mesh.indices.data(), bytes.size());
  writer.assign(p.indices, source + "indices", TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false,
                index_count, bytes, where);
  p.mode = TINYGLTF_MODE_TRIANGLES;

  const tinygltf::Value& attributes = ext.Get("attributes");
  for (const std::string& name : attributes.Keys()) {
    const std::string at = where + " " + name.substr(0, 32);
    const std::uint64_t id = count_member(attributes, name.c_str(), where, true);
    const auto attribute = p.attributes.find(name);
    if (attribute == p.attributes.end()) throw Error(at + ": not among the primitive's attributes");
    const auto found = mesh.attributes.find(static_cast<std::uint32_t>(
        std::min<std::uint64_t>(id, std::numeric_limits<std::uint32_t>::max())));
    if (found == mesh.attributes.end())
      throw Error(at + ": the Draco data have no attribute " + std::to_string(id));
    const DracoAttribute& data = found->second;
    const tinygltf::Accessor& a = accessor(model, attribute->second, at);
    if (a.count != mesh.points)
      throw Error(at + ": accessor " + std::to_string(attribute->second) + " count " +
                  std::to_string(a.count) + " differs from the decoded " +
                  std::to_string(mesh.points) + " points");
    if (component_count(a.type) != data.components)
      throw Error(at + ": accessor " + std::to_string(attribute->second) + " has " +
                  std::to_string(component_count(a.type)) + " components, the Draco attribute " +
                  std::to_string(data.components));
    writer.assign(attribute->second, source + "attribute " + std::to_string(id),
                  data.component_type, a.normalized, mesh.points, data.bytes, at);
  }
}

}  // namespace

DracoMesh decode_draco_mesh(const unsigned char* data, std::size_t size, const std::string& where) {
  const std::string at = where + ": " + kName;
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(data), size);
  const auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok()) throw Error(at + ": " + one_line(type.status().error_msg_string()));
  if (type.value() != draco::TRIANGULAR_MESH) throw Error(at + ": not a Draco triangle mesh");
  draco::Decoder decoder;
  auto result = decoder.DecodeMeshFromBuffer(&buffer);
  if (!result.ok()) throw Error(at + ": " + one_line(result.status().error_msg_string()));
  const std::unique_ptr<draco::Mesh> mesh = std::move(result).value();
  if (!mesh) throw Error(at + ": Draco decoded no mesh");

  DracoMesh out;
  out.points = mesh->num_points();
  const std::uint64_t faces = mesh->num_faces();
  if (out.points > kMaxIndex || 3 * faces > kMaxIndex)
    throw Error(at + ": " + std::to_string(out.points) + " points and " + std::to_string(faces) +
                " faces, more than 32-bit indices address");
  out.indices.resize(3 * faces);
  for (std::uint32_t f = 0; f < faces; ++f) {
    const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = face[static_cast<std::size_t>(k)].value();
      if (v >= out.points)
        throw Error(at + ": face " + std::to_string(f) + " refers to point " + std::to_string(v) +
                    " of " + std::to_string(out.points));
      out.indices[3 * std::size_t(f) + static_cast<std::size_t>(k)] = v;
    }
  }
  for (int i = 0; i < mesh->num_attributes(); ++i) {
    const draco::PointAttribute* att = mesh->attribute(i);
    if (!att) continue;
    const std::uint32_t id = att->unique_id();
    out.attributes[id] = extract(*att, out.points, at + " attribute " + std::to_string(id));
  }
  return out;
}

void decode_draco(tinygltf::Model& model, const std::set<int>& meshes) {
  std::map<std::uint64_t, DracoMesh> decoded;  // by bufferView
  Writer writer(model);
  for (const int index : meshes) {
    if (index < 0 || static_cast<std::size_t>(index) >= model.meshes.size()) continue;
    const auto m = static_cast<std::size_t>(index);
    for (std::size_t i = 0; i < model.meshes[m].primitives.size(); ++i) {
      tinygltf::Primitive& p = model.meshes[m].primitives[i];
      const std::string where = "mesh " + std::to_string(m) + " primitive " + std::to_string(i);
      const tinygltf::Value* ext = extension_object(p.extensions, kName, where);
      if (ext) decode_primitive(model, p, *ext, decoded, writer, where + " " + kName);
    }
  }
  writer.finish();
}

}  // namespace wp::gltf
