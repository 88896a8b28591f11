#pragma once
// The physical parameters calibration can fit, and their coordinates z: Young's modulus and
// density as logarithms (positive), Poisson's ratio as s with ν = ½·logistic(s) (inside
// (0, ½)), each grip's offset as 3 translations (m) and 3 rotations (rad) applied on the left,
// O ← (exp([δr]) R, t + δt), about the TCP in the end effector's frame.
//
// For equilibria x̂ the forces' derivatives ∂F/∂z (F = −∂E/∂x) give the parameter sensitivity
// dx̂/dz = H⁻¹ ∂F/∂z (GrippedObject::force_response), exactly as dx̂/dθ.
#include <string>
#include <vector>

#include <shapectl/sim/gripped_object.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl {

// What a calibration fits; parsed from "youngs_modulus,poisson_ratio,density,grip_offsets".
struct FitSelection {
  bool youngs_modulus = false;
  bool poisson_ratio = false;
  bool density = false;
  bool grip_offsets = false;
  bool empty() const { return !(youngs_modulus || poisson_ratio || density || grip_offsets); }
};
// Throws std::invalid_argument naming the unknown entry and the known ones.
FitSelection parse_fit_selection(const std::string& list);

struct PhysicalParameters {
  double youngs_modulus = 0;  // Pa
  double poisson_ratio = 0;
  double density = 0;                           // kg/m^3
  std::vector<Eigen::Isometry3d> grip_offsets;  // one per scene grip

  static PhysicalParameters of(const Scene& scene);
  // The scene with these values (material and grip offsets); everything else unchanged.
  Scene applied_to(const Scene& scene) const;
};

// One coordinate of z.
struct ParameterCoordinate {
  enum class Kind { LogYoungsModulus, PoissonLogit, LogDensity, GripTranslation, GripRotation };
  Kind kind;
  int grip = -1;     // for grip coordinates
  int axis = -1;     // 0..2 for grip coordinates (the TCP frame's x, y, z)
  std::string name;  // "youngs_modulus", "grip_offsets.left.x", "grip_offsets.left.rx"
  // Typical size of a change worth noticing: 1 (a factor e) for the logarithms, 1 cm, 0.1 rad.
  double scale = 1;
};

class ParameterSpace {
 public:
  ParameterSpace(const Scene& scene, const FitSelection& selection);
  const std::vector<ParameterCoordinate>& coordinates() const { return coordinates_; }
  int size() const { return static_cast<int>(coordinates_.size()); }

  // p moved by dz (size(): one entry per coordinate).
  PhysicalParameters advanced(const PhysicalParameters& p, const Eigen::VectorXd& dz) const;
  // ∂F/∂z at the equilibrium `state` of `object` (built from p.applied_to(scene)): 3n × size().
  Eigen::MatrixXd force_derivatives(const GrippedObject& object, const ObjectState& state,
                                    const PhysicalParameters& p) const;
  // dν/ds etc.: the derivative of the physical value a coordinate moves (Pa, 1, kg/m^3, m,
  // rad) with respect to the coordinate, for reporting standard deviations in physical units.
  double physical_per_coordinate(const ParameterCoordinate& c, const PhysicalParameters& p) const;

 private:
  std::vector<ParameterCoordinate> coordinates_;
};

}  // namespace shapectl
