#include "host/scene/gltf_loader.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <tiny_gltf.h>

#include "host/scene/view.h"
#include "host/util/error.h"
#include "host/util/files.h"
#include "host/util/fnv1a.h"
#include "host/scene/gltf_accessor.h"
#include "host/scene/gltf_draco.h"
#include "host/scene/gltf_extensions.h"
#include "host/scene/gltf_material.h"
#include "host/scene/gltf_meshopt.h"
#include "host/scene/gltf_prepass.h"
#include "host/scene/gltf_nodes.h"
#include "host/scene/gltf_primitive.h"
#include "host/scene/gltf_textures.h"

namespace wp {
namespace {

constexpr const char* kVariants = "KHR_materials_variants";

// tinygltf's messages span lines; wavepath's errors are one line.
std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    const std::size_t first = line.find_first_not_of(" \t\r");
    const std::size_t last = line.find_last_not_of(" \t\r");
    if (first != std::string::npos) out.push_back(line.substr(first, last - first + 1));
    start = end + 1;
  }
  return out;
}

std::string one_line(const std::string& text) {
  std::string out;
  for (const std::string& line : lines(text)) out += (out.empty() ? "" : "; ") + line;
  return out.empty() ? "tinygltf gave no reason" : out;
}

// Below 4 GiB: tinygltf takes the length as 32 bits.
constexpr std::uint64_t kMaxFileBytes = std::numeric_limits<std::uint32_t>::max() - 1;

std::vector<unsigned char> read_file(const std::string& path) {
  std::vector<unsigned char> bytes = read_regular_file(path, kMaxFileBytes);
  if (bytes.empty()) throw Error(path + ": empty file");
  return bytes;
}

// tinygltf's file access for the buffers and images a .gltf names by URI. Its own opens them
// with fopen/ifstream, which block forever on a FIFO (in FileExists too): these stat first and
// refuse anything but a regular file with a wp::Error naming it (parse() catches it).
bool uri_file_exists(const std::string& path, void*) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

std::string uri_expand(const std::string& path, void*) {
  return path;  // tinygltf's own does no expansion either (no ~ or variables in URIs)
}

bool uri_read(std::vector<unsigned char>* out, std::string*, const std::string& path, void*) {
  *out = read_regular_file(path, kMaxFileBytes);
  return true;
}

bool uri_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  *err = "wavepath does not write glTF files";
  return false;
}

bool has_glb_magic(const std::vector<unsigned char>& b) {
  return b.size() >= 4 && std::memcmp(b.data(), "glTF", 4) == 0;
}

// Checks the .glb chunk layout and returns the length to parse. tinygltf 2.7.0 trusts a BIN
// chunk's length up to 8 bytes past the declared end, so this check also keeps it in bounds.
std::size_t check_glb(const std::vector<unsigned char>& b) {
  if (b.size() < 20)
    throw Error("truncated .glb: " + std::to_string(b.size()) + " bytes, the header needs 20");
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, &b[at], 4);  // glTF is little-endian, as are the hosts wavepath runs on
    return std::uint64_t{v};
  };
  if (u32(4) != 2) throw Error("unsupported .glb version " + std::to_string(u32(4)));
  const std::uint64_t length = u32(8);
  if (length > b.size())
    throw Error("truncated .glb: header declares " + std::to_string(length) + " bytes, file has " +
                std::to_string(b.size()));
  const std::uint64_t json_end = 20 + u32(12);
  if (json_end > length)
    throw Error("truncated .glb: JSON chunk ends at byte " + std::to_string(json_end) + " of " +
                std::to_string(length));
  if (u32(16) != 0x4E4F534Au) throw Error("invalid .glb: the first chunk is not JSON");
  if (json_end + 8 <= length && json_end + 8 + u32(json_end) > length)
    throw Error("truncated .glb: BIN chunk ends at byte " +
                std::to_string(json_end + 8 + u32(json_end)) + " of " + std::to_string(length));
  return static_cast<std::size_t>(length);
}

// tinygltf converts the parsed JSON into its model recursively, so a document nested thousands
// deep (e.g. in free-form "extras") overflows the stack. glTF's own structure nests under ten
// levels (nodes refer to each other by index), so anything deeper than this is refused before
// tinygltf sees it.
constexpr int kMaxJsonDepth = 64;

// Counts [ and { nesting outside strings (skipping escaped characters) in JSON text.
void check_json_depth(const unsigned char* text, std::size_t size) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < size; ++i) {
    const unsigned char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // the escaped character cannot end the string
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw Error("JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

// A .glb like `glb` (checked by check_glb, `length` bytes) with its JSON chunk replaced by `json`.
std::vector<unsigned char> replace_glb_json(const std::vector<unsigned char>& glb,
                                            std::size_t length, std::string json) {
  while (json.size() % 4) json += ' ';
  std::uint32_t old_json = 0;
  std::memcpy(&old_json, &glb[12], 4);
  const std::size_t rest = 20 + std::size_t{old_json};  // the BIN chunk, if any, from here
  const std::uint64_t total = 20 + json.size() + (length - rest);
  if (total > kMaxFileBytes) throw Error("the .glb grows past 4 GiB");
  std::uint32_t header[5] = {0, 2, static_cast<std::uint32_t>(total),
                             static_cast<std::uint32_t>(json.size()), 0x4E4F534Au};
  std::memcpy(&header[0], "glTF", 4);
  std::vector<unsigned char> out(static_cast<std::size_t>(total));
  std::memcpy(out.data(), header, sizeof header);
  std::memcpy(out.data() + sizeof header, json.data(), json.size());
  std::memcpy(out.data() + sizeof header + json.size(), glb.data() + rest, length - rest);
  return out;
}

// Parses the file with tinygltf (.glb when it starts with the binary magic, else JSON text);
// tinygltf's warnings go to `warnings`, one line each; the file's FNV-1a digest to `digest`; the
// buffers EXT_meshopt_compression leaves without data to `placeholders` (what tinygltf cannot
// parse in compressed files is rewritten first: gltf_prepass.h).
tinygltf::Model parse(const std::string& path, std::vector<std::string>* warnings,
                      std::uint64_t* digest, gltf::PlaceholderBuffers* placeholders) {
  std::vector<unsigned char> bytes = read_file(path);
  *digest = fnv1a64(bytes.data(), bytes.size());
  const bool glb = has_glb_magic(bytes);
  const std::string ext = std::filesystem::path(path).extension().string();
  if (!glb && (ext == ".glb" || ext == ".GLB"))
    throw Error(path + ": not a binary glTF file (no 'glTF' magic)");

  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&gltf::keep_encoded_image, nullptr);  // decoded when used (gltf_textures)
  loader.SetFsCallbacks({&uri_file_exists, &uri_expand, &uri_read, &uri_write, nullptr});
  tinygltf::Model model;
  std::string err, warn;
  const std::string base = std::filesystem::path(path).parent_path().string();
  bool ok = false;
  try {
    if (glb) {
      std::size_t length = check_glb(bytes);
      std::uint32_t json_length = 0;  // check_glb has checked that the chunk lies in the file
      std::memcpy(&json_length, &bytes[12], 4);
      check_json_depth(bytes.data() + 20, json_length);
      std::string json(reinterpret_cast<const char*>(bytes.data()) + 20, json_length);
      if (gltf::prepare_compressed_json(json, true, placeholders)) {
        bytes = replace_glb_json(bytes, length, std::move(json));
        length = bytes.size();
      }
      ok = loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                       static_cast<unsigned int>(length), base);
    } else {
      check_json_depth(bytes.data(), bytes.size());
      // A copy of the text only for a file that may use the compression extensions.
      std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      std::string json;
      if (gltf::mentions_compression(text.data(), text.size())) {
        json.assign(text);
        if (gltf::prepare_compressed_json(json, false, placeholders)) text = json;
      }
      if (text.size() > kMaxFileBytes) throw Error("the file grows past 4 GiB");
      ok = loader.LoadASCIIFromString(&model, &err, &warn, text.data(),
                                      static_cast<unsigned int>(text.size()), base);
    }
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  } catch (const std::exception& e) {  // tinygltf 2.7.0 throws on some malformed input
    throw Error(path + ": malformed glTF: " + one_line(e.what()));
  }
  if (!ok) throw Error(path + ": " + one_line(err));
  for (const std::string* text : {&err, &warn})  // on success, err holds only remarks
    for (const std::string& line : lines(*text)) warnings->push_back(path + ": " + line);
  return model;
}

// The file's extensions as the table of gltf_extensions.h has them: refused ones (required, not
// supported) are an error naming them; a warning for each ignored one, saying what that means.
void check_extensions(const tinygltf::Model& model, const std::string& path,
                      std::vector<std::string>* warnings) {
  std::vector<ExtensionUse> uses = extension_uses(model.extensionsUsed, model.extensionsRequired);
  std::string refused;
  for (const ExtensionUse& use : uses)
    if (use.support == ExtensionSupport::kRefused)
      refused += (refused.empty() ? "" : ", ") + use.name;
  if (!refused.empty())
    throw RefusedExtensions(path + ": requires unsupported extension" +
                                (refused.find(',') != std::string::npos ? "s " : " ") + refused,
                            std::move(uses));
  for (const ExtensionUse& use : uses)
    if (use.support == ExtensionSupport::kIgnored)
      warnings->push_back(path + ": ignoring unsupported extension " + use.name + " (" + use.note +
                          ")");
}

// A name from the file for a one-line message: control characters become '?'.
std::string printable(const std::string& name) {
  std::string out = name.substr(0, 64);
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return out;
}

// KHR_materials_variants' variant names (the root extension's "variants"), in file order; none
// without the extension.
std::vector<std::string> variant_names(const tinygltf::Model& model) {
  std::vector<std::string> names;
  const auto it = model.extensions.find(kVariants);
  if (it == model.extensions.end()) return names;
  const std::string at = std::string(kVariants) + ": ";
  if (!it->second.IsObject()) throw Error(at + "not an object");
  if (!it->second.Has("variants") || !it->second.Get("variants").IsArray())
    throw Error(at + "variants is not an array");
  const tinygltf::Value& variants = it->second.Get("variants");
  for (int i = 0; i < static_cast<int>(variants.ArrayLen()); ++i) {
    const tinygltf::Value& v = variants.Get(i);
    if (!v.IsObject() || !v.Has("name") || !v.Get("name").IsString())
      throw Error(at + "variant " + std::to_string(i) + " has no name");
    names.push_back(v.Get("name").Get<std::string>());
  }
  return names;
}

// The index of variant `name` among `names`; -1 for "" (no variant). Throws wp::Error listing the
// names when there is no such variant.
int variant_index(const std::vector<std::string>& names, const std::string& name) {
  if (name.empty()) return -1;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  std::string known;
  for (const std::string& n : names) known += (known.empty() ? "'" : ", '") + printable(n) + "'";
  throw Error("no material variant '" + printable(name) + "': " +
              (names.empty() ? std::string("the file has no variants (KHR_materials_variants)")
                             : "the file's variants are " + known));
}

// The texture whose TEXCOORD set generated tangents follow: the normal texture's, else the
// clearcoat normal texture's, else the anisotropy texture's; -1 when there is none.
int tangent_texture(const Material& m) {
  return m.normal_texture >= 0             ? m.normal_texture
         : m.clearcoat_normal_texture >= 0 ? m.clearcoat_normal_texture
                                           : m.anisotropy_texture;
}

// Whether a material reads a tangent frame: for a normal texture (the base's or the clearcoat's)
// or anisotropy (its direction is given in tangent space).
bool needs_tangents(const Material& m) {
  return m.normal_texture >= 0 || m.clearcoat_normal_texture >= 0 || m.anisotropy_strength > 0.0f ||
         m.anisotropy_texture >= 0;
}

// Fills the scene from the node tree of one glTF scene. Messages lack the file name; load_gltf
// adds it.
class SceneBuilder {
 public:
  // `variant`: the index of the selected material variant, -1 for none.
  SceneBuilder(const tinygltf::Model& model, Scene& scene, int variant)
      : model_(model), scene_(scene), variant_(variant) {}

  // With `instancing`, each mesh is loaded once and its placements are Scene::instances.
  void set_instancing(bool instancing) { instancing_ = instancing; }
  // The scene's bounds (Scene::bounds_lo/hi): of its vertices, or of every instance's.
  void compute_bounds() const;

  // What build() will load: the placements and their triangles (gltf_loader.h); `meshes`, when
  // given, receives the meshes placed.
  LoadCounts count(int scene_index, std::set<int>* meshes = nullptr) const;
  // Loads the scene; `counts` (from count()) size the triangle arrays once.
  void build(int scene_index, const LoadCounts& counts);

 private:
  // Visits the nodes of scene `scene_index` depth-first, children in order, with each node's
  // world transform: visit(node, world). Throws for missing nodes, cycles and nodes reached twice.
  template <class Visit>
  void walk(int scene_index, Visit&& visit) const;
  void count_mesh(int mesh, std::uint64_t copies, LoadCounts& counts) const;
  bool any_attribute(const char* name) const;
  void visit(int node, const glm::dmat4& world);
  void add_mesh(int mesh, const glm::dmat4& world);
  void add_instance(int mesh, const glm::dmat4& world);
  void count_placement(int mesh, const std::vector<glm::dmat4>* instances);
  std::uint32_t material_index(int material);
  int primitive_material(const tinygltf::Primitive& p) const;
  gltf::VertexNeeds vertex_needs(std::uint32_t material) const;
  void warn_once(int mesh, std::size_t primitive, const std::string& message);
  static std::string revisit_message(const std::vector<int>& parent, int node, int from);

  const tinygltf::Model& model_;
  Scene& scene_;
  int variant_;
  std::optional<std::uint32_t> default_material_;
  gltf::VertexNeeds file_needs_;  // the optional arrays: whether the scene keeps them at all
  std::set<std::pair<int, std::size_t>> warned_;  // (mesh, primitive): instances warn once
  std::set<int> placed_;                          // the meshes nodes place (GltfSummary)
  bool instancing_ = false;
  // Instancing: each loaded glTF mesh's index in Scene::meshes and its vertices [first, end).
  struct LoadedMesh {
    std::uint32_t index;
    std::size_t first_vertex, end_vertex;
  };
  std::map<int, LoadedMesh> loaded_;
};

// Depth-first, children in order, with an explicit stack: node order defines camera order, and
// a deep hierarchy must not overflow the call stack.
template <class Visit>
void SceneBuilder::walk(int scene_index, Visit&& visit) const {
  const tinygltf::Scene& scene = model_.scenes[static_cast<std::size_t>(scene_index)];
  constexpr int kUnvisited = -2, kRoot = -1;
  std::vector<int> parent(model_.nodes.size(), kUnvisited);
  struct Item {
    int node, from;
    glm::dmat4 parent_world;
  };
  std::vector<Item> stack;
  for (auto it = scene.nodes.rbegin(); it != scene.nodes.rend(); ++it)
    stack.push_back({*it, kRoot, glm::dmat4(1.0)});
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    if (item.node < 0 || static_cast<std::size_t>(item.node) >= model_.nodes.size())
      throw Error((item.from == kRoot ? "scene " + std::to_string(scene_index)
                                      : "node " + std::to_string(item.from)) +
                  " refers to missing node " + std::to_string(item.node));
    if (parent[static_cast<std::size_t>(item.node)] != kUnvisited)
      throw Error(revisit_message(parent, item.node, item.from));
    parent[static_cast<std::size_t>(item.node)] = item.from;
    const tinygltf::Node& node = model_.nodes[static_cast<std::size_t>(item.node)];
    const glm::dmat4 world = item.parent_world * gltf::local_transform(node, item.node);
    visit(item.node, world);
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
      stack.push_back({*it, item.node, world});
  }
}

// `copies` placements of mesh `mesh` in `counts`. A mesh, primitive or accessor that does not exist
// or cannot be read counts nothing: build() reports it.
void SceneBuilder::count_mesh(int mesh, std::uint64_t copies, LoadCounts& counts) const {
  counts.placements += copies;
  if (mesh < 0 || static_cast<std::size_t>(mesh) >= model_.meshes.size()) return;
  for (const tinygltf::Primitive& p : model_.meshes[static_cast<std::size_t>(mesh)].primitives) {
    const auto position = p.attributes.find("POSITION");
    if (!gltf::is_triangle_mode(p.mode) || position == p.attributes.end()) continue;
    const int counted = p.indices >= 0 ? p.indices : position->second;
    // A Draco primitive's accessors hold no data until it is decoded, which happens only after
    // these counts are accepted: what they claim counts (its header must agree: gltf_draco.h).
    const bool draco = p.extensions.count("KHR_draco_mesh_compression") != 0;
    const std::uint64_t n =
        draco && counted >= 0 && static_cast<std::size_t>(counted) < model_.accessors.size()
            ? model_.accessors[static_cast<std::size_t>(counted)].count
            : gltf::readable_count(model_, counted);
    if (draco && p.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      // Draco decodes faces, at most n of them for a strip of n (gltf_draco.cpp): all counted,
      // as they are allocated whatever they turn out to be.
      counts.triangles += copies * n;
      counts.max_triangles += copies * n;
    } else if (p.mode < 0 || p.mode == TINYGLTF_MODE_TRIANGLES) {
      counts.triangles += copies * (n / 3);
      counts.max_triangles += copies * (n / 3);
    } else if (n >= 3) {
      counts.max_triangles += copies * (n - 2);
    }
  }
}

// Whether some primitive of the file has attribute `name`.
bool SceneBuilder::any_attribute(const char* name) const {
  for (const tinygltf::Mesh& mesh : model_.meshes)
    for (const tinygltf::Primitive& p : mesh.primitives)
      if (p.attributes.count(name)) return true;
  return false;
}

LoadCounts SceneBuilder::count(int scene_index, std::set<int>* placed) const {
  LoadCounts counts;
  std::set<int> meshes;
  walk(scene_index, [&](int node, const glm::dmat4&) {
    const tinygltf::Node& n = model_.nodes[static_cast<std::size_t>(node)];
    if (n.mesh < 0) return;
    const std::uint64_t copies = gltf::placements(model_, n);
    count_mesh(n.mesh, copies, counts);
    if (copies == 0 || !meshes.insert(n.mesh).second) return;
    LoadCounts once;
    count_mesh(n.mesh, 1, once);
    counts.mesh_triangles += once.triangles;
    counts.mesh_max_triangles += once.max_triangles;
  });
  counts.meshes = meshes.size();
  if (placed) *placed = std::move(meshes);
  return counts;
}

void SceneBuilder::build(int scene_index, const LoadCounts& counts) {
  for (const TextureRef& t : scene_.textures) file_needs_.uv1 |= t.texcoord == 1;
  for (const Material& m : scene_.materials) file_needs_.tangents |= needs_tangents(m);
  // TEXCOORD_0 and COLOR_0 only where the file has them (8 and 16 bytes a vertex); TEXCOORD_0
  // also for tangents, which are generated from it.
  file_needs_.uv0 = file_needs_.tangents || any_attribute("TEXCOORD_0");
  file_needs_.color0 = any_attribute("COLOR_0");
  // At most max_triangles, each counted from bytes in the file; vertices are counted per
  // primitive as it is loaded (gltf_primitive.cpp).
  const std::uint64_t triangles = instancing_ ? counts.mesh_max_triangles : counts.max_triangles;
  scene_.indices.reserve(3 * triangles);
  scene_.triangle_material.reserve(triangles);
  walk(scene_index, [this](int node, const glm::dmat4& world) { visit(node, world); });
}

std::string SceneBuilder::revisit_message(const std::vector<int>& parent, int node, int from) {
  for (int n = from; n >= 0; n = parent[static_cast<std::size_t>(n)])
    if (n == node) return "the node graph has a cycle through node " + std::to_string(node);
  return "node " + std::to_string(node) + " is reached twice (glTF nodes form a tree)";
}

void SceneBuilder::visit(int node_index, const glm::dmat4& world) {
  const tinygltf::Node& node = model_.nodes[static_cast<std::size_t>(node_index)];
  const std::string where = "node " + std::to_string(node_index) + ": ";
  try {
    if (node.mesh >= 0) {
      const auto instances = gltf::instance_transforms(model_, node, node_index);
      if (instances)
        for (const glm::dmat4& instance : *instances) add_instance(node.mesh, world * instance);
      else
        add_instance(node.mesh, world);
      count_placement(node.mesh, instances ? &*instances : nullptr);
    }
    if (node.camera >= 0) scene_.cameras.push_back(gltf::make_camera(model_, node.camera, world));
    const int light = gltf::node_light(node, node_index);
    std::vector<std::string> clamped;
    if (light >= 0) scene_.lights.push_back(gltf::make_light(model_, light, world, &clamped));
    for (const std::string& w : clamped) scene_.warnings.push_back(scene_.source + ": " + w);
  } catch (const Error& e) {
    throw Error(where + e.what());
  }
}

// One placement of a mesh: a copy in world space, or, with instancing, an instance of the mesh
// (loaded in its own space the first time). A mesh without triangles places no instance.
void SceneBuilder::add_instance(int mesh_index, const glm::dmat4& world) {
  if (!instancing_) {
    add_mesh(mesh_index, world);
    return;
  }
  auto it = loaded_.find(mesh_index);
  if (it == loaded_.end()) {
    const std::size_t first = scene_.triangle_count(), first_vertex = scene_.positions.size();
    add_mesh(mesh_index, glm::dmat4(1.0));
    MeshRange range;
    range.first_triangle = static_cast<std::uint32_t>(first);
    range.triangle_count = static_cast<std::uint32_t>(scene_.triangle_count() - first);
    scene_.meshes.push_back(range);
    const LoadedMesh loaded{static_cast<std::uint32_t>(scene_.meshes.size() - 1), first_vertex,
                            scene_.positions.size()};
    it = loaded_.emplace(mesh_index, loaded).first;
  }
  if (scene_.meshes[it->second.index].triangle_count == 0) return;
  Instance instance;
  instance.to_world = world;
  instance.mesh = it->second.index;
  scene_.instances.push_back(instance);
}

void SceneBuilder::add_mesh(int mesh_index, const glm::dmat4& world) {
  if (static_cast<std::size_t>(mesh_index) >= model_.meshes.size())
    throw Error("mesh " + std::to_string(mesh_index) + " does not exist");
  const tinygltf::Mesh& mesh = model_.meshes[static_cast<std::size_t>(mesh_index)];
  for (std::size_t i = 0; i < mesh.primitives.size(); ++i) {
    const tinygltf::Primitive& p = mesh.primitives[i];
    if (p.mode < 0 || p.mode > 6)  // tinygltf gives 4 (TRIANGLES) when "mode" is absent
      throw Error("mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(i) +
                  ": mode " + std::to_string(p.mode) + " is not a glTF primitive mode (0-6)");
    if (!gltf::is_triangle_mode(p.mode)) {
      static const char* const kModes[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
      const std::string mode = p.mode <= 3 ? kModes[p.mode] : std::to_string(p.mode);
      warn_once(mesh_index, i, "mode " + mode + " is not supported; skipped");
      continue;
    }
    if (!p.attributes.count("POSITION")) {
      warn_once(mesh_index, i, "no POSITION; skipped");
      continue;
    }
    try {
      const std::uint32_t material = material_index(primitive_material(p));
      const std::size_t leftover =
          gltf::append_primitive(model_, p, world, material, vertex_needs(material), scene_);
      if (leftover != 0)
        warn_once(
            mesh_index, i,
            "index count is not a multiple of 3; last " + std::to_string(leftover) + " ignored");
    } catch (const Error& e) {
      throw Error("mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(i) + ": " +
                  e.what());
    }
  }
}

// GltfSummary's counts for a node that places mesh `mesh`, with its EXT_mesh_gpu_instancing
// instances (null: the node has none).
void SceneBuilder::count_placement(int mesh, const std::vector<glm::dmat4>* instances) {
  GltfSummary& summary = scene_.gltf;
  ++summary.mesh_nodes;
  placed_.insert(mesh);
  summary.meshes_placed = placed_.size();
  if (!instances) return;
  ++summary.gpu_instanced_nodes;
  summary.gpu_instances += instances->size();
}

// Materials keep their glTF indices; glTF's default material follows them, added on first use.
std::uint32_t SceneBuilder::material_index(int material) {
  if (material >= 0) {
    if (static_cast<std::size_t>(material) >= model_.materials.size())
      throw Error("material " + std::to_string(material) + " does not exist");
    return static_cast<std::uint32_t>(material);
  }
  if (!default_material_) {
    default_material_ = static_cast<std::uint32_t>(scene_.materials.size());
    scene_.materials.push_back(gltf::default_material());
  }
  return *default_material_;
}

// KHR_materials_variants: the material of primitive `p` under the selected variant, that of the
// mapping naming it, else p.material. The mappings are checked whether or not a variant is
// selected: each names an existing material and existing variants, each variant at most once.
int SceneBuilder::primitive_material(const tinygltf::Primitive& p) const {
  const auto it = p.extensions.find(kVariants);
  if (it == p.extensions.end()) return p.material;
  const std::string at = std::string(kVariants) + ": ";
  const tinygltf::Value& ext = it->second;
  if (!ext.IsObject() || !ext.Has("mappings") || !ext.Get("mappings").IsArray())
    throw Error(at + "mappings is not an array");
  const tinygltf::Value& mappings = ext.Get("mappings");
  std::vector<bool> mapped(scene_.variants.size(), false);
  int material = p.material;
  for (int k = 0; k < static_cast<int>(mappings.ArrayLen()); ++k) {
    const tinygltf::Value& m = mappings.Get(k);
    const std::string where = at + "mapping " + std::to_string(k) + ": ";
    if (!m.IsObject() || !m.Has("material") || !m.Get("material").IsInt())
      throw Error(where + "no material index");
    const int mat = m.Get("material").GetNumberAsInt();
    if (mat < 0 || static_cast<std::size_t>(mat) >= model_.materials.size())
      throw Error(where + "material " + std::to_string(mat) + " does not exist");
    if (!m.Has("variants") || !m.Get("variants").IsArray())
      throw Error(where + "variants is not an array");
    const tinygltf::Value& variants = m.Get("variants");
    for (int j = 0; j < static_cast<int>(variants.ArrayLen()); ++j) {
      const tinygltf::Value& v = variants.Get(j);
      if (!v.IsInt()) throw Error(where + "a variant index is not an integer");
      const int index = v.GetNumberAsInt();
      if (index < 0 || static_cast<std::size_t>(index) >= mapped.size())
        throw Error(where + "variant " + std::to_string(index) + " does not exist (the file has " +
                    std::to_string(mapped.size()) + " variants)");
      if (mapped[static_cast<std::size_t>(index)])
        throw Error(where + "variant " + std::to_string(index) + " is mapped twice");
      mapped[static_cast<std::size_t>(index)] = true;
      if (index == variant_) material = mat;
    }
  }
  return material;
}

// TEXCOORD_1 and tangents are kept for every vertex when any texture reads set 1 or any material
// needs a tangent frame (a normal texture, a clearcoat normal texture, anisotropy), and for none
// otherwise (scene.h). Generated tangents follow the set of the primitive's normal texture, else
// of its clearcoat normal or anisotropy texture.
gltf::VertexNeeds SceneBuilder::vertex_needs(std::uint32_t material) const {
  gltf::VertexNeeds needs = file_needs_;
  const int texture = tangent_texture(scene_.materials[material]);
  if (texture >= 0) needs.tangent_uv = scene_.textures[static_cast<std::size_t>(texture)].texcoord;
  return needs;
}

void SceneBuilder::warn_once(int mesh, std::size_t primitive, const std::string& message) {
  if (!warned_.insert({mesh, primitive}).second) return;
  const std::string& name = model_.meshes[static_cast<std::size_t>(mesh)].name;
  scene_.warnings.push_back(scene_.source + ": mesh " + std::to_string(mesh) +
                            (name.empty() ? "" : " '" + name + "'") + " primitive " +
                            std::to_string(primitive) + ": " + message);
}

void SceneBuilder::compute_bounds() const {
  Scene& scene = scene_;
  if (scene.positions.empty()) {  // an empty scene: a point at the origin, not inverted bounds
    scene.bounds_lo = scene.bounds_hi = glm::vec3(0.0f);
    return;
  }
  scene.bounds_lo = glm::vec3(std::numeric_limits<float>::max());
  scene.bounds_hi = glm::vec3(std::numeric_limits<float>::lowest());
  if (!instancing_) {
    for (const glm::vec3& p : scene.positions) {
      scene.bounds_lo = glm::min(scene.bounds_lo, p);
      scene.bounds_hi = glm::max(scene.bounds_hi, p);
    }
    return;
  }
  // Every vertex of every instance, as the flattened scene would have them (its loader maps them
  // in double too), so that the framing camera is the same either way; past kExactBoundsVertices
  // (a fraction of a second), each instance's box: the mesh's box's corners mapped, which holds
  // the instance but may be larger.
  constexpr std::uint64_t kExactBoundsVertices = std::uint64_t(1) << 26;
  std::vector<const LoadedMesh*> by_index(scene.meshes.size());
  for (const auto& [mesh, loaded] : loaded_) by_index[loaded.index] = &loaded;
  std::uint64_t world_vertices = 0;
  for (const Instance& instance : scene.instances) {
    const LoadedMesh& m = *by_index[instance.mesh];
    world_vertices += m.end_vertex - m.first_vertex;
  }
  const bool exact = world_vertices <= kExactBoundsVertices;
  std::vector<std::pair<glm::dvec3, glm::dvec3>> mesh_box(scene.meshes.size());
  if (!exact)
    for (std::size_t i = 0; i < mesh_box.size(); ++i) {
      glm::dvec3 a(std::numeric_limits<double>::max()), b(std::numeric_limits<double>::lowest());
      for (std::size_t v = by_index[i]->first_vertex; v < by_index[i]->end_vertex; ++v) {
        a = glm::min(a, glm::dvec3(scene.positions[v]));
        b = glm::max(b, glm::dvec3(scene.positions[v]));
      }
      mesh_box[i] = {a, b};
    }
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
  const auto add = [&](const glm::dmat4& m, const glm::dvec3& v) {
    const glm::dvec3 p = glm::dvec3(m * glm::dvec4(v, 1.0));
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  };
  for (const Instance& instance : scene.instances) {
    if (exact) {
      const LoadedMesh& m = *by_index[instance.mesh];
      for (std::size_t v = m.first_vertex; v < m.end_vertex; ++v)
        add(instance.to_world, glm::dvec3(scene.positions[v]));
      continue;
    }
    const auto& [a, b] = mesh_box[instance.mesh];
    for (int c = 0; c < 8; ++c)
      add(instance.to_world, glm::dvec3(c & 1 ? b.x : a.x, c & 2 ? b.y : a.y, c & 4 ? b.z : a.z));
  }
  if (scene.instances.empty()) lo = hi = glm::dvec3(0.0);
  scene.bounds_lo = glm::vec3(lo);
  scene.bounds_hi = glm::vec3(hi);
}

}  // namespace

bool use_instancing(Instancing mode, const LoadCounts& counts) {
  switch (mode) {
    case Instancing::kAlways:
      return true;
    case Instancing::kNever:
      return false;
    case Instancing::kAuto:
      break;
  }
  return counts.max_triangles >= kInstancingGain * counts.mesh_max_triangles &&
         counts.placements > counts.meshes;
}

Scene load_gltf(const std::string& path, const LoadOptions& options) {
  Scene scene;
  scene.source = path;
  gltf::PlaceholderBuffers placeholders;
  tinygltf::Model model = parse(path, &scene.warnings, &scene.digest, &placeholders);
  // The files the glTF file names (a GLB's own binary chunk is in its digest already).
  for (const tinygltf::Buffer& b : model.buffers)
    if (!b.uri.empty()) scene.digest = fnv1a64(b.data.data(), b.data.size(), scene.digest);
  for (const tinygltf::Image& image : model.images)  // encoded bytes (keep_encoded_image)
    if (image.bufferView < 0)
      scene.digest = fnv1a64(image.image.data(), image.image.size(), scene.digest);
  check_extensions(model, path, &scene.warnings);
  scene.gltf.extensions_used = model.extensionsUsed;
  scene.gltf.extensions_required = model.extensionsRequired;
  scene.gltf.meshes = model.meshes.size();
  scene.gltf.images = model.images.size();
  scene.gltf.textures = model.textures.size();
  scene.gltf.materials = model.materials.size();
  try {
    // glTF 1.0 files differ in structure; tinygltf reads some of them as 2.0 nonsense.
    if (model.asset.version.rfind("2.", 0) != 0)
      throw Error("asset.version \"" + model.asset.version.substr(0, 32) +
                  "\" is not 2.x (only glTF 2.0 is supported)");
    if (model.scenes.empty()) throw Error("the file has no scenes");
    // Compressed data first: everything below reads the decoded bytes as uncompressed ones (Draco
    // meshes once the counts are accepted, below).
    gltf::decode_meshopt(model, placeholders);
    const int scene_index = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (static_cast<std::size_t>(scene_index) >= model.scenes.size())
      throw Error("default scene " + std::to_string(scene_index) + " does not exist");
    scene.variants = variant_names(model);
    const int variant = variant_index(scene.variants, options.variant);
    if (variant >= 0) {  // another variant, another scene (the render key)
      scene.variant = options.variant;
      const std::string tag = "KHR_materials_variants:" + options.variant;
      scene.digest = fnv1a64(tag.data(), tag.size(), scene.digest);
    }
    gltf::TextureTable textures(model, scene);
    std::vector<std::string> clamped;  // values beyond what float32 carries (scene.h)
    for (std::size_t i = 0; i < model.materials.size(); ++i)
      scene.materials.push_back(
          gltf::convert_material(model, static_cast<int>(i), textures, &clamped));
    textures.decode();
    for (const std::string& w : clamped) scene.warnings.push_back(path + ": " + w);
    SceneBuilder builder(model, scene, variant);
    std::set<int> placed;
    LoadCounts counts = builder.count(scene_index, &placed);
    counts.instanced = use_instancing(options.instancing, counts);
    if (options.check_counts) options.check_counts(counts);
    gltf::decode_draco(model, placed);
    builder.set_instancing(counts.instanced);
    builder.build(scene_index, counts);
    builder.compute_bounds();
    // An empty scene is valid glTF (only the background shows); say so, in case it is a mistake.
    if (scene.triangle_count() == 0)
      scene.warnings.push_back(path + ": scene " + std::to_string(scene_index) +
                               " has no triangles; only the background will be seen");
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  return scene;
}

Camera framing_camera(const Scene& scene, float aspect) {
  const glm::vec3 center = 0.5f * (scene.bounds_lo + scene.bounds_hi);
  float radius = 0.5f * glm::length(scene.bounds_hi - scene.bounds_lo);
  // A point-sized (or broken) scene still gets a usable view: one scene unit across.
  if (!(radius > 0.0f) || !std::isfinite(radius)) radius = 1.0f;
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) aspect = 1.0f;

  Camera c;
  c.name = "framing";
  c.type = CameraType::kPerspective;
  c.yfov = glm::radians(45.0f);
  const float distance = fit_distance(radius, c.yfov, aspect);
  const float elevation = glm::radians(15.0f);                           // "slightly from above"
  const glm::vec3 back(0.0f, std::sin(elevation), std::cos(elevation));  // towards the camera
  c.position =
      std::isfinite(center.x + center.y + center.z) ? center + distance * back : distance * back;
  c.forward = -back;
  c.up = glm::vec3(0.0f, std::cos(elevation), -std::sin(elevation));
  c.znear = 0.0f;  // nothing lies between the camera and the bounding sphere
  return c;
}

}  // namespace wp
