#pragma once
// The deformed surface as triangles for mesh tools (MeshLab, Blender, CloudCompare): ASCII PLY
// or Wavefront OBJ. Every node is written, in order, so vertex k is node k of the result
// (interior nodes are vertices no face uses).
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

enum class SurfaceFormat { Ply, Obj };

// The format a file name asks for: ".ply" or ".obj" (any case); nullopt for anything else.
std::optional<SurfaceFormat> surface_format(const std::filesystem::path& file);

// The file's text: `positions` stacked [x0; x1; ...] in metres (size 3n), `triangles` indexing
// them (outward-facing, as TetMesh::surface_triangles). Numbers are written so they read back
// exactly. std::invalid_argument if sizes or indices do not match or a number is not finite.
std::string surface_text(SurfaceFormat format, const Positions& positions,
                         const std::vector<std::array<int, 3>>& triangles);

}  // namespace shapectl
