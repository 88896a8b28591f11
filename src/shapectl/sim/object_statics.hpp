#pragma once
// A scene's object as an energy and a statics solver: neo-Hookean elasticity (each element of
// its region's material), gravity, applied loads, contact with the scene's obstacles and (with
// contact.self) with itself, fixed nodes, plus extra terms the caller owns (the robot's grip
// springs).
#include <memory>
#include <optional>
#include <vector>

#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/contact/self_contact.hpp>
#include <shapectl/fem/gravity.hpp>
#include <shapectl/fem/neo_hookean.hpp>
#include <shapectl/sim/contact_stiffness.hpp>
#include <shapectl/sim/lagged_friction.hpp>
#include <shapectl/sim/scene.hpp>
#include <shapectl/sim/statics.hpp>

namespace shapectl {

// The fixed description (immutable, shareable across threads); the changing part of a solve is
// the caller's StaticsWorkspace and positions.
class ObjectStatics {
 public:
  // held_nodes: nodes that extra terms (the robot's grip springs) will hold in place, used only
  // to detect parts of the object that nothing holds. With obstacles the object may rest on
  // them, so that check is left to Newton (a part nothing holds ends Singular or not converged).
  explicit ObjectStatics(const Scene& scene, const std::vector<int>& held_nodes = {});

  // The object's energy terms (elasticity, gravity, the loads, the obstacle contact and the
  // self-contact if any), plus `extra` if given; `contact` (if given) instead of contact(): the
  // same term posed at other joint angles (ObstacleContact::posed).
  EnergyTerms terms(const EnergyTerm* extra = nullptr,
                    const ObstacleContact* contact = nullptr) const;
  // The contact terms at a state: `posed` (null: contact()) and self_contact(), each with κ
  // multiplied by `scale` (the state's adaptive stiffness, contact_stiffness.hpp).
  ContactTerms contact_terms(double scale = 1, const ObstacleContact* posed = nullptr) const;
  // The object's energy terms with `contact`'s contact terms, plus `extra` if given.
  EnergyTerms terms(const EnergyTerm* extra, const ContactTerms& contact) const;
  StaticsWorkspace make_workspace() const { return solver_.make_workspace(); }
  // Equilibrium from the warm start x (fixed nodes must be at their prescribed positions) with
  // the energy plus `extra`, in `ws` (see StaticsSolver::solve for `chord`). An object that
  // nothing holds is reported as Singular without iterating; a start that touches or intersects
  // an obstacle or itself as Inverted without iterating, naming the obstacle or the triangles.
  // `contact`: as in terms(). The contact stiffness starts at κ × contact_scale and is raised
  // where a gap ends pressed below d̂/100 (contact_stiffness.hpp): the result's contact_scale
  // is the scale of x (the same as the workspace's factorization, if it holds one).
  StaticsResult solve(StaticsWorkspace& ws, Positions& x, const EnergyTerm* extra = nullptr,
                      int max_iterations = 0, const StaticsWorkspace* chord = nullptr,
                      const StopRequest& stop = {}, const ObstacleContact* contact = nullptr,
                      double contact_scale = 1) const;
  // The same from scratch (a workspace of its own, no earlier factorization).
  StaticsResult solve(Positions& x, int max_iterations = 0) const;
  // The true Hessian of the object's own energy at x (for tests and tools).
  SparseMatrix hessian(const Positions& x) const { return solver_.hessian(terms(), x); }

  const StaticsSolver& solver() const { return solver_; }
  const TetMesh& mesh() const { return *mesh_; }
  const std::vector<char>& fixed_node() const { return fixed_node_; }
  double weight() const { return gravity_.weight(); }
  // The contact with the scene's obstacles (and the robot's spheres with contact.robot), those on
  // links placed at the reference joints; null without obstacles (no contact term at all).
  const ObstacleContact* contact() const { return contact_ ? &*contact_ : nullptr; }
  // The contact of the object with itself; null unless the scene's contact.self.
  const SelfContact* self_contact() const { return self_contact_ ? &*self_contact_ : nullptr; }
  // The scene's friction (coefficient 0: frictionless, no friction term).
  const FrictionSettings& friction() const { return friction_; }
  // The applied loads' nodal forces (3n, N); zero without loads.
  Eigen::VectorXd load_forces() const;
  // The force Newton stops at: the scene's tolerance, or the round-off floor if larger.
  double force_tolerance() const { return solver_.effective_tolerance(); }

 private:
  std::shared_ptr<const TetMesh> mesh_;
  NeoHookean elasticity_;
  Gravity gravity_;
  std::optional<ConstantForce> loads_;       // none without loads: the default terms stay two
  std::optional<ObstacleContact> contact_;   // none without obstacles
  std::optional<SelfContact> self_contact_;  // none without contact.self
  FrictionSettings friction_;
  std::vector<char> fixed_node_;
  std::string unheld_reason_;
  StaticsSolver solver_;
};

// What round-off alone leaves in a nodal force (N) and in the energy (J) of `mesh` (placed in
// the world) of `material` with total weight `weight`: the floor of the force tolerance and
// the line search's energy resolution (see statics.hpp).
struct RoundoffScale {
  double force = 0;
  double energy = 0;
};
RoundoffScale roundoff_scale(const TetMesh& mesh, const Material& material, double weight);

// Doubles resolve an object's load only while that force floor stays a small share of it: at
// most this share of the mean nodal load (object_load over the nodes). Above it (κ ≫ μ:
// Poisson's ratio near 0.5; stiff and light; far from the origin) the rest shape would pass as
// converged under the object's own weight.
inline constexpr double max_roundoff_share = 0.01;
// The load the force tolerance is relative to, N: the weight (with applied loads: the weight plus
// their magnitudes); for an object with neither, the force that strains it by 0.1 %.
double object_load(const TetMesh& mesh, const Material& material, double weight);
// RoundoffScale::force over max_roundoff_share × the mean nodal load, for `material` on the
// scene's mesh placed in the world under its gravity: above 1 its load cannot be resolved.
double roundoff_load_ratio(const Scene& scene, const Material& material);

// Empty if every connected part of the mesh has a held node; otherwise says which is free.
std::string find_unheld_part(const TetMesh& mesh, const std::vector<char>& held);

}  // namespace shapectl
