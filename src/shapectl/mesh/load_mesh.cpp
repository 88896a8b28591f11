#include <shapectl/mesh/load_mesh.hpp>

#include <string>

#include <shapectl/io/ascii_case.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/msh_reader.hpp>
#include <shapectl/mesh/tetgen_reader.hpp>

namespace shapectl {

TetMesh load_mesh(const std::filesystem::path& file, const SurfaceMeshOptions& surface_options) {
  const std::string extension = lowercase_extension(file);
  if (extension == ".msh") return read_msh(file);
  if (extension == ".node" || extension == ".ele") return read_tetgen(file);
  if (is_surface_file(file)) return mesh_surface(file, surface_options);
  throw InputError(file.string(), "",
                   "unknown mesh format '" + extension +
                       "' (supported: .msh, .node/.ele, and surfaces .obj, .stl, .off)");
}

}  // namespace shapectl
