#pragma once
// Reads OFF (Object File Format) triangle surfaces.
#include <string>

#include <shapectl/mesh/triangle_surface.hpp>

namespace shapectl {

// `text` is the file's content, `name` the file as messages show it. "OFF" (any prefix such as
// "COFF" accepted), "vertices faces edges" (on the header line or the next), then one "x y z"
// line per vertex and one "k i0 ... ik-1 [colour]" line per face; faces are fan-triangulated.
// Throws InputError naming "name:line".
TriangleSurface read_off(const std::string& name, const std::string& text);

}  // namespace shapectl
