#include "host/render/report_json.h"

#include <cstdio>
#include <sstream>

#include "host/util/json.h"

namespace wp {

namespace {
constexpr const char* kUnits = "linear RGB radiance (W/(sr m^2) per channel)";

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
}  // namespace

std::map<std::string, std::string> exr_attributes(const std::string& scene, const RenderSettings& s,
                                                  const RenderReport& r) {
  return {{"wavepath:scene", scene},
          {"wavepath:spp", std::to_string(r.sample_end - s.sample_begin)},
          {"wavepath:spp_requested", std::to_string(s.spp)},
          {"wavepath:stop", stop_reason_name(r.stop)},
          {"wavepath:relative_error", num(r.relative_error)},
          {"wavepath:samples", std::to_string(s.sample_begin) + ":" + std::to_string(r.sample_end)},
          {"wavepath:max_depth", std::to_string(s.max_depth)},
          {"wavepath:rr_depth", std::to_string(s.rr_depth)},
          {"wavepath:rr_threshold", num(s.rr_threshold)},
          {"wavepath:seed", std::to_string(s.seed)},
          {"wavepath:camera", std::to_string(s.camera)},
          {"wavepath:view", view_text(s.view)},
          {"wavepath:background",
           num(s.background.x) + "," + num(s.background.y) + "," + num(s.background.z)},
          {"wavepath:strategy", s.strategy == Strategy::kMis   ? "mis"
                                : s.strategy == Strategy::kNee ? "nee"
                                                               : "bsdf"},
          {"wavepath:mis_heuristic", s.mis_heuristic == MisHeuristic::kPower ? "power" : "balance"},
          {"wavepath:light_select", s.light_select == LightSelect::kPower ? "power" : "uniform"},
          {"wavepath:sampler", sampler_name(s.sampler)},
          {"wavepath:environment", s.environment ? s.environment->source : std::string("constant")},
          {"wavepath:env_intensity", num(s.env_intensity)},
          {"wavepath:env_rotation", num(s.env_rotation)},
          {"wavepath:env_filter", env_filter_name(s.env_filter)},
          {"wavepath:mipmaps", s.mipmaps ? "on" : "off"},
          {"wavepath:device", r.device},
          {"wavepath:features", r.features},
          {"wavepath:nonfinite_samples", std::to_string(r.nonfinite_samples)},
          {"wavepath:units", kUnits}};
}

std::map<std::string, std::string> film_exr_attributes(const FilmInfo& f) {
  return {{"wavepath:spp", std::to_string(f.samples())},
          {"wavepath:samples", std::to_string(f.sample_begin) + ":" + std::to_string(f.sample_end)},
          {"wavepath:device", f.device},
          {"wavepath:render_key", f.key},
          {"wavepath:nonfinite_samples", std::to_string(f.nonfinite_samples)},
          {"wavepath:units", kUnits}};
}

std::string report_json(const RenderSettings& s, const RenderReport& r, double load_seconds,
                        double total_seconds, const std::vector<std::string>& outputs) {
  std::ostringstream o;
  o << "{\"spp\":" << r.sample_end - s.sample_begin << ",\"sample_begin\":" << s.sample_begin
    << ",\"sample_end\":" << r.sample_end << ",\"spp_requested\":" << s.spp
    << ",\"stop\":" << json_string(stop_reason_name(r.stop)) << ",\"passes\":" << r.passes
    << ",\"relative_error\":" << num(r.relative_error) << ",\"checkpoints\":" << r.checkpoints
    << ",\"width\":" << s.width << ",\"height\":" << s.height
    << ",\"seconds\":" << num(r.render_seconds) << ",\"samples_rendered\":" << r.samples_rendered
    << ",\"samples_per_second\":" << num(r.samples_per_second(s))
    << ",\"device\":" << json_string(r.device) << ",\"triangles\":" << r.triangles
    << ",\"instances\":" << r.instances << ",\"world_triangles\":" << r.world_triangles
    << ",\"kernel_build_seconds\":" << num(r.kernel_build_seconds)
    << ",\"kernel_binary_bytes\":" << r.kernel_binary_bytes
    << ",\"bvh_build_seconds\":" << num(r.bvh.build_seconds)
    << ",\"bvh_sah_cost\":" << num(r.bvh.sah_cost)
    << ",\"bvh_cached\":" << (r.bvh_cached ? "true" : "false")
    << ",\"kernel_cached\":" << (r.kernel_cached ? "true" : "false")
    << ",\"setup_seconds\":" << num(r.setup_seconds)
    << ",\"first_pass_seconds\":" << num(r.first_pass_seconds)
    << ",\"load_seconds\":" << num(load_seconds) << ",\"total_seconds\":" << num(total_seconds)
    << ",\"nonfinite_samples\":" << r.nonfinite_samples << ",\"rays\":" << r.rays
    << ",\"features\":" << json_string(r.features)
    << ",\"build_options\":" << json_string(r.build_options) << ",\"wave_size\":" << r.wave_size
    << ",\"bytes_per_path\":" << r.bytes_per_path << ",\"scene_bytes\":" << r.scene_bytes
    << ",\"texture_bytes\":" << r.texture_bytes << ",\"mip_bytes\":" << r.mip_bytes
    << ",\"scene_buffers\":" << r.scene_buffers << ",\"ranks\":" << r.ranks << ",\"outputs\":[";
  for (std::size_t i = 0; i < outputs.size(); ++i) o << (i ? "," : "") << json_string(outputs[i]);
  o << "]";
  // Per bounce index: the walk kept and what each cost per ray while it was timed.
  const auto packets = [&o](const char* key, std::uint32_t packet,
                            const std::vector<PacketTiming>& timing) {
    o << ",\"" << key << "\":";
    if (packet <= 1) {
      o << "null";
      return;
    }
    const auto per_ray = [](const PacketTiming& t, int m) {
      return t.rays[m] ? num(t.seconds[m] * 1e9 / static_cast<double>(t.rays[m])) : "null";
    };
    o << "[";
    for (std::size_t b = 0; b < timing.size(); ++b) {
      const PacketTiming& t = timing[b];
      o << (b ? "," : "") << "{\"bounce\":" << b << ",\"choice\":"
        << (t.choice < 0    ? "\"timing\""
            : t.choice == 1 ? "\"packets\""
                            : "\"single\"")
        << ",\"single_ns_per_ray\":" << per_ray(t, 0) << ",\"packet_ns_per_ray\":" << per_ray(t, 1)
        << ",\"timed_rays\":[" << t.rays[0] << "," << t.rays[1] << "]}";
    }
    o << "]";
  };
  packets("closest_packets", r.closest_packet, r.closest_packets);
  packets("shadow_packets", r.shadow_packet, r.shadow_packets);
  if (s.profile) {
    o << ",\"stage_seconds\":{";
    for (int i = 0; i < kStageCount; ++i)
      o << (i ? "," : "") << json_string(kStageNames[i]) << ":" << num(r.stages.seconds[i]);
    o << "}";
  }
  o << "}";
  return o.str();
}

}  // namespace wp
