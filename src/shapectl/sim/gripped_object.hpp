#pragma once
// The object held by the robot: joint angles θ → quasi-static shape x̂(θ) (paper Section II)
// and its sensitivity dx̂/dθ = H⁻¹ ∂F/∂θ (eq. 9), H the true Hessian at the equilibrium.
#include <memory>

#include <shapectl/robot/kinematics.hpp>
#include <shapectl/sim/grip_springs.hpp>
#include <shapectl/sim/object_statics.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl {

class GrippedObject {
 public:
  // The scene must have a robot and grips; the object's reference shape x⁰ is its placed
  // rest shape, gripped at the reference joints θ⁰.
  explicit GrippedObject(const Scene& scene);

  const Scene& scene() const { return scene_; }
  const RobotModel& robot() const { return *scene_.robot->model; }
  const TetMesh& mesh() const { return statics_->mesh(); }
  int node_count() const { return mesh().node_count(); }
  int joint_count() const { return robot().active_count(); }
  const Eigen::VectorXd& reference_joints() const { return scene_.robot->reference_joints; }
  Positions reference_positions() const { return scene_.world_rest_positions(); }

  // Equilibrium at θ = joints, warm-started from x (overwritten with the result).
  // max_iterations > 0 caps Newton for this call.
  StaticsResult solve(const Eigen::VectorXd& joints, Positions& x, int max_iterations = 0);
  // Robot state of the last solve.
  const KinematicsState& kinematics() const { return grips_->robot_state(); }
  const GripSprings& grips() const { return *grips_; }
  ObjectStatics& statics() { return *statics_; }

  // A warm start for the equilibrium at `to` from the one at `from`: every gripped node of `x`
  // is set to its position in `at_from` moved rigidly with its end effector from `from` to
  // `to`. A linear prediction dx̂/dθ·Δθ puts them off their anchors by ~ r|Δθ|²/2 — tens of
  // newtons through stiff grip springs, and Newton iterations to undo.
  void carry_gripped_nodes(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                           const Positions& at_from, Positions& x) const;
  // dx̂/dθ (3n × m) at the last solve's equilibrium x.
  Eigen::MatrixXd sensitivity(const Positions& x);
  // (dx̂/dθ)ᵀ v by the adjoint method, one solve: λ = H⁻¹ v, result = (∂F/∂θ)ᵀ λ.
  Eigen::VectorXd adjoint(const Positions& x, const Eigen::VectorXd& v);

 private:
  Scene scene_;
  std::unique_ptr<GripSprings> grips_;
  std::unique_ptr<ObjectStatics> statics_;
};

}  // namespace shapectl
