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

bool MaterialRegion::contains(const TetMesh& mesh, const TetRest& tet) const {
  Vec3 centroid = Vec3::Zero();
  for (int a : tet.nodes) centroid += mesh.rest_positions()[a];
  return box.contains(centroid / 4);
}

std::vector<Material> Scene::element_materials() const {
  if (regions.empty()) return {material};
  const std::vector<int> owner = element_regions();
  std::vector<Material> out(owner.size(), material);
  for (std::size_t e = 0; e < owner.size(); ++e)
    if (owner[e] >= 0) out[e] = regions[owner[e]].material;
  return out;
}

std::vector<int> Scene::element_regions() const {
  const auto& tets = object_mesh->tets();
  std::vector<int> out(tets.size(), -1);
  for (std::size_t e = 0; e < tets.size(); ++e)
    for (std::size_t r = 0; r < regions.size(); ++r)
      if (regions[r].contains(*object_mesh, tets[e])) out[e] = static_cast<int>(r);
  return out;
}

Eigen::VectorXd Scene::load_forces() const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * object_mesh->node_count());
  for (const NodeLoad& load : loads)
    for (int i : load.nodes) f.segment<3>(3 * i) += load.force / double(load.nodes.size());
  return f;
}

Vec3 Scene::loads_total() const {
  Vec3 total = Vec3::Zero();
  for (const NodeLoad& load : loads) total += load.force;
  return total;
}

}  // namespace shapectl
