#include <shapectl/sim/scene.hpp>

namespace shapectl {

std::vector<int> NodeSelection::resolve(const TetMesh& mesh) const {
  std::vector<char> chosen(mesh.node_count(), 0);
  for (int i : nodes) chosen[i] = 1;
  if (box)
    for (int i = 0; i < mesh.node_count(); ++i)
      if (box->contains(mesh.rest_positions()[i])) chosen[i] = 1;
  std::vector<int> out;
  for (int i = 0; i < mesh.node_count(); ++i)
    if (chosen[i]) out.push_back(i);
  return out;
}

Positions Scene::world_rest_positions() const {
  Positions x(3 * object_mesh->node_count());
  for (int i = 0; i < object_mesh->node_count(); ++i)
    x.segment<3>(3 * i) = T_world_object * object_mesh->rest_positions()[i];
  return x;
}

}  // namespace shapectl
