#include <shapectl/calib/online_calibration.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

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

OnlineCalibration::OnlineCalibration(Controller& controller, const Scene& model,
                                     OnlineCalibrationOptions options)
    : controller_(controller), model_(model), options_(options), period_(options.period) {
  status_.automatic = options_.automatic;
  options_.calibration.cancel = &cancel_;
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

bool OnlineCalibration::worth_applying(const CalibrationResult& result, std::string* why) {
  bool fitted = false;
  for (const FittedParameter& p : result.parameters) fitted = fitted || !p.held;
  if (!fitted) *why = "not applied: no parameter is identifiable from the frames in the window";
  else if (!(result.rms_after < result.rms_before))
    *why = "not applied: the fit did not lower the residuals (" + result.reason + ")";
  else return true;
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
