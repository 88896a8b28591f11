#pragma once
// Fits physical parameters (calib/model_parameters.hpp) to observed frames of the real object:
// Levenberg–Marquardt on the noise-weighted residuals of every frame jointly
// (calib/observation_residuals.hpp), each frame its own equilibrium at its joints (a scene held
// by fixed nodes alone: the one equilibrium, calib/equilibria.hpp), Jacobians from the exact
// parameter sensitivities dx̂/dz.
//
// Priors (calib/parameter_priors.hpp) are residual rows too: the object's pose and the grip
// offsets carry Gaussian priors by default, so a pose cannot run off to absorb what the model
// gets wrong without being flagged (`implausible`: more than 3 prior σ from its start).
//
// Identifiability is judged twice. At the start, the Jacobian with the prior rows, its columns
// scaled by each coordinate's typical size, is split by SVD; only a direction whose standard
// deviation (the noise-weighted residuals make it 1/singular value) exceeds
// `degenerate_threshold` (2 scales: E/ρ under gravity alone, E seen by no marker) is
// degenerate, and one parameter in it is held at its initial value (the one most likely known:
// density, then Poisson's ratio, Young's modulus, rotations, translations). Everything else is
// fitted. After the fit a held coordinate whose freeing would lower χ² by more than
// `release_chi_squared` (single-coordinate Gauss–Newton on the augmented system) is freed and
// the fit continues. At the fitted point the posterior covariance (J_augᵀJ_aug)⁻¹ gives each
// parameter its verdict: determined (σ ≤ identifiability_threshold scales), weakly determined
// (fitted, its σ large: pinned mostly by its prior, or trading off with another), or not
// determined (held; the report names what it trades off with and what would determine it).
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <shapectl/calib/model_parameters.hpp>
#include <shapectl/calib/observations.hpp>
#include <shapectl/calib/parameter_priors.hpp>

namespace shapectl {

struct CalibrationOptions {
  int max_iterations = 30;
  // Largest standard deviation at the fitted point, in units of the coordinate scales (10 % for
  // material parameters, 1 mm and 0.01 rad for grip offsets and the object's pose), of a
  // determined parameter; above it a fitted parameter is weakly determined.
  double identifiability_threshold = 0.1;
  // Standard deviation (scales, priors included) above which a direction is degenerate and held
  // at the start: a factor e² for the material, 2 cm, 0.2 rad. A pose or grip with its prior
  // never is. Measured: E/ρ of the YuMi cantilever (grip springs make it not exactly
  // degenerate) 3.8 scales at 0.3 mm noise, and fitted it ran to E = 1.6 Pa; E with the pose of
  // a clamped bar seen at its free end, 0.8 (fitted: 24 %).
  double degenerate_threshold = 2;
  // A held coordinate whose freeing would lower χ² by more than this is freed after the fit.
  double release_chi_squared = 4;
  CalibrationPriors priors = {};
  MaterialBounds bounds = {};
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

enum class Verdict { Determined, WeaklyDetermined, NotDetermined };
// "determined", "weakly determined", "not determined"
const char* to_string(Verdict verdict);

struct FittedParameter {
  std::string name;
  std::string unit;  // "Pa", "", "kg/m^3", "m", "rad"
  // Physical value; grip offsets: the coordinate's, in m or rad; the object's pose: its
  // position (m), and its rotation from the scene's as a rotation vector in world axes (rad).
  double initial = 0;
  double fitted = 0;
  // From the posterior covariance (J_augᵀJ_aug)⁻¹ at the fitted point, frames' σ and priors;
  // 0 if held.
  double standard_deviation = 0;
  bool held = false;  // not determined by these observations: kept at `initial`
  Verdict verdict = Verdict::Determined;
  double prior = 0;  // σ of its prior in `unit` (material: relative σ × initial); 0: none
  bool implausible = false;                  // fitted more than 3 prior σ from `initial`
  std::vector<std::string> trades_off_with;  // held: its direction's members; weakly: |ρ| ≥ 0.5
  std::string suggestion;                    // what would determine it (empty when determined)
};

struct UnidentifiedDirection {
  std::vector<std::pair<std::string, double>> combination;  // coordinate name → weight (|w| ≥ 0.1)
  double standard_deviation = 0;                            // in units of the coordinate scales
  std::string held;        // the parameter kept at its initial value for it
  std::string suggestion;  // what observations would determine it
};

struct FrameFit {
  double rms_before = 0, rms_after = 0;  // m: markers' 3D errors and inlier points' distances
  int markers = 0, points = 0, inlier_points_after = 0;
};

struct CalibrationResult {
  Scene scene;  // the input scene with the fitted values
  PhysicalParameters fitted;
  std::vector<FittedParameter> parameters;
  std::vector<UnidentifiedDirection> unidentified;  // the held parameters' directions
  std::vector<std::string> implausible;             // names of the implausible parameters
  std::vector<FrameFit> frames;
  double rms_before = 0, rms_after = 0;  // m, over all frames
  double chi_squared_per_dof = 0;        // ≈ 1 when the model fits to the noise level
  int iterations = 0;
  bool converged = false;
  std::string reason;  // why it stopped
  double seconds = 0;
};

// Throws std::invalid_argument for a selection the scene does not allow (ParameterSpace) or
// observations that do not match it (joints of another robot, or joints without one; a fitted
// object_pose where frames give their own),
// std::runtime_error when a frame's equilibrium cannot be found or the fit is stopped (time
// budget, cancel) before the model was evaluated at the initial values. Throws
// std::invalid_argument too for a scene value outside options.bounds.
CalibrationResult calibrate(const Scene& scene, const Observations& observations,
                            const FitSelection& fit, const CalibrationOptions& options = {});

}  // namespace shapectl
