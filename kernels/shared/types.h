/* Plain-old-data shared by the host and the kernels: scene records, the launch parameters and the
 * layouts of the two big device buffers (scene and path state). See compat.h for the rules.
 *
 * Every kernel takes the same first arguments: the scene buffers with their SceneDesc (where each
 * array is), the path-state buffer with its PathLayout, the queue buffers and a Launch. Adding a
 * scene array or a path field therefore changes no kernel signature.
 */
#ifndef WP_SHARED_TYPES_H
#define WP_SHARED_TYPES_H

#include "compat.h"
#include "bvh_layout.h"

/* Material flags (Material.flags.x). */
#define WP_MAT_DOUBLE_SIDED 1u
#define WP_MAT_ALPHA_MASK 2u  /* alphaMode MASK: a cutout at alpha_cutoff */
#define WP_MAT_ALPHA_BLEND 4u /* alphaMode BLEND: present with probability alpha */
#define WP_MAT_UNLIT 8u       /* KHR_materials_unlit: shows its base colour, scatters nothing */
#define WP_MAT_VOLUME                                                        \
  16u /* KHR_materials_volume (thickness > 0): refraction, absorption inside \
       */

/* Texture wrap modes (TextureRef.meta.y, 8 bits each for S and T). */
/* The largest index of refraction the transport carries (host/scene/scene.h, kMaxIor): the
 * loader clamps the files' indices to it, and the kernels the indices they derive (dispersion). */
#define WP_MAX_IOR 65536.0f

#define WP_WRAP_REPEAT 0u
#define WP_WRAP_CLAMP 1u
#define WP_WRAP_MIRROR 2u
#define WP_TEX_NEAREST (1u << 16) /* magnification filter NEAREST (else bilinear) */
#define WP_TEX_SRGB (1u << 17)    /* texels are sRGB-encoded colour: decode to linear */

/* Light types (Light.meta.x). */
#define WP_LIGHT_POINT 0u
#define WP_LIGHT_SPOT 1u
#define WP_LIGHT_DIRECTIONAL 2u
#define WP_LIGHT_TRIANGLE 3u    /* an emissive triangle (area light) */
#define WP_LIGHT_ENVIRONMENT 4u /* the environment map or the constant background */
#define WP_NO_LIGHT 0xffffffffu

/* Camera types (Camera.meta.x). */
#define WP_CAMERA_PERSPECTIVE 0u
#define WP_CAMERA_ORTHOGRAPHIC 1u

/* Path flags (path_flags in the path state). */
#define WP_PATH_DELTA 1u         /* the last scattering event was a delta (specular) lobe */
#define WP_PATH_CHANNEL_SHIFT 1u /* bits 1-2: the colour channel a dispersive refraction chose */
#define WP_PATH_CHANNEL_MASK 6u  /* (1 R, 2 G, 3 B; 0: all three), kernels/bsdf/bsdf.h */

/* Queues: index arrays of path slots with an atomic counter each (integrator/queues.h). */
#define WP_QUEUE_RAY_A 0u /* rays to trace; A and B swap roles every bounce */
#define WP_QUEUE_RAY_B 1u
#define WP_QUEUE_SURFACE 2u /* paths whose ray hit a surface this bounce */
#define WP_QUEUE_SHADOW 3u  /* paths with a pending shadow ray */
#define WP_QUEUE_COUNT 4u
/* Counters after the queue counters. */
#define WP_COUNTER_NONFINITE                                         \
  4u /* NaN/Inf values dropped anywhere (must stay 0): film samples, \
        path throughputs, light-sample contributions */
#define WP_COUNTER_COUNT 5u

WP_DEV_BEGIN

typedef struct Material {
  float4 base_color; /* linear RGB factor; a: alpha factor */
  float4 emission;  /* radiance factor (rgb): emissiveFactor x emissive strength; w: alpha cutoff */
  float4 params;    /* x: metallic, y: roughness, z: ior, w: transmission */
  float4 volume;    /* rgb: attenuation colour; w: attenuation distance (INFINITY: no absorption) */
  float4 extra;     /* x: normal texture scale, y: thickness factor, z: unused, w: dispersion
                       (KHR_materials_dispersion, 20 / Abbe number; 0: none) */
  uint4 flags;      /* x: WP_MAT_* flags; y, z, w: unused */
  int4 textures0;   /* TextureRef indices (-1: none): x base colour, y metallic-roughness,
                       z normal, w emissive */
  int4 textures1;   /* x: transmission (R), y: specular (A), z: specular colour (RGB),
                       w: clearcoat (R) */
  int4 textures2;   /* x: clearcoat roughness (G), y: clearcoat normal, z: sheen colour (RGB),
                       w: sheen roughness (A) */
  int4 textures3;   /* x: anisotropy (RG direction, B strength), y: iridescence (R),
                       z: iridescence thickness (G), w: diffuse transmission (A) */
  int4 textures4;   /* x: diffuse transmission colour (RGB); y, z, w: -1 (reserved) */
  float4 specular;  /* KHR_materials_specular: rgb specularColorFactor, w specularFactor */
  float4 clearcoat; /* KHR_materials_clearcoat: x factor, y roughness, z normal texture scale;
                       w: unused */
  float4 sheen;     /* KHR_materials_sheen: rgb sheenColorFactor, w sheenRoughnessFactor */
  float4 anisotropy;  /* KHR_materials_anisotropy: x strength, y cos, z sin of the rotation;
                         w: unused */
  float4 iridescence; /* KHR_materials_iridescence: x factor, y ior, z thickness minimum,
                         w thickness maximum (nanometres) */
  float4 diffuse_transmission; /* KHR_materials_diffuse_transmission: rgb colour, w factor */
} Material;

/* A material's use of a texture: glTF textureInfo + sampler + KHR_texture_transform. */
typedef struct TextureRef {
  float4 transform_u; /* u' = x u + y v + z */
  float4 transform_v; /* v' = x u + y v + z */
  uint4 meta; /* x: TextureImage index; y: wrap S (bits 0-7) | wrap T (bits 8-15) | WP_TEX_* flags;
                 z: texture coordinate set (0 or 1); w: the bits of a float, the texture's term
                 of its mip level, 1/2 log2(width x height x |det| of the transform's 2 x 2 part)
                 (kernels/texture/ray_cone.h), or -INFINITY: no mip-maps (level 0 always) */
} TextureRef;

/* A decoded image: width x height texels, row by row from the top (glTF's uv (0,0) is the
 * top-left corner), each a uint of RGBA8 with R in the lowest byte, starting at `offset` in the
 * texel array; then its mip levels 1 .. levels - 1, each right after the one before, each half
 * the size of the one before, rounding down (host/device/mipmap.h; levels = 1: none). */
typedef struct TextureImage {
  uint offset, width, height, levels;
} TextureImage;

/* Everything next-event estimation can choose. */
typedef struct Light {
  float4 position;  /* point, spot: xyz world position, w: range (0: infinite) */
  float4 direction; /* spot, directional: unit direction the light travels */
  float4 intensity; /* point, spot: W/sr; directional: W/m^2 (rgb). Triangles and the environment
                       take their radiance from the material and the map. */
  float4 spot;      /* spot: x angle scale, y angle offset (KHR_lights_punctual falloff) */
  uint4 meta;       /* x: WP_LIGHT_* type; y: scene triangle index (WP_LIGHT_TRIANGLE); z: its
                       instance in a two-level BVH (bvh_layout.h), else WP_NO_INSTANCE */
} Light;

/* One entry of the alias table that picks a light: keep `index` with probability `prob`, else
 * take `alias`; `pmf` is the probability that light `index` is picked in all. */
typedef struct LightAlias {
  float prob;
  uint alias;
  float pmf;
  uint pad;
} LightAlias;

typedef struct Camera {
  float4 position; /* xyz: eye; w: znear (distance along forward) */
  float4 forward;  /* xyz: unit view direction */
  float4 right;    /* xyz: image +x at the edge of the image (NDC x = 1), see camera.h */
  float4 up;       /* xyz: image +y at the edge of the image (NDC y = 1) */
  float4 lens;     /* x: thin-lens radius (0: a pinhole); y: focus distance along forward */
  uint4 meta;      /* x: WP_CAMERA_* type */
} Camera;

/* The scene's arrays lie in up to WP_SCENE_BUFFERS device buffers, each no larger than the
 * device's largest allocation (host/device/device_scene.h). Which buffer holds an array is fixed
 * when the program is built: WP_SCENE_BUFFER_MAP (kernels/geom/scene.h), WP_SCENE_BUFFER_BITS per
 * array in SceneDesc's order, so every scene pointer is one kernel argument plus an offset (a
 * buffer index known only at run time made every kernel slower on PoCL). The offset of each array
 * in its buffer is in SceneDesc, in units of WP_SCENE_ALIGN bytes: a uint reaches 256 GiB. */
#define WP_SCENE_BUFFERS 8
#define WP_SCENE_BUFFER_BITS 3
#define WP_SCENE_ALIGN 64

/* Where each scene array starts in its buffer (64-byte units, above), and how many some hold. */
typedef struct SceneDesc {
  Camera camera;
  float4 background; /* constant radiance of escaped rays (rgb) when there is no map */
  float4 env_params; /* x: intensity scale, y: cos, z: sin of the rotation about +Y; w: unused */
  uint bvh_nodes;    /* BvhNode[] */
  uint isect_tris;   /* IsectTri[] */
  uint tri_vertices; /* uint4[]: x, y, z vertex indices, w material index, per scene triangle */
  uint positions;    /* float4[] per vertex: xyz */
  uint normals;      /* float4[] per vertex: xyz unit */
  uint tangents;     /* float4[] per vertex: xyz unit tangent, w handedness (+-1) */
  uint uvs;          /* float4[] per vertex: xy TEXCOORD_0, zw TEXCOORD_1 */
  uint colors;       /* float4[] per vertex: COLOR_0 (linear rgba) */
  uint materials;    /* Material[] */
  uint textures;     /* TextureRef[] */
  uint images;       /* TextureImage[] */
  uint texels;       /* uint[] RGBA8 */
  uint lights;       /* Light[] */
  uint light_alias;  /* LightAlias[light_count] */
  uint tri_light;    /* uint[] per scene triangle: its index in lights[], or WP_NO_LIGHT; in an
                       instanced scene its index among its mesh's emissive triangles, the light
                       being that plus the instance's first (BvhInstance.meta.y) */
  uint env_texels;   /* float4[] env_width x env_height, linear RGB radiance, rows from +Y down */
  uint env_marginal; /* environment sampling tables (kernels/lights/environment.h) */
  uint env_conditional;
  uint env_width, env_height;
  uint light_count;
  uint env_light; /* index of the WP_LIGHT_ENVIRONMENT light, or WP_NO_LIGHT */
  uint triangle_count;
  /* Two-level BVHs only (bvh_layout.h; arrays after the environment's, which are then always
   * there, maybe empty): */
  uint instances;     /* BvhInstance[] */
  uint instance_refs; /* uint[]: the top-level tree's leaves, indices into instances[] */
  uint pad0;
} SceneDesc;

/* Byte offset of every path-state field in the path buffer, and the number of path slots. */
typedef struct PathLayout {
#define WP_PATH_FIELD(type, name, description) uint name;
#include "path_state.def"
#undef WP_PATH_FIELD
  uint capacity;
} PathLayout;

/* Per-launch parameters, passed by value to every stage kernel. */
typedef struct Launch {
  uint width, height; /* image size in pixels */
  uint pixel_offset;  /* first pixel of this wave (pixels are numbered row by row) */
  uint path_count;    /* paths in this wave (<= the path capacity): wave_pixels x its samples */
  uint sample;        /* the wave's first sample index (0..spp-1) */
  uint seed;          /* user seed */
  uint max_depth;     /* paths end after this many scattering events */
  uint rr_depth;      /* Russian roulette from this bounce on; >= max_depth: never */
  uint queue_in;      /* WP_QUEUE_* the stage reads */
  uint queue_out;     /* WP_QUEUE_* the stage appends to */
  uint wave_pixels; /* pixels in this wave: path slot i renders pixel pixel_offset + i % wave_pixels
                       at sample index sample + i / wave_pixels (stage.h, path_sample) */
  float rr_threshold; /* roulette ends paths whose throughput is below this (roulette_compact.h) */
  uint packet;        /* intersect_closest's rays per work-item: 1, or WP_PACKET where the program
                         has WP_CLOSEST_PACKET (traverse8_packet.h) */
  uint shadow_packet; /* trace_shadow's: 1, or WP_PACKET where the program has WP_SHADOW_PACKET */
  uint shadow_first;  /* trace_shadow's first queue entry: 0, or where an earlier launch of the
                         bounce stopped (Wavefront::run_bounce) */
  uint strategy;      /* WP_STRATEGY_*: the direct light counted (mis.h), a launch parameter so
                         that one program renders every strategy */
} Launch;

WP_DEV_END

#endif /* WP_SHARED_TYPES_H */
