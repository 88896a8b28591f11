#pragma once
// The real object, simulated, to run and test the closed loop without hardware: a physically
// different scene (WORLD.json: the "true" material, density and grip offsets, the same mesh)
// held by the robot at its *measured* joints, and a camera that observes it at a fixed rate.
// `run --robot sim --world WORLD.json` and `serve` use it; the log records its true error.
#include <optional>
#include <random>

#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/control/shape_targets.hpp>
#include <shapectl/sim/gripped_object.hpp>

namespace shapectl {

class SimulatedWorld {
 public:
  // `world` must hold the model's mesh (same nodes) with the same robot; throws
  // std::invalid_argument otherwise, NoEquilibrium (calib/joint_path.hpp) when the world's
  // object has none at the reference joints. rate: observations per second.
  SimulatedWorld(const Scene& world, const Scene& model, SimulatedCamera camera, double rate,
                 unsigned seed = 1);

  // The world's object settled at the robot's measured joints, and an observation of it when
  // one is due at `time` (s, any clock that only moves forward). Throws NoEquilibrium when
  // the world's object has no equilibrium there (the world stays where it was).
  std::optional<ObservationFrame> step(double time, const Eigen::VectorXd& measured_joints);
  // Mean distance of the targets' nodes from their targets in the world, m (NaN without targets).
  double true_error(const ShapeTargets& targets) const;
  const Positions& positions() const { return state_->positions(); }
  SimulatedCamera& camera() { return camera_; }

 private:
  GrippedObject object_;
  std::shared_ptr<WorkspacePool> workspaces_ = WorkspacePool::create();
  SimulatedCamera camera_;
  double period_;
  double next_time_ = 0;
  std::mt19937 rng_;
  std::optional<ObjectState> state_;
};

}  // namespace shapectl
