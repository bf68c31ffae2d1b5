#include "host/bench/embree_ref.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

#include "host/accel/bvh_input.h"
#include "host/util/error.h"

namespace wp::bench {

namespace {

constexpr std::size_t kChunk = 256;  // rays a worker takes at a time

void trace_one(RTCScene scene, const RefRay& r, bool occlusion, std::size_t& hits) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  if (occlusion) {
    RTCRay ray{r.o[0], r.o[1], r.o[2], r.tmin, r.d[0], r.d[1], r.d[2], 0.0f, r.tmax, ~0u, 0, 0};
    rtcOccluded1(scene, &ctx, &ray);
    hits += ray.tfar < 0.0f;  // Embree marks an occluded ray with tfar = -inf
  } else {
    RTCRayHit rh{};
    rh.ray = {r.o[0], r.o[1], r.o[2], r.tmin, r.d[0], r.d[1], r.d[2], 0.0f, r.tmax, ~0u, 0, 0};
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  }
}

// `passes` passes over `rays` by `threads` workers; returns the wall seconds and the hits.
double run_passes(RTCScene scene, const std::vector<RefRay>& rays, bool occlusion, unsigned threads,
                  std::size_t passes, std::size_t& hits) {
  const std::size_t n = rays.size(), total = n * passes;
  std::atomic<std::size_t> next{0}, all_hits{0};
  const auto worker = [&] {
    std::size_t mine = 0;
    for (;;) {
      const std::size_t begin = next.fetch_add(kChunk, std::memory_order_relaxed);
      if (begin >= total) break;
      const std::size_t end = std::min(begin + kChunk, total);
      for (std::size_t i = begin; i < end; ++i) trace_one(scene, rays[i % n], occlusion, mine);
    }
    all_hits += mine;
  };
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  hits = all_hits / passes;
  return seconds;
}

}  // namespace

EmbreeRef::EmbreeRef(const Scene& s) {
  if (s.instances.empty()) {
    flat_ = std::make_unique<bvh::EmbreeScene>(s.positions.data(), s.positions.size(),
                                               s.indices.data(), s.triangle_count(),
                                               /*robust=*/false);
    handle_ = flat_->handle();
    return;
  }
  instanced_ = embree_instances(s, /*robust=*/false);
  handle_ = instanced_->handle();
}

RefTiming EmbreeRef::measure(const std::vector<RefRay>& rays, bool occlusion, unsigned threads,
                             double min_seconds) const {
  RefTiming t;
  if (rays.empty()) return t;
  threads = std::max(threads, 1u);
  const double warm = run_passes(handle_, rays, occlusion, threads, 1, t.hits);
  t.passes = static_cast<std::size_t>(
      std::clamp(std::ceil(min_seconds / std::max(warm, 1e-6)), 1.0, 10000.0));
  t.seconds_per_pass = run_passes(handle_, rays, occlusion, threads, t.passes, t.hits) /
                       static_cast<double>(t.passes);
  return t;
}

}  // namespace wp::bench
