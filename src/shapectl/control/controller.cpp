#include <shapectl/control/controller.hpp>

#include <atomic>
#include <chrono>
#include <cmath>

#include <shapectl/control/centerline.hpp>
#include <shapectl/enum_names.hpp>
#include <shapectl/io/input_error.hpp>

namespace shapectl {

namespace {
using Clock = std::chrono::steady_clock;

// Requests from other threads, applied by the worker before its next iteration.
struct Inbox {
  std::optional<ShapeTargets> targets;
  std::optional<std::vector<Vec3>> centerline;
  bool clear = false;
  std::optional<bool> paused;
  std::optional<Eigen::VectorXd> jog;
  bool reset = false;
  std::optional<ShapeObservation> observation;  // the newest only: an older one is stale
  std::optional<bool> feedback;
  std::optional<Scene> model;
  bool empty() const {
    return !targets && !centerline && !clear && !paused && !jog && !reset && !observation &&
           !feedback && !model;
  }
};

constexpr auto kControllerStatuses =
    enum_names<ControllerStatus>(std::pair{ControllerStatus::Idle, "idle"},
                                 std::pair{ControllerStatus::Optimizing, "optimizing"},
                                 std::pair{ControllerStatus::Converged, "converged"},
                                 std::pair{ControllerStatus::Stuck, "stuck"},
                                 std::pair{ControllerStatus::OutOfTime, "out of time"},
                                 std::pair{ControllerStatus::Paused, "paused"});

// The status once iterations stopped with `outcome`.
ControllerStatus status_after(StepOutcome outcome) {
  switch (outcome) {
    case StepOutcome::Converged: return ControllerStatus::Converged;
    case StepOutcome::Stuck: return ControllerStatus::Stuck;
    case StepOutcome::OutOfTime: return ControllerStatus::OutOfTime;
    case StepOutcome::Improved: break;
  }
  return ControllerStatus::Optimizing;
}
}  // namespace

const char* to_string(ControllerStatus status) { return kControllerStatuses.name(status); }

bool parse(std::string_view name, ControllerStatus* status) {
  return kControllerStatuses.parse(name, status);
}

struct Controller::State {
  Scene scene;
  ControllerOptions options;
  // The object as loaded, for callers on other threads (mesh, robot, sizes: never replaced),
  // and the model the worker solves with (set_model replaces it).
  std::shared_ptr<const GrippedObject> loaded;
  std::shared_ptr<const GrippedObject> object;
  std::unique_ptr<ReducedObjective> objective;
  std::unique_ptr<Optimizer> optimizer;
  std::optional<BarAxis> bar_axis;
  Clock::time_point started = Clock::now();

  // Owned by whoever runs iterations (the worker thread, or the step_once caller).
  Evaluation current;
  std::vector<Vec3> centerline;
  bool paused = false;
  bool idle = true;  // nothing to do until a request arrives
  StepOutcome last_outcome = StepOutcome::Improved;
  std::uint64_t iterations = 0;
  double rate = 0;
  Clock::time_point last_iteration = Clock::now();
  std::string last_error;
  // The closed loop: the user's targets, and the feedback that corrects what the optimizer
  // aims at.
  ShapeTargets user_targets;
  std::unique_ptr<ModelErrorFeedback> feedback;
  bool feedback_on = false;
  std::vector<std::pair<int, Vec3>> observed_markers;
  double observed_error = 0;
  std::uint64_t observations = 0;
  std::optional<ShapeObservation> last_observation;  // the newest one taken
  std::uint64_t observations_ignored = 0;
  std::string observation_problem;
  std::uint64_t model_updates = 0;

  mutable std::mutex inbox_mutex;
  std::condition_variable inbox_changed;
  Inbox inbox;

  mutable std::mutex snapshot_mutex;
  mutable std::condition_variable snapshot_changed;
  std::shared_ptr<const ControllerSnapshot> snapshot;
  std::uint64_t sequence = 0;

  std::mutex step_mutex;  // one runner at a time
  std::thread worker;
  std::atomic<bool> running{false};

  void apply(Inbox in);
  // The objective is immutable: new targets make a new one. It aims at the user's targets,
  // corrected by the model-error feedback when that is on.
  void retarget(ShapeTargets targets) {
    user_targets = std::move(targets);
    aim();
  }
  void aim() {
    objective = std::make_unique<ReducedObjective>(
        objective->with_targets(feedback_on ? feedback->corrected(user_targets) : user_targets));
  }
  // Swaps in a new model at the current θ; false (last_error set) when it has no stable
  // equilibrium there.
  bool replace_model(const Scene& model);
  // Takes an observation into the feedback; true when the optimizer was re-aimed.
  bool take(const ShapeObservation& observation);
  // Whether the corrected targets moved past the threshold from those aimed at now.
  bool moved_enough(const ShapeTargets& corrected) const;
  void iterate();
  void publish();
  void run();
  void validate(const ShapeTargets& t) const;
};

void Controller::State::validate(const ShapeTargets& t) const {
  check_targets(t, loaded->node_count(), "targets");
}

void Controller::State::apply(Inbox in) {
  if (in.reset) {
    current = objective->evaluate(object->reference_joints(), object->reference_positions());
    retarget({});
    centerline.clear();
    objective->rescore(current);
    optimizer->reset();
    last_error.clear();
  }
  if (in.clear) {
    retarget({});
    centerline.clear();
  }
  if (in.targets) {
    retarget(*in.targets);
    centerline.clear();
  }
  if (in.centerline) {
    // Checked when posted; a target the mapping still puts out of bounds (a sketch at the edge
    // of the world, the bar's offset beyond it) is refused here, not thrown out of the thread.
    try {
      retarget(centerline_targets(object->mesh(), *bar_axis, *in.centerline, current.positions));
      centerline = *in.centerline;
    } catch (const InputError& e) {
      retarget({});
      centerline.clear();
      last_error = std::string("centre-line refused: ") + e.what();
    }
  }
  if (in.paused) paused = *in.paused;
  if (in.jog && paused) {
    const Eigen::VectorXd theta =
        in.jog->cwiseMax(object->robot().lower_limits()).cwiseMin(object->robot().upper_limits());
    Evaluation e = objective->evaluate(theta, current.positions, 0, &current);
    if (objective->confirm_stable(e)) {
      current = std::move(e);
      last_error.clear();
    } else {
      last_error = "jog refused: statics " + e.statics.reason;
    }
  }
  if (in.reset) feedback->reset(), observed_markers.clear(), last_observation.reset();
  const bool remodelled = in.model && replace_model(*in.model);
  if (in.feedback) {
    feedback_on = *in.feedback;
    aim();
  }
  const bool reaimed = in.observation && take(*in.observation);
  if (in.clear || in.targets || in.centerline || in.reset || in.feedback || reaimed || remodelled) {
    objective->rescore(current);
    optimizer->reset();
  }
  idle = false;
}

bool Controller::State::replace_model(const Scene& model) {
  auto next_object = std::make_shared<const GrippedObject>(model);
  auto next_objective =
      std::make_unique<ReducedObjective>(*next_object, objective->targets(), objective->options());
  // No chord steps from the old model's factorization: it belongs to another Hessian.
  Evaluation next = next_objective->evaluate(current.joints, current.positions);
  if (!next.statics.converged() || !next_objective->confirm_stable(next)) {
    last_error = "model update refused: no stable equilibrium at the current joints (" +
                 next.statics.reason + ")";
    return false;
  }
  if (last_observation) {
    const Eigen::VectorXd& joints = last_observation->joints;
    const Evaluation before = objective->evaluate(joints, current.positions, 0, &current);
    const Evaluation after = next_objective->evaluate(joints, next.positions, 0, &next);
    if (before.statics.converged() && after.statics.converged())
      feedback->model_changed(before.positions, after.positions);
  }
  current = std::move(next);
  objective = std::move(next_objective);  // before the object it refers to
  object = std::move(next_object);
  ++model_updates;
  last_error.clear();
  if (feedback_on) aim();
  return true;
}

bool Controller::State::take(const ShapeObservation& observation) {
  // The model's prediction at the joints the observation was taken at (the robot may lag θ*),
  // from the current shape with the gripped nodes carried along.
  Positions x = current.positions;
  object->carry_gripped_nodes(current.joints, observation.joints, current.positions, x);
  Evaluation predicted = objective->evaluate(observation.joints, x, 0, &current);
  if (!predicted.statics.converged()) {
    // Not the optimizer's failure: the loop goes on with the next observation.
    ++observations_ignored;
    observation_problem =
        "observation ignored: no equilibrium at its joints (" + predicted.statics.reason + ")";
    return false;
  }
  observation_problem.clear();
  feedback->observe(observation.markers, predicted.positions);
  observed_markers = observation.markers;
  last_observation = observation;
  ++observations;
  double sum = 0;
  int count = 0;
  for (const auto& [node, y] : observation.markers)
    for (int k = 0; k < user_targets.size(); ++k)
      if (user_targets.nodes[k] == node) sum += (y - user_targets.positions[k]).norm(), ++count;
  observed_error = count ? sum / count : NAN;
  if (!feedback_on || !moved_enough(feedback->corrected(user_targets))) return false;
  aim();
  return true;
}

bool Controller::State::moved_enough(const ShapeTargets& corrected) const {
  const ShapeTargets& aimed = objective->targets();
  if (aimed.size() != corrected.size()) return true;
  for (int k = 0; k < aimed.size(); ++k)
    if ((aimed.positions[k] - corrected.positions[k]).norm() > options.feedback.retarget_threshold)
      return true;
  return false;
}

void Controller::State::iterate() {
  Inbox in;
  {
    std::lock_guard lock(inbox_mutex);
    std::swap(in, inbox);
  }
  const bool had_requests = !in.empty();
  if (had_requests) apply(std::move(in));
  const bool work = !paused && !objective->targets().empty() && !idle;
  if (work) {
    try {
      last_outcome = optimizer->step(*objective, current);
    } catch (const std::exception& e) {  // e.g. the start state is no stable equilibrium
      last_outcome = StepOutcome::Stuck;
      last_error = std::string("optimizer stopped: ") + e.what();
    }
    ++iterations;
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - last_iteration).count();
    last_iteration = now;
    if (dt > 0) rate = rate == 0 ? 1 / dt : 0.8 * rate + 0.2 / dt;
    if (last_outcome != StepOutcome::Improved) idle = true;  // wait for the next request
  } else if (objective->targets().empty() || paused) {
    idle = true;
  }
  if (work || had_requests) publish();
}

void Controller::State::publish() {
  auto s = std::make_shared<ControllerSnapshot>();
  const RobotModel& robot = object->robot();
  s->time = std::chrono::duration<double>(Clock::now() - started).count();
  s->joint_names = robot.active_joint_names();
  s->joints = current.joints;
  s->lower_limits = robot.lower_limits();
  s->upper_limits = robot.upper_limits();
  s->T_world_link = forward_kinematics(robot, current.joints).T_world_link;
  s->positions = current.positions;
  s->targets = user_targets;
  s->centerline = centerline;
  s->error = current.error;
  s->objective = current.objective;
  s->min_clearance = current.min_clearance;
  s->within_limits = current.within_limits;
  s->safe = current.safe();
  s->iterations = iterations;
  s->iterations_per_second = rate;
  s->paused = paused;
  s->last_error = last_error;
  s->feedback = feedback_on;
  s->observed_markers = observed_markers;
  s->model_error = feedback->last_model_error();
  s->observed_error = observed_error;
  s->observations = observations;
  s->material = object->scene().material;
  for (const Grip& g : object->scene().grips) s->grip_offsets.push_back(g.offset);
  s->model_updates = model_updates;
  s->observations_ignored = observations_ignored;
  s->observation_problem = observation_problem;
  s->status = paused                         ? ControllerStatus::Paused
              : objective->targets().empty() ? ControllerStatus::Idle
              : !idle                        ? ControllerStatus::Optimizing
                                             : status_after(last_outcome);
  {
    std::lock_guard lock(snapshot_mutex);
    s->sequence = ++sequence;
    snapshot = std::move(s);
  }
  snapshot_changed.notify_all();
}

void Controller::State::run() {
  while (running) {
    {
      std::lock_guard step(step_mutex);
      iterate();
    }
    if (idle) {
      std::unique_lock lock(inbox_mutex);
      inbox_changed.wait_for(lock, std::chrono::milliseconds(50),
                             [&] { return !inbox.empty() || !running; });
    }
  }
}

Controller::Controller(const Scene& scene, ControllerOptions options)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.scene = scene;
  s.options = options;
  s.loaded = std::make_shared<const GrippedObject>(s.scene);
  s.object = s.loaded;
  s.objective = std::make_unique<ReducedObjective>(*s.object);
  s.optimizer = make_optimizer(options.optimizer, options.gradient);
  s.bar_axis = find_bar_axis(s.object->mesh());
  s.feedback = std::make_unique<ModelErrorFeedback>(s.scene.object_mesh, options.feedback);
  s.current = s.objective->evaluate(s.object->reference_joints(), s.object->reference_positions());
  s.publish();
}

Controller::~Controller() { stop(); }

const Scene& Controller::scene() const { return state_->scene; }
const TetMesh& Controller::mesh() const { return state_->loaded->mesh(); }
const RobotModel& Controller::robot() const { return state_->loaded->robot(); }

void Controller::start() {
  if (state_->running.exchange(true)) return;
  state_->worker = std::thread([this] { state_->run(); });
}

void Controller::stop() {
  if (!state_->running.exchange(false)) return;
  state_->inbox_changed.notify_all();
  if (state_->worker.joinable()) state_->worker.join();
}

void Controller::step_once() {
  std::lock_guard step(state_->step_mutex);
  state_->iterate();
}

namespace {
template <class Change>
void post(Controller::State& s, Change change) {
  {
    std::lock_guard lock(s.inbox_mutex);
    change(s.inbox);
  }
  s.inbox_changed.notify_all();
}
}  // namespace

void Controller::set_targets(ShapeTargets targets) {
  state_->validate(targets);
  post(*state_, [&](Inbox& in) {
    in.targets = std::move(targets);
    in.centerline.reset();
    in.clear = false;
  });
}

void Controller::set_centerline(std::vector<Vec3> polyline) {
  if (!state_->bar_axis)
    throw InputError("centerline", "", "the object is not bar-like (length < 3 × thickness)");
  check_centerline(*state_->bar_axis, polyline, "centerline");
  post(*state_, [&](Inbox& in) {
    in.centerline = std::move(polyline);
    in.targets.reset();
    in.clear = false;
  });
}

void Controller::clear_targets() {
  post(*state_, [](Inbox& in) {
    in.clear = true;
    in.targets.reset();
    in.centerline.reset();
  });
}

void Controller::set_paused(bool paused) {
  post(*state_, [&](Inbox& in) { in.paused = paused; });
}

void Controller::set_joints(const Eigen::VectorXd& joints) {
  if (joints.size() != state_->loaded->joint_count())
    throw InputError("joints", "",
                     "one value per active joint (" +
                         std::to_string(state_->loaded->joint_count()) + ")");
  if (!joints.allFinite()) throw InputError("joints", "", "finite values");
  {
    std::lock_guard lock(state_->inbox_mutex);
    const bool pausing = state_->inbox.paused.value_or(snapshot()->paused);
    if (!pausing) throw InputError("joints", "", "the optimizer to be paused before jogging");
  }
  post(*state_, [&](Inbox& in) { in.jog = joints; });
}

void Controller::observe(ShapeObservation observation) {
  const int joints = state_->loaded->joint_count(), nodes = state_->loaded->node_count();
  if (observation.joints.size() != joints)
    throw InputError("observation", "joints",
                     "one value per active joint (" + std::to_string(joints) + ")");
  if (!observation.joints.allFinite()) throw InputError("observation", "joints", "finite values");
  if (observation.markers.empty())
    throw InputError("observation", "markers", "at least one marker");
  for (std::size_t k = 0; k < observation.markers.size(); ++k) {
    const auto& [node, position] = observation.markers[k];
    const std::string where = "markers[" + std::to_string(k) + "]";
    if (node < 0 || node >= nodes)
      throw InputError("observation", where + ".node",
                       "a node from 0 to " + std::to_string(nodes - 1), std::to_string(node));
    check_target_point(position, "observation", where + ".position");
  }
  post(*state_, [&](Inbox& in) { in.observation = std::move(observation); });
}

void Controller::set_feedback(bool on) {
  post(*state_, [&](Inbox& in) { in.feedback = on; });
}

void Controller::set_model(const Scene& model) {
  const Scene& loaded = state_->scene;
  const auto other = [](const std::string& what) {
    throw InputError("model", what,
                     "the controller's object (only material and grip offsets may differ)");
  };
  if (!model.object_mesh || model.object_mesh->node_count() != loaded.object_mesh->node_count())
    other("object.mesh");
  if (!model.robot || model.robot->model->active_count() != loaded.robot->model->active_count())
    other("robot");
  if (model.grips.size() != loaded.grips.size()) other("grips");
  post(*state_, [&](Inbox& in) { in.model = model; });
}

void Controller::reset() {
  post(*state_, [](Inbox& in) {
    in = Inbox{};
    in.reset = true;
  });
}

std::shared_ptr<const ControllerSnapshot> Controller::snapshot() const {
  std::lock_guard lock(state_->snapshot_mutex);
  return state_->snapshot;
}

std::shared_ptr<const ControllerSnapshot> Controller::wait_for_snapshot(
    std::uint64_t after, double timeout_seconds) const {
  std::unique_lock lock(state_->snapshot_mutex);
  state_->snapshot_changed.wait_for(lock, std::chrono::duration<double>(timeout_seconds),
                                    [&] { return state_->snapshot->sequence > after; });
  return state_->snapshot;
}

}  // namespace shapectl
