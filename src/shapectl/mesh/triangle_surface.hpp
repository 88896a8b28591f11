#pragma once
// A triangle surface as the surface readers return it and TetGen takes it.
#include <array>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

struct TriangleSurface {
  std::vector<Vec3> vertices;                 // metres
  std::vector<std::array<int, 3>> triangles;  // indices into vertices
};

}  // namespace shapectl
