#include "tests/gltf/compress_twin.h"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>
#include <webp/encode.h>

#include "host/scene/image_decode.h"

namespace wp::test {
namespace {

using nlohmann::json;

constexpr int kFloat = 5126;

std::uint32_t u32_at(const std::vector<unsigned char>& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, &b[at], 4);
  return v;
}

int components(const std::string& type) {
  return type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 0;
}

int component_size(int type) {
  return type == 5120 || type == 5121 ? 1 : type <= 5123 ? 2 : 4;
}

// Appends `data` to `bin` 4-byte aligned; returns its offset.
std::size_t append_bytes(std::vector<unsigned char>& bin, const void* data, std::size_t size) {
  while (bin.size() % 4) bin.push_back(0);
  const std::size_t offset = bin.size();
  const auto* p = static_cast<const unsigned char*>(data);
  bin.insert(bin.end(), p, p + size);
  return offset;
}

// Appends `data` to `bin` and adds a view of it; returns the view's index.
int append_view(json& doc, std::vector<unsigned char>& bin, const void* data, std::size_t size) {
  const std::size_t offset = append_bytes(bin, data, size);
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}});
  return static_cast<int>(doc["bufferViews"].size()) - 1;
}

void require_extension(json& doc, const char* name) {
  for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
    json& list = doc[key];
    if (std::find(list.begin(), list.end(), name) == list.end()) list.push_back(name);
  }
}

// The bytes of accessor `index` element by element (stride removed), and its element size.
std::vector<unsigned char> accessor_bytes(const json& doc, const std::vector<unsigned char>& bin,
                                          int index, std::size_t* element) {
  const json& a = doc["accessors"][static_cast<std::size_t>(index)];
  const json& v = doc["bufferViews"][a["bufferView"].get<std::size_t>()];
  *element = std::size_t(components(a["type"])) * component_size(a["componentType"]);
  const std::size_t stride = v.value("byteStride", *element);
  const std::size_t base =
      v.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
  const std::size_t count = a["count"];
  std::vector<unsigned char> out(count * *element);
  for (std::size_t i = 0; i < count; ++i)
    std::memcpy(&out[i * *element], &bin.at(base + i * stride + *element - 1) - (*element - 1),
                *element);
  return out;
}

std::vector<std::uint32_t> index_list(const json& doc, const std::vector<unsigned char>& bin,
                                      int index) {
  std::size_t element = 0;
  const std::vector<unsigned char> bytes = accessor_bytes(doc, bin, index, &element);
  std::vector<std::uint32_t> out(bytes.size() / element);
  for (std::size_t i = 0; i < out.size(); ++i) {
    std::uint32_t v = 0;
    std::memcpy(&v, &bytes[i * element], element);  // little-endian
    out[i] = v;
  }
  return out;
}

draco::GeometryAttribute::Type draco_type(const std::string& name) {
  if (name == "POSITION") return draco::GeometryAttribute::POSITION;
  if (name == "NORMAL") return draco::GeometryAttribute::NORMAL;
  if (name.rfind("TEXCOORD_", 0) == 0) return draco::GeometryAttribute::TEX_COORD;
  if (name.rfind("COLOR_", 0) == 0) return draco::GeometryAttribute::COLOR;
  return draco::GeometryAttribute::GENERIC;
}

// The position grid step of Draco's quantisation: the largest extent / (2^bits - 1).
double grid_step(const std::vector<float>& v, int comps, int bits) {
  double range = 0.0;
  for (int c = 0; c < comps; ++c) {
    float lo = v[std::size_t(c)], hi = lo;
    for (std::size_t i = std::size_t(c); i < v.size(); i += std::size_t(comps))
      lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
    range = std::max(range, double(hi) - double(lo));
  }
  return range / double((1 << bits) - 1);
}

// One primitive as a Draco mesh; false (left as it is) when an attribute is not float.
bool draco_primitive(json& doc, Glb& out, json& prim, const DracoBits& bits, DracoSteps* steps,
                     std::size_t mesh) {
  if (prim.value("mode", 4) != 4) return false;
  const json& accessors = doc["accessors"];
  for (const auto& [name, index] : prim["attributes"].items())
    if (accessors[index.get<std::size_t>()]["componentType"] != kFloat) return false;
  const std::size_t points = accessors[prim["attributes"]["POSITION"].get<std::size_t>()]["count"];
  std::vector<std::uint32_t> corners;
  if (prim.contains("indices")) {
    corners = index_list(doc, out.bin, prim["indices"]);
  } else {
    for (std::uint32_t i = 0; i < points; ++i) corners.push_back(i);
  }
  draco::Mesh m;
  m.set_num_points(static_cast<std::uint32_t>(points));
  for (std::size_t f = 0; f + 2 < corners.size(); f += 3)
    m.AddFace({draco::PointIndex(corners[f]), draco::PointIndex(corners[f + 1]),
               draco::PointIndex(corners[f + 2])});
  std::map<std::string, int> ids;
  for (const auto& [name, index] : prim["attributes"].items()) {
    std::size_t element = 0;
    const std::vector<unsigned char> bytes = accessor_bytes(doc, out.bin, index, &element);
    const int comps = static_cast<int>(element / 4);
    draco::GeometryAttribute g;
    g.Init(draco_type(name), nullptr, static_cast<std::uint8_t>(comps), draco::DT_FLOAT32, false,
           std::int64_t(element), 0);
    const int id = m.AddAttribute(g, true, static_cast<std::uint32_t>(points));
    draco::PointAttribute* att = m.attribute(id);
    for (std::uint32_t i = 0; i < points; ++i)
      att->SetAttributeValue(draco::AttributeValueIndex(i), &bytes[i * element]);
    ids[name] = static_cast<int>(att->unique_id());
    if (steps && name == "POSITION") {
      std::vector<float> v(bytes.size() / 4);
      std::memcpy(v.data(), bytes.data(), bytes.size());
      steps->position[mesh] = std::max(steps->position[mesh], grid_step(v, comps, bits.position));
    }
    if (steps && name == "TEXCOORD_0") {
      std::vector<float> v(bytes.size() / 4);
      std::memcpy(v.data(), bytes.data(), bytes.size());
      steps->texcoord[mesh] = std::max(steps->texcoord[mesh], grid_step(v, comps, bits.texcoord));
    }
  }
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits.position);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, bits.normal);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, bits.texcoord);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::GENERIC, bits.generic);
  encoder.SetEncodingMethod(bits.edgebreaker ? draco::MESH_EDGEBREAKER_ENCODING
                                             : draco::MESH_SEQUENTIAL_ENCODING);
  draco::EncoderBuffer encoded;
  if (!encoder.EncodeMeshToBuffer(m, &encoded).ok()) throw std::runtime_error("Draco encoding");
  // The accessors must describe the decoded mesh (Draco may reorder and merge points).
  draco::DecoderBuffer in;
  in.Init(encoded.data(), encoded.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok()) throw std::runtime_error("Draco decoding its own encoding");
  const std::unique_ptr<draco::Mesh> back = std::move(decoded).value();

  json ext = {{"bufferView", append_view(doc, out.bin, encoded.data(), encoded.size())},
              {"attributes", json::object()}};
  for (auto it = prim["attributes"].begin(); it != prim["attributes"].end(); ++it) {
    const std::string name = it.key();
    json a = accessors[it.value().get<std::size_t>()];
    a.erase("bufferView");
    a.erase("byteOffset");
    a["count"] = back->num_points();
    a.erase("min");
    a.erase("max");
    doc["accessors"].push_back(a);
    it.value() = doc["accessors"].size() - 1;
    ext["attributes"][name] = ids[name];
  }
  json idx = {{"componentType", 5125}, {"count", 3 * back->num_faces()}, {"type", "SCALAR"}};
  doc["accessors"].push_back(idx);
  prim["indices"] = doc["accessors"].size() - 1;
  prim["extensions"]["KHR_draco_mesh_compression"] = ext;
  return true;
}

}  // namespace

Glb read_glb(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  const std::vector<unsigned char> b((std::istreambuf_iterator<char>(f)),
                                     std::istreambuf_iterator<char>());
  if (b.size() < 20 || std::memcmp(b.data(), "glTF", 4) != 0)
    throw std::runtime_error(path + ": not a .glb");
  Glb g;
  const std::size_t json_length = u32_at(b, 12);
  g.json.assign(reinterpret_cast<const char*>(&b[20]), json_length);
  const std::size_t bin_at = 20 + json_length;
  if (bin_at + 8 <= b.size())
    g.bin.assign(b.begin() + std::ptrdiff_t(bin_at + 8),
                 b.begin() + std::ptrdiff_t(bin_at + 8 + u32_at(b, bin_at)));
  return g;
}

std::vector<unsigned char> glb_bytes(const Glb& glb) {
  std::string j = glb.json;
  while (j.size() % 4) j += ' ';
  std::vector<unsigned char> bin = glb.bin;
  while (bin.size() % 4) bin.push_back(0);
  std::vector<unsigned char> out;
  const auto u32 = [&](std::size_t v) {
    const auto x = static_cast<std::uint32_t>(v);
    const auto* p = reinterpret_cast<const unsigned char*>(&x);
    out.insert(out.end(), p, p + 4);
  };
  out.insert(out.end(), {'g', 'l', 'T', 'F'});
  u32(2);
  u32(12 + 8 + j.size() + (bin.empty() ? 0 : 8 + bin.size()));
  u32(j.size());
  out.insert(out.end(), {'J', 'S', 'O', 'N'});
  out.insert(out.end(), j.begin(), j.end());
  if (!bin.empty()) {
    u32(bin.size());
    out.insert(out.end(), {'B', 'I', 'N', 0});
    out.insert(out.end(), bin.begin(), bin.end());
  }
  return out;
}

void write_file(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

Glb draco_twin(const Glb& in, const DracoBits& bits, DracoSteps* steps) {
  Glb out = in;
  json doc = json::parse(in.json);
  if (steps) {
    steps->position.assign(doc["meshes"].size(), 0.0);
    steps->texcoord.assign(doc["meshes"].size(), 0.0);
  }
  bool any = false;
  for (std::size_t m = 0; m < doc["meshes"].size(); ++m)
    for (json& prim : doc["meshes"][m]["primitives"])
      any |= draco_primitive(doc, out, prim, bits, steps, m);
  if (any) require_extension(doc, "KHR_draco_mesh_compression");
  doc["buffers"][0]["byteLength"] = out.bin.size();
  out.json = doc.dump();
  return out;
}

Glb meshopt_twin(const Glb& in, const MeshoptFilters& filters) {
  Glb out = in;
  json doc = json::parse(in.json);
  // The views mesh accessors read, with what reads them.
  struct Use {
    int accessor = -1;
    std::string role;  // attribute name or "indices"
    int users = 0;
  };
  std::map<std::size_t, Use> uses;
  for (const json& mesh : doc["meshes"])
    for (const json& prim : mesh["primitives"]) {
      std::vector<std::pair<std::string, int>> refs;
      for (const auto& [name, index] : prim["attributes"].items()) refs.push_back({name, index});
      if (prim.contains("indices")) refs.push_back({"indices", prim["indices"]});
      for (const auto& [role, index] : refs) {
        const json& a = doc["accessors"][std::size_t(index)];
        if (!a.contains("bufferView") || a.contains("sparse")) continue;
        Use& u = uses[a["bufferView"]];
        if (u.accessor != index) ++u.users;
        u.accessor = index;
        u.role = role;
      }
    }
  json fallback_views = json::array();
  std::size_t fallback_size = 0;
  const int fallback = static_cast<int>(doc["buffers"].size());
  for (const auto& [view_index, use] : uses) {
    json& view = doc["bufferViews"][view_index];
    json& a = doc["accessors"][std::size_t(use.accessor)];
    std::size_t element = 0;
    std::vector<unsigned char> data = accessor_bytes(doc, in.bin, use.accessor, &element);
    const std::size_t count = a["count"];
    const bool indices = use.role == "indices";
    if (use.users != 1 || a.value("byteOffset", 0) != 0 || (indices && element == 1) ||
        (indices && count % 3 != 0) || (!indices && element % 4 != 0))
      continue;  // left uncompressed
    json ext = {{"mode", indices ? "TRIANGLES" : "ATTRIBUTES"}};
    std::size_t stride = element;
    const bool float3 = a["componentType"] == kFloat && a["type"] == "VEC3";
    if (filters.on && float3 && use.role == "NORMAL") {
      std::vector<float> v4(count * 4, 0.0f);
      for (std::size_t i = 0; i < count; ++i) std::memcpy(&v4[4 * i], &data[12 * i], 12);
      stride = 8;
      data.assign(count * stride, 0);
      meshopt_encodeFilterOct(data.data(), count, stride, filters.octahedral_bits, v4.data());
      ext["filter"] = "OCTAHEDRAL";
      a["componentType"] = 5122;
      a["normalized"] = true;
      require_extension(doc, "KHR_mesh_quantization");
    } else if (filters.on && float3 && use.role == "POSITION") {
      std::vector<float> v(count * 3);
      std::memcpy(v.data(), data.data(), data.size());
      meshopt_encodeFilterExp(data.data(), count, stride, filters.exponential_bits, v.data());
      ext["filter"] = "EXPONENTIAL";
    }
    std::vector<unsigned char> encoded;
    if (indices) {
      std::vector<std::uint32_t> list(count);
      for (std::size_t i = 0; i < count; ++i) {
        std::uint32_t v = 0;
        std::memcpy(&v, &data[i * element], element);
        list[i] = v;
      }
      encoded.resize(meshopt_encodeIndexBufferBound(count, count));
      encoded.resize(meshopt_encodeIndexBuffer(encoded.data(), encoded.size(), list.data(), count));
    } else {
      encoded.resize(meshopt_encodeVertexBufferBound(count, stride));
      encoded.resize(
          meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), data.data(), count, stride));
    }
    ext["buffer"] = 0;
    ext["byteOffset"] = append_bytes(out.bin, encoded.data(), encoded.size());
    ext["byteLength"] = encoded.size();
    ext["byteStride"] = stride;
    ext["count"] = count;
    fallback_size = (fallback_size + 3) / 4 * 4;
    view["buffer"] = fallback;
    view["byteOffset"] = fallback_size;
    view["byteLength"] = count * stride;
    if (!indices) view["byteStride"] = stride;
    fallback_size += count * stride;
    view["extensions"]["EXT_meshopt_compression"] = ext;
  }
  doc["buffers"][0]["byteLength"] = out.bin.size();
  doc["buffers"].push_back({{"byteLength", fallback_size},
                            {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
  require_extension(doc, "EXT_meshopt_compression");
  out.json = doc.dump();
  return out;
}

std::vector<unsigned char> webp_lossless(const unsigned char* rgba, int w, int h) {
  WebPConfig config;
  WebPPicture picture;
  if (!WebPConfigInit(&config) || !WebPPictureInit(&picture))
    throw std::runtime_error("libwebp init");
  config.lossless = 1;
  config.exact = 1;  // keep RGB under alpha 0 too: texels equal
  picture.use_argb = 1;
  picture.width = w;
  picture.height = h;
  WebPMemoryWriter writer;
  WebPMemoryWriterInit(&writer);
  picture.writer = WebPMemoryWrite;
  picture.custom_ptr = &writer;
  const bool ok = WebPPictureImportRGBA(&picture, rgba, 4 * w) && WebPEncode(&config, &picture);
  std::vector<unsigned char> out(writer.mem, writer.mem + writer.size);
  WebPPictureFree(&picture);
  WebPMemoryWriterClear(&writer);
  if (!ok) throw std::runtime_error("WebP encoding");
  return out;
}

std::vector<unsigned char> jpeg_encode(const std::vector<unsigned char>& samples, int width,
                                       int height, int components, bool progressive,
                                       const std::vector<jpeg_scan_info>& scans) {
  jpeg_compress_struct c;
  jpeg_error_mgr errors;
  c.err = jpeg_std_error(&errors);
  jpeg_create_compress(&c);
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&c, &buffer, &size);
  c.image_width = JDIMENSION(width);
  c.image_height = JDIMENSION(height);
  c.input_components = components;
  c.in_color_space = components == 1 ? JCS_GRAYSCALE : components == 3 ? JCS_RGB : JCS_CMYK;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 100, TRUE);  // every quantisation step 1
  for (int i = 0; i < c.num_components; ++i)
    c.comp_info[i].h_samp_factor = c.comp_info[i].v_samp_factor = 1;
  if (progressive) jpeg_simple_progression(&c);
  if (!scans.empty()) {
    c.scan_info = scans.data();
    c.num_scans = static_cast<int>(scans.size());
  }
  jpeg_start_compress(&c, TRUE);
  while (c.next_scanline < c.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(samples.data()) +
                   std::size_t(c.next_scanline) * std::size_t(width * components);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  std::vector<unsigned char> jpeg(buffer, buffer + size);
  std::free(buffer);
  return jpeg;
}

Glb webp_twin(const Glb& in) {
  Glb out = in;
  json doc = json::parse(in.json);
  for (json& image : doc["images"]) {
    const json& view = doc["bufferViews"][image["bufferView"].get<std::size_t>()];
    const unsigned char* bytes = &in.bin.at(view.value("byteOffset", std::size_t{0}));
    wp::Image decoded;
    decode_image(bytes, view["byteLength"].get<std::size_t>(), "a twin's image", decoded);
    const std::vector<unsigned char> webp =
        webp_lossless(decoded.rgba.data(), decoded.width, decoded.height);
    image["bufferView"] = append_view(doc, out.bin, webp.data(), webp.size());
    image["mimeType"] = "image/webp";
  }
  for (json& texture : doc["textures"]) {
    texture["extensions"]["EXT_texture_webp"] = {{"source", texture["source"]}};
    texture.erase("source");
  }
  require_extension(doc, "EXT_texture_webp");
  doc["buffers"][0]["byteLength"] = out.bin.size();
  out.json = doc.dump();
  return out;
}

}  // namespace wp::test
