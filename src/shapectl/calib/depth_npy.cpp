#include <shapectl/calib/depth_npy.hpp>

#include <cmath>
#include <cstring>

#include <shapectl/calib/little_endian.hpp>
#include <shapectl/calib/npy_header.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>

namespace shapectl {

DepthImage read_depth_npy(const std::string& name, const std::string& bytes, double scale) {
  const NpyArray header = read_npy_header(name, bytes);
  if (header.descr != "<f8" && header.descr != "<f4")
    throw InputError(name, "header 'descr'", "'<f4' or '<f8' (little-endian float32 or float64)",
                     "'" + bounded_preview(header.descr) + "'");
  const std::vector<std::uint64_t>& shape = header.shape;
  if (shape.size() != 2)
    throw InputError(name, "header 'shape'", "(height, width)", npy_shape_text(shape));
  if (shape[0] == 0 || shape[1] == 0 || shape[1] > max_depth_image_pixels / shape[0])
    throw InputError(name, "header 'shape'",
                     "at least 1 and at most " + std::to_string(max_depth_image_pixels) + " pixels",
                     npy_shape_text(shape));
  const std::size_t count = shape[0] * shape[1];
  const std::size_t item = header.descr == "<f8" ? 8 : 4;
  const std::size_t found = bytes.size() - header.data_start;
  if (found != item * count)
    throw InputError(name, "data",
                     std::to_string(count) + " values of " + std::to_string(item) + " bytes (" +
                         std::to_string(item * count) + " bytes) after the header",
                     std::to_string(found) + " bytes");
  DepthImage image{static_cast<int>(shape[1]), static_cast<int>(shape[0]),
                   std::vector<double>(count)};
  const char* data = bytes.data() + header.data_start;
  for (std::size_t i = 0; i < count; ++i) {
    const char* at = data + i * item;
    const double value = item == 8 ? read_little_endian<double>(at) : read_little_endian<float>(at);
    if (std::isinf(value))
      throw InputError(name,
                       "pixel " + std::to_string(i % shape[1]) + ", " +
                           std::to_string(i / shape[1]),
                       "a finite depth, NaN or 0", value);
    image.depth[i] = value > 0 ? value * scale : NAN;
  }
  return image;
}

std::string depth_npy_bytes(const DepthImage& image) {
  std::string out =
      npy_header_bytes("<f4", {std::uint64_t(image.height), std::uint64_t(image.width)});
  for (const double d : image.depth) {
    const float value = static_cast<float>(d);
    char bytes[4];
    std::memcpy(bytes, &value, 4);
    if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + 4);
    out.append(bytes, 4);
  }
  return out;
}

}  // namespace shapectl
