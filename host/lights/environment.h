// Environment lighting: an equirectangular radiance map (.hdr by a bounded reader of its own, .exr
// via OpenEXR) and the tables that importance-sample it (kernels/lights/environment.h reads them).
//
// Direction convention (+Y up, glTF's frame): the map's u runs with the azimuth
// phi = atan2(d.x, -d.z), u = (phi + pi) / (2 pi), so the centre column (u = 0.5) is seen looking
// down -Z (a glTF camera at rest); v = acos(d.y) / pi, row 0 at the top (+Y). A rotation of R
// degrees turns the map about +Y by R (counter-clockwise seen from above).
#pragma once

#include <string>
#include <vector>

#include <glm/vec4.hpp>

namespace wp {

// How escaped rays look the map up (--env-filter; kernels/lights/environment.h): the nearest texel,
// or bilinear interpolation between the four texel centres around the direction. The sampling
// tables depend on it: bilinear tables give each texel the largest luminance of its 3 x 3
// neighbourhood.
enum class EnvFilter { kNearest, kBilinear };
const char* env_filter_name(EnvFilter f);  // "nearest", "bilinear"

struct EnvironmentMap {
  std::string source;
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;  // linear RGB radiance, row by row from the top; w unused
  // Sampling tables in the layout kernels/lights/environment.h expects (see there).
  std::vector<float> marginal;             // per row
  std::vector<float> conditional;          // per texel
  EnvFilter filter = EnvFilter::kNearest;  // the lookup the tables were built for
  // Mean radiance luminance over the sphere (solid-angle weighted), for light selection by power.
  double mean_luminance = 0.0;
  double max_radiance = 0.0;  // the largest texel channel (--env-intensity's limit)
  // What loading changed, one line each (texels beyond kMaxRadiance clamped to it).
  std::vector<std::string> warnings;
};

// Loads an equirectangular map. Throws wp::Error naming the file when it is missing, not a regular
// file, unreadable, of an unsupported format, malformed or truncated, larger than 2^28 texels, or
// holds non-finite or negative values. Texels above scene.h's kMaxRadiance (a .hdr holds up to
// 1.7e38) are clamped to it, with a warning in env.warnings.
EnvironmentMap load_environment(const std::string& path, EnvFilter filter = EnvFilter::kNearest);

// Builds the sampling tables for `filter` (and sets env.filter) and mean_luminance (the nearest
// map's, whatever the filter: it only weighs light selection) from texels/width/height.
void build_environment_tables(EnvironmentMap& env, EnvFilter filter = EnvFilter::kNearest);

}  // namespace wp
