// The host's scene: flat world-space arrays, everything the renderer needs and nothing of glTF's
// structure. Produced by the glTF loader (gltf_loader.h), consumed by the BVH builder and the
// device upload.
//
// Units and conventions (fixed for the whole project):
// - Lengths are in scene units (glTF: metres); the renderer never assumes a scale.
// - Colours are linear RGB. Emission is radiance: emissiveFactor x emissive_strength.
// - A point/spot light's intensity (glTF candela) is read as radiant intensity in W/sr of the
//   linear RGB image, no 683 lm/W factor: it gives irradiance I cos(theta) / d^2 at distance d.
//   A directional light's intensity (glTF lux) is irradiance in W/m^2 on a surface facing it.
// - Triangles wind counter-clockwise seen from their front (glTF); the loader keeps that true under
//   mirroring transforms (negative determinant).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace wp {

// What float32 carries through the transport (README, "Limits"); the loaders clamp larger values
// with a warning. A sample's radiance is emitted radiance times a path's throughput and each
// bounce's BSDF x cosine / pdf, which for sharp lobes and small, distant lights reach far above 1;
// renders of extreme scenes (tests/test_cli_edges.cpp) stay finite with emission up to 2^110 or
// so and give NaN/Inf samples from about 2^120 on (float32 ends at 2^128). Radiance at most
// 2^64 leaves those factors 2^56 to 2^64; the film saturates a sample at 2^32 anyway
// (kernels/shared/film.h), so only light that is dimmed on its way by that much more is lost.
// The limit binds emission (emissiveFactor x emissive strength), punctual lights' colour x
// intensity, environment texels and --env-intensity x the brightest texel, --env-color.
constexpr double kMaxRadiance = 18446744073709551616.0;  // 2^64
// An index of refraction: the kernels form eta^2 (radiance across an interface) and Fresnel's
// ((eta - 1) / (eta + 1))^2, which at 1e39 (beyond float32) gives inf and NaN; at most 2^16 keeps
// eta^2 x radiance within 2^96. (No material comes near: diamond 2.42.)
// The kernels clamp the indices they derive (dispersion's per wavelength) to the same limit,
// kernels/shared/types.h's WP_MAX_IOR.
constexpr double kMaxIor = 65536.0;  // 2^16
// KHR_materials_dispersion's dispersion, 20 / the Abbe number V (glasses: V 20-90, dispersion
// 0.2-1): at most 2^16 keeps the kernels' (ior - 1) x dispersion / 20 within float32 (ior <= 2^16),
// the index it gives being clamped to kMaxIor per wavelength; 1e30 made NaN samples.
constexpr double kMaxDispersion = 65536.0;  // 2^16

enum class AlphaMode : std::uint8_t { kOpaque, kMask, kBlend };

enum class Wrap : std::uint8_t { kRepeat, kClampToEdge, kMirroredRepeat };

// A decoded image, 8-bit RGBA, row by row from the top (uv (0,0) is the top-left corner).
struct Image {
  std::string name;
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // 4 x width x height
};

// A material's use of an image: glTF textureInfo + sampler + KHR_texture_transform.
struct TextureRef {
  int image = -1;  // index into Scene::images
  Wrap wrap_s = Wrap::kRepeat, wrap_t = Wrap::kRepeat;
  bool nearest = false;  // magFilter NEAREST; otherwise bilinear
  bool srgb = false;     // colour data (base colour, emissive): decode sRGB to linear
  int texcoord = 0;      // TEXCOORD_0 or TEXCOORD_1
  // KHR_texture_transform as a 2x3 matrix: (u', v') = (row_u . (u, v, 1), row_v . (u, v, 1)).
  glm::vec3 row_u{1.0f, 0.0f, 0.0f}, row_v{0.0f, 1.0f, 0.0f};
  // minFilter a mip-map mode or unset: minified through its mip chain (host/scene/mipmap.h);
  // minFilter NEAREST or LINEAR ask for none, and get full resolution always.
  bool mipmaps = true;
};

struct Material {
  std::string name;
  glm::vec4 base_color{1.0f};  // baseColorFactor, linear RGB + alpha
  float metallic = 1.0f;       // glTF defaults
  float roughness = 1.0f;
  glm::vec3 emission{0.0f};  // radiance: emissiveFactor x KHR_materials_emissive_strength
  bool double_sided = false;
  AlphaMode alpha_mode = AlphaMode::kOpaque;
  float alpha_cutoff = 0.5f;
  float ior = 1.5f;           // KHR_materials_ior
  float transmission = 0.0f;  // KHR_materials_transmission factor
  bool unlit = false;         // KHR_materials_unlit
  float specular = 1.0f;      // KHR_materials_specular specularFactor (0: a pure Lambertian)
  // KHR_materials_volume: with thickness > 0 the surface bounds a volume (refraction bends rays,
  // the inside absorbs); without it a transmissive surface is thin-walled.
  float thickness = 0.0f;
  glm::vec3 attenuation_color{1.0f};
  float attenuation_distance = 0.0f;  // 0: infinite (no absorption)
  float normal_scale = 1.0f;
  // Indices into Scene::textures, -1 for none.
  int base_color_texture = -1;
  int metallic_roughness_texture = -1;  // G: roughness, B: metallic
  int normal_texture = -1;
  int emissive_texture = -1;
  int transmission_texture = -1;  // R: transmission
  // KHR_materials_specular: colour on the dielectric F0 (clamped to 1), strength on F0 and F90.
  glm::vec3 specular_color{1.0f};
  int specular_texture = -1;        // A: specular (x specular)
  int specular_color_texture = -1;  // RGB (sRGB): specular colour
  // KHR_materials_clearcoat: a GGX dielectric coat (ior 1.5) over everything.
  float clearcoat = 0.0f;
  float clearcoat_roughness = 0.0f;
  float clearcoat_normal_scale = 1.0f;
  int clearcoat_texture = -1;            // R
  int clearcoat_roughness_texture = -1;  // G
  int clearcoat_normal_texture = -1;     // tangent-space normal of the coat
  // KHR_materials_sheen: Charlie sheen over the base.
  glm::vec3 sheen_color{0.0f};
  float sheen_roughness = 0.0f;
  int sheen_color_texture = -1;      // RGB (sRGB)
  int sheen_roughness_texture = -1;  // A
  // KHR_materials_anisotropy: strength in [0, 1], rotation (radians) of the direction from the
  // tangent toward the bitangent.
  float anisotropy_strength = 0.0f;
  float anisotropy_rotation = 0.0f;
  int anisotropy_texture = -1;  // RG: direction (x 2 - 1), B: strength
  // KHR_materials_iridescence: thin-film interference on the specular lobes.
  float iridescence = 0.0f;
  float iridescence_ior = 1.3f;
  float iridescence_thickness_min = 100.0f;  // nanometres
  float iridescence_thickness_max = 400.0f;
  int iridescence_texture = -1;            // R
  int iridescence_thickness_texture = -1;  // G: mix of minimum and maximum
  // KHR_materials_dispersion: 20 / Abbe number (0: none); used with KHR_materials_volume.
  float dispersion = 0.0f;
  // KHR_materials_diffuse_transmission: a Lambertian transmission lobe.
  float diffuse_transmission = 0.0f;
  glm::vec3 diffuse_transmission_color{1.0f};
  int diffuse_transmission_texture = -1;        // A
  int diffuse_transmission_color_texture = -1;  // RGB (sRGB)
};

enum class LightType : std::uint8_t { kPoint, kSpot, kDirectional };

struct PunctualLight {
  std::string name;
  LightType type = LightType::kPoint;
  glm::vec3 position{0.0f};                // world space (point, spot)
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // unit, the direction light travels (spot, directional)
  glm::vec3 intensity{1.0f};  // colour x intensity: W/sr (point, spot) or W/m^2 (directional)
  float range = 0.0f;         // 0: infinite
  float inner_cone = 0.0f;    // radians (spot)
  float outer_cone = 0.7853981633974483f;  // radians (spot), glTF default pi/4
};

enum class CameraType : std::uint8_t { kPerspective, kOrthographic };

struct Camera {
  std::string name;
  CameraType type = CameraType::kPerspective;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit view direction (the node's -Z)
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward (the node's +Y)
  float yfov = 0.8f;                     // perspective: vertical field of view, radians
  float xmag = 1.0f;                     // orthographic: half width of the view, scene units
  float ymag = 1.0f;                     // orthographic: half height
  float znear = 0.0f;  // distance to the near plane along forward; nothing closer is seen
  // Thin lens (perspective only; view.h): rays start on a disc of this radius about `position`,
  // perpendicular to forward, and meet where the pinhole ray through the same image point meets
  // the plane focus_distance along forward. 0: a pinhole.
  float lens_radius = 0.0f;
  float focus_distance = 1.0f;
};

// What the glTF file holds beyond the scene's flat arrays, for reports (`wavepath info`). Filled
// by the loader.
struct GltfSummary {
  std::vector<std::string> extensions_used, extensions_required;  // as the file lists them
  std::size_t meshes = 0;                                         // glTF meshes in the file
  std::size_t meshes_placed = 0;  // distinct meshes the default scene's nodes place
  // Nodes of the default scene with a mesh: each places a copy of its mesh's triangles.
  std::size_t mesh_nodes = 0;
  // EXT_mesh_gpu_instancing: the nodes of mesh_nodes that have it and their instances in all (such
  // a node places a copy of its mesh per instance, and none where it has no instance).
  std::size_t gpu_instanced_nodes = 0, gpu_instances = 0;
  std::size_t images = 0, textures = 0;  // in the file (Scene::images: those materials use)
  std::size_t materials = 0;  // in the file (Scene::materials adds glTF's default one if used)
};

// One mesh of an instanced scene: triangles [first_triangle, first_triangle + triangle_count).
struct MeshRange {
  std::uint32_t first_triangle = 0, triangle_count = 0;
};

// One placement of a mesh in an instanced scene.
struct Instance {
  glm::dmat4 to_world{1.0};  // object to world: the node's world transform (x the GPU instance's)
  std::uint32_t mesh = 0;    // index into Scene::meshes
};

struct Scene {
  std::string source;  // file the scene came from
  // FNV-1a 64 (fnv1a.h) of the bytes the scene was loaded from: the glTF or GLB file, then the
  // external buffers and images it names, in file order. Part of the render key (render.h): it
  // tells films of different scenes apart. 0 for scenes not loaded from a file. A selected
  // material variant (LoadOptions::variant) is hashed in after them: two variants of one file
  // are two scenes.
  std::uint64_t digest = 0;
  // KHR_materials_variants: the file's variant names, in file order, and the one selected
  // ("": none, the file's own materials).
  std::vector<std::string> variants;
  std::string variant;

  // Vertices (world space). normals are unit; uv0 is TEXCOORD_0 or (0,0); color0 is COLOR_0 as
  // linear RGBA or (1,1,1,1). uv0, uv1, color0 and tangents are each either as long as positions
  // or empty, which reads as their default everywhere (the loader keeps uv0 and color0 only for
  // files that have the attribute, uv1 and tangents only where a material needs them).
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uv0;
  std::vector<glm::vec2> uv1;  // TEXCOORD_1 or (0,0)
  std::vector<glm::vec4> color0;
  std::vector<glm::vec4> tangents;  // xyz unit, w handedness; supplied or generated; may be empty

  // Triangles: three vertex indices each (counter-clockwise front), and a material index.
  std::vector<std::uint32_t> indices;            // 3 x triangle_count()
  std::vector<std::uint32_t> triangle_material;  // triangle_count()

  // Instancing. Empty `instances`: the arrays above are the world, every placement of a mesh a
  // copy in world space. Otherwise (LoadOptions::instancing) they hold each placed mesh once, in
  // its own space, mesh i being the triangles of meshes[i], and the world is every instance's
  // mesh placed by its transform (rendered through a two-level BVH: bvh.h, build_two_level).
  // Either way a triangle's material and winding are the file's.
  std::vector<MeshRange> meshes;
  std::vector<Instance> instances;

  std::vector<Material> materials;  // never empty: the loader adds glTF's default material if used
  std::vector<Image> images;
  std::vector<TextureRef> textures;
  std::vector<PunctualLight> lights;
  std::vector<Camera> cameras;  // in node order (depth-first over the default scene)

  glm::vec3 bounds_lo{0.0f}, bounds_hi{0.0f};

  std::vector<std::string> warnings;  // one line each: skipped primitives, unsupported extensions
  GltfSummary gltf;

  std::size_t triangle_count() const { return indices.size() / 3; }
  // Triangles in the world: triangle_count(), or each instance's mesh's count summed.
  std::uint64_t world_triangle_count() const;
};

inline std::uint64_t Scene::world_triangle_count() const {
  if (instances.empty()) return triangle_count();
  std::uint64_t n = 0;
  for (const Instance& i : instances) n += meshes[i.mesh].triangle_count;
  return n;
}

}  // namespace wp
