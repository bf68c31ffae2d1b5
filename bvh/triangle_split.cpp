// Exact bounds of a triangle clipped to a box and cut by an axis-aligned plane: the
// splitPrimitive callback of Embree's spatial-split builder (see build_tree.h for the contract).
//
// Embree only hands the callback the reference's current box and the triangle's index; splitting
// that box alone would leave the references as loose as the triangle's full extent within it.
// Clipping the actual polygon makes every reference's box the tight bounds of its piece, which is
// what makes spatial splits pay off on long diagonal triangles.
#include <algorithm>
#include <cmath>
#include <limits>

#include "build_tree.h"

namespace wp::bvh::detail {
namespace {

// A convex polygon: a triangle clipped by the 6 box planes has at most 3 + 6 vertices.
struct Polygon {
  static constexpr int kMax = 12;
  double p[kMax][3];
  int n = 0;
};

// Sutherland-Hodgman against one half-space: keeps x[dim] <= c (keep_below) or x[dim] >= c.
// Points on the plane are kept, so degenerate (zero-area) triangles survive as segments or points.
// Crossing points get x[dim] = c exactly.
void clip(const Polygon& in, unsigned dim, double c, bool keep_below, Polygon& out) {
  out.n = 0;
  for (int i = 0; i < in.n; ++i) {
    const double* a = in.p[i];
    const double* b = in.p[i + 1 < in.n ? i + 1 : 0];
    const bool ia = keep_below ? a[dim] <= c : a[dim] >= c;
    const bool ib = keep_below ? b[dim] <= c : b[dim] >= c;
    if (ia) {
      for (int k = 0; k < 3; ++k) out.p[out.n][k] = a[k];
      ++out.n;
    }
    if (ia != ib && a[dim] != b[dim]) {
      const double t = (c - a[dim]) / (b[dim] - a[dim]);
      for (int k = 0; k < 3; ++k) out.p[out.n][k] = a[k] + t * (b[k] - a[k]);
      out.p[out.n][dim] = c;
      ++out.n;
    }
  }
}

constexpr float kInf = std::numeric_limits<float>::infinity();

// Bounds in double, grown one point at a time.
struct DBox {
  double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
  void add(const double* q) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = q[k] < lo[k] ? q[k] : lo[k];
      hi[k] = q[k] > hi[k] ? q[k] : hi[k];
    }
  }
};

// Float bounds containing double ones: round to nearest, then step outwards by at least one ulp
// (|f| * 2^-23 >= ulp(f) for normal f; FLT_MIN covers zero and denormals). Branch-free on
// purpose: Embree calls the splitter millions of times and the direction of rounding is random.
float below(double x) {
  const float f = static_cast<float>(x);
  return f - (std::fabs(f) * 0x1p-23f + std::numeric_limits<float>::min());
}
float above(double x) {
  const float f = static_cast<float>(x);
  return f + (std::fabs(f) * 0x1p-23f + std::numeric_limits<float>::min());
}

// The float box containing `b`, intersected with `clip_box`; empty (lo = +inf, hi = -inf) if
// either is.
Box to_float_box(const DBox& b, const Box& clip_box) {
  if (!(b.lo[0] <= b.hi[0])) return Box{glm::vec3(kInf), glm::vec3(-kInf)};  // no points
  Box out{};
  for (int k = 0; k < 3; ++k) {
    out.lo[k] = std::max(below(b.lo[k]), clip_box.lo[k]);
    out.hi[k] = std::min(above(b.hi[k]), clip_box.hi[k]);
  }
  if (out.lo.x <= out.hi.x && out.lo.y <= out.hi.y && out.lo.z <= out.hi.z) return out;
  return Box{glm::vec3(kInf), glm::vec3(-kInf)};
}

}  // namespace

void split_triangle_bounds(const glm::vec3 v[3], const Box& box, unsigned dim, float pos, Box& left,
                           Box& right) {
  Polygon buf[2];
  int cur = 0;
  buf[0].n = 3;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) buf[0].p[i][k] = v[i][k];
  // Clip to the reference's current box, skipping planes no vertex lies beyond (the clipped
  // polygon's vertices are convex combinations of the triangle's, so none can lie beyond either).
  for (unsigned k = 0; k < 3; ++k) {
    const float lo = box.lo[k], hi = box.hi[k];
    if (v[0][k] < lo || v[1][k] < lo || v[2][k] < lo) {
      clip(buf[cur], k, lo, false, buf[1 - cur]);
      cur = 1 - cur;
    }
    if (v[0][k] > hi || v[1][k] > hi || v[2][k] > hi) {
      clip(buf[cur], k, hi, true, buf[1 - cur]);
      cur = 1 - cur;
    }
  }
  // One pass over the edges collects the bounds of both sides of the plane x[dim] = pos.
  const Polygon& poly = buf[cur];
  const double c = pos;
  DBox l, r;
  for (int i = 0; i < poly.n; ++i) {
    const double* a = poly.p[i];
    const double* b = poly.p[i + 1 < poly.n ? i + 1 : 0];
    if (a[dim] <= c) l.add(a);
    if (a[dim] >= c) r.add(a);
    if ((a[dim] < c && b[dim] > c) || (a[dim] > c && b[dim] < c)) {
      const double t = (c - a[dim]) / (b[dim] - a[dim]);
      double q[3];
      for (int k = 0; k < 3; ++k) q[k] = a[k] + t * (b[k] - a[k]);
      q[dim] = c;
      l.add(q);
      r.add(q);
    }
  }
  Box left_box = box, right_box = box;
  left_box.hi[dim] = pos < left_box.hi[dim] ? pos : left_box.hi[dim];
  right_box.lo[dim] = pos > right_box.lo[dim] ? pos : right_box.lo[dim];
  left = to_float_box(l, left_box);
  right = to_float_box(r, right_box);
}

}  // namespace wp::bvh::detail
