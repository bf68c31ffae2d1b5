/* Plain-old-data shared by the host and the kernels: scene records, the launch parameters and the
 * layouts of the two big device buffers (scene and path state). See compat.h for the rules.
 *
 * Every kernel takes the same first arguments: the scene buffer with its SceneDesc (byte offsets
 * of each array in it), the path-state buffer with its PathLayout, the queue buffers and a Launch.
 * Adding a scene array or a path field therefore changes no kernel signature.
 */
#ifndef WP_SHARED_TYPES_H
#define WP_SHARED_TYPES_H

#include "compat.h"
#include "bvh_layout.h"

/* Material flags (Material.flags.x). */
#define WP_MAT_DOUBLE_SIDED 1u

/* Punctual light types (PunctualLight.meta.x). */
#define WP_LIGHT_POINT 0u
#define WP_LIGHT_SPOT 1u
#define WP_LIGHT_DIRECTIONAL 2u

/* Camera types (Camera.meta.x). */
#define WP_CAMERA_PERSPECTIVE 0u
#define WP_CAMERA_ORTHOGRAPHIC 1u

/* Path flags (info.z in the path state). */
#define WP_PATH_DELTA 1u /* the last scattering event was a delta (specular) lobe */

/* Queues: index arrays of path slots with an atomic counter each (see kernels/queues.h). */
#define WP_QUEUE_RAY_A 0u /* rays to trace; A and B swap roles every bounce */
#define WP_QUEUE_RAY_B 1u
#define WP_QUEUE_SURFACE 2u /* paths whose ray hit a surface this bounce */
#define WP_QUEUE_SHADOW 3u  /* paths with a pending shadow ray */
#define WP_QUEUE_COUNT 4u
/* Counters after the queue counters. */
#define WP_COUNTER_NONFINITE 4u /* samples the film rejected as NaN/Inf (must stay 0) */
#define WP_COUNTER_COUNT 5u

WP_DEV_BEGIN

typedef struct Material {
  float4 base_color; /* linear RGB; a: alpha */
  float4 emission;   /* radiance (rgb); w: unused */
  float4 params;     /* x: metallic, y: roughness, z: ior, w: transmission */
  uint4 flags;       /* x: WP_MAT_* flags; y, z, w: reserved (texture references) */
} Material;

typedef struct PunctualLight {
  float4 position;  /* xyz: world position (point, spot); w: range (0: infinite) */
  float4 direction; /* xyz: unit direction the light travels (spot, directional); w: unused */
  float4 intensity; /* rgb: W/sr (point, spot) or W/m^2 (directional); w: unused */
  float4 spot;      /* x: angle scale, y: angle offset (KHR_lights_punctual recommended falloff) */
  uint4 meta;       /* x: WP_LIGHT_* type */
} PunctualLight;

typedef struct Camera {
  float4 position; /* xyz: eye; w: znear (distance along forward) */
  float4 forward;  /* xyz: unit view direction */
  float4 right;    /* xyz: image +x at the edge of the image (NDC x = 1), see camera.h */
  float4 up;       /* xyz: image +y at the edge of the image (NDC y = 1) */
  uint4 meta;      /* x: WP_CAMERA_* type */
} Camera;

/* Where each scene array starts in the scene buffer (bytes, 64-aligned), and how many it holds. */
typedef struct SceneDesc {
  Camera camera;
  float4 background; /* constant radiance of escaped rays (rgb) */
  uint bvh_nodes;    /* BvhNode[] */
  uint isect_tris;   /* IsectTri[] */
  uint tri_vertices; /* uint4[]: x, y, z vertex indices, w material index, per scene triangle */
  uint positions;    /* float4[] per vertex: xyz */
  uint normals;      /* float4[] per vertex: xyz unit */
  uint uvs;          /* float4[] per vertex: xy TEXCOORD_0 */
  uint colors;       /* float4[] per vertex: COLOR_0 (linear rgba) */
  uint materials;    /* Material[] */
  uint lights;       /* PunctualLight[] */
  uint light_count;
  uint triangle_count;
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
  uint path_count;    /* pixels in this wave (<= the path capacity) */
  uint sample;        /* sample index of this pass, 0..spp-1 */
  uint seed;          /* user seed */
  uint bounce;        /* 0 for camera rays */
  uint max_depth;     /* paths end after this many scattering events */
  uint rr_depth;      /* Russian roulette from this bounce on; >= max_depth: never */
  uint queue_in;      /* WP_QUEUE_* the stage reads */
  uint queue_out;     /* WP_QUEUE_* the stage appends to */
  uint pad0;
} Launch;

WP_DEV_END

#endif /* WP_SHARED_TYPES_H */
