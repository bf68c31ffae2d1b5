// build_two_level(): the top-level tree over instances and the meshes' trees merged into one Bvh
// (bvh_layout.h, "Two-level BVH"), and the reference traversal of such a BVH.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <glm/mat4x4.hpp>

#include "traverse_common.h"

namespace wp::bvh {
namespace {

std::uint32_t bits_of(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// Rows of the affine map m (column-major, glm) as float4: x' = dot(row.xyz, x) + row.w.
void rows_of(const glm::dmat4& m, dev::float4 rows[3]) {
  for (int r = 0; r < 3; ++r)
    rows[r] = dev::float4{static_cast<float>(m[0][r]), static_cast<float>(m[1][r]),
                          static_cast<float>(m[2][r]), static_cast<float>(m[3][r])};
}

// The world box of a mesh whose box is [lo, hi] placed by `m`: its 8 corners mapped in double,
// widened by a relative 2^-20 of the box's magnitude so that the float arithmetic of the ray's
// mapping (object_ray) cannot reach a triangle outside it.
void world_box(const glm::dmat4& m, const glm::vec3& lo, const glm::vec3& hi, glm::vec3& out_lo,
               glm::vec3& out_hi) {
  glm::dvec3 a(std::numeric_limits<double>::infinity()), b(-a);
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
    const glm::dvec3 w = glm::dvec3(m * glm::dvec4(corner, 1.0));
    a = glm::min(a, w);
    b = glm::max(b, w);
  }
  const double scale = std::max(
      {std::abs(a.x), std::abs(a.y), std::abs(a.z), std::abs(b.x), std::abs(b.y), std::abs(b.z)});
  const double pad = scale * std::ldexp(1.0, -20);
  out_lo = glm::vec3(a - pad);
  out_hi = glm::vec3(b + pad);
}

// Appends `mesh`'s tree to `out` with its node, triangle/block and primitive references offset;
// returns its root node's index.
std::int32_t append_mesh(const Bvh& mesh, std::uint32_t first_triangle, Bvh& out) {
  constexpr std::size_t kMaxIndex = std::numeric_limits<std::int32_t>::max();
  if (out.width == WP_BVH8_WIDTH) {
    const std::size_t node0 = out.nodes8.size(), block0 = out.blocks.size();
    if (node0 + mesh.nodes8.size() > kMaxIndex || (block0 + mesh.blocks.size()) > (kMaxIndex >> 2))
      throw Error("BVH build: too many nodes or triangles for the device layout");
    for (dev::BvhNode8 n : mesh.nodes8) {
      for (std::int32_t& c : n.child.s) {
        if (c > 0) {
          c += static_cast<std::int32_t>(node0);
        } else if (c < 0) {
          const std::int32_t leaf = ~c;
          c = ~((((leaf >> 2) + static_cast<std::int32_t>(block0)) << 2) | (leaf & 3));
        }  // 0: an unused slot stays unused
      }
      out.nodes8.push_back(n);
    }
    for (dev::TriBlock4 b : mesh.blocks) {
      for (std::uint32_t* p : {&b.prim.x, &b.prim.y, &b.prim.z, &b.prim.w})
        if (*p != 0xffffffffu) *p += first_triangle;
      out.blocks.push_back(b);
    }
    return static_cast<std::int32_t>(node0);
  }
  const std::size_t node0 = out.nodes.size(), tri0 = out.triangles.size();
  if (node0 + mesh.nodes.size() > kMaxIndex || tri0 + mesh.triangles.size() > kMaxIndex)
    throw Error("BVH build: too many nodes or triangles for the device layout");
  const auto relink = [&](std::int32_t& link) {
    link = link >= 0 ? link + static_cast<std::int32_t>(node0)
                     : ~(~link + static_cast<std::int32_t>(tri0));
  };
  for (dev::BvhNode n : mesh.nodes) {
    relink(n.link.x);
    relink(n.link.y);
    out.nodes.push_back(n);
  }
  for (dev::IsectTri t : mesh.triangles) {
    std::uint32_t prim = bits_of(t.v0.w) + first_triangle;
    std::memcpy(&t.v0.w, &prim, sizeof prim);
    out.triangles.push_back(t);
  }
  return static_cast<std::int32_t>(node0);
}

}  // namespace

Ray object_ray(const dev::BvhInstance& inst, const Ray& ray) {
  Ray r = ray;
  const dev::float4* m = inst.to_object;
  for (int i = 0; i < 3; ++i) {
    const float ox = m[i].x * ray.o.x, oy = m[i].y * ray.o.y, oz = m[i].z * ray.o.z;
    r.o[i] = ((ox + oy) + oz) + m[i].w;
    const float dx = m[i].x * ray.d.x, dy = m[i].y * ray.d.y, dz = m[i].z * ray.d.z;
    r.d[i] = (dx + dy) + dz;
  }
  return r;
}

Bvh build_two_level(std::vector<Bvh> meshes, const std::vector<std::uint32_t>& first_triangle,
                    const std::vector<InstanceInput>& instances, const BuildOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (first_triangle.size() != meshes.size())
    throw Error("BVH build: one first triangle per mesh expected");
  for (const Bvh& m : meshes)
    if (m.width != options.width || !m.instances.empty())
      throw Error("BVH build: a mesh's tree is not of the two-level BVH's layout");

  // The instances that have triangles, and a degenerate triangle spanning each one's world box
  // for the builder: (lo, hi, hi) has exactly that box.
  std::vector<dev::BvhInstance> kept;
  std::vector<glm::vec3> corners;
  std::vector<std::uint32_t> corner_index;
  for (const InstanceInput& in : instances) {
    if (in.mesh >= meshes.size()) throw Error("BVH build: an instance of a mesh that is not there");
    const Bvh& mesh = meshes[in.mesh];
    if ((mesh.width == WP_BVH8_WIDTH ? mesh.blocks.empty() : mesh.triangles.empty())) continue;
    const double det = glm::determinant(glm::dmat3(in.to_world));
    if (!std::isfinite(det) || det == 0.0)
      throw Error("BVH build: an instance's transform is singular");
    dev::BvhInstance inst{};
    rows_of(glm::inverse(in.to_world), inst.to_object);
    inst.meta = dev::uint4{0u, 0xffffffffu, det < 0.0 ? WP_INSTANCE_MIRROR : 0u, in.mesh};
    glm::vec3 lo, hi;
    world_box(in.to_world, mesh.lo, mesh.hi, lo, hi);
    const auto k = static_cast<std::uint32_t>(corners.size());
    corners.push_back(lo);
    corners.push_back(hi);
    corner_index.insert(corner_index.end(), {k, k + 1, k + 1});
    kept.push_back(inst);
  }

  BuildOptions top_options = options;
  top_options.spatial_splits = false;  // the boxes are the primitives
  // Up to 4 instances a leaf (one block of the wide layout): with 64 bytes a BvhInstance, 4 a
  // reference and the top-level nodes, 84 bytes an instance at width 8 and 117 at width 2 (more
  // with one a leaf; docs/performance.md, "Instancing").
  top_options.max_leaf_size = 4;
  BuildInput top_input;
  top_input.positions = corners.data();
  top_input.indices = corner_index.data();
  top_input.triangle_count = kept.size();
  Bvh top = build(top_input, top_options);

  Bvh out;
  out.width = options.width;
  out.lo = top.lo;
  out.hi = top.hi;
  out.stats = top.stats;
  if (out.width == WP_BVH8_WIDTH) {
    out.nodes8 = std::move(top.nodes8);
    for (const dev::TriBlock4& b : top.blocks)
      out.instance_refs.insert(out.instance_refs.end(), {b.prim.x, b.prim.y, b.prim.z, b.prim.w});
  } else {
    out.nodes = std::move(top.nodes);
    for (const dev::IsectTri& t : top.triangles) out.instance_refs.push_back(bits_of(t.v0.w));
  }
  std::vector<std::int32_t> roots(meshes.size(), -1);
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    roots[i] = append_mesh(meshes[i], first_triangle[i], out);
    const BuildStats& s = meshes[i].stats;
    out.stats.inner_nodes += s.inner_nodes;
    out.stats.leaves += s.leaves;
    out.stats.triangle_refs += s.triangle_refs;
    meshes[i] = Bvh();  // its memory back before the next is appended
  }
  for (dev::BvhInstance& inst : kept) inst.meta.x = static_cast<std::uint32_t>(roots[inst.meta.w]);
  out.instances = std::move(kept);
  out.stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

namespace detail {

Hit trace_instances(const Bvh& bvh, const Ray& ray, bool any) {
  Hit best;
  Ray r = ray;
  for (std::size_t i = 0; i < bvh.instances.size(); ++i) {
    const dev::BvhInstance& inst = bvh.instances[i];
    const Ray o = object_ray(inst, r);
    const auto root = static_cast<std::int32_t>(inst.meta.x);
    const Hit h = bvh.width == WP_BVH8_WIDTH ? trace_wide(bvh, o, any, root)
                                             : trace_binary(bvh, o, any, root);
    if (!h.hit) continue;
    best = h;
    best.instance = static_cast<std::uint32_t>(i);
    if (any) return best;
    r.tmax = h.t;
  }
  return best;
}

}  // namespace detail
}  // namespace wp::bvh
