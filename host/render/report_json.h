// The render's settings and report as OpenEXR header attributes and as one line of JSON.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "host/render/render.h"
#include "host/util/json.h"

namespace wp {

std::map<std::string, std::string> exr_attributes(const std::string& scene,
                                                  const RenderSettings& settings,
                                                  const RenderReport& report);

// The attributes of an image made from a film alone (`wavepath merge`): spp, samples (A:B),
// device, render_key, nonfinite_samples, units.
std::map<std::string, std::string> film_exr_attributes(const FilmInfo& film);

// One JSON object on one line. Keys: spp (the samples in the image), sample_begin, sample_end,
// spp_requested, stop (stop_reason_name), passes (rendered by this run; not resumed ones),
// relative_error (film.h), checkpoints, width, height, seconds (the
// sample passes), samples_per_second (pixel samples), device, triangles, kernel_build_seconds,
// bvh_build_seconds, bvh_sah_cost, setup_seconds, first_pass_seconds, load_seconds,
// total_seconds, nonfinite_samples, rays, features, wave_size, bytes_per_path, scene_bytes,
// scene_buffers, ranks (processes of an MPI job), outputs, closest_packets (null where the
// program has no closest-hit packets, else per bounce index, the last for every deeper bounce
// too: {bounce, choice "packets" | "single" | "timing", single_ns_per_ray, packet_ns_per_ray,
// timed_rays [single, packets]}; a bounce index not listed traced single rays), shadow_packets
// (the same for shadow rays), and with
// profiling stage_seconds {stage: seconds}.
std::string report_json(const RenderSettings& settings, const RenderReport& report,
                        double load_seconds, double total_seconds,
                        const std::vector<std::string>& outputs);

}  // namespace wp
