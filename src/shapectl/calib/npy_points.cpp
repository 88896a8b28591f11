#include <shapectl/calib/npy_points.hpp>

#include <cstdint>

#include <shapectl/calib/little_endian.hpp>
#include <shapectl/calib/npy_header.hpp>
#include <shapectl/calib/point_cloud_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>

namespace shapectl {

std::vector<Vec3> read_npy_points(const std::string& name, const std::string& bytes) {
  const NpyArray header = read_npy_header(name, bytes);
  if (header.descr != "<f8" && header.descr != "<f4")
    throw InputError(name, "header 'descr'", "'<f8' or '<f4' (little-endian float64 or float32)",
                     "'" + bounded_preview(header.descr) + "'");
  const std::vector<std::uint64_t>& shape = header.shape;
  if (shape.size() != 2 || shape[1] != 3)
    throw InputError(name, "header 'shape'", "(N, 3)", npy_shape_text(shape));
  if (shape[0] > max_point_cloud_points)
    throw InputError(name, "header 'shape'",
                     std::to_string(shape[0]) + " points, more than the limit of " +
                         std::to_string(max_point_cloud_points));

  const std::size_t count = shape[0];
  const std::size_t item = header.descr == "<f8" ? 8 : 4;
  const std::size_t data_start = header.data_start;
  const std::size_t found = bytes.size() - data_start;
  if (found != 3 * item * count)
    throw InputError(name, "data",
                     "expected " + std::to_string(count) + " x 3 values of " +
                         std::to_string(item) + " bytes (" + std::to_string(3 * item * count) +
                         " bytes) after the header, found " + std::to_string(found) + " bytes");
  std::vector<Vec3> points(count);
  const char* data = bytes.data() + data_start;
  for (std::size_t i = 0; i < count; ++i) {
    for (int k = 0; k < 3; ++k) {
      const char* at = data + (3 * i + k) * item;
      points[i][k] = item == 8 ? read_little_endian<double>(at) : read_little_endian<float>(at);
    }
    if (!points[i].allFinite())
      throw InputError(name, "point " + std::to_string(i), "expected finite coordinates");
  }
  return points;
}

}  // namespace shapectl
