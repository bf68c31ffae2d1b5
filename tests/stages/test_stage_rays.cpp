// The stages that make and trace rays: generate_camera_rays, intersect_closest, trace_shadow
// (fixture: stage_fixture.h).
#include "tests/stages/stage_fixture.h"

namespace wp::test::stages {
namespace {

// generate_camera_rays: every slot of the wave once in the ray queue, a fresh path (throughput 1,
// radiance 0, eta scale 1, bounce 0, no flags, no BSDF pdf), pixel = pixel_offset + slot %
// wave_pixels, and a ray from the eye that, projected back through the host's device camera
// (device_camera, kernels/camera/camera.h), falls inside its pixel's square. Two waves: the whole
// image with 4 samples per pixel, and a part of it from pixel 500 with 3 samples from sample index
// 7; slots past the wave's paths are left alone.
TEST_F(Stages, GenerateCameraRaysStartEveryPathInItsPixel) {
  const wp::dev::Camera cam = wp::device_camera(scene_->cameras.at(0), kWidth, kHeight);
  const dvec3 eye = dxyz(cam.position), fwd = dxyz(cam.forward), right = dxyz(cam.right),
              up = dxyz(cam.up);
  struct Wave {
    std::uint32_t sample, first, count, samples;
  };
  for (const Wave w : {Wave{0, 0, kPixels, kSamples}, Wave{7, 500, kPixels - 500, 3}}) {
    SCOPED_TRACE("pixels from " + std::to_string(w.first) + ", " + std::to_string(w.samples) +
                 " samples from " + std::to_string(w.sample));
    wf_->restore(bounces_[0].start);
    for (const Field& field : kFields) poison(layout().*field.offset);
    wf_->write_queue(WP_QUEUE_RAY_A, std::vector<std::uint32_t>(kPaths, 0u));  // stale entries
    const PathView before = view();
    wp::dev::Launch p = wf_->launch_params(w.sample, w.first, w.count, w.samples);
    p.queue_out = WP_QUEUE_RAY_A;
    wf_->launch_stage(Stage::kGenerateCameraRays, p.path_count, p);
    wf_->finish();
    const PathView after = view();

    // Every slot of the wave exactly once.
    ASSERT_EQ(after.counter(WP_QUEUE_RAY_A), p.path_count);
    const std::set<std::uint32_t> queued = queue_set(after.queue(WP_QUEUE_RAY_A), "rays");
    EXPECT_EQ(queued.size(), p.path_count);
    if (!queued.empty()) {
      EXPECT_EQ(*queued.rbegin(), p.path_count - 1);
    }

    Failures f("camera rays");
    double sum_x = 0, sum_y = 0, sum_x2 = 0, sum_y2 = 0;
    for (std::uint32_t slot = 0; slot < p.path_count; ++slot) {
      const std::uint32_t pixel = w.first + slot % w.count;
      const std::uint32_t bounce = bits(after.f4(layout().shadow_l, slot).w),
                          flags = bits(after.f4(layout().shadow_d, slot).w);
      WP_CHECK(f, bounce == 0u && flags == 0u,
               "slot " << slot << ": bounce " << bounce << " flags " << flags);
      const float4 beta = after.f4(layout().throughput, slot);
      WP_CHECK(f, beta.x == 1.0f && beta.y == 1.0f && beta.z == 1.0f && bits(beta.w) == 0u,
               "slot " << slot << " throughput " << str(dxyz(beta)) << " pdf " << beta.w);
      const float4 l = after.f4(layout().radiance, slot);
      WP_CHECK(f, bits(l.x) == 0u && bits(l.y) == 0u && bits(l.z) == 0u && l.w == 1.0f,
               "slot " << slot << " radiance " << str(dxyz(l)) << " eta scale " << l.w);
      const float4 o = after.f4(layout().ray_o, slot), d4 = after.f4(layout().ray_d, slot);
      WP_CHECK(f, o.x == cam.position.x && o.y == cam.position.y && o.z == cam.position.z,
               "slot " << slot << " origin " << str(dxyz(o)) << ", the eye " << str(eye));
      WP_CHECK(f, bits(d4.w) == 0u, "slot " << slot << " pane distance " << d4.w);
      const dvec3 d = dxyz(d4);
      // A unit vector normalised in float: within a few ulps of length 1.
      WP_CHECK(f, std::fabs(glm::length(d) - 1.0) < 1e-6,
               "slot " << slot << " |d| " << glm::length(d));
      // Nothing nearer than znear along the view direction: tmin = znear / cos(d, forward), to
      // float rounding.
      const double tmin = cam.position.w / glm::dot(d, fwd);
      WP_CHECK(f, std::fabs(o.w - tmin) <= 1e-6 * tmin,
               "slot " << slot << " tmin " << o.w << ", expected " << tmin);
      // Back through the camera: d is parallel to fwd + x right + y up (orthogonal vectors, right
      // and up the half extents), so x = (d.right) / (|right|^2 d.fwd), likewise y; then the image
      // point in pixels. Float rounding of the direction moves it by ~1e-6 pixel: 1e-4 is slack.
      const double nx = glm::dot(d, right) / (glm::dot(right, right) * glm::dot(d, fwd));
      const double ny = glm::dot(d, up) / (glm::dot(up, up) * glm::dot(d, fwd));
      const double fx = (nx + 1.0) * 0.5 * kWidth - pixel % kWidth;
      const double fy = (1.0 - ny) * 0.5 * kHeight - pixel / kWidth;
      WP_CHECK(f, fx > -1e-4 && fx < 1.0 + 1e-4 && fy > -1e-4 && fy < 1.0 + 1e-4,
               "slot " << slot << " pixel " << pixel << ": the ray passes at (" << fx << ", " << fy
                       << ") within the pixel");
      sum_x += fx, sum_y += fy, sum_x2 += fx * fx, sum_y2 += fy * fy;
    }
    // The jitter is uniform in the pixel (a box filter): over n independent uniform positions the
    // mean is 1/2 with standard error sqrt(1/12 / n) and the variance 1/12 with standard error
    // sqrt((1/80 - 1/144) / n); within 5 of them (Sobol' points are closer still). A constant or
    // clustered jitter fails here though it stays inside the pixel.
    const double n = p.path_count;
    for (const auto& [s, s2] : {std::pair{sum_x, sum_x2}, std::pair{sum_y, sum_y2}}) {
      const double mean = s / n, var = s2 / n - mean * mean;
      EXPECT_NEAR(mean, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n));
      EXPECT_NEAR(var, 1.0 / 12.0, 5.0 * std::sqrt((1.0 / 80.0 - 1.0 / 144.0) / n));
    }
    // Slots past the wave's paths are not touched.
    std::vector<std::uint32_t> rest;
    for (std::uint32_t slot = p.path_count; slot < kPaths; ++slot) rest.push_back(slot);
    expect_unchanged(before, after, rest, {}, "slots past the wave");
  }
}

// intersect_closest: the hit of every queued ray equals the CPU reference traversal of the same
// BVH (bvh::intersect_closest, bvh/traverse_common.h: the same arithmetic, no fused
// multiply-adds, so bit for bit on a CPU device, whose single-precision division is IEEE's; OpenCL
// 1.2 lets other devices divide within 2.5 ulp, which the watertight test's shear and inverse
// determinant carry into t, u and v: there the same triangle, with u, v within 4e-6 and t within
// 4e-6 of the larger of t and the origin's largest coordinate (the test works in coordinates
// relative to the origin, so a rounding there moves t by as much however near the hit is): some
// 20 times the largest differences an NVIDIA H200 showed, 2.1e-7 in u, 1.8e-8 in t at t 3e-4),
// t, barycentrics and triangle; a miss is t = INFINITY, u = v = 0,
// triangle 0. Camera rays (bounce 0) and BSDF-sampled rays leaving surfaces (bounces 1 and 2),
// on both BVH layouts; and the camera rays again with another tmin (0.9 or 1.0, the eye being 0.8
// before the box), which the renderer's rays leave at znear or 0 (a ray has no far end). Nothing
// but the queued slots' hit records changes.
TEST_F(Stages, IntersectClosestMatchesTheCpuTraversal) {
  const bool exact_division =
      runtime_->device().device.getInfo<CL_DEVICE_TYPE>() == CL_DEVICE_TYPE_CPU;
  for (const Traversal& tr : traversals()) {
    for (int k = 0; k <= kBounces; ++k) {
      const bool window = k == kBounces;
      const int b = window ? 0 : k;
      SCOPED_TRACE(tr.name + ", bounce " + std::to_string(b) +
                   (window ? ", rays with tmin set" : ""));
      const Bounce& c = bounces_[b];
      tr.wf->restore(c.start);  // the bounce's rays, as intersect_closest finds them
      if (window) {
        const PathView start(c.start, layout());
        std::vector<float4> o(kPaths);
        for (std::uint32_t slot = 0; slot < kPaths; ++slot) {
          o[slot] = start.f4(layout().ray_o, slot);
          o[slot].w = slot % 2 ? 0.9f : 1.0f;
        }
        tr.wf->write_paths(layout().ray_o, o);
      }
      poison(layout().hit, *tr.wf);
      const PathView before = view(*tr.wf);
      launch(Stage::kIntersectClosest, c, c.params, *tr.wf);
      const PathView after = view(*tr.wf);
      const std::vector<std::uint32_t> rays = before.queue(c.params.queue_in);
      ASSERT_EQ(rays.size(), c.rays);
      const std::set<std::uint32_t> queued = queue_set(rays, "rays");
      std::size_t hits = 0;
      Failures f("hits against the CPU traversal");
      for (const std::uint32_t slot : rays) {
        const float4 o = before.f4(layout().ray_o, slot), d = before.f4(layout().ray_d, slot);
        const wp::bvh::Hit ref = wp::bvh::intersect_closest(*tr.bvh, {xyz(o), xyz(d), o.w, kInf});
        const float4 h = after.f4(layout().hit, slot);
        hits += ref.hit;
        if (ref.hit) {
          const bool same =
              exact_division
                  ? bits(h.x) == bits(ref.t) && bits(h.y) == bits(ref.u) && bits(h.z) == bits(ref.v)
                  : std::fabs(h.x - ref.t) <= 4e-6f * std::max({ref.t, std::fabs(o.x),
                                                                std::fabs(o.y), std::fabs(o.z)}) &&
                        std::fabs(h.y - ref.u) <= 4e-6f && std::fabs(h.z - ref.v) <= 4e-6f;
          WP_CHECK(f, same && bits(h.w) == ref.triangle,
                   "slot " << slot << ": t " << h.x << " u " << h.y << " v " << h.z << " triangle "
                           << bits(h.w) << ", the reference " << ref.t << " " << ref.u << " "
                           << ref.v << " " << ref.triangle);
        } else {
          WP_CHECK(f, h.x == kInf && bits(h.y) == 0u && bits(h.z) == 0u && bits(h.w) == 0u,
                   "slot " << slot << ": a miss for the reference, the kernel t " << h.x
                           << " triangle " << bits(h.w));
        }
      }
      // Both cases occur: camera rays past the box's edges and rays out of its open front miss.
      EXPECT_GT(hits, rays.size() / (window ? 10 : 2));
      EXPECT_LT(hits, rays.size());
      expect_unchanged(before, after, all_slots(), {"hit"}, "besides the hit record");
      std::vector<std::uint32_t> others;
      for (std::uint32_t slot = 0; slot < kPaths; ++slot)
        if (!queued.count(slot)) others.push_back(slot);
      expect_unchanged(before, after, others, {}, "slots not queued");
    }
  }
}

// trace_shadow: a path's radiance grows by exactly its shadow contribution (one float addition
// per channel) when the CPU reference any-hit traversal (bvh::occluded, the kernels' arithmetic)
// finds nothing on the segment (0, tmax), and stays bit for bit the same otherwise. The shadow
// rays are the ones sample_lights made in bounces 0 and 1, to the ceiling light and to the
// background; both outcomes occur. Both BVH layouts. Nothing else changes.
TEST_F(Stages, TraceShadowAddsUnoccludedContributions) {
  for (int b = 0; b < 2; ++b) {
    const Bounce& c = bounces_[b];
    input(Stage::kTraceShadow, b);
    const wp::Wavefront::Snapshot shadow_rays = wf_->snapshot();
    for (const Traversal& tr : traversals()) {
      SCOPED_TRACE(tr.name + ", bounce " + std::to_string(b));
      tr.wf->restore(shadow_rays);
      const PathView before = view(*tr.wf);
      launch(Stage::kTraceShadow, c, c.params, *tr.wf);
      const PathView after = view(*tr.wf);
      const std::set<std::uint32_t> shadows = queue_set(before.queue(WP_QUEUE_SHADOW), "shadow");
      Failures f("shadow rays against the CPU traversal");
      std::size_t occluded = 0;
      for (const std::uint32_t slot : shadows) {
        const float4 o = before.f4(layout().shadow_o, slot), d = before.f4(layout().shadow_d, slot);
        const bool blocked = wp::bvh::occluded(*tr.bvh, {xyz(o), xyz(d), 0.0f, o.w});
        occluded += blocked;
        const vec3 l0 = before.v3(layout().radiance, slot), l = after.v3(layout().radiance, slot);
        const vec3 expected = blocked ? l0 : l0 + before.v3(layout().shadow_l, slot);
        WP_CHECK(f,
                 bits(l.x) == bits(expected.x) && bits(l.y) == bits(expected.y) &&
                     bits(l.z) == bits(expected.z),
                 "slot " << slot << (blocked ? " (occluded)" : " (unoccluded)") << " radiance "
                         << str(l) << ", expected " << str(expected));
      }
      EXPECT_GT(occluded, 0u);
      EXPECT_LT(occluded, shadows.size());
      expect_unchanged(before, after, all_slots(), {"radiance"}, "besides radiance");
      std::vector<std::uint32_t> others;
      for (std::uint32_t slot = 0; slot < kPaths; ++slot)
        if (!shadows.count(slot)) others.push_back(slot);
      expect_unchanged(before, after, others, {}, "slots without a shadow ray");
    }
  }
}

}  // namespace
}  // namespace wp::test::stages
