#include <shapectl/calib/point_cloud_file.hpp>

#include <string>

#include <shapectl/calib/npy_points.hpp>
#include <shapectl/calib/ply_points.hpp>
#include <shapectl/calib/xyz_points.hpp>
#include <shapectl/io/ascii_case.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>

namespace shapectl {

std::vector<Vec3> read_point_cloud(const std::filesystem::path& file) {
  const std::string extension = lowercase_extension(file);
  const std::string name = file.string();
  if (extension != ".xyz" && extension != ".ply" && extension != ".npy")
    throw InputError(name, "",
                     "unknown point cloud format '" + bounded_preview(extension) +
                         "' (supported: .xyz, .ply, .npy)");
  std::string bytes = read_input_file(file, max_point_cloud_file_bytes, "point cloud");
  if (extension == ".ply") return read_ply_points(name, std::move(bytes));
  if (extension == ".npy") return read_npy_points(name, bytes);
  return read_xyz_points(name, std::move(bytes));
}

}  // namespace shapectl
