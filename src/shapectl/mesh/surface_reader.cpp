#include <shapectl/mesh/surface_reader.hpp>

#include <string>

#include <shapectl/io/ascii_case.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/obj_reader.hpp>
#include <shapectl/mesh/off_reader.hpp>
#include <shapectl/mesh/stl_reader.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

bool is_surface_file(const std::filesystem::path& file) {
  const std::string extension = lowercase_extension(file);
  return extension == ".obj" || extension == ".stl" || extension == ".off";
}

TriangleSurface read_surface(const std::filesystem::path& file) {
  const std::string extension = lowercase_extension(file);
  const std::string name = file.string();
  if (!is_surface_file(file))
    throw InputError(name, "",
                     "unknown surface format '" + extension + "' (supported: .obj, .stl, .off)");
  const std::string text = read_text_file(file);
  if (extension == ".obj") return read_obj(name, text);
  if (extension == ".stl") return read_stl(name, text);
  return read_off(name, text);
}

}  // namespace shapectl
