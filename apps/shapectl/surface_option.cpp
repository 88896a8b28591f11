#include "surface_option.hpp"

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/surface_writer.hpp>

#include "output_option.hpp"

namespace shapectl::cli {

void add_surface_option(CLI::App& cmd, std::string& file) {
  cmd.add_option("--surface", file,
                 "also write the deformed surface triangles as PLY or OBJ (by the extension)")
      ->check(writable_output());
}

void check_surface_option(const std::string& command, const std::string& file) {
  if (!file.empty() && !surface_format(file))
    throw InputError(command, "--surface", "a file name ending in .ply or .obj", file);
}

FileContent surface_file(const std::string& file, const TetMesh& mesh, const Positions& positions) {
  return {file, surface_text(*surface_format(file), positions, mesh.surface_triangles())};
}

}  // namespace shapectl::cli
