#pragma once
// Centre-line targets for bar-like objects (paper Section IV, Fig. 5).
//
// Mapping: the bar's axis is the principal direction of its rest nodes (PCA); each node has an
// axial coordinate s and a cross-section offset o. Along the axis the bar is cut into stations
// and the node nearest the axis in each station is a centre-line node. A node at axial
// fraction t = (s − s_min)/L is sent to the point at fraction t of the sketched polyline's arc
// length (so the whole bar follows the whole sketch); its small offset o is carried along,
// turned by the rotation that takes the rest axis onto the curve's local tangent. The bar end
// nearer the sketch's first point maps to that point.
#include <optional>
#include <string>
#include <vector>

#include <shapectl/control/shape_targets.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

struct BarAxis {
  Vec3 center;       // of the rest nodes
  Vec3 direction;    // unit, along the bar
  double s_min = 0;  // axial range of the nodes relative to center
  double length = 0;
  double thickness = 0;               // largest cross-section extent
  std::vector<int> centerline_nodes;  // ordered from s_min to s_max
};

// The axis if the mesh is bar-like (length ≥ 3 × thickness), else nullopt.
std::optional<BarAxis> find_bar_axis(const TetMesh& mesh);

// Throws InputError naming `source` and "centerline" unless `polyline` is a sketch this bar can
// follow: every point finite and within max_target_distance, and an arc length of at least
// min_centerline_fraction × the bar's length (shorter, a sketch has no shape: its direction is
// round-off, and a bar squeezed onto it would be no shape at all).
inline constexpr double min_centerline_fraction = 1e-3;
void check_centerline(const BarAxis& axis, const std::vector<Vec3>& polyline,
                      const std::string& source);

// Targets for the centre-line nodes of `mesh` (world-placed rest mesh) from a world polyline
// (checked with check_centerline; InputError with source "centerline" if it fails). The
// current shape x decides which bar end maps to the start.
ShapeTargets centerline_targets(const TetMesh& mesh, const BarAxis& axis,
                                const std::vector<Vec3>& polyline, const Positions& x);

}  // namespace shapectl
