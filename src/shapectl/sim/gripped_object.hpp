#pragma once
// The object held by the robot: joint angles θ → quasi-static shape x̂(θ) (paper Section II)
// and its sensitivity dx̂/dθ = H⁻¹ ∂F/∂θ (eq. 9), H the true Hessian at the equilibrium (with
// friction, the Jacobian of the lagged fixed point's force balance: friction_sensitivity.hpp).
//
// Model and data, as in Pinocchio: GrippedObject is the fixed description (scene, robot, grip
// springs, energies, fixed nodes, solver options), immutable and shareable across threads;
// ObjectState is everything that changes, its workspace (symbolic analysis, buffers) included,
// which comes from a WorkspacePool on the state side (docs/architecture.md, "Model and state").
// Every algorithm is a const member taking the state: two threads may work on one
// GrippedObject with states of their own.
#include <memory>
#include <optional>

#include <shapectl/robot/kinematics.hpp>
#include <shapectl/sim/friction_sensitivity.hpp>
#include <shapectl/sim/grip_springs.hpp>
#include <shapectl/sim/object_state.hpp>
#include <shapectl/sim/object_statics.hpp>
#include <shapectl/sim/scene.hpp>
#include <shapectl/sim/workspace_pool.hpp>

namespace shapectl {

class GrippedObject {
 public:
  // The scene must have a robot and grips; the object's reference shape x⁰ is its placed
  // rest shape, gripped at the reference joints θ⁰.
  explicit GrippedObject(const Scene& scene);
  GrippedObject(const GrippedObject&) = delete;
  GrippedObject& operator=(const GrippedObject&) = delete;

  const Scene& scene() const { return scene_; }
  const RobotModel& robot() const { return *scene_.robot->model; }
  const TetMesh& mesh() const { return statics_->mesh(); }
  int node_count() const { return mesh().node_count(); }
  int joint_count() const { return robot().active_count(); }
  const Eigen::VectorXd& reference_joints() const { return scene_.robot->reference_joints; }
  Positions reference_positions() const { return scene_.world_rest_positions(); }
  const GripSprings& grips() const { return *grips_; }
  const ObjectStatics& statics() const { return *statics_; }

  // A state at θ with positions x (not solved: statics() reports NotConverged, 0 iterations),
  // its workspace from `workspaces` (null: one of its own), its contact stiffness scaled by
  // `contact_scale` (ObjectState::contact_scale: a solve of it starts there).
  ObjectState make_state(const Eigen::VectorXd& joints, const Positions& x,
                         std::shared_ptr<WorkspacePool> workspaces = nullptr,
                         double contact_scale = 1) const;
  // Equilibrium at θ = joints, Newton from the state's positions; `state` then describes it.
  // Newton tries steps with `chord`'s factorization first if it holds one (a nearby state's,
  // e.g. the one the warm start came from; it may be `state` itself). max_iterations > 0
  // caps Newton for this call; `stop` may end it early (a time budget).
  // A state at other joints (its positions clear of the obstacles where they put them) with
  // obstacles on links: their motion from there to `joints` is swept against the positions
  // (ObstacleContact::max_obstacle_step); where one would reach the object, the step is
  // split: solved at θ0 + s (θ1 − θ0), the equilibrium carried on, and so on up to `joints`
  // (quasi-static continuation, at most contact.sweep_steps sub-steps, else refused).
  // The contact stiffness starts at the larger contact_scale() of `state` and `chord` (adaptive
  // barrier: it only grows along a chain of states).
  const StaticsResult& solve(ObjectState& state, const Eigen::VectorXd& joints,
                             int max_iterations = 0, const ObjectState* chord = nullptr,
                             const StopRequest& stop = {}) const;
  // A new state solved at θ = joints from the warm start x, chord steps from `chord`'s factor.
  // Its workspace comes from `workspaces`, else from the chord's pool, else is its own.
  ObjectState solve_from(const Eigen::VectorXd& joints, const Positions& x, int max_iterations = 0,
                         const ObjectState* chord = nullptr, const StopRequest& stop = {},
                         std::shared_ptr<WorkspacePool> workspaces = nullptr) const;

  // solve_from for a warm start x clear of the obstacles where `from` puts them (the
  // equilibrium at `from`, or carry_gripped_nodes' warm start from it): obstacles on links are
  // swept from `from` to `to` (solve above).
  ObjectState solve_along(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                          const Positions& x, int max_iterations = 0,
                          const ObjectState* chord = nullptr, const StopRequest& stop = {},
                          std::shared_ptr<WorkspacePool> workspaces = nullptr) const;

  // A warm start for the equilibrium at `to` from the one at `from`: every gripped node of `x`
  // is set to its position in `at_from` moved rigidly with its end effector from `from` to
  // `to`. A linear prediction dx̂/dθ·Δθ puts them off their anchors by ~ r|Δθ|²/2 — tens of
  // newtons through stiff grip springs, and Newton iterations to undo. With obstacles the
  // result is then pulled back towards at_from (an equilibrium, clear of them) as far as the
  // contact's CCD bound asks, so no surface of the warm start passes through an obstacle where
  // they are at `from` (solve_along sweeps the obstacles on links on to `to`).
  void carry_gripped_nodes(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                           const Positions& at_from, Positions& x) const;

  // The derivatives below need the Hessian at the state's positions factored. The state's own
  // factorization is used when it is within `stale_step` metres of them (its solve's last
  // Newton step: an error of that order in H saves a factorization per optimizer iteration);
  // otherwise the state is factored at its positions first.
  // Whether the state is a stable equilibrium (the Hessian there positive definite).
  bool stable(ObjectState& state, double stale_step = 0) const;
  // For a converged state: stable(), and if not, the state's statics() marked Unstable.
  // False without factoring for a state that did not converge. Optimizers ask before
  // accepting a state: an unstable equilibrium is no shape a robot can hold.
  bool confirm_stable(ObjectState& state, double stale_step = 0) const;
  // dx̂/dθ (3n × m). Throws std::runtime_error at an unstable state.
  Eigen::MatrixXd sensitivity(ObjectState& state, double stale_step = 0) const;
  // H⁻¹ ∂F/∂p: the equilibrium's response dx̂/dp to parameters p that change the applied forces
  // by ∂F/∂p (columns, 3n each; material, density, grip offsets: see calib/). Throws
  // std::runtime_error at an unstable state.
  Eigen::MatrixXd force_response(ObjectState& state, const Eigen::MatrixXd& force_change,
                                 double stale_step = 0) const;
  // ∂F/∂θ at the state's positions and joints (3n × m): the grip springs', plus the contact's
  // with obstacles on links (contact_force_jacobian.hpp).
  Eigen::MatrixXd force_jacobian(const ObjectState& state) const;
  // The contact term with its obstacles on links placed at `state`; none if no obstacle is on
  // a link (then statics().contact() is the term at every θ).
  std::optional<ObstacleContact> moving_contact(const KinematicsState& state) const;
  // The contact term at `state` (for its contacts): obstacles on links at its joints, κ at its
  // contact_scale(); none without obstacles.
  std::optional<ObstacleContact> contact_at(const ObjectState& state) const;
  // (dx̂/dθ)ᵀ v by the adjoint method, one solve: λ = H⁻¹ v, result = (∂F/∂θ)ᵀ λ.
  Eigen::VectorXd adjoint(ObjectState& state, const Eigen::VectorXd& v,
                          double stale_step = 0) const;

 private:
  bool factored(ObjectState& state, double stale_step) const;
  // solve() at `joints` from the state's positions, with no sweep.
  void solve_at(ObjectState& state, const Eigen::VectorXd& joints, int max_iterations,
                const ObjectState* chord, const StopRequest& stop) const;
  // solve() from the state's joints to `to`, sweeping the obstacles on links.
  void solve_swept(ObjectState& state, const Eigen::VectorXd& to, int max_iterations,
                   const ObjectState* chord, const StopRequest& stop) const;
  // With friction, the friction at the state's lagged fixed point (friction_sensitivity.hpp);
  // none without friction or for a state never solved.
  std::optional<FixedPointFriction> friction_at(const ObjectState& state) const;
  // A⁻¹ rhs (transposed: A⁻ᵀ rhs) with the state's factor, A the Jacobian of the equilibrium's
  // force balance in x: the Hessian, and with friction its lag Jacobian too.
  Eigen::MatrixXd solve_equilibrium(const ObjectState& state, const Eigen::MatrixXd& rhs,
                                    bool transposed) const;
  // The contact terms at `state`: posed at its joints, κ at its contact_scale().
  ContactTerms contact_terms(const ObjectState& state) const;
  // Positions and a workspace only.
  ObjectState unsolved_state(const Positions& x, std::shared_ptr<WorkspacePool> workspaces) const;

  Scene scene_;
  std::unique_ptr<GripSprings> grips_;
  std::unique_ptr<ObjectStatics> statics_;
};

}  // namespace shapectl
