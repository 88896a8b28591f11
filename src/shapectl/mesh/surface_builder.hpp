#pragma once
// Collects a surface as a file lists it, for the surface readers (OBJ, OFF, STL).
#include <array>
#include <map>
#include <string>
#include <vector>

#include <shapectl/mesh/triangle_surface.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

// Merges vertices with equal coordinates into the first, splits polygons into triangle fans,
// and finally drops vertices no face uses; the rest keep the order they were read in.
// Throws InputError naming `name` beyond 3 × max_surface_triangles vertices or
// max_surface_triangles triangles.
class SurfaceBuilder {
 public:
  explicit SurfaceBuilder(const std::string& name) : name_(name) {}
  void add_vertex(const Vec3& x);
  // Vertices read so far, merged ones included.
  int vertex_count() const { return static_cast<int>(unique_of_read_.size()); }
  // `corners` index the vertices in the order they were read; false if a vertex repeats.
  bool add_polygon(const std::vector<int>& corners);
  // The surface without unused vertices. Throws InputError naming `name` if it has no faces.
  TriangleSurface finish(const std::string& name);

 private:
  std::string name_;
  TriangleSurface surface_;
  std::map<std::array<double, 3>, int> merged_;
  std::vector<int> unique_of_read_;  // for each vertex read, its index in surface_.vertices
};

}  // namespace shapectl
