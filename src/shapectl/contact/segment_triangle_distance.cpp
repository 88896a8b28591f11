#include <shapectl/contact/segment_triangle_distance.hpp>

#include <algorithm>
#include <array>

#include <shapectl/contact/point_triangle_distance.hpp>
#include <shapectl/contact/segment_segment_distance.hpp>

namespace shapectl {

namespace {

// Whether segment ab passes through triangle t0t1t2 (touching counts): its ends are not on one
// side of the plane, and it passes each edge on the same side (signed volumes).
bool crosses(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1, const Vec3& t2) {
  const Vec3 n = (t1 - t0).cross(t2 - t0);
  const double da = (a - t0).dot(n), db = (b - t0).dot(n);
  if (da * db > 0 || (da == 0 && db == 0)) return false;  // coplanar: the distances decide
  const Vec3 ab = b - a;
  const double v0 = (t0 - a).cross(t1 - a).dot(ab), v1 = (t1 - a).cross(t2 - a).dot(ab),
               v2 = (t2 - a).cross(t0 - a).dot(ab);
  return (v0 >= 0 && v1 >= 0 && v2 >= 0) || (v0 <= 0 && v1 <= 0 && v2 <= 0);
}

}  // namespace

double segment_triangle_distance(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                                 const Vec3& t2) {
  if (crosses(a, b, t0, t1, t2)) return 0;
  const std::array<bool, 4> fixed{false, false, false, false};
  double d = std::min(point_triangle_distance<0>(a, t0, t1, t2, fixed),
                      point_triangle_distance<0>(b, t0, t1, t2, fixed));
  const std::array<Vec3, 3> t{t0, t1, t2};
  for (int k = 0; k < 3; ++k)
    d = std::min(d, segment_segment_distance<0>(a, b, t[k], t[(k + 1) % 3], fixed));
  return d;
}

}  // namespace shapectl
