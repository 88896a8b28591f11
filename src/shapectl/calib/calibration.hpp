#pragma once
// Fits physical parameters (calib/model_parameters.hpp) to observed frames of the real object:
// Levenberg–Marquardt on the noise-weighted residuals of every frame jointly
// (calib/observation_residuals.hpp), each frame its own equilibrium at its joints (a scene held
// by fixed nodes alone: the one equilibrium, calib/equilibria.hpp), Jacobians from the exact
// parameter sensitivities dx̂/dz.
//
// Identifiability first: the Jacobian at the start, its columns scaled by each coordinate's
// typical size, is split by SVD; a direction whose standard deviation (the noise-weighted
// residuals make it 1/singular value) exceeds `identifiability_threshold` is one the data
// cannot determine. For each such direction one parameter in it is held at its initial value
// (the one most likely known: density, then Poisson's ratio, Young's modulus, rotations,
// translations) and reported, never fitted to noise. With gravity and grips only, for example,
// the shape depends on stiffness and density through their ratio alone: asked for both, the
// fit holds density and fits Young's modulus.
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <shapectl/calib/model_parameters.hpp>
#include <shapectl/calib/observations.hpp>

namespace shapectl {

struct CalibrationOptions {
  int max_iterations = 30;
  // Largest standard deviation, in units of the coordinate scales (10 % for material
  // parameters, 1 mm and 0.01 rad for grip offsets and the object's pose), of a determined
  // direction.
  double identifiability_threshold = 0.1;
  // Steps to walk the joints from the reference configuration to a frame's (rad, largest joint).
  double path_step = 0.05;
  // s: the fit's time budget, checked between Newton iterations, path steps, frames and trials
  // (a factorization or a sensitivity solve is not cut). Spent, the fit stops with the best
  // values so far, not converged; spent before the first evaluation, it throws.
  double max_seconds = 300;
  // Set from another thread to stop the fit the same way (OnlineCalibration::cancel); may be
  // null.
  const std::atomic<bool>* cancel = nullptr;
  // The statics workspaces of the fit's equilibria (null: a pool of the fit's own). Every
  // trial's model is new, its states' workspaces are not: one symbolic analysis per pattern.
  // OnlineCalibration passes one pool to all its fits.
  std::shared_ptr<WorkspacePool> workspaces = nullptr;
};

struct FittedParameter {
  std::string name;
  std::string unit;  // "Pa", "", "kg/m^3", "m", "rad"
  // Physical value; grip offsets: the coordinate's, in m or rad; the object's pose: its
  // position (m), and its rotation from the scene's as a rotation vector in world axes (rad).
  double initial = 0;
  double fitted = 0;
  double standard_deviation = 0;  // from the Gauss–Newton covariance with the frames' σ; 0 if held
  bool held = false;              // not identifiable from these observations: kept at `initial`
};

struct UnidentifiedDirection {
  std::vector<std::pair<std::string, double>> combination;  // coordinate name → weight (|w| ≥ 0.1)
  double standard_deviation = 0;                            // in units of the coordinate scales
  std::string held;  // the parameter kept at its initial value for it
};

struct FrameFit {
  double rms_before = 0, rms_after = 0;  // m: markers' 3D errors and inlier points' distances
  int markers = 0, points = 0, inlier_points_after = 0;
};

struct CalibrationResult {
  Scene scene;  // the input scene with the fitted values
  PhysicalParameters fitted;
  std::vector<FittedParameter> parameters;
  std::vector<UnidentifiedDirection> unidentified;
  std::vector<FrameFit> frames;
  double rms_before = 0, rms_after = 0;  // m, over all frames
  double chi_squared_per_dof = 0;        // ≈ 1 when the model fits to the noise level
  int iterations = 0;
  bool converged = false;
  std::string reason;  // why it stopped
  double seconds = 0;
};

// Throws std::invalid_argument for a selection the scene does not allow (ParameterSpace) or
// observations that do not match it (joints of another robot, or joints without one),
// std::runtime_error when a frame's equilibrium cannot be found or the fit is stopped (time
// budget, cancel) before the model was evaluated at the initial values.
CalibrationResult calibrate(const Scene& scene, const Observations& observations,
                            const FitSelection& fit, const CalibrationOptions& options = {});

}  // namespace shapectl
