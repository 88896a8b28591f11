#pragma once
// What calibration knows about its parameters before it sees the data (docs/calibration.md,
// "Priors and bounds"): a Gaussian prior on each coordinate's displacement from its start value,
// and hard bounds on the material. A prior enters the fit as one more residual row
// (z − z₀)/σ per coordinate, so the cost, the steps and the covariance all include it; a pose
// or a grip offset then cannot run off to absorb what the model gets wrong (a clamp tilted 24°
// to explain a sag) without the report saying so.
#include <cmath>
#include <string>

#include <shapectl/calib/model_parameters.hpp>

namespace shapectl {

// σ of each prior; 0: none. Rigid motions per coordinate (m, rad); material relative: σ of
// ln E, ln ρ, and of ln ν (as a fraction, 0.5 = 50 %).
struct CalibrationPriors {
  double pose_translation = 0.010;
  double pose_rotation = 2 * M_PI / 180;
  double grip_translation = 0.005;
  double grip_rotation = 3 * M_PI / 180;
  double youngs_modulus = 0;
  double density = 0;
  double poisson_ratio = 0;
  // A depth camera's pose correction: as the object's pose (a camera calibrated to ~1 cm, 2°).
  double camera_translation = 0.010;
  double camera_rotation = 2 * M_PI / 180;

  static CalibrationPriors none() { return {0, 0, 0, 0, 0, 0, 0, 0, 0}; }
};

struct ValueInterval {
  double lower = -INFINITY, upper = INFINITY;
  bool contains(double v) const { return v >= lower && v <= upper; }
};

// Hard bounds on the material's physical values; the fit's steps are projected onto them.
struct MaterialBounds {
  ValueInterval youngs_modulus{0, INFINITY};
  ValueInterval density{0, INFINITY};
  ValueInterval poisson_ratio{0, 0.5};
};

// "object_pose.rotation=2deg,object_pose.translation=10mm,grip_offsets=5mm/3deg,
// camera_poses=10mm/2deg,youngs_modulus=50%": entries change `base` (units mm, m, deg, rad; % for
// material; none or off for no prior); "off" or "none" alone: no priors. Throws
// std::invalid_argument naming the entry and what was expected.
CalibrationPriors parse_priors(const std::string& text, CalibrationPriors base = {});
// "youngs_modulus=1e3:1e8,density=:2000,poisson_ratio=0.3:0.45" (an empty side: unbounded):
// entries change `base`. Throws std::invalid_argument naming the entry.
MaterialBounds parse_bounds(const std::string& text, MaterialBounds base = {});

// The prior's σ for coordinate c in its own units (0: none), the material's start values `p`.
double prior_sigma(const CalibrationPriors& priors, const ParameterCoordinate& c,
                   const PhysicalParameters& p);
// The interval a material coordinate may take (ln E, ln ρ, the logit of ν); unbounded for others.
ValueInterval coordinate_bounds(const MaterialBounds& bounds, const ParameterCoordinate& c);
// The first coordinate of `space` whose value at p lies outside `bounds` ("youngs_modulus"), or
// empty when all lie within.
std::string outside_bounds(const ParameterSpace& space, const PhysicalParameters& p,
                           const MaterialBounds& bounds);
// The value of a material coordinate at p (ln E, ln ρ, s with ν = ½·logistic(s)); 0 for others.
double material_coordinate(const ParameterCoordinate& c, const PhysicalParameters& p);

}  // namespace shapectl
