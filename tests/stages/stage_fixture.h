// The fixture of the stage-kernel tests (tests/stages/test_stage_*.cpp).
//
// Tier kernel: every wavefront stage kernel alone (docs/architecture.md, "Stages"), one test or a
// few per kernel, each named after it. Each launches its one stage on a real path state captured
// from the Cornell box (scenes/cornell_box.gltf at 32 x 24, 4 samples per pixel in one wave of
// 3072 paths; bounces 0 to 2 captured through the renderer's own start_wave / run_bounce) and
// checks what the stage wrote against a host reference computed here from the scene, the host
// camera, the CPU BVH traversal and the light table: never against an earlier output of the
// kernel itself. Where the captured state lacks a case (a back-side hit on the light, an eta
// scale other than 1, a NaN, film values that saturate), a variant plants it, as each test says.
// Besides its outputs, each test checks that the stage leaves alone every field and slot it has
// no business writing (bit for bit).
//
// The scene: the published Cornell box with KHR_materials_specular's factor set to 0 on every
// material. glTF's default factor is 1, a dielectric Fresnel layer over the diffuse base, which
// makes the program glossy (host/device/scene_features.cpp); with 0 the BSDF is Lambert's alone
// (kernels/bsdf/bsdf.h, WP_FEATURE_GLOSSY 0), whose sample weight, pdf and light-sample value have
// closed forms. A small constant background makes escaped rays count and adds an environment
// light to the light table next to the two emissive triangles of the ceiling light, so both
// kinds of light sample and both MIS cases (emission and background found by BSDF sampling)
// occur.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "host/accel/bvh_input.h"
#include "host/device/cl_runtime.h"
#include "host/device/device_scene.h"
#include "host/film/film.h"
#include "host/render/pipeline.h"
#include "host/render/render.h"
#include "host/render/wavefront.h"
#include "host/scene/gltf_loader.h"
#include "tests/float_bits.h"

namespace wp::test::stages {

using glm::dvec3;
using glm::vec3;
using wp::Stage;
using wp::dev::float4;
using wp::dev::uint4;

constexpr int kWidth = 32, kHeight = 24;
constexpr std::uint32_t kPixels = kWidth * kHeight;
constexpr std::uint32_t kSamples = 4;  // per pixel, all in one wave
constexpr std::uint32_t kPaths = kPixels * kSamples;
constexpr int kBounces = 3;  // bounce starts captured: the camera rays and two BSDF-sampled ones
inline const vec3 kBackground(0.02f, 0.03f, 0.05f);
constexpr double kPi = 3.14159265358979323846;
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::uint32_t kSurfFront = 4u;  // WP_SURF_FRONT of kernels/bsdf/bsdf.h (OpenCL C only)

using wp::test::as_float;
using wp::test::bits;
inline vec3 xyz(const float4& v) {
  return {v.x, v.y, v.z};
}
inline dvec3 dxyz(const float4& v) {
  return {v.x, v.y, v.z};
}
inline float max3(vec3 v) {
  return std::max(v.x, std::max(v.y, v.z));
}
inline std::string str(dvec3 v) {
  std::ostringstream o;
  o.precision(9);
  o << "(" << v.x << " " << v.y << " " << v.z << ")";
  return o.str();
}

// A quiet NaN with a payload, written over fields before a launch: a field the stage should write
// but does not keeps it, and a stage that reads a field it should not finds NaN.
constexpr std::uint32_t kPoisonBits = 0x7fc0beefu;
inline const float4 kPoison{as_float(kPoisonBits), as_float(kPoisonBits), as_float(kPoisonBits),
                            as_float(kPoisonBits)};

// Every path-state field (kernels/shared/path_state.def) by name; the AOV fields take no memory
// without AOVs, nor the material extensions' fields without their features (the stage scenes use
// none), so they are left out.
struct Field {
  const char* name;
  wp::dev::uint wp::dev::PathLayout::*offset;
};
#define WP_PATH_FIELD(type, name, description) Field{#name, &wp::dev::PathLayout::name},
#define WP_PATH_AOV_FIELD(type, name, description)
#define WP_PATH_OPT_FIELD(features, type, name, description)
#define WP_PATH_INSTANCE_FIELD(type, name, description)
const Field kFields[] = {
#include "kernels/shared/path_state.def"
};
#undef WP_PATH_INSTANCE_FIELD
#undef WP_PATH_OPT_FIELD
#undef WP_PATH_AOV_FIELD
#undef WP_PATH_FIELD

// The failures of one check over many paths: counted, the first few described, reported once, so
// that a broken kernel gives a readable report instead of thousands of lines.
class Failures {
 public:
  explicit Failures(std::string what) : what_(std::move(what)) {}
  ~Failures() {
    EXPECT_EQ(count_, 0u) << what_ << ": " << count_ << " failure(s), the first:\n" << first_;
  }
  void check(bool ok, const std::function<std::string()>& describe) {
    if (ok) return;
    if (count_++ < 5) first_ += "  " + describe() + "\n";
  }

 private:
  std::string what_, first_;
  std::size_t count_ = 0;
};
#define WP_CHECK(failures, condition, message)     \
  (failures).check((condition), [&] {              \
    std::ostringstream wp_check_out;               \
    wp_check_out.precision(9);                     \
    wp_check_out << #condition << ": " << message; \
    return wp_check_out.str();                     \
  })

// A snapshot of the device state (path state, queues, counters) read by field and slot.
class PathView {
 public:
  PathView(wp::Wavefront::Snapshot s, const wp::dev::PathLayout& layout)
      : s_(std::move(s)), layout_(layout) {}

  float4 f4(wp::dev::uint field, std::uint32_t slot) const { return get<float4>(field, slot); }
  uint4 u4(wp::dev::uint field, std::uint32_t slot) const { return get<uint4>(field, slot); }
  vec3 v3(wp::dev::uint field, std::uint32_t slot) const { return xyz(f4(field, slot)); }
  dvec3 d3(wp::dev::uint field, std::uint32_t slot) const { return dxyz(f4(field, slot)); }
  const unsigned char* raw(wp::dev::uint field, std::uint32_t slot) const {
    return s_.paths.data() + field + std::size_t(slot) * 16;
  }
  // The path's bounce count and flags, in the w lanes of shadow_l and shadow_d
  // (kernels/shared/path_state.def).
  std::uint32_t bounce(std::uint32_t slot) const { return u4(layout_.shadow_l, slot).w; }
  std::uint32_t flags(std::uint32_t slot) const { return u4(layout_.shadow_d, slot).w; }
  std::uint32_t counter(std::uint32_t q) const { return s_.counters[q]; }
  // Entries [0, counter) of queue q.
  std::vector<std::uint32_t> queue(std::uint32_t q) const {
    const auto begin = s_.slots.begin() + std::ptrdiff_t(q) * layout_.capacity;
    return {begin, begin + counter(q)};
  }

 private:
  template <class T>
  T get(wp::dev::uint field, std::uint32_t slot) const {
    T v;
    std::memcpy(&v, raw(field, slot), sizeof v);
    return v;
  }
  wp::Wavefront::Snapshot s_;
  wp::dev::PathLayout layout_;
};

inline std::vector<std::uint32_t> all_slots() {
  std::vector<std::uint32_t> v(kPaths);
  for (std::uint32_t i = 0; i < kPaths; ++i) v[i] = i;
  return v;
}

// The entries of a queue as a set, failing on an entry that is out of range or there twice (the
// queue invariant, kernels/integrator/queues.h).
inline std::set<std::uint32_t> queue_set(const std::vector<std::uint32_t>& q, const char* name) {
  std::set<std::uint32_t> s;
  Failures f(std::string("queue ") + name + " holds distinct slots of the wave");
  for (const std::uint32_t slot : q) {
    WP_CHECK(f, slot < kPaths, "slot " << slot);
    WP_CHECK(f, s.insert(slot).second, "slot " << slot << " twice");
  }
  return s;
}

// Power-heuristic MIS weight of a strategy with pdf `own` against one with pdf `other`
// (kernels/lights/mis.h; RenderSettings' default heuristic).
inline double power_weight(double own, double other) {
  return own * own / (own * own + other * other);
}

class Stages : public ::testing::Test {
 protected:
  // The start of one bounce, as run_bounce begins it: its rays in params.queue_in, the other
  // queues empty.
  struct Bounce {
    wp::Wavefront::Snapshot start;
    wp::dev::Launch params{};
    std::uint32_t rays = 0;
  };

  static void SetUpTestSuite() {
    runtime_ = new wp::ClRuntime(wp::select_device(""));
    scene_ = new wp::Scene(wp::load_gltf(std::string(WP_SOURCE_DIR) + "/scenes/cornell_box.gltf"));
    for (wp::Material& m : scene_->materials) m.specular = 0.0f;  // Lambert alone (see the top)
    settings_ = new wp::RenderSettings();
    settings_->width = kWidth;
    settings_->height = kHeight;
    settings_->wave_size = kPaths;  // one wave of kSamples samples of every pixel
    settings_->background = kBackground;
    settings_->fused = false;
    settings_->seed = 11;
    // The BVH as the renderer builds it for this device: its triangle flags (back-face culling
    // of the single-sided walls) and the device's layout.
    wp::bvh::BuildOptions options;
    options.width = wp::bvh_width(runtime_->device(), *settings_);
    bvh_ = new wp::bvh::Bvh(wp::bvh::build(wp::bvh_input(*scene_, tri_flags_), options));
    wf_ = new wp::Wavefront(*runtime_, *scene_, *bvh_, *settings_);
    ASSERT_EQ(wf_->wave_paths(), kPaths);
    capture();
  }
  static void TearDownTestSuite() {
    delete single_wf_;
    single_wf_ = nullptr;
    delete other_wf_;
    delete other_bvh_;
    other_wf_ = nullptr;
    other_bvh_ = nullptr;
    delete wf_;
    delete bvh_;
    delete settings_;
    delete scene_;
    delete runtime_;
    wf_ = nullptr;
    bvh_ = nullptr;
    settings_ = nullptr;
    scene_ = nullptr;
    runtime_ = nullptr;
  }

  // One wave through the renderer's own loop, its bounce starts kept, then to its end.
  static void capture() {
    wp::dev::Launch p = wf_->start_wave(0, 0, kPixels, kSamples);
    std::uint32_t rays = p.path_count;
    bounces_.clear();
    for (int b = 0; b < kBounces; ++b) {
      Bounce c;
      c.start = wf_->snapshot();
      // What run_bounce zeroes before its stages: the surface, shadow and next ray queues.
      c.start.counters[WP_QUEUE_SURFACE] = 0;
      c.start.counters[WP_QUEUE_SHADOW] = 0;
      c.start.counters[p.queue_out] = 0;
      c.params = p;
      c.rays = rays;
      bounces_.push_back(std::move(c));
      rays = wf_->run_bounce(p, rays);
    }
    while (rays > 0) rays = wf_->run_bounce(p, rays);
    end_ = wf_->snapshot();
  }

  static PathView view(wp::Wavefront& wf = *wf_) {
    return PathView(wf.snapshot(), wf.path_state().layout);
  }
  static const wp::dev::PathLayout& layout() { return wf_->path_state().layout; }

  // Launches `stage` as run_bounce does in bounce `c` (trace_shadow over exactly its queue) and
  // waits for it.
  static void launch(Stage stage, const Bounce& c, const wp::dev::Launch& p,
                     wp::Wavefront& wf = *wf_) {
    const std::uint32_t items = stage == Stage::kTraceShadow ? wf.counter(WP_QUEUE_SHADOW) : c.rays;
    wf.launch_stage(stage, items, p);
    wf.finish();
  }
  // The input of `stage` in bounce b: the bounce's start with the split pipeline's steps before
  // the stage run on it.
  static PathView input(Stage stage, int b) {
    const Bounce& c = bounces_.at(static_cast<std::size_t>(b));
    wf_->restore(c.start);
    for (const wp::Step& step : wp::split_pipeline().bounce) {
      if (step.stage == stage) break;
      launch(step.stage, c, c.params);
    }
    return view();
  }
  static void poison(wp::dev::uint field, wp::Wavefront& wf = *wf_) {
    wf.write_paths(field, std::vector<float4>(kPaths, kPoison));
  }
  // Poisons lanes xyz of `field`, keeping w: for shadow_d and shadow_l, whose w lanes hold the
  // path's flags and bounce count.
  static void poison_xyz(wp::dev::uint field) {
    std::vector<float4> v = wf_->read_paths<float4>(field, kPaths);
    for (float4& e : v) e = {kPoison.x, kPoison.y, kPoison.z, e.w};
    wf_->write_paths(field, v);
  }

  // The two traversal stages run on both BVH layouts: the device's (wf_, bvh_) and the other one
  // (binary on a CPU device, 8-wide on a GPU), a Wavefront of the same scene and settings made on
  // first use, whose path state has the same layout, so that it takes the same captured states;
  // where the device's program traces rays in packets (kernels/traversal/traverse8_packet.h), once
  // more on its layout with one ray per work-item.
  struct Traversal {
    wp::Wavefront* wf;
    const wp::bvh::Bvh* bvh;
    std::string name;
  };
  static std::vector<Traversal> traversals() {
    if (!other_wf_) {
      wp::bvh::BuildOptions options;
      options.width = bvh_->width == 8 ? 2 : 8;
      other_bvh_ = new wp::bvh::Bvh(wp::bvh::build(wp::bvh_input(*scene_, tri_flags_), options));
      other_wf_ = new wp::Wavefront(*runtime_, *scene_, *other_bvh_, *settings_);
      if (wf_->build_options().find("_PACKET=1") != std::string::npos) {
        wp::RenderSettings single = *settings_;
        single.shadow_packets = single.closest_packets = false;
        single_wf_ = new wp::Wavefront(*runtime_, *scene_, *bvh_, single);
      }
    }
    const auto name = [](const wp::bvh::Bvh* b, const wp::Wavefront* w) {
      return "BVH width " + std::to_string(b->width) +
             (w->build_options().find("_PACKET=1") != std::string::npos ? " (packets)" : "");
    };
    std::vector<Traversal> out = {{wf_, bvh_, name(bvh_, wf_)},
                                  {other_wf_, other_bvh_, name(other_bvh_, other_wf_)}};
    if (single_wf_) out.push_back({single_wf_, bvh_, name(bvh_, single_wf_)});
    return out;
  }

  // Fails for every field not in `may_change` that differs (bitwise) between the two states in
  // one of `slots`.
  static void expect_unchanged(const PathView& before, const PathView& after,
                               const std::vector<std::uint32_t>& slots,
                               const std::set<std::string>& may_change, const std::string& what) {
    Failures f("fields the stage must not write, " + what);
    for (const Field& field : kFields) {
      if (may_change.count(field.name)) continue;
      const wp::dev::uint offset = layout().*field.offset;
      for (const std::uint32_t slot : slots)
        WP_CHECK(f, std::memcmp(before.raw(offset, slot), after.raw(offset, slot), 16) == 0,
                 field.name << " of slot " << slot);
    }
  }

  // Host geometry of scene triangle `tri`.
  struct Triangle {
    dvec3 p[3], n[3];  // vertices, vertex normals
    dvec3 cross;       // (p1 - p0) x (p2 - p0): the front side's normal, twice the area long
    const wp::Material* material;
  };
  // How far surface_spawn may move a ray's origin from the surface point of `slot`: the offset
  // distance along ng and at most as much back along the incoming ray, so at most 2 offsets, plus
  // the rounding of the two float additions (an ulp of the point's magnitude each; 2^-21 of
  // p_scale is 4 of them).
  struct SpawnBound {
    double offset, rounding;
  };
  static SpawnBound spawn_bound(const PathView& v, std::uint32_t slot) {
    const double p_scale = v.f4(layout().surf_p, slot).w;
    return {std::ldexp(p_scale, -16), std::ldexp(p_scale, -21)};
  }

  static Triangle triangle(std::uint32_t tri) {
    Triangle t;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = scene_->indices[3 * tri + k];
      t.p[k] = dvec3(scene_->positions[v]);
      t.n[k] = dvec3(scene_->normals[v]);
    }
    t.cross = glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    t.material = &scene_->materials[scene_->triangle_material[tri]];
    return t;
  }
  static bool emissive(const wp::Material& m) { return max3(m.emission) > 0.0f; }
  struct Emitter {
    std::uint32_t tri;
    Triangle t;
  };
  // Replaces every 4th ray of bounce c (after intersect_closest) with one from a random direction
  // (at least 0.1 in cosine from the light's plane) that hits a random point of an emissive
  // triangle at distance 0.05 to 0.55: its hit record, origin and direction made to agree.
  static void aim_at_lights(const Bounce& c) {
    const std::vector<Emitter> em = emitters();
    const PathView in = view();
    std::vector<float4> o(kPaths), d(kPaths), h(kPaths);
    for (std::uint32_t slot = 0; slot < kPaths; ++slot) {
      o[slot] = in.f4(layout().ray_o, slot);
      d[slot] = in.f4(layout().ray_d, slot);
      h[slot] = in.f4(layout().hit, slot);
    }
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    std::normal_distribution<double> normal;
    const std::vector<std::uint32_t> rays = in.queue(c.params.queue_in);
    for (std::size_t i = 0; i < rays.size(); i += 4) {
      const Emitter& e = em[(i / 4) % em.size()];
      double u = u01(rng), v = u01(rng);
      if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
      const dvec3 p = (1.0 - u - v) * e.t.p[0] + u * e.t.p[1] + v * e.t.p[2];
      dvec3 dir;
      do {
        dir = glm::normalize(dvec3(normal(rng), normal(rng), normal(rng)));
      } while (std::fabs(glm::dot(dir, glm::normalize(e.t.cross))) < 0.1);
      const double t = 0.05 + 0.5 * u01(rng);
      const dvec3 origin = p - t * dir;
      const std::uint32_t slot = rays[i];
      o[slot] = {float(origin.x), float(origin.y), float(origin.z), 0.0f};
      d[slot] = {float(dir.x), float(dir.y), float(dir.z), 0.0f};  // no panes passed
      h[slot] = {float(t), float(u), float(v), as_float(e.tri)};
    }
    wf_->write_paths(layout().ray_o, o);
    wf_->write_paths(layout().ray_d, d);
    wf_->write_paths(layout().hit, h);
  }
  // The scene's emissive triangles, from the host scene.
  static std::vector<Emitter> emitters() {
    std::vector<Emitter> v;
    for (std::uint32_t tri = 0; tri < scene_->triangle_count(); ++tri)
      if (emissive(*triangle(tri).material)) v.push_back({tri, triangle(tri)});
    return v;
  }
  // The probability with which NEE picks light `index` of the light table.
  static double light_pmf(std::uint32_t index) { return wf_->lights().alias.at(index).pmf; }

  inline static wp::ClRuntime* runtime_ = nullptr;
  inline static wp::Scene* scene_ = nullptr;
  inline static wp::RenderSettings* settings_ = nullptr;
  inline static std::vector<std::uint32_t> tri_flags_;
  inline static wp::bvh::Bvh* bvh_ = nullptr;
  inline static wp::Wavefront* wf_ = nullptr;
  inline static wp::bvh::Bvh* other_bvh_ = nullptr;
  inline static wp::Wavefront* other_wf_ = nullptr;
  inline static wp::Wavefront* single_wf_ = nullptr;  // the device's layout, no packets
  inline static std::vector<Bounce> bounces_;
  inline static wp::Wavefront::Snapshot
      end_;  // the wave after its last bounce: what accumulate reads
};

}  // namespace wp::test::stages
