#include "support/triangle_intersection.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace shapectl::test {

namespace {

using Real = long double;

int sign(Real v) { return (v > 0) - (v < 0); }

// 2D orientation of (a, b, c) in the plane of axes (u, v).
int orient2d(const Vec3& a, const Vec3& b, const Vec3& c, int u, int v) {
  const Real abu = Real(b[u]) - a[u], abv = Real(b[v]) - a[v];
  const Real acu = Real(c[u]) - a[u], acv = Real(c[v]) - a[v];
  return sign(abu * acv - abv * acu);
}

// Whether r (collinear with p, q) lies within the box of p and q on axes u, v.
bool within(const Vec3& p, const Vec3& q, const Vec3& r, int u, int v) {
  return std::min(p[u], q[u]) <= r[u] && r[u] <= std::max(p[u], q[u]) &&
         std::min(p[v], q[v]) <= r[v] && r[v] <= std::max(p[v], q[v]);
}

// Closed segments pq and rs in 2D.
bool segments_meet_2d(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s, int u, int v) {
  const int o1 = orient2d(p, q, r, u, v), o2 = orient2d(p, q, s, u, v);
  const int o3 = orient2d(r, s, p, u, v), o4 = orient2d(r, s, q, u, v);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && within(p, q, r, u, v)) || (o2 == 0 && within(p, q, s, u, v)) ||
         (o3 == 0 && within(r, s, p, u, v)) || (o4 == 0 && within(r, s, q, u, v));
}

// Closed triangle t contains p in 2D (t not degenerate).
bool inside_2d(const Vec3& p, const Triangle& t, int u, int v) {
  const int a = orient2d(t[0], t[1], p, u, v), b = orient2d(t[1], t[2], p, u, v),
            c = orient2d(t[2], t[0], p, u, v);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

// The two axes of the projection that keeps the plane of t least distorted.
std::array<int, 2> projection_axes(const Triangle& t) {
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).cwiseAbs();
  const int drop = n.x() >= n.y() && n.x() >= n.z() ? 0 : (n.y() >= n.z() ? 1 : 2);
  return {(drop + 1) % 3, (drop + 2) % 3};
}

bool segment_meets_triangle_2d(const Vec3& p, const Vec3& q, const Triangle& t, int u, int v) {
  if (inside_2d(p, t, u, v) || inside_2d(q, t, u, v)) return true;
  for (int e = 0; e < 3; ++e)
    if (segments_meet_2d(p, q, t[e], t[(e + 1) % 3], u, v)) return true;
  return false;
}

}  // namespace

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  Real m[3][3];
  for (int k = 0; k < 3; ++k) {
    m[0][k] = Real(b[k]) - a[k];
    m[1][k] = Real(c[k]) - a[k];
    m[2][k] = Real(d[k]) - a[k];
  }
  return sign(m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
              m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
              m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]));
}

bool segment_meets_triangle(const Vec3& p, const Vec3& q, const Triangle& t) {
  const int sp = orient3d(t[0], t[1], t[2], p), sq = orient3d(t[0], t[1], t[2], q);
  if (sp * sq > 0) return false;  // both strictly on one side
  if (sp == 0 && sq == 0) {
    const auto [u, v] = projection_axes(t);
    return segment_meets_triangle_2d(p, q, t, u, v);
  }
  // The segment crosses (or touches) the plane: it hits the triangle iff the line pq passes
  // on the same side of all three edges (or through one).
  const int a = orient3d(p, q, t[0], t[1]), b = orient3d(p, q, t[1], t[2]),
            c = orient3d(p, q, t[2], t[0]);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

bool triangles_intersect(const Triangle& a, const Triangle& b) {
  int side[3];
  for (int k = 0; k < 3; ++k) side[k] = orient3d(a[0], a[1], a[2], b[k]);
  if (side[0] == side[1] && side[1] == side[2]) {
    if (side[0] != 0) return false;  // b wholly on one side of a's plane
    const auto [u, v] = projection_axes(a);
    for (int e = 0; e < 3; ++e)
      if (segment_meets_triangle_2d(b[e], b[(e + 1) % 3], a, u, v)) return true;
    return inside_2d(a[0], b, u, v);
  }
  for (int e = 0; e < 3; ++e)
    if (segment_meets_triangle(a[e], a[(e + 1) % 3], b) ||
        segment_meets_triangle(b[e], b[(e + 1) % 3], a))
      return true;
  return false;
}

double point_triangle_distance(const Vec3& p, const Triangle& t) {
  // Inside the prism over the triangle: the distance to its plane; else to the nearest edge.
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  bool over = true;
  for (int e = 0; e < 3; ++e) over = over && n.dot((t[(e + 1) % 3] - t[e]).cross(p - t[e])) >= 0;
  if (over) return std::abs(n.normalized().dot(p - t[0]));
  double d = INFINITY;
  for (int e = 0; e < 3; ++e) d = std::min(d, segment_segment_distance(p, p, t[e], t[(e + 1) % 3]));
  return d;
}

double segment_segment_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  // Minimise |p0 + s d1 − q0 − t d2| over [0, 1]²: the interior stationary point if any, else
  // the best of the four edges of the square (each a point–segment problem).
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  auto point_segment = [](const Vec3& x, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double len2 = ab.squaredNorm();
    const double s = len2 > 0 ? std::clamp((x - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (a + s * ab - x).norm();
  };
  double best = std::min({point_segment(p0, q0, q1), point_segment(p1, q0, q1),
                          point_segment(q0, p0, p1), point_segment(q1, p0, p1)});
  const double a = d1.dot(d1), b = d1.dot(d2), c = d2.dot(d2), d = d1.dot(r), e = d2.dot(r);
  const double det = a * c - b * b;
  if (det > 1e-20 * a * c) {
    const double s = (b * e - c * d) / det, t = (a * e - b * d) / det;
    if (s >= 0 && s <= 1 && t >= 0 && t <= 1)
      best = std::min(best, (p0 + s * d1 - q0 - t * d2).norm());
  }
  return best;
}

double segment_triangle_distance(const Vec3& p, const Vec3& q, const Triangle& t) {
  if (segment_meets_triangle(p, q, t)) return 0;
  double d = std::min(point_triangle_distance(p, t), point_triangle_distance(q, t));
  for (int e = 0; e < 3; ++e) d = std::min(d, segment_segment_distance(p, q, t[e], t[(e + 1) % 3]));
  return d;
}

}  // namespace shapectl::test
