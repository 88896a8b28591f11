#include <shapectl/fem/gravity.hpp>

#include <stdexcept>

namespace shapectl {

namespace {
// Stacked nodal forces mᵢ g.
Eigen::VectorXd weights(const Eigen::VectorXd& masses, const Vec3& g) {
  Eigen::VectorXd f(3 * masses.size());
  for (Eigen::Index i = 0; i < masses.size(); ++i) f.segment<3>(3 * i) = masses[i] * g;
  return f;
}
}  // namespace

Eigen::VectorXd lumped_masses(const TetMesh& mesh, double density) {
  return lumped_masses(mesh, {Material{.density = density}});
}

Eigen::VectorXd lumped_masses(const TetMesh& mesh, const std::vector<Material>& materials) {
  const auto& tets = mesh.tets();
  if (materials.size() != 1 && materials.size() != tets.size())
    throw std::invalid_argument("lumped_masses: one material, or one per element");
  const std::size_t stride = materials.size() == 1 ? 0 : 1;
  Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.node_count());
  for (std::size_t e = 0; e < tets.size(); ++e)
    for (int a : tets[e].nodes) m[a] += materials[stride * e].density * tets[e].volume / 4.0;
  return m;
}

Gravity::Gravity(const TetMesh& mesh, double density, const Vec3& g)
    : Gravity(lumped_masses(mesh, density), g) {}

Gravity::Gravity(const TetMesh& mesh, const std::vector<Material>& materials, const Vec3& g)
    : Gravity(lumped_masses(mesh, materials), g) {}

Gravity::Gravity(const Eigen::VectorXd& masses, const Vec3& g)
    : ConstantForce("gravity", weights(masses, g)), weight_(masses.sum() * g.norm()) {}

}  // namespace shapectl
