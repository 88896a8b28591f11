#include <shapectl/calib/calibration.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/SVD>

#include <shapectl/calib/equilibria.hpp>
#include <shapectl/calib/observation_residuals.hpp>

namespace shapectl {

namespace {

using Kind = ParameterCoordinate::Kind;

// The frames' residuals with the model at one set of parameters.
struct FitPoint {
  Equilibria equilibria;  // the parameters and each frame's equilibrium
  std::vector<FrameResiduals> frames;
  std::vector<double> cutoffs;  // each frame's outlier cut-off
  double cost = 0;

  Eigen::VectorXd residuals() const {
    Eigen::Index rows = 0;
    for (const auto& f : frames) rows += f.residuals.size();
    Eigen::VectorXd r(rows);
    rows = 0;
    for (const auto& f : frames)
      r.segment(rows, f.residuals.size()) = f.residuals, rows += f.residuals.size();
    return r;
  }
  Eigen::MatrixXd jacobian() const {
    Eigen::Index rows = 0;
    for (const auto& f : frames) rows += f.jacobian.rows();
    Eigen::MatrixXd J(rows, frames.front().jacobian.cols());
    rows = 0;
    for (const auto& f : frames)
      J.middleRows(rows, f.jacobian.rows()) = f.jacobian, rows += f.jacobian.rows();
    return J;
  }
  double rms(std::size_t k) const {
    return frames[k].observation_count
               ? std::sqrt(frames[k].sum_squared_error / frames[k].observation_count)
               : 0;
  }
  double rms() const {
    double sum = 0;
    int count = 0;
    for (const auto& f : frames) sum += f.sum_squared_error, count += f.observation_count;
    return count ? std::sqrt(sum / count) : 0;
  }
};

class CalibrationProblem {
 public:
  CalibrationProblem(const Scene& scene, const Observations& observations,
                     const ParameterSpace& space, const CalibrationOptions& options,
                     StopRequest stop)
      : scene_(scene),
        observations_(observations),
        space_(space),
        options_(options),
        stop_(std::move(stop)),
        workspaces_(options.workspaces ? options.workspaces : WorkspacePool::create()),
        surface_(scene.object_mesh->surface_triangles()) {}

  // The fit at p. Equilibria start from `warm`'s (see frame_equilibria). New cut-offs are
  // chosen from the result when `cutoffs` is empty; the Jacobian is formed when asked.
  FitPoint evaluate(const PhysicalParameters& p, const Equilibria* warm,
                    const std::vector<double>& cutoffs, bool with_jacobian) {
    FitPoint out;
    out.equilibria = frame_equilibria(scene_, space_, p, observations_, warm,
                                      {.with_sensitivity = with_jacobian,
                                       .path_step = options_.path_step,
                                       .stop = stop_,
                                       .workspaces = workspaces_});
    const Equilibrium* surface_at = nullptr;  // frames of a fixed scene share one equilibrium
    for (std::size_t k = 0; k < observations_.frames.size(); ++k) {
      const ObservationFrame& frame = observations_.frames[k];
      const Equilibrium& e = *out.equilibria.frames[k];
      if (&e != surface_at) surface_.update(e.positions), surface_at = &e;
      const double cutoff = cutoffs.empty() ? outlier_cutoff(frame, surface_) : cutoffs[k];
      out.frames.push_back(frame_residuals(frame, e.positions, surface_, cutoff, e.dx_dz));
      out.cutoffs.push_back(cutoff);
      out.cost += out.frames.back().cost();
    }
    return out;
  }

 private:
  const Scene& scene_;
  const Observations& observations_;
  const ParameterSpace& space_;
  const CalibrationOptions& options_;
  StopRequest stop_;
  std::shared_ptr<WorkspacePool> workspaces_;
  SurfaceDistance surface_;
};

// Lower holds first: the parameters most likely known already.
int hold_rank(Kind kind) {
  switch (kind) {
    case Kind::LogDensity: return 0;
    case Kind::PoissonLogit: return 1;
    case Kind::LogYoungsModulus: return 2;
    case Kind::GripRotation:
    case Kind::PoseRotation: return 3;
    case Kind::GripTranslation:
    case Kind::PoseTranslation: return 4;
  }
  return 5;
}

// The coordinates the data determines (indices into the space), after holding one coordinate
// for each direction it does not; `unidentified` lists those directions.
std::vector<int> identifiable_coordinates(const ParameterSpace& space, const Eigen::MatrixXd& J,
                                          double threshold,
                                          std::vector<UnidentifiedDirection>& unidentified) {
  std::vector<int> active(space.size());
  for (int k = 0; k < space.size(); ++k) active[k] = k;
  while (!active.empty()) {
    Eigen::MatrixXd scaled(J.rows(), active.size());
    for (std::size_t a = 0; a < active.size(); ++a)
      scaled.col(a) = J.col(active[a]) * space.coordinates()[active[a]].scale;
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinV);
    const Eigen::Index last = static_cast<Eigen::Index>(active.size()) - 1;
    const double s = last < svd.singularValues().size() ? svd.singularValues()[last] : 0;
    const double deviation = s > 0 ? 1 / s : INFINITY;
    if (deviation <= threshold) break;
    const Eigen::VectorXd v = svd.matrixV().col(last);
    UnidentifiedDirection direction;
    direction.standard_deviation = deviation;
    // Hold the most-likely-known coordinate among those that make up the direction.
    std::size_t hold = active.size();
    for (std::size_t a = 0; a < active.size(); ++a) {
      const ParameterCoordinate& c = space.coordinates()[active[a]];
      if (std::abs(v[a]) >= 0.1) direction.combination.emplace_back(c.name, v[a]);
      if (std::abs(v[a]) < 0.3 * v.cwiseAbs().maxCoeff()) continue;
      if (hold == active.size() ||
          hold_rank(c.kind) < hold_rank(space.coordinates()[active[hold]].kind))
        hold = a;
    }
    direction.held = space.coordinates()[active[hold]].name;
    unidentified.push_back(direction);
    active.erase(active.begin() + static_cast<std::ptrdiff_t>(hold));
  }
  return active;
}

// Frames whose joints do not fit the scene (observations read for another scene).
void check_frames(const Scene& scene, const Observations& observations) {
  const Eigen::Index joints = scene.robot ? scene.robot->model->active_count() : 0;
  for (std::size_t k = 0; k < observations.frames.size(); ++k)
    if (observations.frames[k].joints.size() != joints)
      throw std::invalid_argument("frame " + std::to_string(k) + ": " +
                                  std::to_string(observations.frames[k].joints.size()) +
                                  " joint values for a scene with " + std::to_string(joints) +
                                  " active joints");
}

Eigen::MatrixXd columns(const Eigen::MatrixXd& J, const std::vector<int>& active) {
  Eigen::MatrixXd out(J.rows(), active.size());
  for (std::size_t a = 0; a < active.size(); ++a) out.col(a) = J.col(active[a]);
  return out;
}

// The value a coordinate reports: the physical parameter, the offset's component, the pose's
// position or its rotation from the `initial` pose (a rotation vector, world axes).
double reported_value(const ParameterCoordinate& c, const PhysicalParameters& p,
                      const PhysicalParameters& initial) {
  switch (c.kind) {
    case Kind::LogYoungsModulus: return p.youngs_modulus;
    case Kind::PoissonLogit: return p.poisson_ratio;
    case Kind::LogDensity: return p.density;
    case Kind::GripTranslation: return p.grip_offsets[c.grip].translation()[c.axis];
    case Kind::GripRotation: {
      const Eigen::AngleAxisd r(p.grip_offsets[c.grip].linear());
      return (r.angle() * r.axis())[c.axis];
    }
    case Kind::PoseTranslation: return p.object_pose.translation()[c.axis];
    case Kind::PoseRotation: {
      const Eigen::AngleAxisd r(p.object_pose.linear() * initial.object_pose.linear().transpose());
      return (r.angle() * r.axis())[c.axis];
    }
  }
  return 0;
}

const char* unit_of(Kind kind) {
  switch (kind) {
    case Kind::LogYoungsModulus: return "Pa";
    case Kind::PoissonLogit: return "";
    case Kind::LogDensity: return "kg/m^3";
    case Kind::GripTranslation:
    case Kind::PoseTranslation: return "m";
    case Kind::GripRotation:
    case Kind::PoseRotation: return "rad";
  }
  return "";
}

// Why the fit must stop now (cancelled, or its time budget spent), or empty.
std::string stop_reason(const CalibrationOptions& options,
                        std::chrono::steady_clock::time_point started) {
  if (options.cancel && options.cancel->load()) return "cancelled";
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (seconds > options.max_seconds) {
    std::ostringstream reason;
    reason << "time limit of " << options.max_seconds << " s reached";
    return reason.str();
  }
  return {};
}

}  // namespace

CalibrationResult calibrate(const Scene& scene, const Observations& observations,
                            const FitSelection& fit, const CalibrationOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  if (observations.frames.empty()) throw std::invalid_argument("no observed frames");
  check_frames(scene, observations);
  const ParameterSpace space(scene, fit);
  // Asked deep inside (each Newton iteration, path step, frame): the first reason sticks.
  std::string stopped;
  const StopRequest stop = [&] {
    if (stopped.empty()) stopped = stop_reason(options, started);
    return !stopped.empty();
  };
  CalibrationProblem problem(scene, observations, space, options, stop);
  const PhysicalParameters initial = PhysicalParameters::of(scene);

  CalibrationResult result;
  FitPoint at;
  try {
    at = problem.evaluate(initial, nullptr, {}, true);
  } catch (const std::runtime_error&) {
    if (stop()) throw std::runtime_error(stopped + " before the model was evaluated");
    throw;
  }
  const FitPoint before = at;
  const std::vector<int> active =
      identifiable_coordinates(space, at.jacobian(), options.identifiability_threshold,
                               result.unidentified);
  double lambda = -1;  // set at the first iteration
  result.reason = "iteration limit";
  for (int iteration = 0; iteration < options.max_iterations && !active.empty(); ++iteration) {
    if (stop()) break;
    const Eigen::MatrixXd J = columns(at.jacobian(), active);
    const Eigen::VectorXd r = at.residuals();
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    if (lambda < 0) lambda = 1e-3;  // relative to the diagonal (Marquardt)
    bool accepted = false;
    double step = 0;
    for (int trial = 0; trial < 12 && !accepted && !stop(); ++trial) {
      Eigen::MatrixXd A = JtJ;
      A.diagonal() += lambda * JtJ.diagonal().cwiseMax(1e-12 * JtJ.diagonal().maxCoeff());
      const Eigen::VectorXd delta = -A.ldlt().solve(g);
      Eigen::VectorXd dz = Eigen::VectorXd::Zero(space.size());
      step = 0;
      for (std::size_t a = 0; a < active.size(); ++a) {
        dz[active[a]] = delta[a];
        step = std::max(step, std::abs(delta[a]) / space.coordinates()[active[a]].scale);
      }
      FitPoint next;
      try {
        next = problem.evaluate(space.advanced(at.equilibria.parameters, dz), &at.equilibria,
                                at.cutoffs, false);
      } catch (const std::runtime_error&) {
        lambda *= 4;  // a step too far for statics: shorter (or stopped: the loop ends)
        continue;
      }
      if (next.cost < at.cost) {
        const double decrease = (at.cost - next.cost) / std::max(at.cost, 1e-300);
        try {
          at = problem.evaluate(next.equilibria.parameters, &next.equilibria, {}, true);
        } catch (const std::runtime_error&) {
          if (stop()) break;  // `at` stays the last point with a Jacobian
          throw;
        }
        lambda = std::max(lambda / 3, 1e-12);
        accepted = true;
        result.iterations = iteration + 1;
        if (decrease < 1e-10 || step < 1e-8) {
          result.converged = true;
          result.reason = "converged: cost decrease " + std::to_string(decrease) + ", step " +
                          std::to_string(step);
        }
      } else {
        lambda *= 4;
      }
    }
    if (!accepted && stop()) break;
    if (!accepted) {
      // No step lowers the cost: at a minimum up to round-off.
      result.converged = true;
      result.reason = "converged: no step lowers the cost further";
    }
    if (result.converged) break;
  }
  if (active.empty()) result.reason = "nothing identifiable to fit";
  if (!stopped.empty() && !result.converged) result.reason = stopped;

  // Gauss–Newton covariance of the fitted coordinates (residuals are in units of σ).
  const Eigen::MatrixXd J = columns(at.jacobian(), active);
  const Eigen::MatrixXd covariance =
      active.empty() ? Eigen::MatrixXd() : Eigen::MatrixXd((J.transpose() * J).inverse());
  for (int k = 0; k < space.size(); ++k) {
    const ParameterCoordinate& c = space.coordinates()[k];
    FittedParameter f{.name = c.name,
                      .unit = unit_of(c.kind),
                      .initial = reported_value(c, initial, initial),
                      .fitted = reported_value(c, at.equilibria.parameters, initial)};
    const auto a = std::find(active.begin(), active.end(), k);
    f.held = a == active.end();
    if (!f.held) {
      const Eigen::Index i = a - active.begin();
      f.standard_deviation =
          space.physical_per_coordinate(c, at.equilibria.parameters) * std::sqrt(covariance(i, i));
    }
    result.parameters.push_back(f);
  }
  for (std::size_t k = 0; k < observations.frames.size(); ++k) {
    const ObservationFrame& frame = observations.frames[k];
    result.frames.push_back({.rms_before = before.rms(k),
                             .rms_after = at.rms(k),
                             .markers = static_cast<int>(frame.markers.size()),
                             .points = static_cast<int>(frame.points.size()),
                             .inlier_points_after = at.frames[k].inlier_points});
  }
  result.rms_before = before.rms();
  result.rms_after = at.rms();
  const Eigen::Index rows = at.residuals().size();
  const Eigen::Index dof = rows - static_cast<Eigen::Index>(active.size());
  result.chi_squared_per_dof = dof > 0 ? at.residuals().squaredNorm() / double(dof) : 0;
  result.fitted = at.equilibria.parameters;
  result.scene = result.fitted.applied_to(scene);
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace shapectl
