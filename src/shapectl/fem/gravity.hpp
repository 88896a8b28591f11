#pragma once
// Gravitational potential E_g = −Σ mᵢ g·xᵢ (paper eq. 3) with lumped nodal masses: each tet
// gives a quarter of its mass to each corner. For a constant body force this equals the
// consistent linear-element load.
#include <vector>

#include <shapectl/fem/constant_force.hpp>
#include <shapectl/fem/material.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// Lumped nodal masses (kg), size n; isolated nodes get 0.
Eigen::VectorXd lumped_masses(const TetMesh& mesh, double density);
// The same with each element's density from `materials`: one for every element, or one per
// element in mesh.tets() order.
Eigen::VectorXd lumped_masses(const TetMesh& mesh, const std::vector<Material>& materials);

class Gravity : public ConstantForce {
 public:
  // g: gravitational acceleration in the world frame, m/s^2 (e.g. (0, 0, −9.81)).
  Gravity(const TetMesh& mesh, double density, const Vec3& g);
  // Densities from `materials` (as lumped_masses).
  Gravity(const TetMesh& mesh, const std::vector<Material>& materials, const Vec3& g);
  // Total weight of the object, N.
  double weight() const { return weight_; }

 private:
  Gravity(const Eigen::VectorXd& masses, const Vec3& g);
  double weight_ = 0;
};

}  // namespace shapectl
