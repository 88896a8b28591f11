#pragma once
// Reads STL triangle surfaces, ASCII or binary.
#include <string>

#include <shapectl/mesh/triangle_surface.hpp>

namespace shapectl {

// `bytes` is the file's content, `name` the file as messages show it. Binary when the file is
// exactly 84 + 50 n bytes for the n its header states (80-byte header, uint32 n, per triangle
// 12 little-endian float32 — normal, 3 vertices — and a uint16); otherwise ASCII, which must
// start with "solid" (facets of "outer loop", three "vertex x y z", "endloop", "endfacet").
// Normals are ignored. Throws InputError naming the file (and line, or triangle).
TriangleSurface read_stl(const std::string& name, const std::string& bytes);

}  // namespace shapectl
