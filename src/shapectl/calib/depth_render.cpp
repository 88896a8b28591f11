#include <shapectl/calib/depth_render.hpp>

#include <algorithm>
#include <cmath>

namespace shapectl {

DepthImage render_depth(const TetMesh& mesh, const Positions& positions, const PinholeIntrinsics& k,
                        const Eigen::Isometry3d& T_world_camera, int width, int height) {
  DepthImage image{width, height, std::vector<double>(std::size_t(width) * height, NAN)};
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  for (const auto& t : mesh.surface_triangles()) {
    Vec3 c[3];
    double u_lo = INFINITY, u_hi = -INFINITY, v_lo = INFINITY, v_hi = -INFINITY;
    bool in_front = true;
    for (int i = 0; i < 3; ++i) {
      c[i] = T_camera_world * Vec3(positions.segment<3>(3 * t[i]));
      in_front = in_front && c[i].z() > 1e-3;
      const double u = k.fx * c[i].x() / c[i].z() + k.cx, v = k.fy * c[i].y() / c[i].z() + k.cy;
      u_lo = std::min(u_lo, u), u_hi = std::max(u_hi, u);
      v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
    }
    if (!in_front) continue;
    const int u0 = std::max(0, int(std::ceil(u_lo))),
              u1 = std::min(width - 1, int(std::floor(u_hi)));
    const int v0 = std::max(0, int(std::ceil(v_lo))),
              v1 = std::min(height - 1, int(std::floor(v_hi)));
    // Ray p = z d with d = ((u − cx)/fx, (v − cy)/fy, 1): Möller–Trumbore gives z directly.
    const Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0];
    for (int v = v0; v <= v1; ++v)
      for (int u = u0; u <= u1; ++u) {
        const Vec3 d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1);
        const Vec3 p = d.cross(e2);
        const double det = e1.dot(p);
        if (std::abs(det) < 1e-300) continue;  // the ray runs along the triangle
        const Vec3 s = -c[0];
        const double a = s.dot(p) / det;
        const Vec3 q = s.cross(e1);
        const double b = d.dot(q) / det;
        if (a < 0 || b < 0 || a + b > 1) continue;
        const double z = e2.dot(q) / det;
        double& stored = image.depth[std::size_t(v) * width + u];
        if (z > 0 && !(stored <= z)) stored = z;
      }
  }
  return image;
}

}  // namespace shapectl
