// Runs Embree's generic BVH builder (rtcBuildBVH) over the input triangles and collects the
// intermediate tree of build_tree.h through the builder's callbacks.
//
// What Embree 3.13 needs for spatial splits to happen at all: RTC_BUILD_QUALITY_HIGH, a
// splitPrimitive callback AND primitiveArrayCapacity > primitiveCount; missing either, it silently
// runs the plain binned SAH builder. It also keeps a per-reference split budget in the top 5 bits
// of geomID (so geomIDs must stay below 2^27, else it falls back too) and clears them again
// before createLeaf. We put the scene triangle index in primID and leave geomID 0.
//
// What it does about maxDepth (observed with 3.13.5, widths 2 and 8; see also
// tests/test_bvh8.cpp, DeepInputStaysWithinTheDepthLimit): depth counts levels, the root 1 and
// leaves included. Once the SAH recursion reaches depth maxDepth - 8 it stops using the SAH and
// builds the rest of that subtree by object-median splits, each node filled to the branching
// factor ("large leaf" mode), which still never makes a leaf larger than maxLeafSize. If even that
// cannot fit (a subtree at depth d holding more than branching^(maxDepth - d) * maxLeafSize
// references) it reports RTC_ERROR_UNKNOWN "depth limit reached" and rtcBuildBVH returns null,
// which build() turns into bvh::Error; it never returns an oversized leaf. So its trees have leaves
// of at most maxLeafSize and inner nodes at depth <= maxDepth - 1. E.g. maxDepth 3, width 8,
// maxLeafSize 8: 512 references build (depth 3), 513 fail. With WP_BVH8_MAX_DEPTH = 24 a failure
// needs more than 8^8 * maxLeafSize references left at depth 16; with WP_BVH_MAX_DEPTH = 48
// (width 2), more than 2^8 * maxLeafSize left at depth 40 (not seen on our meshes).
// flatten_wide copes with oversized leaves anyway (it splits them), should another Embree
// version return them.
#include <cmath>
#include <limits>
#include <mutex>
#include <new>
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <embree3/rtcore_builder.h>

#include "build_tree.h"

namespace wp::bvh::detail {

struct EmbreeTree::Handles {
  RTCDevice device = nullptr;
  RTCBVH bvh = nullptr;
  ~Handles() {
    if (bvh) rtcReleaseBVH(bvh);
    if (device) rtcReleaseDevice(device);
  }
};

EmbreeTree::EmbreeTree() = default;
EmbreeTree::EmbreeTree(EmbreeTree&&) noexcept = default;
EmbreeTree::~EmbreeTree() = default;

namespace {

// Spare reference slots for spatial splits, as a multiple of the triangle count.
constexpr std::size_t kSplitCapacityFactor = 2;

// Largest input: leaf references are stored as ~index in an int32, with up to
// kSplitCapacityFactor references per triangle.
constexpr std::size_t kMaxTriangles =
    static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()) / kSplitCapacityFactor;

// State shared by the callbacks; they run concurrently on Embree's worker threads.
struct BuildContext {
  const BuildInput* input = nullptr;
  std::mutex mutex;
  std::string first_error;  // first error reported by Embree or by a callback

  void fail(const std::string& message) {
    std::lock_guard<std::mutex> lock(mutex);
    if (first_error.empty()) first_error = message;
  }
  void triangle(std::uint32_t index, glm::vec3 v[3]) const {
    const std::uint32_t* idx = input->indices + 3 * static_cast<std::size_t>(index);
    for (int i = 0; i < 3; ++i) v[i] = input->positions[idx[i]];
  }
  // With spatial splits: the triangles' corners, 3 per triangle. The splitter runs millions of
  // times in random triangle order; one contiguous fetch beats chasing indices into positions.
  std::vector<glm::vec3> corners;
};

const char* error_name(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE:
      return "no error";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
    default:
      return "unknown error";
  }
}

void on_embree_error(void* user, RTCError code, const char* message) {
  static_cast<BuildContext*>(user)->fail(std::string(error_name(code)) + ": " +
                                         (message ? message : ""));
}

Box to_box(const RTCBounds& b) {
  return Box{glm::vec3(b.lower_x, b.lower_y, b.lower_z),
             glm::vec3(b.upper_x, b.upper_y, b.upper_z)};
}

void* create_node(RTCThreadLocalAllocator alloc, unsigned child_count, void* user) {
  if (child_count < 2 || child_count > kMaxBranching) {
    static_cast<BuildContext*>(user)->fail("Embree made a node with " +
                                           std::to_string(child_count) + " children");
    return nullptr;
  }
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(TreeInner), alignof(TreeInner));
  if (!mem) return nullptr;  // Embree reported the error
  auto* node = new (mem) TreeInner{};
  node->is_leaf = false;
  node->child_count = child_count;
  return node;
}

void set_node_children(void* node, void** children, unsigned child_count, void*) {
  if (!node) return;
  auto* inner = static_cast<TreeInner*>(node);
  for (unsigned i = 0; i < child_count; ++i)
    inner->children[i] = static_cast<const TreeNode*>(children[i]);
}

void set_node_bounds(void* node, const RTCBounds** bounds, unsigned child_count, void*) {
  if (!node) return;
  auto* inner = static_cast<TreeInner*>(node);
  for (unsigned i = 0; i < child_count; ++i) inner->bounds[i] = to_box(*bounds[i]);
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count,
                  void*) {
  const std::size_t bytes = sizeof(TreeLeaf) + count * sizeof(std::uint32_t);
  void* mem = rtcThreadLocalAlloc(alloc, bytes, alignof(TreeLeaf));
  if (!mem) return nullptr;
  auto* leaf = new (mem) TreeLeaf{};
  auto* ids = reinterpret_cast<std::uint32_t*>(static_cast<char*>(mem) + sizeof(TreeLeaf));
  leaf->is_leaf = true;
  leaf->count = static_cast<unsigned>(count);
  leaf->prims = ids;
  Box b{glm::vec3(std::numeric_limits<float>::infinity()),
        glm::vec3(-std::numeric_limits<float>::infinity())};
  for (std::size_t i = 0; i < count; ++i) {
    new (ids + i) std::uint32_t(prims[i].primID);
    b.lo = glm::min(b.lo, glm::vec3(prims[i].lower_x, prims[i].lower_y, prims[i].lower_z));
    b.hi = glm::max(b.hi, glm::vec3(prims[i].upper_x, prims[i].upper_y, prims[i].upper_z));
  }
  leaf->bounds = b;
  return leaf;
}

void split_primitive(const RTCBuildPrimitive* prim, unsigned dim, float pos, RTCBounds* left,
                     RTCBounds* right, void* user) {
  const glm::vec3* v =
      &static_cast<const BuildContext*>(user)->corners[3 * std::size_t(prim->primID)];
  const Box box{glm::vec3(prim->lower_x, prim->lower_y, prim->lower_z),
                glm::vec3(prim->upper_x, prim->upper_y, prim->upper_z)};
  Box l, r;
  split_triangle_bounds(v, box, dim, pos, l, r);
  left->lower_x = l.lo.x, left->lower_y = l.lo.y, left->lower_z = l.lo.z;
  left->upper_x = l.hi.x, left->upper_y = l.hi.y, left->upper_z = l.hi.z;
  right->lower_x = r.lo.x, right->lower_y = r.lo.y, right->lower_z = r.lo.z;
  right->upper_x = r.hi.x, right->upper_y = r.hi.y, right->upper_z = r.hi.z;
}

// The largest leaf the layout of `width` stores.
int max_leaf_size_for(int width) {
  return width == WP_BVH8_WIDTH ? 4 * WP_BVH8_MAX_LEAF_BLOCKS : WP_BVH_MAX_LEAF_SIZE;
}

void validate(const BuildInput& input, const BuildOptions& options) {
  if (input.triangle_count > 0 && (!input.positions || !input.indices))
    throw Error("BVH build: missing vertex positions or indices");
  if (input.triangle_count > kMaxTriangles)
    throw Error("BVH build: too many triangles (" + std::to_string(input.triangle_count) +
                ", at most " + std::to_string(kMaxTriangles) + ")");
  if (options.width != 2 && options.width != WP_BVH8_WIDTH)
    throw Error("BVH build: width " + std::to_string(options.width) + " is not 2 or 8");
  const int max_leaf = max_leaf_size_for(options.width);
  if (options.max_leaf_size < 1 || options.max_leaf_size > max_leaf)
    throw Error("BVH build: max_leaf_size " + std::to_string(options.max_leaf_size) +
                " is outside 1.." + std::to_string(max_leaf) + " for width " +
                std::to_string(options.width));
  const auto valid_cost = [](float c) { return std::isfinite(c) && c > 0.0f; };
  if (!valid_cost(options.traversal_cost) || !valid_cost(options.intersection_cost))
    throw Error("BVH build: SAH costs must be finite and positive");
}

// One build primitive per triangle (its bounds, primID = index), into an array of `capacity`
// slots; also returns the scene bounds. Throws on a non-finite vertex.
std::vector<RTCBuildPrimitive> make_primitives(const BuildContext& ctx, std::size_t capacity,
                                               Box& scene, double& total_area) {
  const std::size_t n = ctx.input->triangle_count;
  std::vector<RTCBuildPrimitive> prims(capacity);
  scene = Box{glm::vec3(std::numeric_limits<float>::infinity()),
              glm::vec3(-std::numeric_limits<float>::infinity())};
  total_area = 0;
  for (std::size_t i = 0; i < n; ++i) {
    glm::vec3 v[3];
    ctx.triangle(static_cast<std::uint32_t>(i), v);
    for (const glm::vec3& p : v)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw Error("BVH build: triangle " + std::to_string(i) + " has a non-finite vertex");
    const Box b{glm::min(glm::min(v[0], v[1]), v[2]), glm::max(glm::max(v[0], v[1]), v[2])};
    RTCBuildPrimitive& p = prims[i];
    p.lower_x = b.lo.x, p.lower_y = b.lo.y, p.lower_z = b.lo.z, p.geomID = 0;
    p.upper_x = b.hi.x, p.upper_y = b.hi.y, p.upper_z = b.hi.z;
    p.primID = static_cast<unsigned>(i);
    scene.lo = glm::min(scene.lo, b.lo);
    scene.hi = glm::max(scene.hi, b.hi);
    total_area += surface_area(b);
  }
  return prims;
}

// Embree's settings for `options`; spatial splits need both the splitter and spare capacity.
//
// The wide tree: 8 children per node, maxDepth WP_BVH8_MAX_DEPTH, and sahBlockSize 4, so that
// Embree's SAH charges a leaf of n triangles ceil(n / 4) times the intersection cost, as the
// layout packs it into ceil(n / 4) TriBlock4 tested 4 lanes at once. The costs stay 1 and 1: one
// 8-wide node test (8 slab tests at once) against one block test (4 triangle tests at once), the
// same as Embree's own BVH8 over Triangle4 (sahBlockSize 4, both costs 1). Measured with 200k
// camera and interior rays on the reference (nodes visited + blocks tested per ray, and the SAH
// with unit costs; leaves of 8):
//                      (Ct, Ci) = (1, 1)   per-triangle SAH   (1, 2)      (2, 1)
//   soup 200k                 16.5 + 9.8   21.4 + 4.8 *       18.8 + 6.6  14.5 + 12.9
//   FlightHelmet 95k          4.67 + 2.04  5.20 + 2.15        4.84 + 2.00 4.62 + 2.09
//   DamagedHelmet 15k         5.73 + 3.25  6.27 + 3.46        5.96 + 3.22 5.62 + 3.35
//   long diagonals 50k        168 + 720    215 + 873          170 + 722   168 + 720
//   SAH: FlightHelmet         19.1         23.2               20.2        18.9
// (* blocks of mostly one triangle). Block-counting beats per-triangle costs everywhere (8-20%
// lower SAH, fewer nodes and blocks); the cost ratio moves work between nodes and blocks by a
// few percent either way, and (1, 1) is never far from the best.
RTCBuildArguments build_arguments(const BuildOptions& options, bool splits,
                                  std::vector<RTCBuildPrimitive>& prims, std::size_t count) {
  const bool wide = options.width == WP_BVH8_WIDTH;
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = splits ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = static_cast<unsigned>(options.width);
  args.maxDepth = wide ? WP_BVH8_MAX_DEPTH : WP_BVH_MAX_DEPTH;
  args.sahBlockSize = wide ? 4 : 1;
  args.minLeafSize = 1;
  args.maxLeafSize = static_cast<unsigned>(options.max_leaf_size);
  args.traversalCost = options.traversal_cost;
  args.intersectionCost = options.intersection_cost;
  args.primitives = prims.data();
  args.primitiveCount = count;
  args.primitiveArrayCapacity = splits ? prims.size() : count;
  args.createNode = create_node;
  args.setNodeChildren = set_node_children;
  args.setNodeBounds = set_node_bounds;
  args.createLeaf = create_leaf;
  args.splitPrimitive = splits ? split_primitive : nullptr;
  return args;
}

}  // namespace

EmbreeTree build_embree_tree(const BuildInput& input, const BuildOptions& options) {
  validate(input, options);
  EmbreeTree tree;
  tree.handles = std::make_unique<EmbreeTree::Handles>();
  const std::size_t n = input.triangle_count;
  if (n == 0) {  // nothing for Embree to build: no root, and bounds at the origin
    tree.scene_bounds = Box{glm::vec3(0.0f), glm::vec3(0.0f)};
    return tree;
  }
  BuildContext ctx;
  ctx.input = &input;

  double total_area = 0;
  // Spare capacity only for spatial splits; Embree rejects splits of zero-area boxes anyway (and
  // its split budget divides by the total area), so a scene of such boxes builds without them.
  std::vector<RTCBuildPrimitive> prims = make_primitives(
      ctx, options.spatial_splits ? n * kSplitCapacityFactor : n, tree.scene_bounds, total_area);
  const bool splits = options.spatial_splits && total_area > 0;
  if (splits) {
    ctx.corners.resize(3 * n);
    for (std::size_t i = 0; i < n; ++i)
      ctx.triangle(static_cast<std::uint32_t>(i), &ctx.corners[3 * i]);
  }

  RTCDevice device = rtcNewDevice(nullptr);
  if (!device)
    throw Error(std::string("BVH build: cannot create an Embree device (") +
                error_name(rtcGetDeviceError(nullptr)) + ")");
  tree.handles->device = device;
  rtcSetDeviceErrorFunction(device, on_embree_error, &ctx);
  // Detaches `ctx` from the device before either goes (declared last, so destroyed first).
  struct DetachErrorFunction {
    RTCDevice device;
    ~DetachErrorFunction() { rtcSetDeviceErrorFunction(device, nullptr, nullptr); }
  } detach{device};
  tree.handles->bvh = rtcNewBVH(device);
  if (!tree.handles->bvh) throw Error("BVH build: Embree: " + ctx.first_error);

  RTCBuildArguments args = build_arguments(options, splits, prims, n);
  args.bvh = tree.handles->bvh;
  args.userPtr = &ctx;
  tree.root = static_cast<const TreeNode*>(rtcBuildBVH(&args));
  const RTCError code = rtcGetDeviceError(device);
  if (ctx.first_error.empty() && code != RTC_ERROR_NONE) ctx.first_error = error_name(code);
  if (ctx.first_error.empty() && !tree.root) ctx.first_error = "no tree returned";
  if (!ctx.first_error.empty()) throw Error("BVH build: Embree failed: " + ctx.first_error);
  return tree;
}

}  // namespace wp::bvh::detail
