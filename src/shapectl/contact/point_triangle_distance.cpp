#include <shapectl/contact/point_triangle_distance.hpp>

namespace shapectl {

// Ericson, Real-Time Collision Detection, 5.1.5: the Voronoi region of p, tested corner by
// corner, edge by edge, from the barycentric coordinates' numerators.
PointTriangleRegion point_triangle_region(const Vec3& p, const Vec3& a, const Vec3& b,
                                          const Vec3& c, Vec3* closest) {
  const auto result = [&](PointTriangleRegion region, const Vec3& q) {
    if (closest) *closest = q;
    return region;
  };
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return result(PointTriangleRegion::A, a);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return result(PointTriangleRegion::B, b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
    return result(PointTriangleRegion::AB, a + d1 / (d1 - d3) * ab);
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return result(PointTriangleRegion::C, c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
    return result(PointTriangleRegion::CA, a + d2 / (d2 - d6) * ac);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return result(PointTriangleRegion::BC, b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b));
  const double denominator = 1 / (va + vb + vc);
  return result(PointTriangleRegion::Face, a + ab * (vb * denominator) + ac * (vc * denominator));
}

}  // namespace shapectl
