/* The flattened BVH as the device traverses it (shared by host and OpenCL C).
 *
 * Binary BVH, both child boxes stored in the parent (64 bytes per node), nodes in depth-first
 * order with node 0 the root. A child reference `link.x`/`link.y` is
 *   >= 0 : index of an inner node,
 *   <  0 : a leaf; ~ref is the index of its first triangle in the reordered triangle array and
 *          link.z (child 0) / link.w (child 1) its triangle count (1..WP_BVH_MAX_LEAF_SIZE).
 * An empty child (only in a root: beside the leaf of a scene that is a single leaf, or both
 * children of a scene without triangles) is a leaf with count 0: rays may enter its (inverted,
 * lo > hi) box, but it holds no triangle to test.
 *
 * Triangles are reordered so that every leaf's triangles are contiguous. Each is stored as its
 * three world-space vertices, exactly as the scene gives them, for the watertight test: triangles
 * sharing an edge then share its vertices bit for bit, and the test evaluates the edge the same way
 * for both (traverse_common.h). The spare w lanes carry
 *   v0.w : the index of the triangle in the scene (as_float of a uint),
 *   v1.w : WP_TRI_* flags (as_float of a uint).
 * The front face is counter-clockwise (glTF): the geometric normal cross(v1 - v0, v2 - v0) points
 * to it.
 */
#ifndef WP_SHARED_BVH_LAYOUT_H
#define WP_SHARED_BVH_LAYOUT_H

#include "compat.h"

/* The traversal kernels keep a private stack of this many node references. The builder limits
 * the tree depth so that depth-first traversal (pushing at most one node per level) never needs
 * more: Embree's maxDepth is set to WP_BVH_MAX_DEPTH. */
#define WP_BVH_MAX_DEPTH 48
#define WP_BVH_STACK_SIZE WP_BVH_MAX_DEPTH
/* Largest leaf the builder makes; the link.z/link.w counts never exceed it. */
#define WP_BVH_MAX_LEAF_SIZE 8

/* Triangle flags (IsectTri.v1.w). */
#define WP_TRI_CULL_BACKFACE 1u /* single-sided material: back faces are not there for any ray */
#define WP_TRI_ALPHA 2u         /* alphaMode MASK or BLEND: a hit counts only if alpha_passes() */

WP_DEV_BEGIN

typedef struct BvhNode {
  float4 c0_xy; /* child 0 box: lo.x, hi.x, lo.y, hi.y */
  float4 c1_xy; /* child 1 box: lo.x, hi.x, lo.y, hi.y */
  float4 c01_z; /* lo.z of child 0, hi.z of child 0, lo.z of child 1, hi.z of child 1 */
  int4 link;    /* x, y: child references; z, w: leaf triangle counts (0 for inner children) */
} BvhNode;

/* The wide layout, for CPU devices (-D WP_BVH_WIDTH=8): 8 children per node, their boxes stored
 * as structure-of-arrays so one node is tested with float8 operations, and leaves made of blocks
 * of 4 triangles tested together with float4 operations. Nodes are depth-first, node 0 the root.
 * child.s[i]:
 *   >= 0 : index of an inner node;
 *   <  0 : a leaf; with c = ~child.s[i], its blocks are [c >> 2, (c >> 2) + (c & 3) + 1) in the
 *          block array (1 to WP_BVH8_MAX_LEAF_BLOCKS blocks);
 * an unused slot has child 0 (node 0 is the root, never a child: traversal skips it) and the box
 * lo = hi = +INFINITY, which keeps out every ray with a finite tmax (a ray with tmax = INFINITY
 * and no negative direction component does enter it, with tnear = tfar = INFINITY). A used box has
 * lo <= hi on every axis (bvh_check_wide checks it): traverse8.h takes each axis's near plane by
 * the sign of the ray's direction. */
#define WP_BVH8_WIDTH 8
#define WP_BVH8_MAX_LEAF_BLOCKS 4
/* Embree's maxDepth for the wide tree; the traversal stack holds at most 7 entries per level. */
#define WP_BVH8_MAX_DEPTH 24
#define WP_BVH8_STACK_SIZE (7 * WP_BVH8_MAX_DEPTH + 1)

typedef struct BvhNode8 {
  float8 lo_x, hi_x, lo_y, hi_y, lo_z, hi_z; /* child boxes, lane i = child i */
  int8 child;
} BvhNode8;

/* Four triangles, lane by lane: the vertices (as in IsectTri), each as 3 axes (x, y, z) so the
 * watertight test can pick the axes by the ray's direction, the scene triangle index and WP_TRI_*
 * flags. Unused lanes have all vertices 0 (zero area: never hit) and prim 0xffffffff. */
typedef struct TriBlock4 {
  float4 v0[3];
  float4 v1[3];
  float4 v2[3];
  uint4 prim;
  uint4 flags;
} TriBlock4;

/* Two-level BVH (scenes that place meshes more than once: host/accel/two_level.h). The node array
 * holds the top-level tree first (node 0 its root), then each distinct mesh's tree, in the layout
 * above, with node and triangle references already offset into the shared arrays. The top-level
 * tree's leaves reference instances instead of triangles, through the instance reference array
 * (uint): binary, a leaf ~ref with count n references entries [~ref, ~ref + n); wide, a leaf c
 * references the 4 x ((c & 3) + 1) entries from 4 x (c >> 2), unused ones WP_NO_INSTANCE. Each
 * entry is an index into the instance array. A ray reaching an instance continues in its mesh's
 * tree (root node BvhInstance.meta.x) with its origin and direction mapped into the mesh's space
 * by to_object; the direction is not renormalised, so distances along the ray are the same in
 * both spaces. */
#define WP_NO_INSTANCE 0xffffffffu
#define WP_INSTANCE_MIRROR 1u /* the transform's determinant is negative (BvhInstance.meta.z) */

typedef struct BvhInstance {
  /* Rows of the world-to-object affine map: x' = dot(row.xyz, x) + row.w. Shading maps the other
   * way with its inverse, computed where it is needed (kernels/geom/instance.h): 48 bytes an
   * instance fewer than storing both. */
  float4 to_object[3];
  uint4 meta; /* x: the mesh's root node; y: the light of the mesh's first emissive triangle here,
                 or WP_NO_LIGHT (host/lights/light_table.h); z: WP_INSTANCE_* flags; w: mesh */
} BvhInstance;

typedef struct IsectTri {
  float4 v0; /* xyz: vertex 0; w: scene triangle index (bits of a uint) */
  float4 v1; /* xyz: vertex 1; w: WP_TRI_* flags (bits of a uint) */
  float4 v2; /* xyz: vertex 2; w: unused (0) */
} IsectTri;

WP_DEV_END

#endif /* WP_SHARED_BVH_LAYOUT_H */
