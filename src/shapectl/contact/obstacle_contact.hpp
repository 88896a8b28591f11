#pragma once
// The contact energy between the object's surface and the scene's obstacles (IPC, Li et al.
// 2020): for every pair of an object primitive and an obstacle primitive closer than d̂,
//   E = κ Σ b(d),  b(d) = −(d − d̂)² ln(d / d̂) for 0 < d < d̂, 0 beyond, +inf for d ≤ 0,
// d the unsigned distance less the obstacle's radius. The pairs: object surface vertex –
// obstacle triangle (point–triangle distance, its edges and corners included) / segment /
// point / half-space; obstacle point – object surface triangle; obstacle segment – object
// surface edge. b is C² at d̂, so Newton and the sensitivities stay exact; each pair's Hessian
// block is exact and, with project_psd, projected on its own. No edge–edge mollifier (self-
// contact has IPC's): contacts are merged as pairs of features, and mollifying the line–line one
// alone would make the energy jump where its closest point reaches an edge's end.
//
// Obstacles on robot links (Obstacle::link) are placed by the links' poses (posed()); they
// couple x and θ: for_each_coupling gives ∂²E/∂x∂p, p their points, for ∂F/∂θ.
// An obstacle never touches its ignored nodes: pairs with one are no pairs at all.
//
// Every pair couples nodes of one surface triangle (or one edge, one vertex): the Hessian's
// elements are the surface's vertices, edges and triangles, fixed, so the assembler's pattern
// and the symbolic factorization stay valid while contacts come and go.
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <shapectl/contact/obstacle.hpp>
#include <shapectl/contact/obstacle_motion.hpp>
#include <shapectl/fem/energy_term.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// One pair in contact at x, for results and the GUI.
struct ContactPoint {
  int obstacle = -1;          // index into the obstacles
  Vec3 point = Vec3::Zero();  // the closest point on the object, world, m
  Vec3 force = Vec3::Zero();  // the force the obstacle exerts on the object there, N
  double distance = 0;        // gap d, m
};

struct ContactSummary {
  int count = 0;                    // pairs with d < d̂
  double min_distance = 0;          // smallest d over all pairs (+inf if no pair is within d̂)
  Vec3 force_total = Vec3::Zero();  // Σ forces of the obstacles on the object, N
  struct PerObstacle {
    int count = 0;
    Vec3 force = Vec3::Zero();
  };
  std::vector<PerObstacle> by_obstacle;  // in obstacle order
  std::vector<ContactPoint> points;      // every pair with d < d̂
  double stiffness = 0;                  // the term's κ (the adaptive barrier may have raised it)
};

// One pair in contact at x, as friction (friction.hpp) lags it: the object's closest point is
// Σ weights[a] x(nodes[a]) over its element's nodes.
struct ContactPair {
  int element = -1;   // its Hessian element (hessian_elements order)
  int obstacle = -1;  // index into the obstacles
  int node_count = 0;
  std::array<int, 3> nodes{};
  std::array<double, 3> weights{};  // closest-point weights (barycentric, segment parameter)
  Vec3 normal = Vec3::Zero();       // unit, from the obstacle towards the object
  double force = 0;                 // normal force λ = κ |b′(d)|, N
};

// A pair with the derivatives of what friction lags with respect to its element's node
// coordinates (3 × node_count columns, the rest zero): how λ, n and w change with the lag state
// (friction_lag.hpp). From the gap's gradient g and Hessian h: n = Σₐ gₐ (translating the
// element by t moves the gap by n·t), wₐ = gₐ·n, λ = −κ b′(d).
struct ContactPairDerivatives {
  ContactPair pair;
  Eigen::Matrix<double, 1, 9> force = Eigen::Matrix<double, 1, 9>::Zero();    // ∂λ/∂x
  Eigen::Matrix<double, 3, 9> normal = Eigen::Matrix<double, 3, 9>::Zero();   // ∂n/∂x
  Eigen::Matrix<double, 3, 9> weights = Eigen::Matrix<double, 3, 9>::Zero();  // row a: ∂wₐ/∂x
};

class ObstacleContact : public EnergyTerm {
 public:
  // The object's surface from `mesh` (its surface_triangles()), `obstacles` in the world.
  // stiffness κ in J/m² (see default_contact_stiffness).
  // Obstacles on links are placed by T_world_link (per robot link; needed if there are any).
  ObstacleContact(const TetMesh& mesh, std::vector<Obstacle> obstacles, double distance,
                  double stiffness, const std::vector<Eigen::Isometry3d>& T_world_link = {});

  // Whether an obstacle is on a robot link (the term then depends on θ).
  bool moves() const;
  // The same term with the obstacles on links placed by T_world_link (the surface, hence the
  // Hessian's elements, unchanged); a copy sharing everything if none moves.
  ObstacleContact posed(const std::vector<Eigen::Isometry3d>& T_world_link) const;
  // The same term with κ multiplied by `factor` > 0 (the adaptive stiffness,
  // sim/contact_stiffness.hpp), sharing everything else.
  ObstacleContact scaled(double factor) const;
  // ∂²E/∂x∂p at x for the obstacles on links: visit(node, obstacle, p, B) for each object node
  // and obstacle point p (world, where it is now) of every contact within d̂, B = ∂²E/∂xₙ∂p
  // (3 × 3). p moves rigidly with its link, so ∂F/∂θ = −Σ B ∂p/∂θ.
  using CouplingVisit = std::function<void(int node, int obstacle, const Vec3& p, const Mat3& B)>;
  void for_each_coupling(const Positions& x, const CouplingVisit& visit) const;

  std::string_view name() const override { return "contact"; }
  double value(const Positions& x) const override;
  void add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override;
  void hessian_elements(const Positions& x, ElementNodes& elements) const override;
  void add_hessian(const Positions& x, ElementHessianSink& sink, bool project_psd) const override;
  // Continuous collision detection: the largest α ∈ (0, 1] such that on the way from x to
  // x + α·dx no pair's gap falls below 10 % of where it started (so no surface passes through
  // an obstacle, however thin); 1 if none comes that close.
  double max_step(const Positions& x, const Eigen::VectorXd& dx) const override;
  // CCD of the obstacles' own motion: the object fixed at x (clear of them), the obstacles on
  // links moving along `motion` from where this term has them (its s = 0): the largest
  // s ∈ [0, 1] such that no pair's gap falls below 10 % of where it started on the way (a
  // bound: conservative advancement with motion's travel bounds). 1 if none moves. If s < 1,
  // `limiting` (if given) is set to the obstacle that bounds it.
  double max_obstacle_step(const Positions& x, ObstacleMotion& motion,
                           int* limiting = nullptr) const;

  ContactSummary summary(const Positions& x) const;
  // Every pair with 0 < d < d̂ at x, with its closest-point weights, normal and normal force.
  std::vector<ContactPair> pairs(const Positions& x) const;
  // The same pairs with their derivatives (for the lagged friction's exact sensitivities).
  std::vector<ContactPairDerivatives> pair_derivatives(const Positions& x) const;
  // The first object surface triangle that intersects or touches (d ≤ 0) an obstacle at x, as
  // {obstacle, triangle index into the mesh's surface_triangles()}; {-1, -1} if none.
  std::array<int, 2> first_intersection(const Positions& x) const;

  // As given: those on links in their link's frame.
  const std::vector<Obstacle>& obstacles() const { return *obstacles_; }
  double distance() const { return distance_; }
  double stiffness() const { return stiffness_; }

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;                        // surface, candidate search structures
  std::shared_ptr<const std::vector<Obstacle>> obstacles_;  // shared by posed copies
  double distance_;
  double stiffness_;
};

// κ such that a node carrying the mean nodal weight (weight / node count, N) against a flat
// obstacle rests at a gap of d̂/2: κ = w̄ / |b′(d̂/2)|.
double default_contact_stiffness(double weight, int node_count, double distance);

}  // namespace shapectl
