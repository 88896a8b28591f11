#pragma once
// Tetrahedralizes a closed triangle surface (OBJ, STL or OFF) with TetGen.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <shapectl/mesh/tet_mesh.hpp>
#include <shapectl/types.hpp>

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

struct TriangleSurface {
  std::vector<Vec3> vertices;                 // metres
  std::vector<std::array<int, 3>> triangles;  // indices into vertices
};

// True for the surface formats read_surface reads (.obj, .stl, .off, in any letter case).
bool is_surface_file(const std::filesystem::path& file);

// Reads a triangle surface by extension: .obj (v/f lines; polygons fan-triangulated; f 1/2/3,
// f 1//3 and negative indices), .stl (ASCII or binary) or .off. Vertices with identical
// coordinates are merged into the first; vertices no face uses are dropped; the rest keep the
// file's order. Throws InputError naming the file and line.
TriangleSurface read_surface(const std::filesystem::path& file);

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
