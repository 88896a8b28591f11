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
#include <shapectl/enum_names.hpp>

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
      const CameraMotion camera =
          frame.camera ? space_.camera_motion(frame.camera->index, frame.camera->position, p)
                       : CameraMotion{};
      const double cutoff = cutoffs.empty() ? outlier_cutoff(frame, surface_, camera) : cutoffs[k];
      out.frames.push_back(frame_residuals(frame, e.positions, surface_, cutoff, e.dx_dz, camera));
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
    case Kind::PoseRotation:
    case Kind::CameraRotation: return 3;
    case Kind::GripTranslation:
    case Kind::PoseTranslation:
    case Kind::CameraTranslation: return 4;
  }
  return 5;
}

// Each coordinate's displacement from `initial` (z − z₀): the logarithms' and the logit's
// difference, the translation's, and the rotation vector of R R₀ᵀ (world axes for the pose,
// the offset's left factor for a grip).
Eigen::VectorXd displacement(const ParameterSpace& space, const PhysicalParameters& p,
                             const PhysicalParameters& initial) {
  const auto turned = [](const Eigen::Matrix3d& R, const Eigen::Matrix3d& R0) -> Vec3 {
    const Eigen::AngleAxisd r(R * R0.transpose());
    return r.angle() * r.axis();
  };
  Eigen::VectorXd d(space.size());
  for (int k = 0; k < space.size(); ++k) {
    const ParameterCoordinate& c = space.coordinates()[k];
    switch (c.kind) {
      case Kind::GripTranslation:
        d[k] = (p.grip_offsets[c.grip].translation() -
                initial.grip_offsets[c.grip].translation())[c.axis];
        break;
      case Kind::GripRotation:
        d[k] =
            turned(p.grip_offsets[c.grip].linear(), initial.grip_offsets[c.grip].linear())[c.axis];
        break;
      case Kind::PoseTranslation:
        d[k] = (p.object_pose.translation() - initial.object_pose.translation())[c.axis];
        break;
      case Kind::PoseRotation:
        d[k] = turned(p.object_pose.linear(), initial.object_pose.linear())[c.axis];
        break;
      case Kind::CameraTranslation:
        d[k] = (p.camera_pose(c.camera).translation() -
                initial.camera_pose(c.camera).translation())[c.axis];
        break;
      case Kind::CameraRotation:
        d[k] = turned(p.camera_pose(c.camera).linear(),
                      initial.camera_pose(c.camera).linear())[c.axis];
        break;
      default: d[k] = material_coordinate(c, p) - material_coordinate(c, initial);
    }
  }
  return d;
}

// The priors as rows of the augmented system: residual (z − z₀)/σ with Jacobian 1/σ on the
// diagonal (the rotation vector's derivative taken as the identity: exact at the start, off by
// O(angle²) a few degrees away). Coordinates without a prior have weight 0.
struct PriorRows {
  Eigen::VectorXd weight;  // 1/σ, or 0
  Eigen::VectorXd residuals(const ParameterSpace& space, const PhysicalParameters& p,
                            const PhysicalParameters& initial) const {
    return weight.cwiseProduct(displacement(space, p, initial));
  }
};

// p with every coordinate not in `active` moved back to its value in `initial`.
PhysicalParameters back_to_initial(const ParameterSpace& space, const std::vector<int>& active,
                                   const PhysicalParameters& p, const PhysicalParameters& initial) {
  Eigen::VectorXd dz = -displacement(space, p, initial);
  for (int k : active) dz[k] = 0;
  return space.advanced(p, dz);
}

// The coordinates of `active` (indices into the space) left to fit after holding one coordinate
// for each degenerate direction of the scaled augmented Jacobian J; `unidentified` gets them.
std::vector<int> identifiable_coordinates(const ParameterSpace& space, std::vector<int> active,
                                          const Eigen::MatrixXd& J,
                                          const Eigen::VectorXd& prior_weight, double threshold,
                                          std::vector<UnidentifiedDirection>& unidentified) {
  while (!active.empty()) {
    Eigen::MatrixXd scaled = Eigen::MatrixXd::Zero(J.rows() + space.size(), active.size());
    for (std::size_t a = 0; a < active.size(); ++a) {
      const double scale = space.coordinates()[active[a]].scale;
      scaled.col(a).head(J.rows()) = J.col(active[a]) * scale;
      scaled(J.rows() + active[a], a) = prior_weight[active[a]] * scale;
    }
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

bool is_material(Kind k) {
  return k == Kind::LogYoungsModulus || k == Kind::LogDensity || k == Kind::PoissonLogit;
}

// What would determine a parameter of kind `kind` that trades off with `partners` (kinds).
std::string suggestion(Kind kind, const std::vector<Kind>& partners) {
  const auto has = [&](auto pred) {
    return pred(kind) || std::any_of(partners.begin(), partners.end(), pred);
  };
  const auto any_partner = [&](auto pred) {
    return std::any_of(partners.begin(), partners.end(), pred);
  };
  const auto is = [](Kind want) { return [want](Kind k) { return k == want; }; };
  const auto grip = [](Kind k) { return k == Kind::GripTranslation || k == Kind::GripRotation; };
  const auto pose = [](Kind k) { return k == Kind::PoseTranslation || k == Kind::PoseRotation; };
  const auto camera = [](Kind k) {
    return k == Kind::CameraTranslation || k == Kind::CameraRotation;
  };
  if (has(is(Kind::LogYoungsModulus)) && has(is(Kind::LogDensity)))
    return "add a frame with a different load of known size (its \"loads\" in the observations "
           "file: a hanging weight of known mass, e.g. hung from the free end, or from the "
           "middle of an object held at both ends), or weigh the object and give its density: "
           "under gravity alone the shape shows only E/density";
  if (has(camera))
    return "markers (a tracker sees the object in the world's frame), or a second camera's "
           "points: one camera's offset moves all it sees as the object's pose does";
  if (is_material(kind) && any_partner(grip))
    return "a second robot pose that turns the object against gravity";
  if (is_material(kind) && any_partner(pose))
    return "markers where the object bends (on the free end and along it; the middle of an "
           "object held at both ends), or the clamp's pose measured and given in the scene";
  if (kind == Kind::PoissonLogit)
    return "observations of a twist or a squeeze (a bar that only bends barely shows Poisson's "
           "ratio)";
  if (is_material(kind))
    return "a marker where the object deflects most (a cantilever's free end, the middle of an "
           "object held at both ends): no observed point moves with it";
  if (any_partner(is_material))
    return grip(kind)
               ? "a second robot pose that turns the object against gravity"
               : "markers where the object bends (on the free end and along it; the middle of "
                 "an object held at both ends)";
  return "markers not all on one line, or points on the object's end faces";
}

// Frames whose joints do not fit the scene (observations read for another scene); a fitted pose
// where frames give theirs.
void check_frames(const Scene& scene, const Observations& observations, const FitSelection& fit) {
  for (std::size_t k = 0; k < observations.frames.size() && fit.object_pose; ++k)
    if (observations.frames[k].object_pose)
      throw std::invalid_argument(
          "object_pose: not fitted when frames give their own "
          "(frames[" +
          std::to_string(k) + "].object_pose: a known condition)");
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
    case Kind::LogYoungsModulus: return p.material(c.region).youngs_modulus;
    case Kind::PoissonLogit: return p.material(c.region).poisson_ratio;
    case Kind::LogDensity: return p.material(c.region).density;
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
    case Kind::CameraTranslation: return p.camera_pose(c.camera).translation()[c.axis];
    case Kind::CameraRotation: {
      const Eigen::AngleAxisd r(p.camera_pose(c.camera).linear());
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
    case Kind::PoseTranslation:
    case Kind::CameraTranslation: return "m";
    case Kind::GripRotation:
    case Kind::PoseRotation:
    case Kind::CameraRotation: return "rad";
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

// Each coordinate's value where it has bounds (ln E, ln ρ, the logit of ν); 0 for the others.
Eigen::VectorXd material_coordinates(const ParameterSpace& space, const PhysicalParameters& p) {
  Eigen::VectorXd z(space.size());
  for (int k = 0; k < space.size(); ++k) z[k] = material_coordinate(space.coordinates()[k], p);
  return z;
}

constexpr auto kVerdicts =
    enum_names<Verdict>(std::pair{Verdict::Determined, "determined"},
                        std::pair{Verdict::WeaklyDetermined, "weakly determined"},
                        std::pair{Verdict::NotDetermined, "not determined"});

}  // namespace

const char* to_string(Verdict verdict) { return kVerdicts.name(verdict); }

CalibrationResult calibrate(const Scene& scene, const Observations& observations,
                            const FitSelection& fit, const CalibrationOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  if (observations.frames.empty()) throw std::invalid_argument("no observed frames");
  check_frames(scene, observations, fit);
  const ParameterSpace space(scene, fit, camera_count(observations));
  const PhysicalParameters initial = PhysicalParameters::of(scene);
  if (const std::string name = outside_bounds(space, initial, options.bounds); !name.empty())
    throw std::invalid_argument(name + ": the scene's value is outside its bounds");
  // Asked deep inside (each Newton iteration, path step, frame): the first reason sticks.
  std::string stopped;
  const StopRequest stop = [&] {
    if (stopped.empty()) stopped = stop_reason(options, started);
    return !stopped.empty();
  };
  CalibrationProblem problem(scene, observations, space, options, stop);
  PriorRows priors{Eigen::VectorXd::Zero(space.size())};
  std::vector<ValueInterval> bounds;
  for (int k = 0; k < space.size(); ++k) {
    const double sigma = prior_sigma(options.priors, space.coordinates()[k], initial);
    priors.weight[k] = sigma > 0 ? 1 / sigma : 0;
    bounds.push_back(coordinate_bounds(options.bounds, space.coordinates()[k]));
  }
  const Eigen::VectorXd prior_information = priors.weight.cwiseAbs2();
  // The fit's cost: the frames' and the priors' ½ Σ r².
  const auto cost = [&](const FitPoint& f) {
    return f.cost + 0.5 * priors.residuals(space, f.equilibria.parameters, initial).squaredNorm();
  };

  CalibrationResult result;
  FitPoint at;
  try {
    at = problem.evaluate(initial, nullptr, {}, true);
  } catch (const std::runtime_error&) {
    if (stop()) throw std::runtime_error(stopped + " before the model was evaluated");
    throw;
  }
  const FitPoint before = at;
  std::vector<int> active(space.size());
  for (int k = 0; k < space.size(); ++k) active[k] = k;
  active = identifiable_coordinates(space, active, at.jacobian(), priors.weight,
                                    options.degenerate_threshold, result.unidentified);
  double lambda = 1e-3;  // relative to the diagonal (Marquardt)
  int iteration = 0;
  // Levenberg–Marquardt over `active` from `at` until converged, stopped or out of iterations.
  const auto fit_active = [&] {
    result.converged = active.empty();
    result.reason = active.empty() ? "nothing identifiable to fit" : "iteration limit";
    for (; iteration < options.max_iterations && !active.empty(); ++iteration) {
      if (stop()) break;
      // A direction that turns degenerate on the way (E running off where the markers stop
      // seeing it) is held too: back at its initial value.
      const std::size_t fitted = active.size();
      active = identifiable_coordinates(space, active, at.jacobian(), priors.weight,
                                        options.degenerate_threshold, result.unidentified);
      if (active.size() < fitted) {
        at = problem.evaluate(back_to_initial(space, active, at.equilibria.parameters, initial),
                              &at.equilibria, {}, true);
        if (active.empty()) {
          result.converged = true, result.reason = "nothing identifiable to fit";
          break;
        }
      }
      const Eigen::MatrixXd J = columns(at.jacobian(), active);
      const Eigen::VectorXd r = at.residuals();
      const Eigen::VectorXd prior_r = priors.residuals(space, at.equilibria.parameters, initial);
      Eigen::MatrixXd JtJ = J.transpose() * J;
      Eigen::VectorXd g = J.transpose() * r;
      // A coordinate at a bound that the gradient pushes outwards stays there this iteration.
      const Eigen::VectorXd z = material_coordinates(space, at.equilibria.parameters);
      std::vector<char> blocked(active.size(), 0);
      for (std::size_t a = 0; a < active.size(); ++a) {
        const int k = active[a];
        JtJ(a, a) += prior_information[k];
        g[a] += priors.weight[k] * prior_r[k];
        blocked[a] = (z[k] <= bounds[k].lower && g[a] > 0) || (z[k] >= bounds[k].upper && g[a] < 0);
        if (!blocked[a]) continue;
        JtJ.row(a).setZero(), JtJ.col(a).setZero(), JtJ(a, a) = 1, g[a] = 0;
      }
      const double current = cost(at);
      bool accepted = false;
      double step = 0, decrease = 0;
      for (int trial = 0; trial < 12 && !accepted && !stop(); ++trial) {
        Eigen::MatrixXd A = JtJ;
        A.diagonal() += lambda * JtJ.diagonal().cwiseMax(1e-12 * JtJ.diagonal().maxCoeff());
        const Eigen::VectorXd delta = -A.ldlt().solve(g);
        Eigen::VectorXd dz = Eigen::VectorXd::Zero(space.size());
        step = 0;
        for (std::size_t a = 0; a < active.size(); ++a) {
          const int k = active[a];
          // Projected onto the bounds.
          dz[k] = std::clamp(z[k] + delta[a], bounds[k].lower, bounds[k].upper) - z[k];
          step = std::max(step, std::abs(dz[k]) / space.coordinates()[k].scale);
        }
        FitPoint next;
        try {
          next = problem.evaluate(space.advanced(at.equilibria.parameters, dz), &at.equilibria,
                                  at.cutoffs, false);
        } catch (const std::runtime_error&) {
          lambda *= 4;  // a step too far for statics: shorter (or stopped: the loop ends)
          continue;
        }
        const double next_cost = cost(next);
        if (next_cost < current) {
          decrease = (current - next_cost) / std::max(current, 1e-300);
          try {
            at = problem.evaluate(next.equilibria.parameters, &next.equilibria, {}, true);
          } catch (const std::runtime_error&) {
            if (stop()) break;  // `at` stays the last point with a Jacobian
            throw;
          }
          lambda = std::max(lambda / 3, 1e-12);
          accepted = true;
          result.iterations = iteration + 1;
        } else {
          lambda *= 4;
        }
      }
      if (!accepted && stop()) break;
      if (accepted && (decrease < 1e-10 || step < 1e-8)) {
        result.converged = true;
        result.reason = "converged: cost decrease " + std::to_string(decrease) + ", step " +
                        std::to_string(step);
      } else if (!accepted) {
        // No step lowers the cost: at a minimum up to round-off.
        result.converged = true;
        result.reason = "converged: no step lowers the cost further";
      }
      if (result.converged) {
        ++iteration;
        break;
      }
    }
  };
  // A held coordinate is never kept while freeing it would lower χ² by more than the noise
  // explains: the predicted decrease of single-coordinate Gauss–Newton on the augmented system.
  std::vector<char> released(space.size(), 0);
  for (;;) {
    fit_active();
    if (!result.converged) break;
    const Eigen::MatrixXd J = at.jacobian();
    const Eigen::VectorXd r = at.residuals();
    int release = -1;
    double best = options.release_chi_squared;
    for (int k = 0; k < space.size(); ++k) {
      // Each once: one held again on the way is degenerate after all.
      if (std::find(active.begin(), active.end(), k) != active.end() || released[k]) continue;
      const double jtj = J.col(k).squaredNorm() + prior_information[k];
      const double gain = jtj > 0 ? std::pow(J.col(k).dot(r), 2) / jtj : 0;
      if (gain > best) best = gain, release = k;
    }
    if (release < 0) break;
    released[release] = 1;
    active.insert(std::upper_bound(active.begin(), active.end(), release), release);
    const std::string name = space.coordinates()[release].name;
    result.unidentified.erase(std::remove_if(result.unidentified.begin(), result.unidentified.end(),
                                             [&](const UnidentifiedDirection& d) {
                                               return d.held == name;
                                             }),
                              result.unidentified.end());
  }
  if (!stopped.empty() && !result.converged) result.reason = stopped;

  // The posterior covariance of the fitted coordinates (residuals in units of σ, priors in).
  const Eigen::MatrixXd J = columns(at.jacobian(), active);
  Eigen::MatrixXd information = J.transpose() * J;
  for (std::size_t a = 0; a < active.size(); ++a) information(a, a) += prior_information[active[a]];
  const Eigen::MatrixXd covariance =
      active.empty() ? Eigen::MatrixXd() : Eigen::MatrixXd(information.inverse());
  const Eigen::VectorXd moved = displacement(space, at.equilibria.parameters, initial);
  for (int k = 0; k < space.size(); ++k) {
    const ParameterCoordinate& c = space.coordinates()[k];
    FittedParameter f;
    f.name = c.name;
    f.unit = unit_of(c.kind);
    f.initial = reported_value(c, initial, initial);
    f.fitted = reported_value(c, at.equilibria.parameters, initial);
    const double per = space.physical_per_coordinate(c, initial);
    if (priors.weight[k] > 0) {
      f.prior = per / priors.weight[k];
      f.implausible = std::abs(moved[k]) * priors.weight[k] > 3;
      if (f.implausible) result.implausible.push_back(c.name);
    }
    const auto a = std::find(active.begin(), active.end(), k);
    std::vector<Kind> partners;
    if (a == active.end()) {
      f.held = true;
      f.verdict = Verdict::NotDetermined;
      for (const UnidentifiedDirection& d : result.unidentified)
        if (d.held == c.name)
          for (const auto& [name, weight] : d.combination)
            if (name != c.name) f.trades_off_with.push_back(name);
    } else {
      const Eigen::Index i = a - active.begin();
      const double sigma = std::sqrt(covariance(i, i));
      f.standard_deviation = space.physical_per_coordinate(c, at.equilibria.parameters) * sigma;
      f.verdict = sigma / c.scale <= options.identifiability_threshold ? Verdict::Determined
                                                                       : Verdict::WeaklyDetermined;
      for (std::size_t b = 0; b < active.size() && f.verdict == Verdict::WeaklyDetermined; ++b)
        if (Eigen::Index(b) != i &&
            std::abs(covariance(i, b)) >= 0.5 * sigma * std::sqrt(covariance(b, b)))
          f.trades_off_with.push_back(space.coordinates()[active[b]].name);
    }
    for (const std::string& name : f.trades_off_with)
      for (const ParameterCoordinate& other : space.coordinates())
        if (other.name == name) partners.push_back(other.kind);
    if (f.verdict != Verdict::Determined) f.suggestion = suggestion(c.kind, partners);
    result.parameters.push_back(f);
  }
  for (UnidentifiedDirection& d : result.unidentified)
    for (const FittedParameter& f : result.parameters)
      if (f.name == d.held) d.suggestion = f.suggestion;
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
