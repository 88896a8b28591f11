#pragma once
// A scene's object as an energy and a statics solver: neo-Hookean elasticity, gravity, fixed
// nodes, plus extra terms the caller owns (the robot's grip springs).
#include <memory>
#include <vector>

#include <shapectl/fem/gravity.hpp>
#include <shapectl/fem/neo_hookean.hpp>
#include <shapectl/sim/scene.hpp>
#include <shapectl/sim/statics.hpp>

namespace shapectl {

class ObjectStatics {
 public:
  // extra_terms: not owned, must outlive this. held_nodes: nodes those terms hold in place
  // (gripped nodes), used only to detect parts of the object that nothing holds.
  ObjectStatics(const Scene& scene, std::vector<const EnergyTerm*> extra_terms = {},
                const std::vector<int>& held_nodes = {});

  // Equilibrium from the warm start x (fixed nodes must be at their prescribed positions).
  // An object that nothing holds is reported as Singular without iterating.
  StaticsResult solve(Positions& x, int max_iterations = 0);
  StaticsSolver& solver() { return *solver_; }
  const TetMesh& mesh() const { return *mesh_; }
  const std::vector<char>& fixed_node() const { return fixed_node_; }
  double weight() const { return gravity_.weight(); }
  // The force Newton stops at: the scene's tolerance, or the round-off floor if larger.
  double force_tolerance() const { return solver_->effective_tolerance(); }

 private:
  std::shared_ptr<const TetMesh> mesh_;
  NeoHookean elasticity_;
  Gravity gravity_;
  std::vector<char> fixed_node_;
  std::string unheld_reason_;
  std::unique_ptr<StaticsSolver> solver_;
};

// What round-off alone leaves in a nodal force (N) and in the energy (J) of `mesh` (placed in
// the world) of `material` with total weight `weight`: the floor of the force tolerance and
// the line search's energy resolution (see statics.hpp).
struct RoundoffScale {
  double force = 0;
  double energy = 0;
};
RoundoffScale roundoff_scale(const TetMesh& mesh, const Material& material, double weight);

// Empty if every connected part of the mesh has a held node; otherwise says which is free.
std::string find_unheld_part(const TetMesh& mesh, const std::vector<char>& held);

}  // namespace shapectl
