#include <shapectl/fem/gravity.hpp>

namespace shapectl {

Eigen::VectorXd lumped_masses(const TetMesh& mesh, double density) {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.node_count());
  for (const auto& t : mesh.tets())
    for (int a : t.nodes) m[a] += density * t.volume / 4.0;
  return m;
}

Gravity::Gravity(const TetMesh& mesh, double density, const Vec3& g) {
  const Eigen::VectorXd m = lumped_masses(mesh, density);
  gradient_.resize(3 * mesh.node_count());
  for (int i = 0; i < mesh.node_count(); ++i) gradient_.segment<3>(3 * i) = -m[i] * g;
  weight_ = m.sum() * g.norm();
}

}  // namespace shapectl
