#include "host/lights/emission.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "host/scene/srgb.h"

namespace wp {

namespace {

// Texel index i (any integer) wrapped into [0, n) as the sampler wraps
// (kernels/texture/textures.h).
int wrap_texel(long long i, int n, Wrap mode) {
  if (mode == Wrap::kClampToEdge) return static_cast<int>(std::clamp<long long>(i, 0, n - 1));
  if (mode == Wrap::kMirroredRepeat) {
    long long m = i % (2LL * n);
    if (m < 0) m += 2LL * n;
    return static_cast<int>(m < n ? m : 2LL * n - 1 - m);
  }
  long long m = i % n;
  return static_cast<int>(m < 0 ? m + n : m);
}

// The values of the 256 codes, decoded (srgb) or not: made once, not per triangle (a 46,000
// triangle emitter made them 46,000 times, a tenth of DamagedHelmet's start-up).
const std::array<double, 256>& decode_table(bool srgb) {
  static const auto make = [](bool s) {
    std::array<double, 256> t{};
    for (int c = 0; c < 256; ++c) t[std::size_t(c)] = s ? srgb_to_linear(c / 255.0) : c / 255.0;
    return t;
  };
  static const std::array<double, 256> colour = make(true), data = make(false);
  return srgb ? colour : data;
}

// A texture's image with its decoding, for lookups by texel index.
class TexelReader {
 public:
  TexelReader(const Image& img, bool srgb) : img_(img), decode_(decode_table(srgb)) {}
  glm::dvec3 fetch(int x, int y) const {
    const std::uint8_t* p = &img_.rgba[4 * (static_cast<std::size_t>(y) * img_.width + x)];
    return {decode_[p[0]], decode_[p[1]], decode_[p[2]]};
  }

 private:
  const Image& img_;
  const std::array<double, 256>& decode_;
};

// The texture at texture-space point (x, y) = uv x size, filtered as the kernels filter.
glm::dvec3 filtered(const TexelReader& r, const TextureRef& t, int w, int h, double x, double y) {
  if (t.nearest)
    return r.fetch(wrap_texel(static_cast<long long>(std::floor(x)), w, t.wrap_s),
                   wrap_texel(static_cast<long long>(std::floor(y)), h, t.wrap_t));
  const double fx = x - 0.5, fy = y - 0.5, x0 = std::floor(fx), y0 = std::floor(fy);
  const double ax = fx - x0, ay = fy - y0;
  const auto i0 = static_cast<long long>(x0), j0 = static_cast<long long>(y0);
  const int a = wrap_texel(i0, w, t.wrap_s), b = wrap_texel(i0 + 1, w, t.wrap_s);
  const int c = wrap_texel(j0, h, t.wrap_t), d = wrap_texel(j0 + 1, h, t.wrap_t);
  const glm::dvec3 top = (1.0 - ax) * r.fetch(a, c) + ax * r.fetch(b, c);
  const glm::dvec3 bottom = (1.0 - ax) * r.fetch(a, d) + ax * r.fetch(b, d);
  return (1.0 - ay) * top + ay * bottom;
}

double max3(glm::dvec3 v) {
  return std::max(v.x, std::max(v.y, v.z));
}

}  // namespace

TriangleEmission triangle_emission(const Scene& scene, std::size_t tri) {
  const Material& m = scene.materials[scene.triangle_material[tri]];
  TriangleEmission e;
  if (!(std::max(m.emission.x, std::max(m.emission.y, m.emission.z)) > 0.0f)) return e;
  if (m.emissive_texture < 0) {
    e.mean = m.emission;
    e.peak = std::max(m.emission.x, std::max(m.emission.y, m.emission.z));
    return e;
  }
  const TextureRef& t = scene.textures[static_cast<std::size_t>(m.emissive_texture)];
  const Image& img = scene.images[static_cast<std::size_t>(t.image)];
  const int w = img.width, h = img.height;
  const std::vector<glm::vec2>& uvs = t.texcoord == 1 ? scene.uv1 : scene.uv0;
  // Texture-space corners (KHR_texture_transform applied), in texels.
  std::array<glm::dvec2, 3> p;
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t v = scene.indices[3 * tri + k];
    const glm::dvec2 uv = v < uvs.size() ? glm::dvec2(uvs[v]) : glm::dvec2(0.0);
    p[k] = {(t.row_u.x * uv.x + t.row_u.y * uv.y + t.row_u.z) * w,
            (t.row_v.x * uv.x + t.row_v.y * uv.y + t.row_v.z) * h};
  }
  const glm::dvec3 factor(m.emission);
  const TexelReader reader(img, t.srgb);

  // Peak: every texel the filter can reach from the triangle, i.e. its bounding box grown by one
  // texel (bilinear reaches the neighbours of the texel a point is in). A box wider than the
  // image in a wrapping direction covers the whole image there.
  const double lo_x = std::min({p[0].x, p[1].x, p[2].x}), hi_x = std::max({p[0].x, p[1].x, p[2].x});
  const double lo_y = std::min({p[0].y, p[1].y, p[2].y}), hi_y = std::max({p[0].y, p[1].y, p[2].y});
  if (!std::isfinite(lo_x + hi_x + lo_y + hi_y)) {  // no usable coordinates: stay a light
    e.mean = m.emission;
    e.peak = static_cast<float>(max3(factor));
    return e;
  }
  const auto span = [](double lo, double hi, int n) {
    const double a = std::floor(lo) - 1.0, b = std::floor(hi) + 1.0;
    return b - a + 1.0 >= n ? std::pair<long long, long long>{0, n - 1}
                            : std::pair<long long, long long>{static_cast<long long>(a),
                                                              static_cast<long long>(b)};
  };
  const auto [x0, x1] = span(lo_x, hi_x, w);
  const auto [y0, y1] = span(lo_y, hi_y, h);
  double peak = 0.0;
  for (long long y = y0; y <= y1; ++y)
    for (long long x = x0; x <= x1; ++x)
      peak = std::max(peak, max3(factor * reader.fetch(wrap_texel(x, w, t.wrap_s),
                                                       wrap_texel(y, h, t.wrap_t))));
  e.peak = static_cast<float>(peak);
  if (!(peak > 0.0)) return e;

  // Mean: midpoints of an n x n grid in the square that maps area-uniformly onto the triangle
  // (b1 = sqrt(s) (1 - t), b2 = sqrt(s) t, the mapping NEE samples with), n growing with the
  // texels the triangle covers.
  const double texels = 0.5 * std::fabs((p[1].x - p[0].x) * (p[2].y - p[0].y) -
                                        (p[2].x - p[0].x) * (p[1].y - p[0].y));
  const int n = static_cast<int>(std::clamp(std::ceil(std::sqrt(texels)), 16.0, 32.0));
  glm::dvec3 sum(0.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double r = std::sqrt((i + 0.5) / n), s = (j + 0.5) / n;
      const double b1 = r * (1.0 - s), b2 = r * s;
      const glm::dvec2 q = (1.0 - b1 - b2) * p[0] + b1 * p[1] + b2 * p[2];
      sum += filtered(reader, t, w, h, q.x, q.y);
    }
  e.mean = glm::vec3(factor * sum / double(n * n));
  return e;
}

}  // namespace wp
