// `wavepath info`'s output (info.h): a report for a person, or one JSON object.
#include <cmath>
#include <cstdio>
#include <sstream>

#include "host/cli/info.h"
#include "host/util/json.h"

namespace wp::cli {

namespace {

constexpr double kDegrees = 57.29577951308232;

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string quoted(const std::string& name) {
  return name.empty() ? std::string("(no name)") : "\"" + name + "\"";
}

const char* camera_type(const Camera& c) {
  return c.type == CameraType::kPerspective ? "perspective" : "orthographic";
}

const char* layout_use(int width) {
  return width == WP_BVH8_WIDTH ? "CPUs" : "GPUs";
}

// "label       text", the label in a column of its own.
void line(std::ostringstream& o, const std::string& label, const std::string& text) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%-12s", label.c_str());
  o << buf << text << "\n";
}

std::string extension_row(const ExtensionUse& e) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "  %-36s %-9s %-10s ", e.name.c_str(),
                e.required ? "required" : "used", extension_support_name(e.support));
  return buf + e.note + "\n";
}

void text_extensions(std::ostringstream& o, const std::vector<ExtensionUse>& uses) {
  line(o, "extensions", uses.empty() ? "none" : std::to_string(uses.size()) + ":");
  for (const ExtensionUse& e : uses) o << extension_row(e);
}

void text_geometry(std::ostringstream& o, const Scene& s) {
  const GltfSummary& g = s.gltf;
  const bool instanced = !s.instances.empty();
  if (instanced)
    line(o, "geometry",
         std::to_string(s.world_triangle_count()) +
             " triangles in the world: " + std::to_string(s.instances.size()) + " instances of " +
             std::to_string(s.meshes.size()) + " mesh(es) holding " +
             std::to_string(s.triangle_count()) + " triangles, " +
             std::to_string(s.positions.size()) + " vertices (a two-level BVH)");
  else
    line(o, "geometry",
         std::to_string(s.triangle_count()) + " triangles, " + std::to_string(s.positions.size()) +
             " vertices (all placements, each a copy)");
  const std::string each = instanced ? "each an instance of its mesh" : "each a copy of its mesh";
  line(o, "meshes",
       std::to_string(g.meshes) + " in the file, " + std::to_string(g.meshes_placed) +
           " placed by " + std::to_string(g.mesh_nodes) + " node(s): " + each);
  if (g.gpu_instanced_nodes)
    line(o, "",
         "EXT_mesh_gpu_instancing: " + std::to_string(g.gpu_instances) + " instances on " +
             std::to_string(g.gpu_instanced_nodes) + " node(s), " + each);
}

void text_materials(std::ostringstream& o, const Scene& s, const SceneInfo& info) {
  const GltfSummary& g = s.gltf;
  line(o, "materials",
       std::to_string(s.materials.size()) +
           (s.materials.size() > g.materials
                ? " (the file's " + std::to_string(g.materials) + " and glTF's default material)"
                : "") +
           ", " + std::to_string(info.emissive_materials) + " emissive" +
           (s.variant.empty() ? "" : "; variant " + quoted(s.variant)));
  std::uint64_t texels = 0;
  for (const Image& img : s.images) texels += std::uint64_t(img.width) * std::uint64_t(img.height);
  line(o, "textures",
       std::to_string(s.textures.size()) + " in use over " + std::to_string(s.images.size()) +
           " image(s), " + human_bytes(texels * kTexelBytes) + " of texels (" +
           std::to_string(g.textures) + " textures, " + std::to_string(g.images) +
           " images in the file)");
  for (std::size_t i = 0; i < s.images.size(); ++i) {
    const Image& img = s.images[i];
    line(o, "  image " + std::to_string(i),
         quoted(img.name) + " " + std::to_string(img.width) + " x " + std::to_string(img.height) +
             ", " +
             human_bytes(std::uint64_t(img.width) * std::uint64_t(img.height) * kTexelBytes) +
             " packed (RGBA8)");
  }
}

void text_cameras(std::ostringstream& o, const Scene& s) {
  line(o, "cameras",
       s.cameras.empty()
           ? "none: render frames the scene (45 degree yfov)"
           : std::to_string(s.cameras.size()) + " in node order, by index as render --camera I");
  for (std::size_t i = 0; i < s.cameras.size(); ++i) {
    const Camera& c = s.cameras[i];
    std::string text = quoted(c.name) + " " + camera_type(c);
    if (c.type == CameraType::kPerspective)
      text += ", yfov " + num(c.yfov) + " rad (" + num(c.yfov * kDegrees) + " degrees)";
    else
      text += ", xmag " + num(c.xmag) + ", ymag " + num(c.ymag);
    line(o, "  " + std::to_string(i), text);
  }
}

void text_lights(std::ostringstream& o, const SceneInfo& info) {
  line(o, "lights",
       std::to_string(info.point_lights) + " point, " + std::to_string(info.spot_lights) +
           " spot, " + std::to_string(info.directional_lights) + " directional; " +
           std::to_string(info.emissive_triangles) +
           " emissive triangles (those not black everywhere); NEE chooses among " +
           std::to_string(info.table_lights) + " light(s)");
}

void text_memory(std::ostringstream& o, const SceneInfo& info) {
  const StateMemory& m = info.state;
  line(o, "memory",
       "on the device for " + std::to_string(info.settings.width) + " x " +
           std::to_string(info.settings.height) + " (fused pipeline, no AOVs, no --env)");
  const auto row = [&](const std::string& label, const auto& value) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "  %-26s", label.c_str());
    o << buf;
    for (const BvhInfo& b : info.bvhs) {
      std::snprintf(buf, sizeof buf, "%-22s", value(b).c_str());
      o << buf;
    }
    o << "\n";
  };
  row("", [](const BvhInfo& b) {
    return std::to_string(b.width) + "-wide BVH (" + layout_use(b.width) + ")";
  });
  row("BVH nodes", [](const BvhInfo& b) { return human_bytes(b.bytes.nodes); });
  row("BVH triangle data", [](const BvhInfo& b) { return human_bytes(b.bytes.primitives); });
  row("packed scene, in all", [](const BvhInfo& b) { return human_bytes(b.layout.total_bytes()); });
  const std::string state = human_bytes(m.path_state.bytes);
  row("path state (" + std::to_string(m.path_state.bytes_per_path) + " B/path)",
      [&](const BvhInfo&) { return state; });
  const std::string queues = human_bytes(m.queues + m.counters);
  row("queues and counters", [&](const BvhInfo&) { return queues; });
  const std::string film = human_bytes(m.film);
  row("film", [&](const BvhInfo&) { return film; });
  row("total", [&](const BvhInfo& b) { return human_bytes(b.layout.total_bytes() + m.total()); });
  row("BVH sizes from", [](const BvhInfo& b) {
    return b.source == "estimate" ? std::string("estimate (at least)") : b.source;
  });
  line(o, "", "render's BVH layout: 8-wide on CPU devices, 2-wide on GPUs (--bvh-width)");
  line(o, "",
       std::string(info.wave_device.empty() ? "a GPU's wave (--device for another's)"
                                            : "a wave on " + info.wave_device) +
           ": " + std::to_string(m.wave.pixels) + " pixels x " + std::to_string(m.wave.samples) +
           " sample(s) = " + std::to_string(m.wave.paths()) + " paths");
}

void text_cache(std::ostringstream& o, const SceneInfo& info) {
  line(o, "BVH cache", "render loads and stores BVHs there unless --no-bvh-cache");
  for (const BvhInfo& b : info.bvhs) {
    std::string text = b.cache;
    if (b.cache == "valid") text += ", " + human_bytes(b.cache_file_bytes) + ": render loads it";
    if (b.cache == "absent") text += ": render builds and stores it";
    if (b.cache == "unusable") text += ": render builds it again and replaces it";
    if (!b.cache_file.empty()) text += "; " + b.cache_file;
    line(o, "  " + std::to_string(b.width) + "-wide", text);
  }
}

std::string json_extensions(const std::vector<ExtensionUse>& uses) {
  std::string out = "[";
  for (std::size_t i = 0; i < uses.size(); ++i)
    out += std::string(i ? "," : "") + "{\"name\":" + json_string(uses[i].name) +
           ",\"required\":" + (uses[i].required ? "true" : "false") +
           ",\"status\":" + json_string(extension_support_name(uses[i].support)) +
           ",\"note\":" + json_string(uses[i].note) + "}";
  return out + "]";
}

void json_contents(std::ostringstream& o, const Scene& s, const SceneInfo& info) {
  const GltfSummary& g = s.gltf;
  o << ",\"triangles\":" << s.world_triangle_count()
    << ",\"stored_triangles\":" << s.triangle_count() << ",\"instances\":" << s.instances.size()
    << ",\"vertices\":" << s.positions.size() << ",\"meshes\":" << g.meshes
    << ",\"meshes_placed\":" << g.meshes_placed << ",\"mesh_instances\":" << g.mesh_nodes
    << ",\"gpu_instanced_nodes\":" << g.gpu_instanced_nodes
    << ",\"gpu_instances\":" << g.gpu_instances << ",\"materials\":" << s.materials.size()
    << ",\"file_materials\":" << g.materials
    << ",\"emissive_materials\":" << info.emissive_materials
    << ",\"variant\":" << json_string(s.variant) << ",\"textures\":" << s.textures.size()
    << ",\"file_textures\":" << g.textures << ",\"file_images\":" << g.images << ",\"images\":[";
  for (std::size_t i = 0; i < s.images.size(); ++i) {
    const Image& img = s.images[i];
    o << (i ? "," : "") << "{\"index\":" << i << ",\"name\":" << json_string(img.name)
      << ",\"width\":" << img.width << ",\"height\":" << img.height
      << ",\"bytes\":" << std::uint64_t(img.width) * std::uint64_t(img.height) * kTexelBytes << "}";
  }
  o << "],\"cameras\":[";
  for (std::size_t i = 0; i < s.cameras.size(); ++i) {
    const Camera& c = s.cameras[i];
    o << (i ? "," : "") << "{\"index\":" << i << ",\"name\":" << json_string(c.name)
      << ",\"type\":" << json_string(camera_type(c));
    if (c.type == CameraType::kPerspective)
      o << ",\"yfov\":" << num(c.yfov);
    else
      o << ",\"xmag\":" << num(c.xmag) << ",\"ymag\":" << num(c.ymag);
    o << "}";
  }
  o << "],\"lights\":{\"point\":" << info.point_lights << ",\"spot\":" << info.spot_lights
    << ",\"directional\":" << info.directional_lights
    << ",\"emissive_triangles\":" << info.emissive_triangles << ",\"table\":" << info.table_lights
    << "}";
}

void json_memory(std::ostringstream& o, const SceneInfo& info) {
  const StateMemory& m = info.state;
  o << ",\"features\":" << json_string(info.features.describe())
    << ",\"width\":" << info.settings.width << ",\"height\":" << info.settings.height
    << ",\"wave_paths\":" << m.wave.paths() << ",\"bytes_per_path\":" << m.path_state.bytes_per_path
    << ",\"path_state_bytes\":" << m.path_state.bytes << ",\"queue_bytes\":" << m.queues
    << ",\"counter_bytes\":" << m.counters << ",\"film_bytes\":" << m.film << ",\"bvh\":[";
  for (std::size_t i = 0; i < info.bvhs.size(); ++i) {
    const BvhInfo& b = info.bvhs[i];
    o << (i ? "," : "") << "{\"width\":" << b.width
      << ",\"default_on\":" << json_string(b.width == WP_BVH8_WIDTH ? "cpu" : "gpu")
      << ",\"source\":" << json_string(b.source)
      << ",\"exact\":" << (b.source == "estimate" ? "false" : "true")
      << ",\"node_bytes\":" << b.bytes.nodes << ",\"primitive_bytes\":" << b.bytes.primitives
      << ",\"scene_bytes\":" << b.layout.total_bytes()
      << ",\"total_bytes\":" << b.layout.total_bytes() + m.total() << ",\"scene_arrays\":{";
    for (std::size_t k = 0; k < b.layout.sizes.size(); ++k)
      o << (k ? "," : "") << json_string(scene_array_name(k)) << ":" << b.layout.sizes[k];
    o << "},\"cache\":" << json_string(b.cache) << ",\"cache_file\":" << json_string(b.cache_file)
      << ",\"cache_file_bytes\":" << b.cache_file_bytes << "}";
  }
  o << "]";
}

}  // namespace

std::string info_text(const Scene& s, const SceneInfo& info) {
  std::ostringstream o;
  line(o, "scene", s.source);
  text_geometry(o, s);
  text_materials(o, s, info);
  text_cameras(o, s);
  text_lights(o, info);
  text_extensions(o, info.extensions);
  line(o, "features", info.features.describe() + " (the kernels compiled in)");
  text_memory(o, info);
  text_cache(o, info);
  line(o, "warnings", s.warnings.empty() ? "none" : std::to_string(s.warnings.size()) + ":");
  for (const std::string& w : s.warnings) o << "  " << w << "\n";
  return o.str();
}

std::string info_json(const Scene& s, const SceneInfo& info) {
  std::ostringstream o;
  o << "{\"scene\":" << json_string(s.source) << ",\"loaded\":true";
  json_contents(o, s, info);
  o << ",\"extensions\":" << json_extensions(info.extensions);
  json_memory(o, info);
  o << ",\"warnings\":[";
  for (std::size_t i = 0; i < s.warnings.size(); ++i)
    o << (i ? "," : "") << json_string(s.warnings[i]);
  o << "]}\n";
  return o.str();
}

std::string refused_text(const std::string& file, const std::vector<ExtensionUse>& uses) {
  std::ostringstream o;
  line(o, "scene", file + " (not loaded: it requires extensions wavepath does not support)");
  text_extensions(o, uses);
  return o.str();
}

std::string refused_json(const std::string& file, const std::string& error,
                         const std::vector<ExtensionUse>& uses) {
  return "{\"scene\":" + json_string(file) + ",\"loaded\":false,\"error\":" + json_string(error) +
         ",\"extensions\":" + json_extensions(uses) + "}\n";
}

}  // namespace wp::cli
