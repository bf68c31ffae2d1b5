#include "host/device/device_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>

#include <sys/mman.h>
#include <unistd.h>

#include <glm/geometric.hpp>

#include "host/scene/mipmap.h"
#include "host/util/error.h"
#include "host/util/parallel.h"

namespace wp {

namespace {

dev::float4 f4(glm::vec3 v, float w = 0.0f) {
  return {v.x, v.y, v.z, w};
}
dev::float4 f4(glm::vec4 v) {
  return {v.x, v.y, v.z, v.w};
}

// Every array starts at a 64-byte boundary of its buffer; an empty one still takes 16 bytes (a
// buffer is never empty). pack_scene and scene_layout both place arrays with these.
std::uint64_t aligned(std::uint64_t end) {
  return (end + WP_SCENE_ALIGN - 1) & ~std::uint64_t(WP_SCENE_ALIGN - 1);
}
std::uint64_t padded(std::uint64_t size) {
  return std::max<std::uint64_t>(size, 16);
}

std::string too_many_texels() {
  return "scene too large for the device: more than 2^32 texels in its images";
}

// The arrays pack_scene packs, in its order (SceneDesc's); the environment's three come last and
// only with a map.
constexpr std::array<const char*, 20> kArrayNames = {"BVH node",
                                                     "BVH triangle",
                                                     "triangle vertex",
                                                     "position",
                                                     "normal",
                                                     "tangent",
                                                     "uv",
                                                     "colour",
                                                     "material",
                                                     "texture",
                                                     "image",
                                                     "texel",
                                                     "light",
                                                     "light alias",
                                                     "triangle light",
                                                     "environment texel",
                                                     "environment marginal",
                                                     "environment conditional",
                                                     "instance",
                                                     "instance reference"};

dev::Material device_material(const Material& m) {
  dev::Material d{};
  d.base_color = f4(m.base_color);
  d.emission = f4(m.emission, m.alpha_cutoff);
  d.params = {m.metallic, m.roughness, m.ior, m.transmission};
  d.volume =
      f4(m.attenuation_color, m.attenuation_distance > 0.0f ? m.attenuation_distance : INFINITY);
  d.extra = {m.normal_scale, m.thickness, 0.0f, m.dispersion};
  dev::uint flags = 0;
  if (m.double_sided) flags |= WP_MAT_DOUBLE_SIDED;
  if (m.alpha_mode == AlphaMode::kMask) flags |= WP_MAT_ALPHA_MASK;
  if (m.alpha_mode == AlphaMode::kBlend) flags |= WP_MAT_ALPHA_BLEND;
  if (m.unlit) flags |= WP_MAT_UNLIT;
  if (m.thickness > 0.0f) flags |= WP_MAT_VOLUME;
  d.flags = {flags, 0u, 0u, 0u};
  d.textures0 = {m.base_color_texture, m.metallic_roughness_texture, m.normal_texture,
                 m.emissive_texture};
  d.textures1 = {m.transmission_texture, m.specular_texture, m.specular_color_texture,
                 m.clearcoat_texture};
  d.textures2 = {m.clearcoat_roughness_texture, m.clearcoat_normal_texture, m.sheen_color_texture,
                 m.sheen_roughness_texture};
  d.textures3 = {m.anisotropy_texture, m.iridescence_texture, m.iridescence_thickness_texture,
                 m.diffuse_transmission_texture};
  d.textures4 = {m.diffuse_transmission_color_texture, -1, -1, -1};
  d.specular = f4(m.specular_color, m.specular);
  d.clearcoat = {m.clearcoat, m.clearcoat_roughness, m.clearcoat_normal_scale, 0.0f};
  d.sheen = f4(m.sheen_color, m.sheen_roughness);
  d.anisotropy = {m.anisotropy_strength, std::cos(m.anisotropy_rotation),
                  std::sin(m.anisotropy_rotation), 0.0f};
  d.iridescence = {m.iridescence, m.iridescence_ior, m.iridescence_thickness_min,
                   m.iridescence_thickness_max};
  d.diffuse_transmission = f4(m.diffuse_transmission_color, m.diffuse_transmission);
  return d;
}

dev::uint wrap_bits(Wrap w) {
  return w == Wrap::kRepeat        ? WP_WRAP_REPEAT
         : w == Wrap::kClampToEdge ? WP_WRAP_CLAMP
                                   : WP_WRAP_MIRROR;
}

// The texture's term of its mip level (TextureRef.meta.w, kernels/texture/ray_cone.h): 1/2 log2 of
// the texels its coordinates' unit square covers, the image's width x height times the area scale
// of the transform; -INFINITY (level 0 always) without a chain.
float lod_term(const TextureRef& t, const dev::TextureImage& image) {
  const double det = double(t.row_u.x) * t.row_v.y - double(t.row_u.y) * t.row_v.x;
  if (!t.mipmaps || image.levels < 2 || !(std::fabs(det) > 0.0)) return -INFINITY;
  return static_cast<float>(0.5 * std::log2(double(image.width) * image.height * std::fabs(det)));
}

dev::TextureRef device_texture(const TextureRef& t, const dev::TextureImage& image) {
  dev::TextureRef d{};
  d.transform_u = f4(t.row_u);
  d.transform_v = f4(t.row_v);
  dev::uint bits = wrap_bits(t.wrap_s) | (wrap_bits(t.wrap_t) << 8);
  if (t.nearest) bits |= WP_TEX_NEAREST;
  if (t.srgb) bits |= WP_TEX_SRGB;
  const float lod = lod_term(t, image);
  dev::uint lod_bits;
  std::memcpy(&lod_bits, &lod, sizeof lod_bits);
  d.meta = {static_cast<dev::uint>(t.image), bits, static_cast<dev::uint>(t.texcoord), lod_bits};
  return d;
}

void pack_rgba8(const std::vector<std::uint8_t>& rgba, std::vector<dev::uint>& texels) {
  for (std::size_t i = 0; i + 3 < rgba.size(); i += 4)
    texels.push_back(dev::uint(rgba[i]) | dev::uint(rgba[i + 1]) << 8 |
                     dev::uint(rgba[i + 2]) << 16 | dev::uint(rgba[i + 3]) << 24);
}

// Per image: whether it gets a mip chain (with `mipmaps`, when a texture minifies it through
// mip-maps, TextureRef::mipmaps), and whether a texture uses it as colour (sRGB).
struct ImageUses {
  std::vector<char> chained, colour;
};
ImageUses image_uses(const Scene& scene, bool mipmaps) {
  ImageUses u{std::vector<char>(scene.images.size(), 0), std::vector<char>(scene.images.size(), 0)};
  for (const TextureRef& t : scene.textures) {
    if (t.image < 0 || std::size_t(t.image) >= scene.images.size()) continue;
    u.chained[std::size_t(t.image)] |= mipmaps && t.mipmaps;
    u.colour[std::size_t(t.image)] |= t.srgb;
  }
  return u;
}

// The levels image i is packed with.
int packed_levels(const Image& img, const ImageUses& uses, std::size_t i) {
  return uses.chained[i] ? mip_levels(img.width, img.height) : 1;
}

// All images' texels in one array, RGBA8 with R in the lowest byte; with `mipmaps`, each image
// that image_uses chains is followed by its chain, filtered as colour when a texture uses it as
// colour (sRGB), else as data. The chains of a batch of images (one per hardware thread) are made
// at once, each on a thread of its own, so that no more than a batch of them is held beside the
// packed texels; the packing keeps the images' order.
void pack_images(const Scene& scene, bool mipmaps, std::vector<dev::TextureImage>& images,
                 std::vector<dev::uint>& texels) {
  const ImageUses uses = image_uses(scene, mipmaps);
  const std::size_t count = scene.images.size(), batch = host_threads();
  std::vector<std::vector<std::uint8_t>> chains(batch);
  std::vector<int> levels(batch);
  for (std::size_t first = 0; first < count; first += batch) {
    const std::size_t n = std::min(batch, count - first);
    parallel_for(n, [&](std::size_t k) {
      const std::size_t i = first + k;
      levels[k] = packed_levels(scene.images[i], uses, i);
      if (levels[k] > 1) chains[k] = mip_chain(scene.images[i], uses.colour[i] != 0);
    });
    for (std::size_t k = 0; k < n; ++k) {
      const Image& img = scene.images[first + k];
      images.push_back({static_cast<dev::uint>(texels.size()), static_cast<dev::uint>(img.width),
                        static_cast<dev::uint>(img.height), static_cast<dev::uint>(levels[k])});
      pack_rgba8(img.rgba, texels);
      if (levels[k] > 1) pack_rgba8(chains[k], texels);
      std::vector<std::uint8_t>().swap(chains[k]);  // freed before the next batch
    }
  }
}

std::uint64_t ceil_div(std::uint64_t a, std::uint64_t b) {
  return (a + b - 1) / b;
}

}  // namespace

dev::Camera device_camera(const Camera& c, int width, int height) {
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const glm::vec3 forward = glm::normalize(c.forward);
  const glm::vec3 right = glm::normalize(glm::cross(forward, c.up));
  const glm::vec3 up = glm::cross(right, forward);
  float half_w, half_h;
  if (c.type == CameraType::kPerspective) {
    half_h = std::tan(0.5f * c.yfov);
    half_w = half_h * aspect;
  } else {
    half_h = c.ymag;
    half_w = c.ymag * aspect;
  }
  dev::Camera d{};
  d.position = f4(c.position, c.znear);
  d.forward = f4(forward);
  d.right = f4(right * half_w);
  d.up = f4(up * half_h);
  d.lens = {c.lens_radius, c.focus_distance, 0.0f, 0.0f};
  d.meta = {c.type == CameraType::kPerspective ? WP_CAMERA_PERSPECTIVE : WP_CAMERA_ORTHOGRAPHIC, 0u,
            0u, 0u};
  return d;
}

namespace {

// One scene array: its elements, the SceneDesc field that receives its offset, and what writes
// elements [begin, end) in place: a copy of an array that exists, or, for the per-triangle and
// per-vertex arrays, their conversion straight into the buffer (no intermediate copy of gigabytes
// for tens of millions of triangles).
struct SceneArray {
  std::uint64_t count, element_bytes;
  dev::uint* offset;
  std::function<void(unsigned char* to, std::size_t begin, std::size_t end)> write;
  // With HostArrays::kRelease: the host arrays the write reads (element i from the same fraction
  // i / count of each), and what frees them once it is done.
  struct Source {
    unsigned char* data;
    std::uint64_t bytes;
  };
  std::vector<Source> sources = {};
  std::function<void()> release = {};
  std::uint64_t bytes() const { return count * element_bytes; }
};

// The host arrays packing frees as it goes (HostArrays::kRelease); null members: it keeps them.
struct Owned {
  Scene* scene = nullptr;
  bvh::Bvh* bvh = nullptr;
};

template <class T, class A>
void free_vector(std::vector<T, A>& v) {
  std::vector<T, A>().swap(v);
}

// Marks `vectors` as what `array` reads and frees once written.
template <class... Vectors>
void frees(SceneArray& array, Vectors&... vectors) {
  (array.sources.push_back({reinterpret_cast<unsigned char*>(vectors.data()),
                            vectors.size() * sizeof(typename Vectors::value_type)}),
   ...);
  array.release = [&vectors...] { (free_vector(vectors), ...); };
}

// An array with sources is written this many bytes at a time, and the pages of its sources read
// so far are returned to the system after each slice (pack), so that the host never holds more
// than about a slice of an array twice (tests/test_scale_flat.py bounds the peak with it).
constexpr std::uint64_t kReleaseSlice = std::uint64_t(16) << 20;

// Writes `a` at `to`; with sources, slice by slice, returning each source's pages once read
// (madvise MADV_DONTNEED: they are not read again, and are freed whole right after), then frees
// the sources.
void write_array(const SceneArray& a, unsigned char* to) {
  if (a.sources.empty() || a.count == 0) {
    a.write(to, 0, a.count);
    if (a.release) a.release();
    return;
  }
  const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  // Per source, the first byte not yet returned, at a page boundary inside the source.
  std::vector<std::uintptr_t> kept;
  for (const SceneArray::Source& s : a.sources)
    kept.push_back((reinterpret_cast<std::uintptr_t>(s.data) + page - 1) & ~(page - 1));
  const std::size_t step = std::max<std::uint64_t>(1, kReleaseSlice / a.element_bytes);
  for (std::size_t begin = 0; begin < a.count; begin += step) {
    const std::size_t end = std::min<std::size_t>(a.count, begin + step);
    a.write(to, begin, end);
    for (std::size_t k = 0; k < a.sources.size(); ++k) {
      const SceneArray::Source& s = a.sources[k];
      // Elements [0, end) read at most these first bytes (each element's share, rounded down).
      const std::uintptr_t read =
          reinterpret_cast<std::uintptr_t>(s.data) + s.bytes / a.count * end;
      const std::uintptr_t upto = read & ~(page - 1);
      if (upto > kept[k]) {
        madvise(reinterpret_cast<void*>(kept[k]), upto - kept[k], MADV_DONTNEED);
        kept[k] = upto;
      }
    }
  }
  a.release();
}

template <class Items>
SceneArray copy_array(const Items& items, dev::uint& offset) {
  const std::uint64_t size = sizeof(items[0]);
  const unsigned char* data = reinterpret_cast<const unsigned char*>(items.data());
  return SceneArray{items.size(), size, &offset,
                    [data, size](unsigned char* to, std::size_t begin, std::size_t end) {
                      if (end > begin)
                        std::memcpy(to + begin * size, data + begin * size, (end - begin) * size);
                    }};
}

// `count` elements of type T, element i made by make(i).
template <class Make>
SceneArray convert_array(std::size_t count, dev::uint& offset, Make make) {
  using T = decltype(make(std::size_t{0}));
  return SceneArray{count, sizeof(T), &offset,
                    [make](unsigned char* to, std::size_t begin, std::size_t end) {
                      T* out = reinterpret_cast<T*>(to);
                      for (std::size_t i = begin; i < end; ++i) out[i] = make(i);
                    }};
}

// The scene's materials, textures and images in their device form, which the arrays copy.
struct DeviceMaterials {
  std::vector<dev::Material> materials;
  std::vector<dev::TextureRef> textures;
  std::vector<dev::TextureImage> images;
  std::vector<dev::uint> texels;
};

DeviceMaterials device_materials(const Scene& scene, bool mipmaps) {
  DeviceMaterials m;
  for (const Material& material : scene.materials) m.materials.push_back(device_material(material));
  pack_images(scene, mipmaps, m.images, m.texels);
  for (const TextureRef& t : scene.textures)
    m.textures.push_back(device_texture(t, m.images.at(static_cast<std::size_t>(t.image))));
  if (m.texels.size() > 0xffffffffu) throw Error(too_many_texels());
  return m;
}

// The per-triangle and per-vertex arrays, in kArrayNames' order from tri_vertices on. An array
// the program does not read is not packed, but its source is freed all the same.
void add_geometry_arrays(const Scene& scene, const VertexArrays& packed, dev::SceneDesc& d,
                         Scene* owned, std::vector<SceneArray>& arrays) {
  const std::size_t tris = scene.triangle_count(), verts = scene.positions.size();
  arrays.push_back(convert_array(tris, d.tri_vertices, [&](std::size_t i) {
    return dev::uint4{scene.indices[3 * i], scene.indices[3 * i + 1], scene.indices[3 * i + 2],
                      scene.triangle_material[i]};
  }));
  if (owned) frees(arrays.back(), owned->indices, owned->triangle_material);
  arrays.push_back(
      convert_array(verts, d.positions, [&](std::size_t i) { return f4(scene.positions[i]); }));
  if (owned) frees(arrays.back(), owned->positions);
  arrays.push_back(
      convert_array(verts, d.normals, [&](std::size_t i) { return f4(scene.normals[i]); }));
  if (owned) frees(arrays.back(), owned->normals);
  arrays.push_back(convert_array(packed.tangents ? verts : 0, d.tangents, [&](std::size_t i) {
    return i < scene.tangents.size() ? f4(scene.tangents[i]) : dev::float4{1, 0, 0, 1};
  }));
  if (owned) frees(arrays.back(), owned->tangents);
  arrays.push_back(convert_array(packed.uvs ? verts : 0, d.uvs, [&](std::size_t i) {
    const glm::vec2 uv0 = i < scene.uv0.size() ? scene.uv0[i] : glm::vec2(0.0f);
    const glm::vec2 uv1 = i < scene.uv1.size() ? scene.uv1[i] : glm::vec2(0.0f);
    return dev::float4{uv0.x, uv0.y, uv1.x, uv1.y};
  }));
  if (owned) frees(arrays.back(), owned->uv0, owned->uv1);
  arrays.push_back(convert_array(packed.colors ? verts : 0, d.colors, [&](std::size_t i) {
    return i < scene.color0.size() ? f4(scene.color0[i]) : dev::float4{1, 1, 1, 1};
  }));
  if (owned) frees(arrays.back(), owned->color0);
}

// Every array in kArrayNames' order. The BVH is in the layout the program was built for
// (WP_BVH_WIDTH): the same two fields either way.
std::vector<SceneArray> scene_arrays(const Scene& scene, const bvh::Bvh& bvh, const SceneExtras& x,
                                     DeviceMaterials& m, dev::SceneDesc& d, Owned owned) {
  std::vector<SceneArray> arrays;
  arrays.push_back(bvh.width == 8 ? copy_array(bvh.nodes8, d.bvh_nodes)
                                  : copy_array(bvh.nodes, d.bvh_nodes));
  if (owned.bvh) frees(arrays.back(), owned.bvh->nodes8, owned.bvh->nodes);
  arrays.push_back(bvh.width == 8 ? copy_array(bvh.blocks, d.isect_tris)
                                  : copy_array(bvh.triangles, d.isect_tris));
  if (owned.bvh) frees(arrays.back(), owned.bvh->blocks, owned.bvh->triangles);
  add_geometry_arrays(scene, x.vertex_arrays, d, owned.scene, arrays);
  arrays.push_back(copy_array(m.materials, d.materials));
  arrays.push_back(copy_array(m.textures, d.textures));
  arrays.push_back(copy_array(m.images, d.images));
  arrays.push_back(copy_array(m.texels, d.texels));
  // The device texels are a copy of the images' (device_materials), made before any buffer.
  if (owned.scene) frees(arrays.back(), m.texels);
  arrays.push_back(copy_array(x.lights->lights, d.lights));
  arrays.push_back(copy_array(x.lights->alias, d.light_alias));
  arrays.push_back(copy_array(x.lights->tri_light, d.tri_light));
  if (x.env) {
    arrays.push_back(copy_array(x.env->texels, d.env_texels));
    arrays.push_back(copy_array(x.env->marginal, d.env_marginal));
    arrays.push_back(copy_array(x.env->conditional, d.env_conditional));
  }
  if (!bvh.instances.empty()) {
    if (!x.env) {  // the instance arrays' places are after the environment's
      static const std::vector<float> none;
      arrays.push_back(copy_array(none, d.env_texels));
      arrays.push_back(copy_array(none, d.env_marginal));
      arrays.push_back(copy_array(none, d.env_conditional));
    }
    const std::vector<dev::uint>& first_light = x.lights->instance_light;
    arrays.push_back(convert_array(bvh.instances.size(), d.instances, [&](std::size_t i) {
      dev::BvhInstance inst = bvh.instances[i];
      inst.meta.y = i < first_light.size() ? first_light[i] : WP_NO_LIGHT;
      return inst;
    }));
    arrays.push_back(copy_array(bvh.instance_refs, d.instance_refs));
  }
  return arrays;
}

// The SceneDesc's fields that are not array offsets: camera, background, environment, counts.
void describe_scene(const Scene& scene, const SceneExtras& x, dev::SceneDesc& d) {
  d.camera = x.camera;
  d.background = f4(x.background);
  const float rotation = x.env_rotation_degrees * 3.14159265358979f / 180.0f;
  d.env_params = {x.env_intensity, std::cos(rotation), std::sin(rotation), 0.0f};
  d.light_count = static_cast<dev::uint>(x.lights->lights.size());
  d.env_light = x.lights->env_light;
  d.triangle_count = static_cast<dev::uint>(scene.triangle_count());
  if (x.env) {
    d.env_width = static_cast<dev::uint>(x.env->width);
    d.env_height = static_cast<dev::uint>(x.env->height);
  }
}

// pack_scene, freeing what `owned` names as it goes.
PackedScene pack(const Scene& scene, const bvh::Bvh& bvh, const SceneExtras& x,
                 std::uint64_t max_buffer, Owned owned) {
  DeviceMaterials materials = device_materials(scene, x.mipmaps);
  if (owned.scene)
    for (Image& image : owned.scene->images) free_vector(image.rgba);
  PackedScene p;
  p.texel_bytes = materials.texels.size() * kTexelBytes;
  std::uint64_t level0 = 0;
  for (const dev::TextureImage& image : materials.images)
    level0 += std::uint64_t(image.width) * image.height * kTexelBytes;
  p.mip_bytes = p.texel_bytes - level0;
  describe_scene(scene, x, p.desc);  // before the arrays it counts may be freed
  const std::vector<SceneArray> arrays = scene_arrays(scene, bvh, x, materials, p.desc, owned);
  std::vector<std::uint64_t> sizes;
  for (const SceneArray& a : arrays) sizes.push_back(a.bytes());
  const SceneLayout layout = plan_scene_layout(sizes, max_buffer);
  // The buffers' bytes are not initialised (PageAligned): each is written once, array by array
  // with the gaps between them zeroed, so that a page is resident only once it is filled.
  p.buffers.resize(layout.buffer_bytes.size());
  std::vector<std::uint64_t> filled(p.buffers.size(), 0);
  for (std::size_t i = 0; i < p.buffers.size(); ++i) p.buffers[i].resize(layout.buffer_bytes[i]);
  for (std::size_t i = 0; i < arrays.size(); ++i) {
    const SceneLayout::Place place = layout.places[i];
    unsigned char* const buffer = p.buffers[place.buffer].data();
    std::uint64_t& end = filled[static_cast<std::size_t>(place.buffer)];
    std::memset(buffer + end, 0, place.offset - end);
    write_array(arrays[i], buffer + place.offset);
    end = place.offset + arrays[i].bytes();
    *arrays[i].offset = static_cast<dev::uint>(place.offset / WP_SCENE_ALIGN);
  }
  for (std::size_t b = 0; b < p.buffers.size(); ++b)
    std::memset(p.buffers[b].data() + filled[b], 0, p.buffers[b].size() - filled[b]);
  p.buffer_map = layout.buffer_map();
  return p;
}

}  // namespace

PackedScene pack_scene(const Scene& scene, const bvh::Bvh& bvh, const SceneExtras& x,
                       std::uint64_t max_buffer) {
  return pack(scene, bvh, x, max_buffer, Owned{});
}

PackedScene pack_scene(Scene& scene, bvh::Bvh& bvh, const SceneExtras& x, std::uint64_t max_buffer,
                       HostArrays host) {
  return pack(scene, bvh, x, max_buffer,
              host == HostArrays::kRelease ? Owned{&scene, &bvh} : Owned{});
}

std::uint64_t SceneLayout::buffer_map() const {
  std::uint64_t map = 0;
  for (std::size_t i = 0; i < places.size(); ++i)
    map |= std::uint64_t(places[i].buffer) << (WP_SCENE_BUFFER_BITS * i);
  return map;
}

std::uint64_t SceneLayout::total_bytes() const {
  std::uint64_t total = 0;
  for (const std::uint64_t b : buffer_bytes) total += b;
  return total;
}

SceneLayout plan_scene_layout(const std::vector<std::uint64_t>& sizes, std::uint64_t max_buffer) {
  max_buffer = std::min(max_buffer, kSceneBufferReach);
  std::uint64_t total = 0;
  for (const std::uint64_t size : sizes) total += padded(size);
  SceneLayout layout;
  layout.sizes = sizes;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    const std::uint64_t size = padded(sizes[i]);
    if (size > max_buffer)
      throw Error("scene too large for the device: its " + std::string(kArrayNames.at(i)) +
                  " array needs " + human_bytes(size) +
                  ", more than the device's largest buffer (" + human_bytes(max_buffer) + ")");
    if (layout.buffer_bytes.empty() || aligned(layout.buffer_bytes.back()) + size > max_buffer)
      layout.buffer_bytes.push_back(0);
    if (layout.buffer_bytes.size() > WP_SCENE_BUFFERS)
      throw Error("scene too large for the device: " + human_bytes(total) + " does not fit in " +
                  std::to_string(WP_SCENE_BUFFERS) + " buffers of at most " +
                  human_bytes(max_buffer) + " (the device's largest buffer)");
    const std::uint64_t offset = aligned(layout.buffer_bytes.back());
    layout.places.push_back({static_cast<int>(layout.buffer_bytes.size() - 1), offset});
    layout.buffer_bytes.back() = offset + size;
  }
  return layout;
}

std::string human_bytes(std::uint64_t bytes) {
  char text[48];
  if (bytes >= (1ull << 30))
    std::snprintf(text, sizeof(text), "%.2f GiB", double(bytes) / double(1ull << 30));
  else if (bytes >= (1ull << 20))
    std::snprintf(text, sizeof(text), "%.1f MiB", double(bytes) / double(1ull << 20));
  else
    std::snprintf(text, sizeof(text), "%llu bytes", static_cast<unsigned long long>(bytes));
  return text;
}

const char* scene_array_name(std::size_t index) {
  return kArrayNames.at(index);
}

SceneCounts scene_counts(const Scene& scene, const EnvironmentMap* env, bool mipmaps) {
  SceneCounts c;
  c.triangles = scene.triangle_count();
  c.vertices = scene.positions.size();
  c.materials = scene.materials.size();
  c.textures = scene.textures.size();
  c.images = scene.images.size();
  const ImageUses uses = image_uses(scene, mipmaps);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    const Image& img = scene.images[i];
    for (int k = 0; k < packed_levels(img, uses, i); ++k)
      c.texels += std::uint64_t(mip_size(img.width, k)) * std::uint64_t(mip_size(img.height, k));
  }
  c.lights = scene.lights.size();
  c.instances = scene.instances.size();
  if (env) {
    c.env_texels = env->texels.size();
    c.env_marginal = env->marginal.size();
    c.env_conditional = env->conditional.size();
  }
  return c;
}

BvhBytes bvh_bytes(const bvh::Bvh& b) {
  if (b.width == WP_BVH8_WIDTH)
    return {b.nodes8.size() * sizeof(dev::BvhNode8), b.blocks.size() * sizeof(dev::TriBlock4),
            b.instance_refs.size() * sizeof(std::uint32_t)};
  return {b.nodes.size() * sizeof(dev::BvhNode), b.triangles.size() * sizeof(dev::IsectTri),
          b.instance_refs.size() * sizeof(std::uint32_t)};
}

BvhBytes min_bvh_bytes(std::uint64_t triangles, int width) {
  // n inner nodes of at most `fan_out` children have fan_out * n child slots, which hold the n - 1
  // non-root nodes and every leaf: n >= (leaves - 1) / (fan_out - 1).
  const auto min_nodes = [](std::uint64_t leaves, std::uint64_t fan_out) {
    return std::max<std::uint64_t>(1, ceil_div(leaves > 0 ? leaves - 1 : 0, fan_out - 1));
  };
  if (width == WP_BVH8_WIDTH) {
    const std::uint64_t blocks = ceil_div(triangles, 4);
    const std::uint64_t leaves = ceil_div(blocks, WP_BVH8_MAX_LEAF_BLOCKS);
    return {min_nodes(leaves, WP_BVH8_WIDTH) * sizeof(dev::BvhNode8),
            blocks * sizeof(dev::TriBlock4)};
  }
  const std::uint64_t leaves = ceil_div(triangles, WP_BVH_MAX_LEAF_SIZE);
  return {min_nodes(leaves, 2) * sizeof(dev::BvhNode), triangles * sizeof(dev::IsectTri)};
}

SceneLayout scene_layout(const SceneCounts& c, const BvhBytes& bvh, std::uint64_t max_buffer) {
  if (c.texels > 0xffffffffu) throw Error(too_many_texels());
  const auto optional = [&](bool packed) { return packed ? c.vertices * sizeof(dev::float4) : 0; };
  // pack_scene's arrays in its order.
  std::vector<std::uint64_t> sizes = {bvh.nodes,
                                      bvh.primitives,
                                      c.triangles * sizeof(dev::uint4),  // tri_vertices
                                      c.vertices * sizeof(dev::float4),  // positions
                                      c.vertices * sizeof(dev::float4),  // normals
                                      optional(c.vertex_arrays.tangents),
                                      optional(c.vertex_arrays.uvs),
                                      optional(c.vertex_arrays.colors),
                                      c.materials * sizeof(dev::Material),
                                      c.textures * sizeof(dev::TextureRef),
                                      c.images * sizeof(dev::TextureImage),
                                      c.texels * kTexelBytes,
                                      c.lights * sizeof(dev::Light),
                                      c.lights * sizeof(dev::LightAlias),
                                      c.triangles * sizeof(std::uint32_t)};  // tri_light
  if (c.env_texels || c.env_marginal || c.env_conditional || c.instances) {
    sizes.push_back(c.env_texels * sizeof(glm::vec4));
    sizes.push_back(c.env_marginal * sizeof(float));
    sizes.push_back(c.env_conditional * sizeof(float));
  }
  if (c.instances) {
    sizes.push_back(c.instances * sizeof(dev::BvhInstance));
    sizes.push_back(bvh.instance_refs);
  }
  return plan_scene_layout(sizes, max_buffer);
}

}  // namespace wp
