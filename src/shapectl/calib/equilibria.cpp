#include <shapectl/calib/equilibria.hpp>

#include <memory>
#include <stdexcept>
#include <string>

#include <shapectl/calib/joint_path.hpp>

namespace shapectl {

namespace {

bool same_loads(const std::vector<NodeLoad>& a, const std::vector<NodeLoad>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k].nodes != b[k].nodes || a[k].force != b[k].force) return false;
  return true;
}

// The loads on the object in `frame`: its own, or the scene's.
const std::vector<NodeLoad>& frame_loads(const Scene& scene, const ObservationFrame& frame) {
  return frame.loads ? *frame.loads : scene.loads;
}

// Where the object is in `frame` at `parameters`: the frame's known pose, or the fitted one.
Eigen::Isometry3d frame_pose(const PhysicalParameters& parameters, const ObservationFrame& frame) {
  return frame.object_pose ? *frame.object_pose : parameters.object_pose;
}

bool same_conditions(const Scene& scene, const ObservationFrame& a, const ObservationFrame& b) {
  const bool same_pose = a.object_pose.has_value() == b.object_pose.has_value() &&
                         (!a.object_pose || a.object_pose->matrix() == b.object_pose->matrix());
  return same_pose && same_loads(frame_loads(scene, a), frame_loads(scene, b));
}

// Each frame's conditions (loads, pose): the index of the first frame with the same ones.
std::vector<std::size_t> frame_conditions(const Scene& scene, const Observations& observations) {
  std::vector<std::size_t> out(observations.frames.size());
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k] = k;
    for (std::size_t j = 0; j < k && out[k] == k; ++j)
      if (out[j] == j && same_conditions(scene, observations.frames[j], observations.frames[k]))
        out[k] = j;
  }
  return out;
}

// The scene at `parameters` under the conditions of `frame`.
Scene frame_scene(const Scene& scene, const PhysicalParameters& parameters,
                  const ObservationFrame& frame) {
  Scene out = parameters.applied_to(scene);
  out.loads = frame_loads(scene, frame);
  out.T_world_object = frame_pose(parameters, frame);
  return out;
}

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
  // One model per set of conditions, built when a frame first needs it.
  const std::vector<std::size_t> cases = frame_conditions(scene, observations);
  std::vector<std::unique_ptr<GrippedObject>> objects(observations.frames.size());
  Equilibria out{.parameters = parameters, .frames = {}};
  for (std::size_t k = 0; k < observations.frames.size(); ++k) {
    std::unique_ptr<GrippedObject>& model = objects[cases[k]];
    if (!model)
      model =
          std::make_unique<GrippedObject>(frame_scene(scene, parameters, observations.frames[k]));
    const GrippedObject& object = *model;
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

// Fixed nodes alone hold the object: frames differ only by their conditions (loads, a known
// pose) and the noise, so the frames of one set of conditions see one equilibrium. A warm
// start is first moved rigidly into the new pose, so that its fixed nodes are where that pose
// puts them. `placed`: the scene under frame `frame`'s conditions.
std::shared_ptr<const Equilibrium> fixed_equilibrium(const Scene& placed,
                                                     const ParameterSpace& space,
                                                     const PhysicalParameters& parameters,
                                                     const Observations& observations,
                                                     const Equilibria* warm, std::size_t frame,
                                                     const EquilibriumOptions& options) {
  const ObjectStatics statics(placed);
  const auto pooled = options.workspaces
                          ? options.workspaces->acquire(statics.solver())
                          : std::make_shared<StaticsWorkspace>(statics.make_workspace());
  StaticsWorkspace& ws = *pooled;
  Positions x;
  StaticsResult r;
  if (warm) {
    x = carried(warm->frames[frame]->positions,
                frame_pose(warm->parameters, observations.frames[frame]), placed.T_world_object);
    r = statics.solve(ws, x, nullptr, 0, nullptr, options.stop);
  }
  if (!r.converged()) {
    x = placed.world_rest_positions();
    r = statics.solve(ws, x, nullptr, 0, nullptr, options.stop);
  }
  if (!r.converged())
    throw std::runtime_error("frame " + std::to_string(frame) +
                             ": no equilibrium of the fixed scene: " + r.reason);
  auto e = std::make_shared<Equilibrium>();
  if (options.with_sensitivity) {
    const StaticsSolver& solver = statics.solver();
    // At the stiffness the solve ended at (the adaptive contact barrier).
    if (!solver.factor(statics.terms(nullptr, statics.contact_terms(r.contact_scale)), ws, x))
      throw std::runtime_error("frame " + std::to_string(frame) +
                               ": the fixed scene's equilibrium is unstable (its Hessian is not "
                               "positive definite)");
    e->dx_dz =
        solver.solve_with_factor(ws, space.force_derivatives(statics, placed, x, parameters)) +
        space.pose_motion(x, parameters);
  }
  e->positions = std::move(x);
  return e;
}

Equilibria fixed_equilibria(const Scene& scene, const ParameterSpace& space,
                            const PhysicalParameters& parameters, const Observations& observations,
                            const Equilibria* warm, const EquilibriumOptions& options) {
  const std::vector<std::size_t> cases = frame_conditions(scene, observations);
  Equilibria out{.parameters = parameters, .frames = {}};
  for (std::size_t k = 0; k < observations.frames.size(); ++k)
    out.frames.push_back(
        cases[k] < k ? out.frames[cases[k]]
                     : fixed_equilibrium(frame_scene(scene, parameters, observations.frames[k]),
                                         space, parameters, observations, warm, k, options));
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
