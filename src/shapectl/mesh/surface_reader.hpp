#pragma once
// Reads a closed triangle surface (OBJ, STL or OFF), choosing the format by extension.
#include <filesystem>

#include <shapectl/mesh/triangle_surface.hpp>

namespace shapectl {

// True for the surface formats read_surface reads (.obj, .stl, .off, in any letter case).
bool is_surface_file(const std::filesystem::path& file);

// Reads a triangle surface by extension: .obj (v/f lines; polygons fan-triangulated; f 1/2/3,
// f 1//3 and negative indices), .stl (ASCII or binary) or .off. Vertices with identical
// coordinates are merged into the first; vertices no face uses are dropped; the rest keep the
// file's order. Throws InputError naming the file and line.
TriangleSurface read_surface(const std::filesystem::path& file);

}  // namespace shapectl
