#pragma once
// What a depth camera would see of the object: its surface triangles (TetMesh::
// surface_triangles() at `positions`) rendered into a depth buffer, exactly per pixel: each
// pixel's ray (calib/depth_image.hpp) meets the nearest triangle at the depth it records. For
// tests and the simulated world; simple, not fast (every triangle's pixel box is scanned).
#include <shapectl/calib/depth_image.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// A width × height image; pixels whose ray meets no triangle hold NaN. Triangles with a corner
// at or behind the camera's plane (z ≤ 1 mm) are left out: the camera looks at the object from
// outside it.
DepthImage render_depth(const TetMesh& mesh, const Positions& positions,
                        const PinholeIntrinsics& intrinsics,
                        const Eigen::Isometry3d& T_world_camera, int width, int height);

}  // namespace shapectl
