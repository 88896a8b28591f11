#pragma once
// Covers collision primitives with spheres: every point of the primitive lies inside some
// sphere, with a modest count. Used to generate collision spheres from URDF collision geometry.
// All geometry is in the primitive's frame (or any one frame), metres.
#include <array>
#include <vector>

#include <shapectl/robot/robot_model.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

struct CoverSphere {
  Vec3 center = Vec3::Zero();
  double radius = 0;
};

// At most this many cells along one axis: a long thin part gets a chain of spheres, never
// hundreds of them.
inline constexpr int max_cover_cells_per_axis = 8;

// A box with full edge lengths `size`, centred at the origin: a grid of cells, each inside its
// circumscribed sphere. Cells are about as long as the box's smallest edge.
std::vector<CoverSphere> cover_box(const Vec3& size);
// A cylinder of `radius` and `length` along z, centred at the origin: slices along z, each
// inside one sphere on the axis.
std::vector<CoverSphere> cover_cylinder(double radius, double length);
// A URDF primitive (sphere, box, cylinder) given in its link frame: spheres in the link frame.
std::vector<CoverSphere> cover_shape(const Shape& shape);

// A triangle mesh (vertices in one frame): the grid cells of its bounding box that touch a
// triangle or, for a closed mesh, lie inside it, each inside its circumscribed sphere. Covers
// every point of every triangle and, when the mesh is closed, the enclosed volume.
// Empty for a mesh without triangles. Indices must be valid (checked by the reader).
std::vector<CoverSphere> cover_triangle_mesh(const std::vector<Vec3>& vertices,
                                             const std::vector<std::array<int, 3>>& triangles);

}  // namespace shapectl
