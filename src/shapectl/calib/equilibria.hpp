#pragma once
// What calibration asks of the model at one set of parameters p: each observed frame's
// equilibrium x̂ and, when asked, its sensitivity dx̂/dz (calib/model_parameters.hpp). Two kinds
// of scene answer it:
// - a robot holds the object: each frame has its own equilibrium at the frame's joints (Newton
//   from a warm start, or walked from the reference joints, calib/joint_path.hpp), and
//   dx̂/dz = H⁻¹ ∂F/∂z;
// - fixed nodes alone hold it: the frames of one load case see one equilibrium, solved once,
//   and dx̂/dz = H⁻¹ ∂F/∂z plus the rigid motion of the object's pose
//   (ParameterSpace::pose_motion).
// Each frame's equilibrium is under its own loads (ObservationFrame::loads) or the scene's.
// Nothing else: an object held by neither cannot be loaded.
#include <memory>
#include <vector>

#include <shapectl/calib/model_parameters.hpp>
#include <shapectl/calib/observations.hpp>

namespace shapectl {

struct Equilibrium {
  Positions positions;    // x̂, 3n, world frame, m
  Eigen::MatrixXd dx_dz;  // 3n × the space's size; empty unless asked for
};

// The equilibria of every observed frame at `parameters`; frames that see the same equilibrium
// share it.
struct Equilibria {
  PhysicalParameters parameters;
  std::vector<std::shared_ptr<const Equilibrium>> frames;  // one per observed frame
};

struct EquilibriumOptions {
  bool with_sensitivity = false;  // also dx̂/dz
  double path_step = 0.05;        // rad: see calib/joint_path.hpp
  // Asked between frames and Newton iterations (may be empty); true ends the search with
  // std::runtime_error (a calibration's time budget or its cancel).
  StopRequest stop = {};
  // Where the equilibria take their statics workspaces (null: their own): one pool for every
  // trial of a calibration keeps one symbolic analysis per pattern, not one per trial.
  std::shared_ptr<WorkspacePool> workspaces = nullptr;
};

// Newton starts from `warm` (the frames' equilibria at nearby parameters) when given. Throws
// std::runtime_error naming the frame when an equilibrium cannot be found or, with the
// sensitivity, is unstable.
Equilibria frame_equilibria(const Scene& scene, const ParameterSpace& space,
                            const PhysicalParameters& parameters, const Observations& observations,
                            const Equilibria* warm, const EquilibriumOptions& options);

}  // namespace shapectl
