#include <shapectl/mesh/surface_builder.hpp>

#include <algorithm>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/mesh_limits.hpp>

namespace shapectl {

void SurfaceBuilder::add_vertex(const Vec3& x) {
  if (static_cast<long>(unique_of_read_.size()) >= 3 * max_surface_triangles)
    throw InputError(name_, "",
                     "more than " + std::to_string(3 * max_surface_triangles) +
                         " vertices (the limit for a surface)");
  const auto [it, inserted] =
      merged_.emplace(std::array<double, 3>{x.x(), x.y(), x.z()}, int(surface_.vertices.size()));
  if (inserted) surface_.vertices.push_back(x);
  unique_of_read_.push_back(it->second);
}

bool SurfaceBuilder::add_polygon(const std::vector<int>& corners) {
  if (static_cast<long>(surface_.triangles.size() + corners.size()) - 2 > max_surface_triangles)
    throw InputError(name_, "",
                     "more than " + std::to_string(max_surface_triangles) +
                         " triangles (the limit for a surface)");
  std::vector<int> unique;
  for (int c : corners) unique.push_back(unique_of_read_[c]);
  std::vector<int> sorted = unique;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;
  for (std::size_t k = 1; k + 1 < unique.size(); ++k)
    surface_.triangles.push_back({unique[0], unique[k], unique[k + 1]});
  return true;
}

TriangleSurface SurfaceBuilder::finish(const std::string& name) {
  if (surface_.triangles.empty()) throw InputError(name, "", "no faces");
  std::vector<int> new_index(surface_.vertices.size(), -1);
  for (const auto& t : surface_.triangles)
    for (int v : t) new_index[v] = 0;
  TriangleSurface out;
  for (std::size_t v = 0; v < surface_.vertices.size(); ++v)
    if (new_index[v] == 0) {
      new_index[v] = static_cast<int>(out.vertices.size());
      out.vertices.push_back(surface_.vertices[v]);
    }
  for (const auto& t : surface_.triangles)
    out.triangles.push_back({new_index[t[0]], new_index[t[1]], new_index[t[2]]});
  return out;
}

}  // namespace shapectl
