// Whether two renders estimate the same image, from their own standard errors (scene-tier tests
// that compare a scene with a twin that must render alike: compressed, instanced).
#pragma once

#include <cmath>
#include <cstddef>

#include <gtest/gtest.h>

#include "host/render/render.h"

namespace wp::test {

// The small renders such twin tests compare: width x height pixels, spp samples, paths of at most
// max_depth events under a constant grey background.
inline RenderSettings twin_settings(int width, int height, int spp, int max_depth,
                                    float background) {
  RenderSettings s;
  s.width = width;
  s.height = height;
  s.spp = spp;
  s.max_depth = max_depth;
  s.background = glm::vec3(background);
  return s;
}

// Per channel, the image means differ by less than 4 standard errors of their difference. Each
// mean's variance is the sum of its pixels' variances (of their means) over the pixel count
// squared; the two renders share their random numbers, which correlates them positively, so the
// difference's true variance is below the sum of the two and the bound is conservative (a false
// failure has odds below 1e-4).
inline void expect_same_estimate(const Rendered& a, const Rendered& b, const char* what) {
  const std::size_t pixels = a.image.rgb.size() / 3;
  ASSERT_EQ(b.image.rgb.size(), a.image.rgb.size());
  for (std::size_t c = 0; c < 3; ++c) {
    double mean_a = 0, mean_b = 0, var = 0;
    for (std::size_t i = c; i < a.image.rgb.size(); i += 3) {
      mean_a += a.image.rgb[i];
      mean_b += b.image.rgb[i];
      var += double(a.variance.rgb[i]) + double(b.variance.rgb[i]);
    }
    const double n = double(pixels);
    EXPECT_GT(mean_a / n, 0.01) << what << " channel " << c;  // not a black image
    EXPECT_LE(std::abs(mean_a - mean_b) / n, 4.0 * std::sqrt(var) / n) << what << " channel " << c;
  }
}

}  // namespace wp::test
