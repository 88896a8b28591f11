#pragma once
// Reads Wavefront OBJ triangle surfaces.
#include <string>

#include <shapectl/mesh/triangle_surface.hpp>

namespace shapectl {

// `text` is the file's content, `name` the file as messages show it. "v x y z" and
// "f a b c ..." lines (a may be "a/t/n" or "a//n", negative indices count back from the last
// vertex read); polygons are fan-triangulated; every other line (vt, vn, g, o, s, usemtl, ...)
// is ignored. Throws InputError naming "name:line".
TriangleSurface read_obj(const std::string& name, const std::string& text);

}  // namespace shapectl
