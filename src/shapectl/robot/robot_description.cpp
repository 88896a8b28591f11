#include <shapectl/robot/robot_description.hpp>

#include <shapectl/io/input_file.hpp>

namespace shapectl {

std::string read_robot_description(const std::filesystem::path& file, const XacroOptions& xacro) {
  if (is_xacro_file(file)) return expand_xacro_file(file, xacro);
  return read_input_file(file, max_urdf_file_bytes, "URDF");
}

}  // namespace shapectl
