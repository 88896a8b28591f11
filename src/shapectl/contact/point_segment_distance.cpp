#include <shapectl/contact/point_segment_distance.hpp>

namespace shapectl {

PointSegmentRegion point_segment_region(const Vec3& p, const Vec3& a, const Vec3& b, double* t) {
  const Vec3 e = b - a;
  const double length2 = e.squaredNorm();
  // A degenerate segment is its point a.
  const double s = length2 > 0 ? (p - a).dot(e) / length2 : 0.0;
  if (s <= 0) {
    if (t) *t = 0;
    return PointSegmentRegion::A;
  }
  if (s >= 1) {
    if (t) *t = 1;
    return PointSegmentRegion::B;
  }
  if (t) *t = s;
  return PointSegmentRegion::Interior;
}

}  // namespace shapectl
