#pragma once
// Runs TetGen on a closed triangle surface in a child process, so that TetGen's crashes on
// inputs it rejects become error messages.
#include <array>
#include <string>
#include <vector>

#include <shapectl/mesh/triangle_surface.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

struct TetgenOutput {
  std::vector<Vec3> points;              // the input vertices first (unless TetGen dropped one)
  std::vector<std::array<int, 4>> tets;  // indices into points, numbered from 0
};

// tetrahedralize(switches) on the surface as a piecewise linear complex, one facet per
// triangle. `switches` are TetGen's command-line switches without the dash; they must include
// "z" (number from 0). Checks nothing about the surface or the output (the caller does).
// TetGen failures (self-intersections, out of memory, a crash) throw InputError naming
// `source`; invalid switches throw std::logic_error; no pipe or fork, std::runtime_error.
TetgenOutput run_tetgen(const TriangleSurface& surface, const std::string& switches,
                        const std::string& source);

}  // namespace shapectl
