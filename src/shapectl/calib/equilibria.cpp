#include <shapectl/calib/equilibria.hpp>

#include <stdexcept>
#include <string>

#include <shapectl/calib/joint_path.hpp>

namespace shapectl {

namespace {

// A robot holds the object: frame k's equilibrium at its joints, Newton from the warm start,
// or (without one, or when that fails) walked from the reference joints.
ObjectState robot_equilibrium(const GrippedObject& object, const Eigen::VectorXd& joints,
                              const Positions* warm, std::size_t frame,
                              const EquilibriumOptions& options) {
  if (options.stop && options.stop())
    throw std::runtime_error("frame " + std::to_string(frame) + ": stopped");
  if (warm) {
    ObjectState state =
        object.solve_from(joints, *warm, 0, nullptr, options.stop, options.workspaces);
    if (state.statics().converged() && object.stable(state)) return state;
  }
  try {
    return equilibrium_along_path(object, joints, options.path_step, options.stop,
                                  options.workspaces);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("frame " + std::to_string(frame) + ": " + e.what());
  }
}

Equilibria robot_equilibria(const Scene& scene, const ParameterSpace& space,
                            const PhysicalParameters& parameters, const Observations& observations,
                            const Equilibria* warm, const EquilibriumOptions& options) {
  const GrippedObject object(parameters.applied_to(scene));
  Equilibria out{.parameters = parameters, .frames = {}};
  for (std::size_t k = 0; k < observations.frames.size(); ++k) {
    ObjectState state = robot_equilibrium(object, observations.frames[k].joints,
                                          warm ? &warm->frames[k]->positions : nullptr, k, options);
    auto e = std::make_shared<Equilibrium>();
    if (options.with_sensitivity)
      e->dx_dz = object.force_response(state, space.force_derivatives(object, state, parameters));
    e->positions = state.positions();
    out.frames.push_back(std::move(e));
  }
  return out;
}

// x moved by the rigid motion that takes the object from pose `from` to pose `to`.
Positions carried(const Positions& x, const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) {
  const Eigen::Isometry3d motion = to * from.inverse();
  Positions out(x.size());
  for (Eigen::Index i = 0; i < x.size() / 3; ++i)
    out.segment<3>(3 * i) = motion * Vec3(x.segment<3>(3 * i));
  return out;
}

// Fixed nodes alone hold the object: nothing differs from frame to frame but the noise, so
// every frame sees the one equilibrium. A warm start is first moved rigidly into the new pose,
// so that its fixed nodes are where that pose puts them.
Equilibria fixed_equilibria(const Scene& scene, const ParameterSpace& space,
                            const PhysicalParameters& parameters, const Observations& observations,
                            const Equilibria* warm, const EquilibriumOptions& options) {
  const Scene placed = parameters.applied_to(scene);
  const ObjectStatics statics(placed);
  const auto pooled = options.workspaces
                          ? options.workspaces->acquire(statics.solver())
                          : std::make_shared<StaticsWorkspace>(statics.make_workspace());
  StaticsWorkspace& ws = *pooled;
  Positions x;
  StaticsResult r;
  if (warm) {
    x = carried(warm->frames.front()->positions, warm->parameters.object_pose,
                parameters.object_pose);
    r = statics.solve(ws, x, nullptr, 0, nullptr, options.stop);
  }
  if (!r.converged()) {
    x = placed.world_rest_positions();
    r = statics.solve(ws, x, nullptr, 0, nullptr, options.stop);
  }
  if (!r.converged()) throw std::runtime_error("no equilibrium of the fixed scene: " + r.reason);
  auto e = std::make_shared<Equilibrium>();
  if (options.with_sensitivity) {
    const StaticsSolver& solver = statics.solver();
    if (!solver.factor(statics.terms(), ws, x))
      throw std::runtime_error(
          "the fixed scene's equilibrium is unstable (its Hessian is not positive definite)");
    e->dx_dz =
        solver.solve_with_factor(ws, space.force_derivatives(statics, placed, x, parameters)) +
        space.pose_motion(x, parameters);
  }
  e->positions = std::move(x);
  Equilibria out{.parameters = parameters, .frames = {}};
  out.frames.assign(observations.frames.size(), e);
  return out;
}

}  // namespace

Equilibria frame_equilibria(const Scene& scene, const ParameterSpace& space,
                            const PhysicalParameters& parameters, const Observations& observations,
                            const Equilibria* warm, const EquilibriumOptions& options) {
  if (scene.robot) return robot_equilibria(scene, space, parameters, observations, warm, options);
  return fixed_equilibria(scene, space, parameters, observations, warm, options);
}

}  // namespace shapectl
