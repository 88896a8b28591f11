#include <shapectl/contact/segment_segment_distance.hpp>

#include <algorithm>

namespace shapectl {

// Ericson, Real-Time Collision Detection, 5.1.9, with degenerate segments as points.
SegmentSegmentClosest segment_segment_closest(const Vec3& a0, const Vec3& a1, const Vec3& b0,
                                              const Vec3& b1) {
  const Vec3 d1 = a1 - a0, d2 = b1 - b0, r = a0 - b0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const auto clamp01 = [](double v) { return std::clamp(v, 0.0, 1.0); };
  double s = 0, t = 0;
  if (a > 0 && e > 0) {
    const double c = d1.dot(r), b = d1.dot(d2);
    const double denominator = a * e - b * b;
    // Parallel (to rounding): any s gives the distance somewhere; take the end s = 0.
    s = denominator > 1e-12 * a * e ? clamp01((b * f - c * e) / denominator) : 0.0;
    t = (b * s + f) / e;
    if (t < 0) {
      t = 0;
      s = clamp01(-c / a);
    } else if (t > 1) {
      t = 1;
      s = clamp01((b - c) / a);
    }
  } else if (a > 0) {
    s = clamp01(-d1.dot(r) / a);
  } else if (e > 0) {
    t = clamp01(f / e);
  }
  return {s, t, a > 0 && s > 0 && s<1, e> 0 && t > 0 && t < 1};
}

}  // namespace shapectl
