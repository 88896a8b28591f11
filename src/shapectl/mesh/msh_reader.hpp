#pragma once
// Reads Gmsh meshes in the MSH 2.2 and 4.1 ASCII formats.
#include <filesystem>

#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// Linear tetrahedra (element type 4) become the mesh; every other element type (points, lines,
// triangles, quadrangles, higher-order elements) is ignored. Nodes keep the file's order: node i
// of the mesh is the i-th node listed in $Nodes, whatever its tag (tags may have gaps).
// Coordinates are taken as metres. Gmsh writes positively oriented tets, so none are reordered.
// Throws InputError naming the file, line and element: missing or truncated file, wrong counts,
// unknown node tags, non-numeric or non-finite values, binary files, unsupported versions,
// no tetrahedra, inverted or degenerate tetrahedra.
TetMesh read_msh(const std::filesystem::path& file);

}  // namespace shapectl
