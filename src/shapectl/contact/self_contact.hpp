#pragma once
// The object's contact with itself (IPC, Li et al. 2020): for every pair of primitives of its
// own surface closer than d̂ — a surface vertex and a surface triangle, or two surface edges —
//   E = κ Σ b(d),  b(d) = −(d − d̂)² ln(d / d̂) for 0 < d < d̂, 0 beyond, +inf for d ≤ 0,
// d the unsigned point–triangle or segment–segment distance (the same b, κ and d̂ as the
// obstacle contact). Pairs left out: those sharing a node (their distance is 0 for ever), and
// those closer than d̂ at rest (neighbours across a thin part of the mesh), so the rest shape is
// never in contact with itself. Every pair is a primitive pair: a vertex near an edge is counted
// by each triangle at that edge (IPC's own formulation, no merging of duplicates).
//
// Each pair couples 4 nodes anywhere on the surface, so the Hessian's elements are the pairs
// within d̂ at x (hessian_elements(x)), in a fixed order for a given x: energy, gradient and
// Hessian are functions of x alone, and the assembler builds a new pattern (statics a new
// symbolic analysis) whenever that set of pairs changes.
//
// Smoothness: each pair's distance is one of IPC's smooth pieces (point–point, point–line,
// point–plane, line–line) chosen by where the closest points lie: C¹ across the pieces' borders,
// not C² there. Edge–edge pairs use the exact segment–segment distance with IPC's mollifier:
// their barrier is multiplied by e(c), c = |e0 × e1|², which fades from 1 to 0 as the edges
// turn parallel (below ε = 10⁻³ |e0|²|e1|² at rest; edge_mollifier.hpp), so the line–line
// piece's derivatives, which grow as 1/sin of the edges' angle, are damped to nothing and the
// switch to an end (point–line) for parallel edges costs no smoothness; gradient and Hessian
// by the product rule, exact. The vertex–triangle pairs keep parallel edges apart.
//
// Finding the pairs: a BVH finds the "near" pairs at a reference state (within d̂ + 2 margin by
// a cheap separating-axis bound, separation.hpp); every call at a state whose surface vertices
// are all within the margin of it reuses them (the last few kept, thread-safe), as does max_step
// for a short step. Same pairs, same order as a BVH at every call (docs/contact.md).
//
// It does not depend on θ: nothing in ∂F/∂θ.
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <shapectl/fem/energy_term.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// The pairs within d̂ at x, for results and the GUI. No force: a pair pushes its two sides
// apart with equal and opposite forces, so the object's self-contact forces sum to zero.
struct SelfContactSummary {
  int count = 0;                                                  // pairs with d < d̂
  double min_distance = std::numeric_limits<double>::infinity();  // smallest d over them
  std::vector<Vec3> points;       // each pair's meeting point: midway between its closest points, m
  std::vector<double> distances;  // each pair's d, in the order of points
};

class SelfContact : public EnergyTerm {
 public:
  // The surface of `mesh` (its surface_triangles()); its rest positions decide which pairs are
  // neighbours (closer than `distance` at rest). κ = stiffness, J/m².
  SelfContact(const TetMesh& mesh, double distance, double stiffness);
  // The same term with κ multiplied by `factor` > 0 (the adaptive stiffness,
  // sim/contact_stiffness.hpp), sharing everything else.
  SelfContact scaled(double factor) const;

  std::string_view name() const override { return "self-contact"; }
  double value(const Positions& x) const override;
  void add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override;
  // The pairs within d̂ at x, 4 nodes each (vertex, triangle / edge, edge).
  void hessian_elements(const Positions& x, ElementNodes& elements) const override;
  void add_hessian(const Positions& x, ElementHessianSink& sink, bool project_psd) const override;
  // Continuous collision detection, as the obstacle term's: the largest α ∈ (0, 1] such that on
  // the way from x to x + α·dx no pair's gap falls below 10 % of where it started.
  double max_step(const Positions& x, const Eigen::VectorXd& dx) const override;

  // The smallest gap over the pairs within d̂ at x; +inf if none is.
  double min_distance(const Positions& x) const;
  SelfContactSummary summary(const Positions& x) const;
  // Two surface triangles (indices into the mesh's surface_triangles()) sharing no node that
  // intersect or touch at x; {-1, -1} if none. Every such pair, neighbours at rest included.
  std::array<int, 2> first_intersection(const Positions& x) const;

  double distance() const { return distance_; }
  double stiffness() const { return stiffness_; }

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;  // the surface and the pairs left out
  double distance_;
  double stiffness_;
};

}  // namespace shapectl
