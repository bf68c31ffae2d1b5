// The options of a render as a user gives them (the command line, tests, benchmarks). render()
// resolves them once, for a device and a scene, into a RenderPlan (plan.h), which the wavefront
// loop (wavefront.h) takes.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <glm/vec3.hpp>

#include "host/lights/environment.h"
#include "host/lights/light_table.h"
#include "host/scene/view.h"

namespace wp {

enum class Strategy { kMis, kNee, kBsdf };
enum class MisHeuristic { kPower, kBalance };
// Sample pattern (kernels/sampling/rng.h): Owen-scrambled Sobol' points, the light and BSDF pairs
// of two bounces chained to one sample order (kSobol) or every group in an order of its own
// (kSobolPadded), or independent hashes.
enum class Sampler { kSobol, kIndependent, kSobolPadded };
// The --sampler name of a pattern ("sobol", "independent", "sobol-padded").
const char* sampler_name(Sampler s);

struct RenderSettings {
  int width = 640;
  int height = 480;
  int spp = 64;  // samples per pixel
  // The render takes sample indices [sample_begin, sample_begin + spp), within [0, 2^20): a
  // part of a longer render, whose films merge exactly (host/film/film.h).
  int sample_begin = 0;
  // Record albedo, normal and depth per sample too (AOVs, kernels/shared/film.h; FilmImages).
  bool aov = false;
  int max_depth = 12;  // scattering events per path at most
  // Russian roulette from this many scattering events on (>= max_depth: off); why 5: the study in
  // docs/accuracy.md, "Russian roulette".
  int rr_depth = 5;
  // Roulette's throughput threshold: from rr_depth on, a path whose throughput (largest channel,
  // kernels/integrator/roulette_compact.h) m is below it survives with probability
  // m / rr_threshold and then carries rr_threshold; at or above it, always. 1 is pbrt's rule
  // (survival probability = throughput); why 0.5: docs/accuracy.md, "the survival threshold".
  float rr_threshold = 0.5f;
  std::uint32_t seed = 0;      // the image is a pure function of (scene, settings, seed)
  glm::vec3 background{0.0f};  // radiance of escaped rays when there is no environment map
  std::shared_ptr<const EnvironmentMap> environment;  // optional
  float env_intensity = 1.0f;                         // scales the map
  float env_rotation = 0.0f;                          // degrees about +Y
  // The map's lookup (--env-filter); a map whose tables were built for the other filter gets
  // tables rebuilt for this one (Wavefront's constructor).
  EnvFilter env_filter = EnvFilter::kBilinear;
  // Minify textures through mip chains at the level of each path's ray cone (--mipmaps;
  // kernels/texture/ray_cone.h), where the scene has a texture whose sampler allows mip-maps.
  bool mipmaps = true;
  Strategy strategy = Strategy::kMis;
  MisHeuristic mis_heuristic = MisHeuristic::kPower;
  LightSelect light_select = LightSelect::kPower;
  Sampler sampler = Sampler::kSobol;
  int camera = -1;            // index into Scene::cameras; -1: the first, or a framing camera
  View view;                  // a camera placed from the command line, field of view, lens (view.h)
  bool all_features = false;  // build every kernel feature regardless of the scene
  // Path slots per wave; 0: the device's (auto_wave_paths, wave_shape) on a CPU device, else
  // min(pixels, 2^20), or for an image of fewer than kMultiSamplePaths pixels, as many whole
  // samples of it as fit in kMultiSamplePaths. A size above the pixel count also holds several
  // samples (its quotient by the pixel count).
  std::size_t wave_size = 0;
  std::size_t local_size = 0;  // work-group size; 0: 64
  bool profile = false;        // time every kernel launch with profiling events
  // One fused kernel per bounce for everything at a hit (kernels/shade.cl), or the split stages
  // (shade_surface, sample_lights, sample_bsdf, roulette_compact): the same image bit for bit
  // (pipeline.h). Fused by default: the faster on PoCL (docs/performance.md, "Fused shading").
  bool fused = true;
  // Cache hints for the path state ahead in each queue, on PoCL's CPU devices
  // (kernels/util/features.h, WP_PREFETCH); elsewhere nothing. The same image either way.
  bool prefetch = true;
  // Shadow rays traced eight to a work-item where they are plain any-hit queries, on PoCL's CPU
  // devices with the wide BVH (kernels/traversal/traverse8_packet.h), at the bounces where the
  // first waves timed that faster (Wavefront::packet_mode); elsewhere one each. The same image.
  bool shadow_packets = true;
  // Closest-hit rays likewise, where the program has no instances or alpha (the same walk's
  // closest-hit form: the answer does not depend on which rays share a packet).
  bool closest_packets = true;
  // trace_shadow launched before its queue's length is read back, over this times the share of
  // shadow rays the same bounce of the last wave had (Wavefront::run_bounce), the rest, if any,
  // once the length is known; 0: always after the read-back, over the exact length. The same
  // image; tests set it below 1 so that the rest is launched.
  float shadow_ahead = 1.03f;
  // The fused shade kernel eight paths per work-item (kernels/integrator/shade_packet.h) on
  // PoCL's CPU devices, in scenes of untextured surfaces, Lambertian or metallic-roughness
  // without extensions or transmission, without instances or AOVs. The same image.
  bool shade_packets = true;
  // The packet kernels above on any device, not only on PoCL's CPU devices (tests run them under
  // Oclgrind with it). The same image.
  bool force_packets = false;
  int bvh_width = 0;  // BVH layout: 2, 8, or 0 for the device's default (render.h)
  // Where built kernel programs are cached (host/device/program_cache.h; the command line passes
  // bvh::cache_dir()); empty: nothing is cached.
  std::string kernel_cache_dir;
  // Most bytes in one scene buffer (device_scene.h); 0: the device's largest allocation. Smaller
  // values split even small scenes over several buffers (tests).
  std::uint64_t scene_buffer_bytes = 0;
};

}  // namespace wp
