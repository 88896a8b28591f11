#pragma once
// Tetrahedralizes a closed triangle surface (OBJ, STL or OFF) with TetGen: checks the surface
// and the options, runs TetGen (tetgen_runner.hpp), checks what it made.
#include <filesystem>
#include <string>

#include <shapectl/mesh/surface_reader.hpp>  // read_surface, is_surface_file, TriangleSurface
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

struct SurfaceMeshOptions {
  // Upper bound on a tet's circumradius / shortest edge (TetGen -q); 0 turns refinement off.
  double max_radius_edge_ratio = 1.4;
  // Upper bound on a tet's volume in m^3 (TetGen -a); 0 means no bound.
  double max_tet_volume = 0;
  // Keep the input triangles as the boundary, adding no Steiner points on it (TetGen -Y).
  bool keep_surface = false;
  // Where these options were given, for messages about them: e.g. "scene.json" and
  // "object.mesh" give "scene.json: object.mesh.max_tet_volume: ..."; empty: the surface's name.
  std::string origin_file = "";
  std::string origin_path = "";
};

// Tetrahedralizes a closed surface. Node order: the surface vertices first, in order, then the
// points TetGen added. Throws InputError naming `source` if the surface is not closed (every edge
// shared by exactly two triangles), or if TetGen refuses it (e.g. it intersects itself).
// Vertices must lie within 1e6 m of the origin (TetGen's predicates overflow beyond).
// Bounded work: a max_tet_volume below enclosed volume / max_tetgen_volume_ratio is refused
// before TetGen runs, and TetGen adds at most max_tetgen_added_points (needing more is an error).
TetMesh tetrahedralize_surface(const TriangleSurface& surface, const SurfaceMeshOptions& options,
                               const std::string& source = "surface");

// read_surface followed by tetrahedralize_surface.
TetMesh mesh_surface(const std::filesystem::path& file, const SurfaceMeshOptions& options = {});

}  // namespace shapectl
