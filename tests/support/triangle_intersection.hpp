#pragma once
// Exact-predicate geometry for checking contact results, written apart from contact/: whether
// two triangles share a point, and distances from points and segments to triangles. Tests use
// it to show that no equilibrium passes through an obstacle.
//
// Triangle–triangle: two closed triangles intersect iff an edge of one meets the other (for
// triangles in different planes the intersection is the overlap of their two chords on the
// planes' common line, and an end of that overlap lies on an edge), or, for triangles in one
// plane, iff their 2D projections overlap. Every decision is a sign of an orientation
// determinant (evaluated in long double), as in Guigue and Devillers (2003).
#include <array>

#include <shapectl/types.hpp>

namespace shapectl::test {

using Triangle = std::array<Vec3, 3>;

// Sign of det[b − a, c − a, d − a]: > 0 when d is on the side a, b, c turn counter-clockwise
// towards; 0 when the four points lie in one plane.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Whether the closed segment pq shares a point with the closed triangle t.
bool segment_meets_triangle(const Vec3& p, const Vec3& q, const Triangle& t);
// Whether the closed triangles share a point (touching counts).
bool triangles_intersect(const Triangle& a, const Triangle& b);

// Closest distances, m.
double point_triangle_distance(const Vec3& p, const Triangle& t);
double segment_segment_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);
double segment_triangle_distance(const Vec3& p, const Vec3& q, const Triangle& t);

}  // namespace shapectl::test
