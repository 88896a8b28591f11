#pragma once
// The equilibrium at joints far from where the object is known: walk θ from the reference
// joints in steps of at most `max_step` (rad, largest joint), carrying the gripped nodes along
// with their grippers and solving at each step. One jump would drag the gripped nodes past
// their neighbours and invert elements.
#include <stdexcept>

#include <shapectl/sim/gripped_object.hpp>

namespace shapectl {

// The object has no equilibrium found on the way: a failed solve (a material too soft for
// its weight, a pose that inverts it), not a bug.
class NoEquilibrium : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A step where Newton does not converge is halved (up to 4 times). Throws NoEquilibrium with
// Newton's reason when an equilibrium on the way is not found even so.
ObjectState equilibrium_along_path(const GrippedObject& object, const Eigen::VectorXd& joints,
                                   double max_step = 0.05);

}  // namespace shapectl
