// The shading stages: shade_surface, sample_lights, sample_bsdf, roulette_compact and the fused
// shade (fixture: stage_fixture.h).
#include "tests/stages/stage_fixture.h"

namespace wp::test::stages {
namespace {

// shade_surface, against a host reference of each queued path's hit:
// - the surface queue holds exactly the rays that hit something (bounce < max_depth), once each;
// - the surface record: the point on the ray (o + t d, see the tolerance below) with its
//   magnitude bound, the triangle's unit normal turned to face the ray, the interpolated vertex
//   normal on the same side, the material's factors exactly, the front flag;
// - radiance: a ray that hits the light's emitting (front) side gains throughput x emission x
//   the MIS weight, one that misses throughput x background x the MIS weight; for a camera ray
//   the weight is 1 (nothing else could have found the light), so bounce 0 must be exact; from
//   bounce 1 on it is the power heuristic of the BSDF sample's pdf (path_bsdf_pdf) against the
//   pdf with which NEE would have picked that point (light pmf x dist^2 / (area cos)) or that
//   direction of the constant background (env pmf / 4 pi), computed here in double.
// Everything else is left as it was; with max_depth = bounce nothing is queued, the radiance
// gained all the same. Bounces 0 to 2, and bounce 1 with a quarter of its hits replaced by hits on
// the light from random directions, half of them on its back, which does not emit (single-sided),
// and at all angles.
TEST_F(Stages, ShadeSurfaceResolvesHitsEmissionAndBackground) {
  for (int k = 0; k <= kBounces; ++k) {
    const bool aimed = k == kBounces;
    const int b = aimed ? 1 : k;
    SCOPED_TRACE("bounce " + std::to_string(b) + (aimed ? ", hits on the light" : ""));
    const Bounce& c = bounces_[b];
    input(Stage::kShadeSurface, b);
    if (aimed) aim_at_lights(c);
    for (const char* name :
         {"surf_p", "surf_ng", "surf_ns", "surf_color", "surf_params"})  // written when queued
      for (const Field& field : kFields)
        if (std::string(field.name) == name) poison(layout().*field.offset);
    const wp::Wavefront::Snapshot input_state = wf_->snapshot();
    const PathView before = view();
    launch(Stage::kShadeSurface, c, c.params);
    const PathView after = view();

    const std::vector<std::uint32_t> rays = before.queue(c.params.queue_in);
    std::set<std::uint32_t> expected_surfaces;
    for (const std::uint32_t slot : rays)
      if (before.f4(layout().hit, slot).x < kInf && before.bounce(slot) < c.params.max_depth)
        expected_surfaces.insert(slot);
    EXPECT_EQ(after.counter(WP_QUEUE_SURFACE), expected_surfaces.size());
    EXPECT_EQ(queue_set(after.queue(WP_QUEUE_SURFACE), "surface"), expected_surfaces);

    const auto& lights = wf_->lights();
    ASSERT_NE(lights.env_light, WP_NO_LIGHT) << "a non-zero background is a light";
    const double env_pdf = light_pmf(lights.env_light) / (4.0 * kPi);
    Failures fr("radiance"), fs("surface record");
    std::size_t emitter_hits = 0, misses = 0;
    for (const std::uint32_t slot : rays) {
      const dvec3 o = before.d3(layout().ray_o, slot), d = before.d3(layout().ray_d, slot);
      const float4 hit = before.f4(layout().hit, slot);
      const vec3 beta = before.v3(layout().throughput, slot);
      const float bsdf_pdf = before.f4(layout().throughput, slot).w;
      const vec3 l0 = before.v3(layout().radiance, slot), l = after.v3(layout().radiance, slot);
      // Exact for a camera ray (throughput 1, radiance 0, weight 1); from bounce 1 on the weight
      // is computed here in double against the kernel's float: 1e-5 relative is ~100 ulps, the
      // rounding of a few divisions and a square on the way.
      const auto expect_gain = [&](vec3 le, double w) {
        if (b == 0) {
          WP_CHECK(
              fr, bits(bsdf_pdf) == 0u && l == l0 + beta * le,
              "slot " << slot << " radiance " << str(l) << ", expected " << str(l0 + beta * le));
          return;
        }
        const dvec3 expected = dvec3(l0) + dvec3(beta) * dvec3(le) * w;
        WP_CHECK(fr, glm::length(dvec3(l) - expected) <= 1e-5 * glm::length(expected) + 1e-30,
                 "slot " << slot << " radiance " << str(l) << ", expected " << str(expected));
      };
      if (!(hit.x < kInf)) {
        ++misses;
        expect_gain(kBackground, b == 0 ? 1.0 : power_weight(bsdf_pdf, env_pdf));
        continue;
      }
      const std::uint32_t tri = bits(hit.w);
      const Triangle t = triangle(tri);
      const bool front = glm::dot(t.cross, d) < 0.0;
      const wp::Material& m = *t.material;
      if (emissive(m) && (front || m.double_sided)) {
        ++emitter_hits;
        double w = 1.0;
        if (b > 0) {
          // NEE's pdf of this point: the light's pmf x dist^2 / (area cos)
          // (kernels/lights/lights.h).
          const double area = 0.5 * glm::length(t.cross);
          const double cos_l = std::fabs(glm::dot(glm::normalize(t.cross), d));
          const double p_light =
              light_pmf(lights.tri_light.at(tri)) * double(hit.x) * hit.x / (area * cos_l);
          w = power_weight(bsdf_pdf, p_light);
        }
        expect_gain(m.emission, w);
      } else {
        WP_CHECK(fr,
                 std::memcmp(before.raw(layout().radiance, slot),
                             after.raw(layout().radiance, slot), 16) == 0,
                 "slot " << slot << " hit no emitter, radiance " << str(l) << " was " << str(l0));
      }
      if (!expected_surfaces.count(slot)) continue;

      const dvec3 p = after.d3(layout().surf_p, slot);
      const float p_scale = after.f4(layout().surf_p, slot).w;
      const double u = hit.y, v = hit.z;
      // The point: interpolated from the vertices, it lies on the ray within the rounding of t
      // (a few ulps of the magnitudes involved, along the normal; 1/cos along the ray) and of the
      // interpolation (a few ulps of p_scale): 2^-18 (32 ulps) of their sum, over |cos|.
      const double cos_in = std::fabs(glm::dot(glm::normalize(t.cross), d));
      const double mag =
          std::max({std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)}) + hit.x + double(p_scale);
      const double tol_p = std::ldexp(mag, -18) / std::max(cos_in, 1e-3);
      WP_CHECK(
          fs, glm::length(p - (o + double(hit.x) * d)) <= tol_p,
          "slot " << slot << " point " << str(p) << ", on the ray " << str(o + double(hit.x) * d));
      // Its magnitude bound: the largest component of |b0 p0| + |b1 p1| + |b2 p2|.
      const dvec3 scale =
          glm::abs((1.0 - u - v) * t.p[0]) + glm::abs(u * t.p[1]) + glm::abs(v * t.p[2]);
      const double expected_scale = std::max({scale.x, scale.y, scale.z});
      WP_CHECK(fs, std::fabs(p_scale - expected_scale) <= 1e-6 * expected_scale,
               "slot " << slot << " p_scale " << p_scale << ", expected " << expected_scale);
      // Normals: unit vectors from float arithmetic, 1e-6 is a few ulps.
      const dvec3 ng_ref = (front ? 1.0 : -1.0) * glm::normalize(t.cross);
      const dvec3 ng = after.d3(layout().surf_ng, slot);
      WP_CHECK(fs, glm::length(ng - ng_ref) < 1e-6 && glm::dot(ng, d) < 0.0,
               "slot " << slot << " ng " << str(ng) << ", expected " << str(ng_ref));
      dvec3 ns_ref = glm::normalize((1.0 - u - v) * t.n[0] + u * t.n[1] + v * t.n[2]);
      if (glm::dot(ns_ref, ng_ref) < 0.0) ns_ref = -ns_ref;
      if (!(glm::dot(ns_ref, -d) > 1e-4)) ns_ref = ng_ref;  // facing away: the true normal
      const dvec3 ns = after.d3(layout().surf_ns, slot);
      WP_CHECK(fs, glm::length(ns - ns_ref) < 1e-6,
               "slot " << slot << " ns " << str(ns) << ", expected " << str(ns_ref));
      const float4 color = after.f4(layout().surf_color, slot);
      const float4 params = after.f4(layout().surf_params, slot);
      const float specular = after.f4(layout().surf_ng, slot).w;
      WP_CHECK(fs,
               color.x == m.base_color.x && color.y == m.base_color.y &&
                   color.z == m.base_color.z && color.w == m.metallic && params.x == m.roughness &&
                   params.y == m.ior && params.z == m.transmission && specular == m.specular,
               "slot " << slot << " material " << str(dxyz(color)) << " " << color.w << " "
                       << params.x << " " << params.y << " " << params.z << " " << specular);
      if (std::fabs(glm::dot(glm::normalize(t.cross), d)) > 1e-6)  // not a grazing tie
        WP_CHECK(fs, bits(params.w) == (front ? kSurfFront : 0u),
                 "slot " << slot << " flags " << bits(params.w) << ", front " << front);
    }
    EXPECT_GT(emitter_hits, 0u) << "some rays find the ceiling light";
    EXPECT_GT(misses, 0u) << "some rays leave the box";
    expect_unchanged(before, after, all_slots(),
                     {"radiance", "surf_p", "surf_ng", "surf_ns", "surf_color", "surf_params"},
                     "besides radiance and the surface record");
    std::vector<std::uint32_t> not_surfaces;
    for (std::uint32_t slot = 0; slot < kPaths; ++slot)
      if (!expected_surfaces.count(slot)) not_surfaces.push_back(slot);
    expect_unchanged(before, after, not_surfaces, {"radiance"}, "slots that do not scatter");

    // At max_depth nothing scatters any more; the hit's emission still counts.
    wf_->restore(input_state);
    wp::dev::Launch last = c.params;
    last.max_depth = static_cast<std::uint32_t>(b);
    launch(Stage::kShadeSurface, c, last);
    const PathView at_max = view();
    EXPECT_EQ(at_max.counter(WP_QUEUE_SURFACE), 0u) << "paths at max_depth scatter no more";
    for (const std::uint32_t slot : rays)
      EXPECT_EQ(
          std::memcmp(at_max.raw(layout().radiance, slot), after.raw(layout().radiance, slot), 16),
          0)
          << "slot " << slot;
  }
}

// sample_lights: every shadow-queue slot is a surface-queue slot, once; its shadow ray starts just
// off the surface point (at most 2 offset distances, kernels/geom/surface.h) on the side of the
// normal the light is on, has a unit direction and either ends (origin + dir x tmax) on the
// emitting side of an emissive triangle of the host's scene, within the offset that keeps it off
// that triangle, or has tmax = INFINITY (the environment light). Its contribution is finite,
// positive and equal to a host evaluation of throughput x f x L x cos / pdf x w_light for Lambert's
// f = base / pi, the pdf of the light point (pmf x dist^2 / (area cos_light), or pmf / 4 pi for the
// background) and the power heuristic against the BSDF's pdf cos / pi (tolerance below). Only
// shadow fields change.
TEST_F(Stages, SampleLightsMakesShadowRaysToLightPoints) {
  ASSERT_FALSE(wf_->features().glossy) << "Lambert's BSDF alone: " << wf_->features().describe();
  const std::vector<Emitter> lights_geometry = emitters();
  ASSERT_EQ(lights_geometry.size(), 2u) << "the Cornell box's light is one quad";
  const auto& lights = wf_->lights();
  // From a point that sees the emitting side of the whole light above both its normals, every
  // point of the light makes a shadow ray, so the points sampled there are uniform over the
  // light's area (kernels/lights/lights.h, sample_triangle): each barycentric coordinate has mean
  // 1/3 and standard deviation sqrt(1/18) (a flat Dirichlet's marginal), checked within 5 standard
  // errors.
  const auto sees_whole_light = [&](dvec3 p, dvec3 ns, dvec3 ng) {
    for (const Emitter& em : lights_geometry) {
      if (!(glm::dot(p - em.t.p[0], em.t.cross) > 0.0)) return false;
      for (const dvec3& v : em.t.p)
        if (!(glm::dot(v - p, ns) > 0.0 && glm::dot(v - p, ng) > 0.0)) return false;
    }
    return true;
  };
  double bary_sum[3] = {0.0, 0.0, 0.0};
  std::size_t bary_n = 0;
  for (int b = 0; b < 2; ++b) {
    SCOPED_TRACE("bounce " + std::to_string(b));
    const Bounce& c = bounces_[b];
    input(Stage::kSampleLights, b);
    poison(layout().shadow_o);
    poison_xyz(layout().shadow_d);  // the w lanes hold the path's flags and bounce count
    poison_xyz(layout().shadow_l);
    const PathView before = view();
    launch(Stage::kSampleLights, c, c.params);
    const PathView after = view();
    const std::set<std::uint32_t> surfaces = queue_set(before.queue(WP_QUEUE_SURFACE), "surface");
    const std::vector<std::uint32_t> shadow_list = after.queue(WP_QUEUE_SHADOW);
    const std::set<std::uint32_t> shadows = queue_set(shadow_list, "shadow");
    EXPECT_EQ(shadows.size(), shadow_list.size());
    EXPECT_TRUE(std::includes(surfaces.begin(), surfaces.end(), shadows.begin(), shadows.end()))
        << "shadow rays only from surfaces";
    // Most points of the box see the light or the background from their side: not a count to
    // predict without the random numbers, but not a handful either.
    EXPECT_GT(shadows.size(), surfaces.size() / 2);

    Failures f("shadow rays");
    std::size_t to_area = 0, to_env = 0, edge_on = 0;
    for (const std::uint32_t slot : shadows) {
      double min_cos = 0.0;
      const dvec3 p = before.d3(layout().surf_p, slot), ng = before.d3(layout().surf_ng, slot),
                  ns = before.d3(layout().surf_ns, slot);
      const auto [off, rounding] = spawn_bound(before, slot);
      const dvec3 color = before.d3(layout().surf_color, slot);
      const dvec3 beta = before.d3(layout().throughput, slot);
      const float4 so = after.f4(layout().shadow_o, slot), sd = after.f4(layout().shadow_d, slot);
      const dvec3 o = dxyz(so), dir = dxyz(sd), c_dev = after.d3(layout().shadow_l, slot);
      WP_CHECK(f,
               after.flags(slot) == before.flags(slot) && after.bounce(slot) == before.bounce(slot),
               "slot " << slot << " flags or bounce changed");
      WP_CHECK(f, std::fabs(glm::length(dir) - 1.0) < 1e-6,
               "slot " << slot << " |dir| " << glm::length(dir));
      WP_CHECK(f, glm::length(o - p) <= 2.0 * off + rounding && glm::dot(o - p, ng) > 0.5 * off,
               "slot " << slot << " origin " << str(o) << " off point " << str(p) << " by "
                       << glm::length(o - p) << " (offset " << off << ")");
      WP_CHECK(f,
               std::isfinite(c_dev.x) && std::isfinite(c_dev.y) && std::isfinite(c_dev.z) &&
                   std::min({c_dev.x, c_dev.y, c_dev.z}) >= 0.0 &&
                   std::max({c_dev.x, c_dev.y, c_dev.z}) > 0.0,
               "slot " << slot << " contribution " << str(c_dev));
      dvec3 wi, li;
      double pdf_light, angle;
      if (so.w == kInf) {
        ++to_env;
        // The environment light: the ray's direction is the light sample's own, so only the
        // rounding of a float dot product (~2^-22) separates the cosines here from the kernel's.
        wi = dir;
        li = dvec3(kBackground);
        pdf_light = light_pmf(lights.env_light) / (4.0 * kPi);
        angle = std::ldexp(1.0, -22);
      } else {
        ++to_area;
        const dvec3 e = o + dir * double(so.w);
        // The emissive triangle it ends on: within its edges (1e-5 in barycentrics: the end is a
        // float computation of the target point), and within the target's offset off its plane.
        const Emitter* hit = nullptr;
        double plane = 0.0, b1 = 0.0, b2 = 0.0;
        for (const Emitter& em : lights_geometry) {
          const dvec3 n = glm::normalize(em.t.cross);
          const dvec3 q = e - em.t.p[0];
          const double dist_plane = glm::dot(q, n);
          const dvec3 in_plane = q - dist_plane * n;
          const dvec3 e1 = em.t.p[1] - em.t.p[0], e2 = em.t.p[2] - em.t.p[0];
          const double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
          const double r1 = glm::dot(in_plane, e1), r2 = glm::dot(in_plane, e2);
          const double det = d11 * d22 - d12 * d12;
          const double u1 = (d22 * r1 - d12 * r2) / det, u2 = (d11 * r2 - d12 * r1) / det;
          if (u1 > -1e-5 && u2 > -1e-5 && u1 + u2 < 1.0 + 1e-5)
            hit = &em, plane = dist_plane, b1 = u1, b2 = u2;
        }
        WP_CHECK(f, hit != nullptr, "slot " << slot << " ends at " << str(e) << ", on no light");
        if (!hit) continue;
        if (sees_whole_light(p, ns, ng)) {
          bary_sum[0] += 1.0 - b1 - b2, bary_sum[1] += b1, bary_sum[2] += b2;
          ++bary_n;
        }
        // The target is the light point q moved off the light toward its emitting (front) side by
        // 2^-16 of q's magnitude bound (kernels/lights/lights.h, sample_triangle), and e is that
        // target up to the rounding of o + dir tmax and of the target itself, far below 16 ulps of
        // coordinates below 1 (2^-20).
        const dvec3 n = glm::normalize(hit->t.cross);
        const dvec3 scale = glm::abs((1.0 - b1 - b2) * hit->t.p[0]) + glm::abs(b1 * hit->t.p[1]) +
                            glm::abs(b2 * hit->t.p[2]);
        const double q_off = std::ldexp(std::max({scale.x, scale.y, scale.z}), -16);
        WP_CHECK(f, std::fabs(plane - q_off) <= std::ldexp(1.0, -20),
                 "slot " << slot << " ends " << plane << " off the light's plane, not " << q_off);
        // The kernel's direction runs from the surface point p to q: both known here, q once the
        // offset is undone. What is left is the rounding of e (o + dir tmax) and of q - p in the
        // kernel, far below 16 ulps of coordinates below 1 (2^-20): an angle of 2^-20 / dist.
        const dvec3 to = e - n * q_off - p;
        const double dist = glm::length(to);
        wi = to / dist;
        angle = std::ldexp(1.0, -20) / dist;
        const double area = 0.5 * glm::length(hit->t.cross);
        const double cos_l = -glm::dot(n, wi);
        WP_CHECK(f, cos_l > -angle, "slot " << slot << " sees the light's back, cos " << cos_l);
        pdf_light = light_pmf(lights.tri_light.at(hit->tri)) * dist * dist / (area * cos_l);
        li = dvec3(hit->t.material->emission);
        min_cos = std::min(glm::dot(ns, wi), cos_l);
      }
      // The light is above both normals (Lambert's BSDF is 0 elsewhere): exactly so for the
      // kernel's direction, to `angle` for wi.
      const double cos_s = glm::dot(ns, wi);
      WP_CHECK(f, cos_s > -angle && glm::dot(ng, wi) > -angle,
               "slot " << slot << " light below the normals, cos " << cos_s << " (shading), "
                       << glm::dot(ng, wi) << " (geometric)");
      if (so.w == kInf) min_cos = cos_s;
      // The value: each cosine may differ from the kernel's by `angle`, the distance by `angle`
      // relative; the value goes with both cosines and 1 / dist^2, and the MIS weight with their
      // ratio (at most twice its relative change): 16 angles over the smaller cosine bound the
      // whole, plus 1e-5 for the kernel's float arithmetic. A light point seen almost edge-on,
      // where that exceeds 1e-2, is rare (counted below): only its sign and finiteness count.
      if (16.0 * angle > 1e-2 * min_cos) {
        ++edge_on;
        continue;
      }
      const double rel_tol = 1e-5 + 16.0 * angle / min_cos;
      const double w = power_weight(pdf_light, cos_s / kPi);
      const dvec3 c_ref = beta * (color / kPi) * li * (cos_s * w / pdf_light);
      WP_CHECK(f, glm::length(c_dev - c_ref) <= rel_tol * glm::length(c_ref),
               "slot " << slot << (so.w == kInf ? " (environment)" : " (area)") << " contribution "
                       << str(c_dev) << ", expected " << str(c_ref) << " within " << rel_tol
                       << " relative");
    }
    EXPECT_LT(edge_on, shadows.size() / 100) << "light samples seen edge-on";
    EXPECT_GT(to_area, 0u);
    EXPECT_GT(to_env, 0u);
    expect_unchanged(before, after, all_slots(), {"shadow_o", "shadow_d", "shadow_l"},
                     "besides the shadow ray");
    std::vector<std::uint32_t> others;
    for (std::uint32_t slot = 0; slot < kPaths; ++slot)
      if (!shadows.count(slot)) others.push_back(slot);
    expect_unchanged(before, after, others, {}, "slots without a shadow ray");
  }
  ASSERT_GT(bary_n, 100u);
  for (const double sum : bary_sum)
    EXPECT_NEAR(sum / double(bary_n), 1.0 / 3.0, 5.0 * std::sqrt(1.0 / 18.0 / double(bary_n)))
        << "mean barycentric coordinate of " << bary_n << " light points";
}

// sample_bsdf on Lambert's BSDF, for every surface path: a unit direction above both normals, the
// pdf cos / pi (cos to the shading normal), throughput x base colour (f cos / pdf of a Lambertian:
// one float multiplication, so exactly), radiance and eta scale unchanged (nothing refracts), no
// delta flag, no pane distance, tmin 0 and tmax INFINITY, and an origin just off the surface point
// on the normal's side (surface_spawn: at most 2 offset distances away). Directions are
// cosine-distributed: the mean of cos is 2/3 (its standard deviation is sqrt(1/2 - 4/9) = 0.236
// per sample; within 5 standard errors). Slots not in the surface queue are left alone.
TEST_F(Stages, SampleBsdfSamplesLambertsCosineLobe) {
  ASSERT_FALSE(wf_->features().glossy) << "Lambert's BSDF alone: " << wf_->features().describe();
  double sum_cos = 0.0;
  std::size_t n = 0;
  for (int b = 0; b < 2; ++b) {
    SCOPED_TRACE("bounce " + std::to_string(b));
    const Bounce& c = bounces_[b];
    input(Stage::kSampleBsdf, b);
    const PathView before = view();
    launch(Stage::kSampleBsdf, c, c.params);
    const PathView after = view();
    const std::set<std::uint32_t> surfaces = queue_set(before.queue(WP_QUEUE_SURFACE), "surface");
    ASSERT_GT(surfaces.size(), c.rays / 2);
    Failures f("BSDF samples");
    for (const std::uint32_t slot : surfaces) {
      const dvec3 p = before.d3(layout().surf_p, slot), ng = before.d3(layout().surf_ng, slot),
                  ns = before.d3(layout().surf_ns, slot);
      const auto [off, rounding] = spawn_bound(before, slot);
      const vec3 color = before.v3(layout().surf_color, slot);
      const float4 beta0 = before.f4(layout().throughput, slot);
      const float4 beta = after.f4(layout().throughput, slot);
      const float4 o = after.f4(layout().ray_o, slot), d4 = after.f4(layout().ray_d, slot);
      const dvec3 d = dxyz(d4);
      WP_CHECK(f, std::fabs(glm::length(d) - 1.0) < 1e-6,
               "slot " << slot << " |d| " << glm::length(d));
      const double cos_s = glm::dot(ns, d);
      WP_CHECK(f, cos_s > 0.0 && glm::dot(ng, d) > 0.0,
               "slot " << slot << " direction " << str(d) << " below ns " << str(ns) << " or ng "
                       << str(ng));
      // The pdf from the stored unit vectors in double: float rounding of a 3-term dot product
      // is ~2e-7 absolute.
      WP_CHECK(f, std::fabs(beta.w - cos_s / kPi) <= 1e-6 * cos_s / kPi + 2e-7,
               "slot " << slot << " pdf " << beta.w << ", cos / pi " << cos_s / kPi);
      const vec3 expected = xyz(beta0) * color;
      WP_CHECK(
          f, xyz(beta) == expected,
          "slot " << slot << " throughput " << str(xyz(beta)) << ", expected " << str(expected));
      const float4 l0 = before.f4(layout().radiance, slot), l = after.f4(layout().radiance, slot);
      WP_CHECK(f, std::memcmp(&l0, &l, 16) == 0,
               "slot " << slot << " radiance or eta scale changed");
      WP_CHECK(
          f, after.bounce(slot) == before.bounce(slot) && after.flags(slot) == 0u,
          "slot " << slot << " bounce " << after.bounce(slot) << " flags " << after.flags(slot));
      const float4 sd0 = before.f4(layout().shadow_d, slot), sd = after.f4(layout().shadow_d, slot);
      WP_CHECK(f, std::memcmp(&sd0, &sd, 12) == 0, "slot " << slot << " shadow ray changed");
      WP_CHECK(f, o.w == 0.0f && bits(d4.w) == 0u,
               "slot " << slot << " tmin " << o.w << " pane distance " << d4.w);
      const dvec3 to = dxyz(o) - p;
      WP_CHECK(f, glm::length(to) <= 2.0 * off + rounding && glm::dot(to, ng) > 0.5 * off,
               "slot " << slot << " origin " << str(dxyz(o)) << " off " << str(p) << " by "
                       << glm::length(to) << " (offset " << off << ")");
      sum_cos += cos_s;
      ++n;
    }
    expect_unchanged(before, after, all_slots(), {"ray_o", "ray_d", "throughput", "shadow_d"},
                     "besides the next ray, throughput and flags");
    std::vector<std::uint32_t> others;
    for (std::uint32_t slot = 0; slot < kPaths; ++slot)
      if (!surfaces.count(slot)) others.push_back(slot);
    expect_unchanged(before, after, others, {}, "slots not in the surface queue");
  }
  EXPECT_NEAR(sum_cos / double(n), 2.0 / 3.0, 5.0 * std::sqrt((1.0 / 2.0 - 4.0 / 9.0) / double(n)))
      << "mean cosine of " << n << " directions";
}

// roulette_compact, with roulette at once (rr_depth 0) and thresholds 0.7 and 0.5, on bounces 0
// and 1 after sample_bsdf, and on bounce 1 again with planted values: eta scales of 2.25 and 1/2.25
// (refraction into and out of glass; the Lambertian box has none), some zero throughputs and one
// NaN. From the state before, on the host: m = max channel of the throughput x eta scale /
// rr_threshold (in float, as the kernel), q = min(1, m). Then:
// - the next ray queue holds surface paths only, each once, and its counter is its length;
// - every survivor has bounce + 1 and throughput x q = the old throughput (1e-6 relative: one
//   float division, which OpenCL allows 2.5 ulps);
// - every path with q = 1 survives, unchanged but for its bounce; paths that end are untouched;
//   paths with zero throughput end, a NaN one too, counted as non-finite;
// - among the paths with q < 1 the survivors' count S agrees with the expected sum of q. With
//   independent survival S has variance sum q (1 - q) (a sum of Bernoulli variables; the
//   stratified Sobol' numbers of one pixel's samples only lower it), so |S - sum q| <=
//   5 sqrt(sum q (1 - q)) + 1 fails by chance with probability ~6e-7 per check.
// And roulette only from bounce rr_depth - 1 on: with rr_depth = bounce + 1 it applies, with
// bounce + 2 every path with a positive throughput survives unchanged.
TEST_F(Stages, RouletteCompactKeepsPathsWithProbabilityQ) {
  for (int k = 0; k < 3; ++k) {
    const bool planted = k == 2;
    const int b = planted ? 1 : k;
    const Bounce& c = bounces_[b];
    input(Stage::kRouletteCompact, b);
    if (planted) {
      const PathView in = view();
      std::vector<float4> beta(kPaths), l(kPaths);
      for (std::uint32_t slot = 0; slot < kPaths; ++slot) {
        beta[slot] = in.f4(layout().throughput, slot);
        l[slot] = in.f4(layout().radiance, slot);
      }
      const std::vector<std::uint32_t> surfaces = in.queue(WP_QUEUE_SURFACE);
      for (std::size_t i = 0; i < surfaces.size(); ++i) {
        const std::uint32_t slot = surfaces[i];
        l[slot].w = i % 3 == 0 ? 2.25f : i % 3 == 1 ? 1.0f / 2.25f : 1.0f;
        if (i % 50 == 7) beta[slot].x = beta[slot].y = beta[slot].z = 0.0f;
        if (i == 11) beta[slot].y = std::numeric_limits<float>::quiet_NaN();
      }
      wf_->write_paths(layout().throughput, beta);
      wf_->write_paths(layout().radiance, l);
    }
    const wp::Wavefront::Snapshot input_state = wf_->snapshot();
    const PathView before = view();
    const std::set<std::uint32_t> surfaces = queue_set(before.queue(WP_QUEUE_SURFACE), "surface");
    struct Case {
      std::uint32_t rr_depth;
      float threshold;
    };
    for (const Case r : {Case{0, 0.7f}, Case{0, 0.5f}, Case{std::uint32_t(b) + 1, 0.7f},
                         Case{std::uint32_t(b) + 2, 0.7f}}) {
      SCOPED_TRACE("bounce " + std::to_string(b) + (planted ? " (planted values)" : "") +
                   ", rr_depth " + std::to_string(r.rr_depth) + ", threshold " +
                   std::to_string(r.threshold));
      const bool roulette = std::uint32_t(b) + 1 >= r.rr_depth;
      wf_->restore(input_state);
      wp::dev::Launch p = c.params;
      p.rr_depth = r.rr_depth;
      p.rr_threshold = r.threshold;
      launch(Stage::kRouletteCompact, c, p);
      const PathView after = view();
      const std::vector<std::uint32_t> next_list = after.queue(p.queue_out);
      const std::set<std::uint32_t> next = queue_set(next_list, "next rays");
      EXPECT_TRUE(std::includes(surfaces.begin(), surfaces.end(), next.begin(), next.end()));
      Failures f("roulette");
      double sum_q = 0.0, var = 0.0;
      std::size_t survivors = 0, at_risk = 0, nonfinite = 0;
      for (const std::uint32_t slot : surfaces) {
        const float4 beta0 = before.f4(layout().throughput, slot);
        const float4 beta = after.f4(layout().throughput, slot);
        const std::uint32_t bounce0 = before.bounce(slot), bounce = after.bounce(slot);
        const float4 sl0 = before.f4(layout().shadow_l, slot),
                     sl = after.f4(layout().shadow_l, slot);
        WP_CHECK(f, std::memcmp(&sl0, &sl, 12) == 0, "slot " << slot << " shadow ray changed");
        // The count moves on for every path roulette sees, also one it ends (trace_shadow finds
        // its shadow ray's bounce one below).
        WP_CHECK(f, bounce == bounce0 + 1,
                 "slot " << slot << " bounce " << bounce << " was " << bounce0);
        const bool survived = next.count(slot) > 0;
        const bool finite =
            std::isfinite(beta0.x) && std::isfinite(beta0.y) && std::isfinite(beta0.z);
        nonfinite += !finite;
        const float m =
            finite ? max3(xyz(beta0)) * before.f4(layout().radiance, slot).w / r.threshold : 0.0f;
        if (!(m > 0.0f)) {  // nothing left to carry (or NaN): always ends, untouched
          WP_CHECK(f, !survived && std::memcmp(&beta0, &beta, 16) == 0,
                   "slot " << slot << " with throughput " << str(xyz(beta0)) << " survived "
                           << survived);
          continue;
        }
        const double q = roulette ? std::min(1.0, double(m)) : 1.0;
        if (!survived) {
          WP_CHECK(f, q < 1.0, "slot " << slot << " with q = 1 ended (m " << m << ")");
          WP_CHECK(f, std::memcmp(&beta0, &beta, 16) == 0, "slot " << slot << " ended but changed");
        } else {
          if (q == 1.0) {
            WP_CHECK(f, std::memcmp(&beta0, &beta, 16) == 0,
                     "slot " << slot << " with q = 1: throughput " << str(xyz(beta)) << " was "
                             << str(xyz(beta0)));
          } else {
            const dvec3 back = dxyz(beta) * q;
            WP_CHECK(f,
                     glm::length(back - dxyz(beta0)) <= 1e-6 * glm::length(dxyz(beta0)) &&
                         beta.w == beta0.w,
                     "slot " << slot << " throughput " << str(dxyz(beta)) << " x q " << q << " = "
                             << str(back) << ", was " << str(dxyz(beta0)));
          }
        }
        if (q < 1.0) {
          ++at_risk;
          sum_q += q;
          var += q * (1.0 - q);
          survivors += survived;
        }
      }
      EXPECT_EQ(after.counter(WP_COUNTER_NONFINITE) - before.counter(WP_COUNTER_NONFINITE),
                nonfinite);
      EXPECT_EQ(nonfinite, planted ? 1u : 0u);
      if (!roulette) {
        EXPECT_EQ(at_risk, 0u);
      } else {
        EXPECT_GT(at_risk, 100u) << "paths roulette can end";
        EXPECT_LE(std::fabs(double(survivors) - sum_q), 5.0 * std::sqrt(var) + 1.0)
            << survivors << " of " << at_risk << " survived, expected " << sum_q;
      }
      expect_unchanged(before, after, all_slots(), {"throughput", "shadow_l"},
                       "besides throughput and bounce");
    }
  }
}

// shade (fused): on the same input (a bounce after intersect_closest), the fused kernel leaves the
// path state and the queues exactly as shade_surface, sample_lights, sample_bsdf and
// roulette_compact do in turn: every field bit for bit but the surface record (the fused kernel
// keeps it in registers), the shadow and next ray queues as sets (their order depends on which
// work-group reached the counter first, kernels/integrator/queues.h). Bounces 0 to 2, with the
// render's roulette settings and with roulette at once (rr_depth 0). The scene is Lambertian and
// untextured, so on PoCL's CPU devices the fused kernel shades eight paths per work-item in SIMD
// lanes (kernels/integrator/shade_packet.h), and this compares that with the single-path stages.
TEST_F(Stages, ShadeDoesWhatTheSplitStagesDo) {
  const wp::DeviceEntry& device = runtime_->device();
  if (!device.gpu && device.platform_name == "Portable Computing Language") {
    EXPECT_NE(wf_->build_options().find("-D WP_SHADE_PACKET=1"), std::string::npos)
        << wf_->build_options();
  }
  for (int b = 0; b < kBounces; ++b) {
    const Bounce& c = bounces_[b];
    for (const std::uint32_t rr_depth : {c.params.rr_depth, 0u}) {
      SCOPED_TRACE("bounce " + std::to_string(b) + ", rr_depth " + std::to_string(rr_depth));
      wp::dev::Launch p = c.params;
      p.rr_depth = rr_depth;
      input(Stage::kShadeSurface, b);
      const wp::Wavefront::Snapshot input_state = wf_->snapshot();
      for (const Stage s : {Stage::kShadeSurface, Stage::kSampleLights, Stage::kSampleBsdf,
                            Stage::kRouletteCompact})
        launch(s, c, p);
      const PathView split = view();
      wf_->restore(input_state);
      launch(Stage::kShade, c, p);
      const PathView fused = view();
      expect_unchanged(split, fused, all_slots(),
                       {"surf_p", "surf_ng", "surf_ns", "surf_color", "surf_params"},
                       "the fused kernel against the split stages");
      for (const std::uint32_t q : {p.queue_out, WP_QUEUE_SHADOW}) {
        EXPECT_EQ(fused.counter(q), split.counter(q)) << "queue " << q;
        EXPECT_EQ(queue_set(fused.queue(q), "fused"), queue_set(split.queue(q), "split"))
            << "queue " << q;
      }
      EXPECT_GT(split.counter(p.queue_out), 0u);
      EXPECT_GT(split.counter(WP_QUEUE_SHADOW), 0u);
    }
  }
}

}  // namespace
}  // namespace wp::test::stages
