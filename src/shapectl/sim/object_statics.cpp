#include <shapectl/sim/object_statics.hpp>

#include <numeric>

namespace shapectl {

std::string find_unheld_part(const TetMesh& mesh, const std::vector<char>& held) {
  // Union-find over tet connectivity; isolated nodes count as held (they do not move).
  std::vector<int> parent(mesh.node_count());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto& t : mesh.tets())
    for (int a = 1; a < 4; ++a) parent[root(t.nodes[a])] = root(t.nodes[0]);
  std::vector<char> part_held(mesh.node_count(), 0);
  for (int i = 0; i < mesh.node_count(); ++i)
    if (held[i]) part_held[root(i)] = 1;
  for (int i : mesh.isolated_nodes()) part_held[root(i)] = 1;
  for (int i = 0; i < mesh.node_count(); ++i)
    if (!part_held[root(i)]) {
      int size = 0;
      for (int k = 0; k < mesh.node_count(); ++k) size += root(k) == root(i);
      return "singular system: nothing holds the object (the part with node " + std::to_string(i) +
             ", " + std::to_string(size) + " nodes, has no fixed or gripped node)";
    }
  return "";
}

namespace {
std::shared_ptr<const TetMesh> placed_mesh(const Scene& scene) {
  std::vector<Vec3> p;
  p.reserve(scene.object_mesh->node_count());
  for (const auto& X : scene.object_mesh->rest_positions()) p.push_back(scene.T_world_object * X);
  std::vector<std::array<int, 4>> tets;
  for (const auto& t : scene.object_mesh->tets()) tets.push_back(t.nodes);
  return std::make_shared<const TetMesh>(std::move(p), std::move(tets), scene.source.string());
}
}  // namespace

ObjectStatics::ObjectStatics(const Scene& scene, std::vector<const EnergyTerm*> extra_terms,
                             const std::vector<int>& held_nodes)
    : mesh_(placed_mesh(scene)),
      elasticity_(*mesh_, scene.material),
      gravity_(*mesh_, scene.material.density, scene.gravity),
      fixed_node_(mesh_->node_count(), 0) {
  if (scene.fixed)
    for (int i : scene.fixed->resolve(*scene.object_mesh)) fixed_node_[i] = 1;
  // Nodes no element touches carry no stiffness: keep them where they are.
  for (int i : mesh_->isolated_nodes()) fixed_node_[i] = 1;
  std::vector<char> held = fixed_node_;
  for (int i : held_nodes) held[i] = 1;
  unheld_reason_ = find_unheld_part(*mesh_, held);

  std::vector<const EnergyTerm*> terms = {&elasticity_, &gravity_};
  terms.insert(terms.end(), extra_terms.begin(), extra_terms.end());
  // Converged when every nodal force is a tiny fraction of the weight (or, for a weightless
  // object, of the force that strains it by 0.1 %).
  const double size = (mesh_->bounds_max() - mesh_->bounds_min()).norm();
  const double scale = gravity_.weight() > 0 ? gravity_.weight() : 1e-3 * scene.material.mu * size * size;
  StaticsOptions options{.force_tolerance = scene.statics.relative_tolerance * scale,
                         .max_iterations = scene.statics.max_iterations,
                         .backend = scene.statics.backend};
  solver_ = std::make_unique<StaticsSolver>(mesh_->node_count(), terms, fixed_node_, options);
}

StaticsResult ObjectStatics::solve(Positions& x, int max_iterations) {
  if (!unheld_reason_.empty()) {
    StaticsResult r;
    r.status = StaticsStatus::Singular;
    r.reason = unheld_reason_;
    return r;
  }
  return solver_->solve(x, max_iterations);
}

}  // namespace shapectl
