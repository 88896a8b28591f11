#pragma once
// The changing half of a gripped object (the fixed half is GrippedObject): joint angles θ, the
// robot's kinematics at θ, the object's positions (the equilibrium x̂(θ) after a converged
// solve), the last solve's result, and the factorization with the point it belongs to (in a
// workspace from the pool it was made with, if any). Every algorithm on a GrippedObject takes
// one explicitly; nothing else remembers a past call. Made by GrippedObject::make_state or
// solve_from; move-only (it owns its factorization); one thread at a time changes it.
#include <memory>

#include <shapectl/robot/kinematics.hpp>
#include <shapectl/sim/statics.hpp>

namespace shapectl {

class WorkspacePool;

class ObjectState {
 public:
  ObjectState(ObjectState&&) noexcept = default;
  ObjectState& operator=(ObjectState&&) noexcept = default;
  ObjectState(const ObjectState&) = delete;
  ObjectState& operator=(const ObjectState&) = delete;

  const Eigen::VectorXd& joints() const { return joints_; }
  const KinematicsState& kinematics() const { return kinematics_; }
  const Positions& positions() const { return positions_; }
  const StaticsResult& statics() const { return statics_; }
  // The factor on the contact stiffness κ its positions are at (the adaptive barrier,
  // contact_stiffness.hpp): 1 until a solve raises it. Every derivative at the state (its
  // factorization, ∂F/∂θ, dx̂/dθ, the contacts' forces) is at that κ, and states solved with
  // this one as the chord start from it.
  double contact_scale() const { return statics_.contact_scale; }
  // Whether it holds a factorization (of the Hessian at its positions, or at the last Newton
  // iterate before them).
  bool has_factor() const { return workspace_ && workspace_->has_factor; }
  // The pool its workspace came from (null: a workspace of its own); states solved from this
  // one (GrippedObject::solve_from with it as the chord) take theirs from it too.
  const std::shared_ptr<WorkspacePool>& workspaces() const { return workspaces_; }

 private:
  friend class GrippedObject;
  ObjectState() = default;

  Eigen::VectorXd joints_;
  KinematicsState kinematics_;
  Positions positions_;
  StaticsResult statics_;
  std::shared_ptr<WorkspacePool> workspaces_;
  std::shared_ptr<StaticsWorkspace> workspace_;  // from workspaces_ if set
  // With friction: the anchor of its solve (its warm start; lagged_friction.hpp), which the
  // friction at the equilibrium, hence its Hessian and sensitivities, count slip from. Empty
  // without friction or before a solve.
  Positions friction_anchor_;
};

}  // namespace shapectl
