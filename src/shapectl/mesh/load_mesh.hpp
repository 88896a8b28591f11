#pragma once
// One entry point for every mesh file format, chosen by extension.
#include <filesystem>

#include <shapectl/mesh/surface_mesher.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// .msh: Gmsh MSH 2.2 or 4.1 ASCII; .node or .ele: TetGen pair; .obj, .stl, .off: a closed
// surface tetrahedralized with `surface_options`. Extensions are case-insensitive.
// Throws InputError naming the file (and line) for an unknown extension or bad content.
TetMesh load_mesh(const std::filesystem::path& file,
                  const SurfaceMeshOptions& surface_options = {});

}  // namespace shapectl
