#pragma once
// Calibration while the controller runs (the closed loop's slow half; model-error feedback is
// the fast half). Observed frames go to the controller's feedback (their markers) and into a
// sliding window; from time to time, or when asked, the window is calibrated in a background
// thread (calib/calibration.hpp, starting from the current model) and a fit that lowers the
// residuals is handed to the controller (Controller::set_model), which continues from the
// same joints: the robot sees no jump, only better predictions.
//
// The window keeps the newest frames of distinct poses: a frame taken within `same_pose` of
// the joints where the newest kept pose was first seen replaces that pose's frame (a robot
// standing still adds noise, not information). Measured from where the pose was first seen,
// not from its newest frame, so that a robot creeping in small steps between frames (a loaded
// machine's optimizer improving little by little) still adds a pose every `same_pose`. Parameters
// the window cannot determine are held (the calibration's identifiability test), never fitted to
// noise.
#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <shapectl/calib/calibration.hpp>
#include <shapectl/control/controller.hpp>

namespace shapectl {

// How far the online calibration may take the model: from the scene's values in total, and from
// the current model in one fit. A fit beyond is not applied (a calibration from lying frames
// must not hand the optimizer an implausible model). The defaults are the uncertainties of
// docs/calibration.md: stiffness known to ±50 %, density to ±10 %, grips millimetres and
// degrees off; twice that and more.
struct ModelBounds {
  double stiffness_factor = 2;     // E within [E₀/2, 2E₀]
  double density_factor = 1.5;     // ρ within [ρ₀/1.5, 1.5ρ₀]
  double poisson_ratio = 0.1;      // |ν − ν₀|
  double grip_translation = 0.01;  // m, per grip offset (and the object's pose)
  double grip_rotation = 0.1;      // rad, per grip offset (and the object's pose)
};
// The first value of `to` outside `bounds` around `from`, in words ("youngs_modulus 3.1e5 Pa is
// 2.4x 1.3e5 Pa"); empty when every value is within.
std::string beyond_bounds(const PhysicalParameters& from, const PhysicalParameters& to,
                          const ModelBounds& bounds);

struct OnlineCalibrationOptions {
  FitSelection fit{.youngs_modulus = true,
                   .poisson_ratio = false,
                   .density = false,
                   .grip_offsets = true};
  bool automatic = true;  // calibrate every `period` while new frames arrive
  // s between automatic calibrations. A fit that changes no parameter by more than its
  // standard deviation (the model has settled) doubles the wait, up to max_period: a settled
  // model must not keep a core busy that the optimizer needs.
  double period = 2.0;
  double max_period = 30.0;
  int new_frames = 3;        // frames since the last calibration before an automatic one
  int window = 6;            // frames kept
  double same_pose = 0.005;  // rad (m for prismatic joints), largest joint difference
  // A fit that takes longer than max_seconds stops with what it has (not converged, not
  // applied unless it lowered the residuals): a session is never stuck "running".
  // Stricter than `shapectl calibrate`: a model handed to a running controller takes no weakly
  // determined jump, so anything not determined at the start is held and never freed (a window
  // of nearby poses determines E to ±25 %, and fitted it went to 0.3x of a truth 1.5x the
  // scene's). Priors on the pose and grips as calibrate's.
  CalibrationOptions calibration{.max_iterations = 8,
                                 .degenerate_threshold = 0.1,
                                 .release_chi_squared = INFINITY,
                                 .max_seconds = 30};
  std::size_t max_drawn_points = 1000;  // of the newest cloud, for a GUI to draw
  ModelBounds bounds = {};
  // A fit whose residuals stay above this χ²/dof (RMS 10σ) does not explain its window: frames
  // the model cannot explain at any parameters (lies, a slipped grip) are in it. Not applied.
  double max_chi_squared_per_dof = 100;
};

struct OnlineCalibrationStatus {
  bool automatic = false;
  bool running = false;
  int frames = 0;                                   // in the window
  std::uint64_t runs = 0;                           // calibrations finished
  std::uint64_t applied_runs = 0;                   // of them, handed to the controller
  std::shared_ptr<const CalibrationResult> result;  // the newest finished one, or null
  bool applied = false;                             // whether that one was handed over
  std::string error;                                // why the newest one failed or was not applied
  std::vector<Vec3> points;                         // the newest frame's cloud, thinned
};

class OnlineCalibration {
 public:
  // `controller` must outlive this; `model` is the scene it was made from.
  OnlineCalibration(Controller& controller, const Scene& model,
                    OnlineCalibrationOptions options = {});
  ~OnlineCalibration();  // cancels a running calibration and waits for it to stop
  OnlineCalibration(const OnlineCalibration&) = delete;
  OnlineCalibration& operator=(const OnlineCalibration&) = delete;

  // One checked frame (read_observation_frame) observed at `time` (s): its markers to the
  // controller's loop, the frame to the window.
  void observe(const ObservationFrame& frame);
  // Calibrates the window now, in the background; false with the reason when it cannot: one
  // is running, no frames, or fewer than 3 measured numbers (marker coordinates, points) per
  // parameter to fit.
  bool start(std::string* why = nullptr);
  void set_automatic(bool on);
  // Blocks until a running calibration has finished (poll() then hands it over).
  void wait();
  // Asks a running calibration to stop at its next check (a Newton iteration, a path step, a
  // frame): it finishes soon after with what it has, reason "cancelled"; poll() hands it over.
  void cancel() { cancel_ = true; }
  // Call often (each tick): hands a finished calibration to the controller, and starts an
  // automatic one when it is due. `time`: s, any clock that only moves forward.
  void poll(double time);
  OnlineCalibrationStatus status() const;
  const OnlineCalibrationOptions& options() const { return options_; }

 private:
  void finish();  // the worker's result to the controller (worker joined)
  // Whether `result` should replace the current model; the reason in `why` if not.
  bool worth_applying(const CalibrationResult& result, std::string* why) const;

  Controller& controller_;
  const PhysicalParameters scene_values_;  // as loaded: the bounds' centre
  Scene model_;  // the controller's model: the scene with every applied fit
  OnlineCalibrationOptions options_;
  std::deque<ObservationFrame> window_;
  Eigen::VectorXd newest_pose_first_joints_;  // where window_.back()'s pose was first seen
  int frames_since_start_ = 0;
  double last_start_ = -1e300;
  double period_;  // the wait now: options_.period, doubled while fits change nothing

  mutable std::mutex mutex_;  // guards status_ and outcome_ (the worker writes them)
  OnlineCalibrationStatus status_;
  std::optional<CalibrationResult> outcome_;
  std::string outcome_error_;
  std::atomic<bool> done_{false};
  std::atomic<bool> cancel_{false};  // read by the worker's calibration
  std::thread worker_;
};

}  // namespace shapectl
