#include <shapectl/sim/gripped_object.hpp>

#include <algorithm>
#include <stdexcept>

#include <shapectl/sim/contact_force_jacobian.hpp>
#include <shapectl/sim/link_motion.hpp>
#include <shapectl/sim/rigid_motion.hpp>

namespace shapectl {

namespace {
std::vector<std::pair<int, int>> node_links(const Scene& scene) {
  std::vector<std::pair<int, int>> out;
  for (const auto& g : scene.grips)
    for (int node : g.nodes)
      out.emplace_back(node, scene.robot->end_effectors[g.end_effector].link);
  return out;
}

// Moves each gripped node's link-frame point by its grip's offset (about the TCP), in
// node_links order.
void apply_grip_offsets(const Scene& scene, std::vector<GrippedNode>& nodes) {
  std::size_t k = 0;
  for (const auto& g : scene.grips) {
    const Vec3 tcp = scene.robot->end_effectors[g.end_effector].tcp_link;
    const Eigen::Isometry3d offset_link =
        Eigen::Translation3d(tcp) * g.offset * Eigen::Translation3d(-tcp);
    for (std::size_t n = 0; n < g.nodes.size(); ++n, ++k)
      nodes[k].point_link = offset_link * nodes[k].point_link;
  }
}
}  // namespace

GrippedObject::GrippedObject(const Scene& scene) : scene_(scene) {
  if (!scene_.robot) throw std::invalid_argument("GrippedObject needs a scene with a robot");
  const auto pairs = node_links(scene_);
  const KinematicsState reference = forward_kinematics(robot(), scene_.robot->reference_joints);
  std::vector<GrippedNode> gripped =
      GripSprings::attach(reference, scene_.world_rest_positions(), pairs);
  apply_grip_offsets(scene_, gripped);
  grips_ = std::make_unique<GripSprings>(robot(), std::move(gripped), scene_.grip_stiffness);
  std::vector<int> held;
  for (const auto& p : pairs) held.push_back(p.first);
  statics_ = std::make_unique<ObjectStatics>(scene_, held);
}

ObjectState GrippedObject::make_state(const Eigen::VectorXd& joints, const Positions& x,
                                      std::shared_ptr<WorkspacePool> workspaces,
                                      double contact_scale) const {
  ObjectState s = unsolved_state(x, std::move(workspaces));
  s.statics_.contact_scale = contact_scale;
  s.joints_ = joints;
  s.kinematics_ = forward_kinematics(robot(), joints);
  return s;
}

ObjectState GrippedObject::unsolved_state(const Positions& x,
                                          std::shared_ptr<WorkspacePool> workspaces) const {
  ObjectState s;
  s.positions_ = x;
  s.workspaces_ = std::move(workspaces);
  s.workspace_ = s.workspaces_ ? s.workspaces_->acquire(statics_->solver())
                               : std::make_shared<StaticsWorkspace>(statics_->make_workspace());
  return s;
}

const StaticsResult& GrippedObject::solve(ObjectState& state, const Eigen::VectorXd& joints,
                                          int max_iterations, const ObjectState* chord,
                                          const StopRequest& stop) const {
  const ObstacleContact* contact = statics_->contact();
  if (contact && contact->moves() && state.joints_.size() == joints.size() &&
      state.joints_ != joints)
    solve_swept(state, joints, max_iterations, chord, stop);
  else solve_at(state, joints, max_iterations, chord, stop);
  return state.statics_;
}

void GrippedObject::solve_at(ObjectState& state, const Eigen::VectorXd& joints, int max_iterations,
                             const ObjectState* chord, const StopRequest& stop) const {
  state.joints_ = joints;
  state.kinematics_ = forward_kinematics(robot(), joints);
  const GripEnergy grip(*grips_, state.kinematics_);
  const StaticsWorkspace* chord_ws = chord ? chord->workspace_.get() : nullptr;
  const std::optional<ObstacleContact> contact = moving_contact(state.kinematics_);
  // The lagged friction anchors at the warm start (lagged_friction.hpp).
  state.friction_anchor_ = statics_->friction().coefficient > 0 ? state.positions_ : Positions();
  const double scale = std::max(state.contact_scale(), chord ? chord->contact_scale() : 1.0);
  state.statics_ = statics_->solve(*state.workspace_, state.positions_, &grip, max_iterations,
                                   chord_ws, stop, contact ? &*contact : nullptr, scale);
}

void GrippedObject::solve_swept(ObjectState& state, const Eigen::VectorXd& to, int max_iterations,
                                const ObjectState* chord, const StopRequest& stop) const {
  const ObstacleContact& contact = *statics_->contact();
  const int most = scene_.contact.sweep_steps;
  Eigen::VectorXd from = state.joints_;
  int sub_steps = 0, iterations = 0, factorizations = 0;
  std::string swept;  // the obstacle that split the step last
  // The state is reported at `to`, its result counting every sub-step's work.
  const auto finish = [&](const std::string& note) {
    if (state.joints_ != to) {
      state.joints_ = to;
      state.kinematics_ = forward_kinematics(robot(), to);
    }
    state.statics_.iterations += iterations;
    state.statics_.factorizations += factorizations;
    if (!note.empty()) state.statics_.reason += " (" + note + ")";
  };
  for (;;) {
    LinkMotion motion(robot(), from, to);
    int limiting = -1;
    const double s = contact.posed(motion.kinematics().T_world_link)
                         .max_obstacle_step(state.positions_, motion, &limiting);
    if (s >= 1) break;
    swept = contact.obstacles()[static_cast<std::size_t>(limiting)].name;
    if (sub_steps == most) {
      state.statics_ = {};
      state.statics_.reason =
          "obstacle '" + swept +
          "' sweeps into the object on the way to the joints: " + std::to_string(most) +
          " sub-steps (contact.sweep_steps) did not reach them";
      finish("");
      return;
    }
    const Eigen::VectorXd at = from + s * (to - from);
    solve_at(state, at, max_iterations, chord, stop);
    ++sub_steps;
    if (!state.statics_.converged()) {
      finish("sub-step " + std::to_string(sub_steps) + " of a sweep of obstacle '" + swept +
             "' towards the object: the joints were not reached");
      return;
    }
    iterations += state.statics_.iterations;
    factorizations += state.statics_.factorizations;
    chord = &state;  // the last sub-step's factorization, the nearest
    // The next warm start: the equilibrium at `at` predicted to `to` to first order (the object
    // pushed ahead of the obstacle, so the next sweep goes farther than the gap), its gripped
    // nodes carried, cut short where it would reach an obstacle where they are at `at`. The
    // solve's last factorization is near enough for a prediction.
    const Positions equilibrium = state.positions_;
    constexpr double kAnyFactor = 1e300;
    if (stable(state, kAnyFactor))
      state.positions_ =
          with_finite_rotation(equilibrium, sensitivity(state, kAnyFactor) * (to - at));
    carry_gripped_nodes(at, to, equilibrium, state.positions_);
    from = at;
  }
  solve_at(state, to, max_iterations, chord, stop);
  finish(sub_steps == 0 ? ""
                        : std::to_string(sub_steps) + " sub-steps: obstacle '" + swept +
                              "' swept towards the object");
}

ObjectState GrippedObject::solve_along(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                       const Positions& x, int max_iterations,
                                       const ObjectState* chord, const StopRequest& stop,
                                       std::shared_ptr<WorkspacePool> workspaces) const {
  if (!workspaces && chord) workspaces = chord->workspaces_;
  ObjectState s = unsolved_state(x, std::move(workspaces));
  s.joints_ = from;  // where x is clear of the obstacles: solve() sweeps them on from there
  solve(s, to, max_iterations, chord, stop);
  return s;
}

ObjectState GrippedObject::solve_from(const Eigen::VectorXd& joints, const Positions& x,
                                      int max_iterations, const ObjectState* chord,
                                      const StopRequest& stop,
                                      std::shared_ptr<WorkspacePool> workspaces) const {
  if (!workspaces && chord) workspaces = chord->workspaces_;
  ObjectState s = unsolved_state(x, std::move(workspaces));  // solve() sets θ, kinematics
  solve(s, joints, max_iterations, chord, stop);
  return s;
}

void GrippedObject::carry_gripped_nodes(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                        const Positions& at_from, Positions& x) const {
  const KinematicsState a = forward_kinematics(robot(), from), b = forward_kinematics(robot(), to);
  for (const auto& g : scene_.grips) {
    const int link = scene_.robot->end_effectors[g.end_effector].link;
    const Eigen::Isometry3d motion = b.T_world_link[link] * a.T_world_link[link].inverse();
    for (int i : g.nodes) x.segment<3>(3 * i) = motion * at_from.segment<3>(3 * i);
  }
  // The prediction moves every node straight from at_from: cut short where a surface would
  // pass through an obstacle on the way (the CCD bound, obstacles on links where they were at
  // `from`), so the solve starts clear of them. An obstacle on a link that has moved onto the
  // warm start is not chased: the solve at `to` refuses that start (Inverted).
  if (const ObstacleContact* contact = statics_->contact()) {
    const std::optional<ObstacleContact> posed = moving_contact(a);
    const Eigen::VectorXd dx = x - at_from;
    if (const double alpha = (posed ? *posed : *contact).max_step(at_from, dx); alpha < 1)
      x = at_from + alpha * dx;
  }
}

bool GrippedObject::factored(ObjectState& state, double stale_step) const {
  const StaticsSolver& solver = statics_->solver();
  StaticsWorkspace& ws = *state.workspace_;
  if (solver.factor_distance(ws, state.positions_) <= stale_step) return true;
  const GripEnergy grip(*grips_, state.kinematics_);
  const ContactTerms contact = contact_terms(state);  // `terms` points into it
  EnergyTerms terms = statics_->terms(&grip, contact);
  const std::optional<FixedPointFriction> friction = friction_at(state);
  if (friction) terms.push_back(&friction->term);
  return solver.factor(terms, ws, state.positions_);
}

ContactTerms GrippedObject::contact_terms(const ObjectState& state) const {
  const std::optional<ObstacleContact> contact = moving_contact(state.kinematics_);
  return statics_->contact_terms(state.contact_scale(), contact ? &*contact : nullptr);
}

std::optional<FixedPointFriction> GrippedObject::friction_at(const ObjectState& state) const {
  if (state.friction_anchor_.size() == 0) return std::nullopt;
  return fixed_point_friction(*contact_at(state), statics_->friction(), state.friction_anchor_,
                              state.positions_);
}

Eigen::MatrixXd GrippedObject::solve_equilibrium(const ObjectState& state,
                                                 const Eigen::MatrixXd& rhs,
                                                 bool transposed) const {
  const std::optional<FixedPointFriction> friction = friction_at(state);
  if (!friction) return statics_->solver().solve_with_factor(*state.workspace_, rhs);
  const SparseMatrix lag = transposed ? SparseMatrix(friction->lag.transpose()) : friction->lag;
  return solve_with_lag(statics_->solver(), *state.workspace_, lag, rhs);
}

std::optional<ObstacleContact> GrippedObject::moving_contact(const KinematicsState& state) const {
  const ObstacleContact* contact = statics_->contact();
  if (!contact || !contact->moves()) return std::nullopt;
  return contact->posed(state.T_world_link);
}

std::optional<ObstacleContact> GrippedObject::contact_at(const ObjectState& state) const {
  return contact_terms(state).obstacles;
}

Eigen::MatrixXd GrippedObject::force_jacobian(const ObjectState& state) const {
  Eigen::MatrixXd dF = grips_->force_jacobian(state.kinematics_, node_count());
  if (const std::optional<ObstacleContact> contact = contact_at(state); contact && contact->moves())
    dF += contact_force_jacobian(*contact, robot(), state.kinematics_, state.positions_);
  return dF;
}

bool GrippedObject::stable(ObjectState& state, double stale_step) const {
  return factored(state, stale_step);
}

bool GrippedObject::confirm_stable(ObjectState& state, double stale_step) const {
  if (!state.statics_.converged()) return false;
  if (stable(state, stale_step)) return true;
  state.statics_.status = StaticsStatus::Unstable;
  state.statics_.reason = "unstable equilibrium: the Hessian there is not positive definite";
  return false;
}

Eigen::MatrixXd GrippedObject::sensitivity(ObjectState& state, double stale_step) const {
  return force_response(state, force_jacobian(state), stale_step);
}

Eigen::MatrixXd GrippedObject::force_response(ObjectState& state,
                                              const Eigen::MatrixXd& force_change,
                                              double stale_step) const {
  factored(state, stale_step);
  return solve_equilibrium(state, force_change, false);
}

Eigen::VectorXd GrippedObject::adjoint(ObjectState& state, const Eigen::VectorXd& v,
                                       double stale_step) const {
  factored(state, stale_step);
  const Eigen::VectorXd lambda = solve_equilibrium(state, v, true);
  Eigen::VectorXd out = grips_->force_jacobian_transpose_times(state.kinematics_, lambda);
  if (const std::optional<ObstacleContact> contact = contact_at(state); contact && contact->moves())
    add_contact_force_jacobian_transpose_times(*contact, robot(), state.kinematics_,
                                               state.positions_, lambda, out);
  return out;
}

}  // namespace shapectl
