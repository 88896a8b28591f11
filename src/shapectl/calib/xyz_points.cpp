#include <shapectl/calib/xyz_points.hpp>

#include <shapectl/calib/point_cloud_file.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

std::vector<Vec3> read_xyz_points(const std::string& name, std::string text) {
  TextLines in(name, std::move(text), TextLines::Comments::Hash);
  std::vector<Vec3> points;
  while (in.next()) {
    if (in.size() < 3)
      in.fail("", "expected at least 3 values (x y z), found " + std::to_string(in.size()));
    if (points.size() == max_point_cloud_points)
      in.fail("", "more than the limit of " + std::to_string(max_point_cloud_points) + " points");
    points.push_back(in.point(0, "point " + std::to_string(points.size())));
  }
  return points;
}

}  // namespace shapectl
