#pragma once
// Whether a segment meets a triangle, and how far apart they are: for first_intersection.
#include <shapectl/types.hpp>

namespace shapectl {

// The distance between segment ab and triangle t0t1t2: 0 where the segment crosses it.
double segment_triangle_distance(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                                 const Vec3& t2);

}  // namespace shapectl
