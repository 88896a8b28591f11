#include <shapectl/calib/online_calibration.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <shapectl/calib/live_observation.hpp>

namespace shapectl {

namespace {
// At most `count` points of `cloud`, evenly strided.
std::vector<Vec3> thinned(const std::vector<Vec3>& cloud, std::size_t count) {
  if (cloud.size() <= count) return cloud;
  std::vector<Vec3> out;
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k) out.push_back(cloud[k * cloud.size() / count]);
  return out;
}

// Whether some fitted parameter moved by more than its standard deviation.
bool changed_significantly(const CalibrationResult& r) {
  for (const FittedParameter& p : r.parameters)
    if (!p.held && std::abs(p.fitted - p.initial) > p.standard_deviation) return true;
  return false;
}

bool same_pose(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double tolerance) {
  return a.size() == b.size() && (a.size() == 0 || (a - b).cwiseAbs().maxCoeff() <= tolerance);
}
}  // namespace

std::string beyond_bounds(const PhysicalParameters& from, const PhysicalParameters& to,
                          const ModelBounds& bounds) {
  char text[160];
  const auto factor = [&](const char* name, const char* unit, double a, double b, double most) {
    const double f = std::max(b / a, a / b);
    if (!(f <= most))
      std::snprintf(text, sizeof text, "%s %.3g %s is %.2fx %.3g %s (at most %gx)", name, b, unit,
                    b / a, a, unit, most);
    return !(f <= most);
  };
  const auto moved = [&](const std::string& name, const Eigen::Isometry3d& a,
                         const Eigen::Isometry3d& b) {
    const double t = (b.translation() - a.translation()).norm();
    const double r = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
    if (!(t <= bounds.grip_translation && r <= bounds.grip_rotation))
      std::snprintf(text, sizeof text, "%s moved %.1f mm and %.3f rad (at most %.1f mm, %.3f rad)",
                    name.c_str(), t * 1e3, r, bounds.grip_translation * 1e3, bounds.grip_rotation);
    return !(t <= bounds.grip_translation && r <= bounds.grip_rotation);
  };
  if (factor("youngs_modulus", "Pa", from.youngs_modulus, to.youngs_modulus,
             bounds.stiffness_factor) ||
      factor("density", "kg/m^3", from.density, to.density, bounds.density_factor))
    return text;
  if (!(std::abs(to.poisson_ratio - from.poisson_ratio) <= bounds.poisson_ratio)) {
    std::snprintf(text, sizeof text, "poisson_ratio %.3f is %+.3f from %.3f (at most %g)",
                  to.poisson_ratio, to.poisson_ratio - from.poisson_ratio, from.poisson_ratio,
                  bounds.poisson_ratio);
    return text;
  }
  for (std::size_t g = 0; g < from.grip_offsets.size() && g < to.grip_offsets.size(); ++g)
    if (moved("grip_offsets[" + std::to_string(g) + "]", from.grip_offsets[g], to.grip_offsets[g]))
      return text;
  if (moved("object_pose", from.object_pose, to.object_pose)) return text;
  return "";
}

OnlineCalibration::OnlineCalibration(Controller& controller, const Scene& model,
                                     OnlineCalibrationOptions options)
    : controller_(controller),
      scene_values_(PhysicalParameters::of(model)),
      model_(model),
      options_(options),
      period_(options.period) {
  status_.automatic = options_.automatic;
  options_.calibration.cancel = &cancel_;
  // Fits of one object: their equilibria keep the symbolic analyses from fit to fit.
  if (!options_.calibration.workspaces) options_.calibration.workspaces = WorkspacePool::create();
}

OnlineCalibration::~OnlineCalibration() {
  cancel();
  if (worker_.joinable()) worker_.join();
}

void OnlineCalibration::observe(const ObservationFrame& frame) {
  if (!frame.markers.empty()) controller_.observe(live_observation(frame));
  if (!window_.empty() && same_pose(newest_pose_first_joints_, frame.joints, options_.same_pose)) {
    window_.back() = frame;
  } else {
    window_.push_back(frame);
    newest_pose_first_joints_ = frame.joints;
  }
  while (static_cast<int>(window_.size()) > options_.window) window_.pop_front();
  ++frames_since_start_;
  std::lock_guard lock(mutex_);
  status_.frames = static_cast<int>(window_.size());
  if (!frame.points.empty()) status_.points = thinned(frame.points, options_.max_drawn_points);
}

bool OnlineCalibration::start(std::string* why) {
  const auto refuse = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  if (worker_.joinable()) return refuse("a calibration is running");
  if (window_.empty()) return refuse("no observed frames yet");
  // A fit needs more numbers than it has unknowns, by a margin: one marker seen from one pose
  // (3 numbers) "fits" two grip offsets exactly, noise included, and the model gets worse.
  std::size_t measured = 0;
  for (const ObservationFrame& f : window_) measured += 3 * f.markers.size() + f.points.size();
  std::size_t needed = 0;
  try {
    needed = 3 * static_cast<std::size_t>(ParameterSpace(model_, options_.fit).size());
  } catch (const std::invalid_argument& e) {  // a parameter this scene does not have
    return refuse(e.what());
  }
  if (measured < needed)
    return refuse("too few observations: " + std::to_string(measured) + " measured numbers for " +
                  std::to_string(needed / 3) + " parameters (at least " + std::to_string(needed) +
                  ": more markers, or frames at other poses)");
  Observations observations{{window_.begin(), window_.end()}};
  frames_since_start_ = 0;
  done_ = false;
  cancel_ = false;
  {
    std::lock_guard lock(mutex_);
    status_.running = true;
  }
  worker_ = std::thread([this, observations = std::move(observations), model = model_] {
    std::optional<CalibrationResult> result;
    std::string error;
    try {
      result = calibrate(model, observations, options_.fit, options_.calibration);
    } catch (const std::exception& e) {
      error = e.what();
    }
    std::lock_guard lock(mutex_);
    outcome_ = std::move(result);
    outcome_error_ = std::move(error);
    done_ = true;
  });
  return true;
}

void OnlineCalibration::wait() {
  while (worker_.joinable() && !done_) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void OnlineCalibration::set_automatic(bool on) {
  options_.automatic = on;
  std::lock_guard lock(mutex_);
  status_.automatic = on;
}

void OnlineCalibration::poll(double time) {
  if (worker_.joinable() && done_) finish();
  const bool due = options_.automatic && !worker_.joinable() &&
                   frames_since_start_ >= options_.new_frames && time - last_start_ >= period_;
  if (!due) return;
  std::string why;
  if (start(&why)) {
    last_start_ = time;
  } else {  // say why nothing happens; try again once more frames have come
    frames_since_start_ = 0;
    std::lock_guard lock(mutex_);
    status_.error = why;
  }
}

bool OnlineCalibration::worth_applying(const CalibrationResult& result, std::string* why) const {
  bool fitted = false;
  for (const FittedParameter& p : result.parameters) fitted = fitted || !p.held;
  if (!fitted) {
    *why = "not applied: no parameter is identifiable from the frames in the window";
  } else if (!(result.rms_after < result.rms_before)) {
    *why = "not applied: the fit did not lower the residuals (" + result.reason + ")";
  } else if (!(result.chi_squared_per_dof <= options_.max_chi_squared_per_dof)) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "not applied: the fit leaves chi2/dof %.3g (RMS %.1f mm, at most %g): the "
                  "window holds frames the model cannot explain",
                  result.chi_squared_per_dof, result.rms_after * 1e3,
                  options_.max_chi_squared_per_dof);
    *why = text;
  } else if (const std::string total = beyond_bounds(scene_values_, result.fitted, options_.bounds);
             !total.empty()) {
    *why = "not applied: beyond the bounds from the scene's values: " + total;
  } else if (const std::string step =
                 beyond_bounds(PhysicalParameters::of(model_), result.fitted, options_.bounds);
             !step.empty()) {
    *why = "not applied: a jump beyond the bounds from the current model: " + step;
  } else {
    return true;
  }
  return false;
}

void OnlineCalibration::finish() {
  worker_.join();
  std::lock_guard lock(mutex_);
  status_.running = false;
  ++status_.runs;
  status_.error = outcome_error_;
  status_.applied = false;
  const bool settled = !outcome_ || !changed_significantly(*outcome_);
  period_ = settled ? std::min(2 * period_, options_.max_period) : options_.period;
  if (outcome_) {
    status_.applied = worth_applying(*outcome_, &status_.error);
    if (status_.applied) {
      model_ = outcome_->fitted.applied_to(model_);
      controller_.set_model(model_);
      ++status_.applied_runs;
    }
  }
  status_.result =
      outcome_ ? std::make_shared<const CalibrationResult>(std::move(*outcome_)) : nullptr;
  outcome_.reset();
}

OnlineCalibrationStatus OnlineCalibration::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

}  // namespace shapectl
