#include <shapectl/control/controller.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <shapectl/control/centerline.hpp>
#include <shapectl/enum_names.hpp>
#include <shapectl/io/input_error.hpp>

namespace shapectl {

namespace {
using Clock = std::chrono::steady_clock;

// `scene` with the linear solver `options` set, if it sets one (ControllerOptions).
Scene with_linear_solver(Scene scene, const ControllerOptions& options) {
  if (options.linear_solver) scene.statics.backend = *options.linear_solver;
  return scene;
}

// Requests from other threads, applied by the worker before its next iteration.
struct Inbox {
  std::optional<ShapeTargets> targets;
  std::optional<std::vector<Vec3>> centerline;
  bool clear = false;
  std::optional<bool> paused;
  std::optional<Eigen::VectorXd> jog;
  std::optional<std::vector<int>> jog_refused_links;  // a jog refused for self-collision
  bool reset = false;
  std::optional<ShapeObservation> observation;  // the newest only: an older one is stale
  std::optional<bool> feedback;
  std::optional<Scene> model;
  bool empty() const {
    return !targets && !centerline && !clear && !paused && !jog && !jog_refused_links && !reset &&
           !observation && !feedback && !model;
  }
};

constexpr auto kControllerStatuses =
    enum_names<ControllerStatus>(std::pair{ControllerStatus::Idle, "idle"},
                                 std::pair{ControllerStatus::Optimizing, "optimizing"},
                                 std::pair{ControllerStatus::Reached, "reached"},
                                 std::pair{ControllerStatus::BestEffort, "best effort"},
                                 std::pair{ControllerStatus::Paused, "paused"},
                                 std::pair{ControllerStatus::Failed, "failed"});

std::string millimetres(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f mm", metres * 1e3);
  return text;
}

// Which links overlap another's spheres, and the closest pair, at `joints`.
void find_collisions(const CollisionModel& collisions, const KinematicsState& kinematics,
                     ControllerSnapshot& s) {
  const auto pairs = collisions.closest_pairs(kinematics, collisions.spheres().size());
  if (pairs.empty()) return;
  s.closest_pair = pairs.front();
  for (const SphereClearance& p : pairs) {
    if (p.clearance >= 0) break;
    for (int sphere : {p.first, p.second})
      s.colliding_links.push_back(collisions.spheres()[sphere].link);
  }
  std::sort(s.colliding_links.begin(), s.colliding_links.end());
  s.colliding_links.erase(std::unique(s.colliding_links.begin(), s.colliding_links.end()),
                          s.colliding_links.end());
}
}  // namespace

const char* to_string(ControllerStatus status) { return kControllerStatuses.name(status); }

bool parse(std::string_view name, ControllerStatus* status) {
  return kControllerStatuses.parse(name, status);
}

ControllerStatus stopped_status(const Evaluation& best, bool failed, double tolerance) {
  if (failed || !best.statics().converged()) return ControllerStatus::Failed;
  return best.error.max <= tolerance ? ControllerStatus::Reached : ControllerStatus::BestEffort;
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
  // How the last run of iterations ended: failed (no equilibrium, an error), or else the
  // reasons the targets stay beyond the tolerance (empty detail when within it).
  bool failed = false;
  ShortfallReport shortfall;
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
  // The centre of the feedback's trust region (ControllerOptions::trust_region): where the
  // optimizer stopped after the user's last request; empty while it walks for that request.
  std::optional<Eigen::VectorXd> loop_start;

  mutable std::mutex inbox_mutex;
  std::condition_variable inbox_changed;
  Inbox inbox;
  // The joints the last accepted jog asked for (guarded by inbox_mutex): the next jog's step is
  // measured from there, as the snapshot may not show it yet. Cleared by pause, resume, reset.
  std::optional<Eigen::VectorXd> jogged_to;
  // The last set_paused (under inbox_mutex): a jog right after a pause is judged by it, not by
  // a snapshot that may not show the pause yet (the thread applies, then publishes).
  bool pause_requested = false;

  mutable std::mutex snapshot_mutex;
  mutable std::condition_variable snapshot_changed;
  std::shared_ptr<const ControllerSnapshot> snapshot;
  std::uint64_t sequence = 0;

  std::mutex step_mutex;  // one runner at a time
  std::thread worker;
  std::atomic<bool> running{false};
  // Set while stop() waits: the optimizer's step in progress ends at its next statics check
  // (one step of a 12k-tet object can take seconds; `serve` and `run` stop within 1 s).
  std::atomic<bool> stopping{false};

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
  // The user's request: the optimizer walks free until it stops, and the loop starts there.
  void free_walk() {
    loop_start.reset();
    optimizer->box.reset();
  }
  // The optimizer stopped: if it was the walk for the user's request, the loop starts here.
  void start_loop() {
    if (loop_start) return;
    loop_start = current.joints();
    optimizer->box = Optimizer::JointBox{current.joints().array() - options.trust_region,
                                         current.joints().array() + options.trust_region};
  }
  // Swaps in a new model at the current θ; false (last_error set) when it has no stable
  // equilibrium there.
  bool replace_model(const Scene& model);
  // Takes an observation into the feedback; true when the optimizer was re-aimed.
  bool take(const ShapeObservation& observation);
  // Re-aims at the corrected targets if they moved enough (moved_enough) and the loop has
  // started; true if it did.
  bool reaim(double sigma);
  // Whether the corrected targets moved (RMS over the targets) past the threshold, or past
  // what the estimate's noise explains for observations of noise `sigma`, from those aimed at.
  bool moved_enough(const ShapeTargets& corrected, double sigma) const;
  // Judges the state the optimizer stopped at (failed, shortfall).
  void judge_stop();
  ControllerStatus status() const;
  void iterate();
  void publish();
  void run();
  void validate(const ShapeTargets& t) const;
  // Throws InputError for a jog from `from` to `to` that steps too far. For one into
  // self-collision, returns why (else empty) and the links that would overlap.
  std::string jog_collision(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                            std::vector<int>& links) const;
  std::vector<int> jog_refused_links;  // of the last jog refused for self-collision
};

void Controller::State::validate(const ShapeTargets& t) const {
  check_targets(t, loaded->node_count(), "targets");
}

std::string Controller::State::jog_collision(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                             std::vector<int>& links) const {
  const RobotModel& robot = loaded->robot();
  Eigen::Index j = 0;
  const double step = (to - from).cwiseAbs().maxCoeff(&j);
  if (step > options.max_jog_step + 1e-12) {
    char expected[64];
    std::snprintf(expected, sizeof expected, "a step of at most %.3g rad from the current joints",
                  options.max_jog_step);
    throw InputError("jog refused", robot.active_joint_names()[j], expected,
                     std::to_string(step) + " rad");
  }
  const auto& collisions = loaded->scene().robot->collisions;
  if (!collisions || collisions->pair_count() == 0) return {};
  const SphereClearance worst = collisions->closest_pairs(forward_kinematics(robot, to), 1).front();
  // Out of a collision is allowed: only a jog that makes (or deepens) an overlap is refused.
  if (worst.clearance >= 0 ||
      worst.clearance >= collisions->min_clearance(forward_kinematics(robot, from)))
    return {};
  const auto& spheres = collisions->spheres();
  links = {spheres[worst.first].link, spheres[worst.second].link};
  return "jog refused: self-collision: " + robot.links()[links[0]].name + " and " +
         robot.links()[links[1]].name + " would overlap by " + millimetres(-worst.clearance);
}

void Controller::State::apply(Inbox in) {
  if (in.reset || in.clear || in.targets || in.centerline || (in.feedback && !*in.feedback))
    free_walk();
  if (in.reset) {
    current = objective->evaluate(object->reference_joints(), object->reference_positions());
    retarget({});
    centerline.clear();
    objective->rescore(current);
    optimizer->reset();
    last_error.clear();
    jog_refused_links.clear();
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
      retarget(centerline_targets(object->mesh(), *bar_axis, *in.centerline, current.positions()));
      centerline = *in.centerline;
    } catch (const InputError& e) {
      retarget({});
      centerline.clear();
      last_error = std::string("centre-line refused: ") + e.what();
    }
  }
  if (in.paused) {
    paused = *in.paused;
    if (!paused) jog_refused_links.clear();
  }
  if (in.jog && paused) {
    jog_refused_links.clear();
    const Eigen::VectorXd theta =
        in.jog->cwiseMax(object->robot().lower_limits()).cwiseMin(object->robot().upper_limits());
    Evaluation e = objective->evaluate(theta, current.positions(), 0, &current);
    if (objective->confirm_stable(e)) {
      current = std::move(e);
      last_error.clear();
      free_walk();
    } else {
      last_error = "jog refused: statics " + e.statics().reason;
      std::lock_guard lock(inbox_mutex);
      if (jogged_to && *jogged_to == theta) jogged_to = current.joints();  // stayed here
    }
  }
  if (in.jog_refused_links) jog_refused_links = *in.jog_refused_links;  // after the jog before it
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
  // The same pool: the new model's states (same mesh, fixed nodes and grips) keep the
  // symbolic analyses.
  auto next_objective =
      std::make_unique<ReducedObjective>(*next_object, objective->targets(), objective->options(),
                                         objective->workspaces());
  // No chord steps from the old model's factorization: it belongs to another Hessian.
  Evaluation next = next_objective->evaluate(current.joints(), current.positions());
  if (!next.statics().converged() || !next_objective->confirm_stable(next)) {
    last_error = "model update refused: no stable equilibrium at the current joints (" +
                 next.statics().reason + ")";
    return false;
  }
  if (last_observation) {
    const Eigen::VectorXd& joints = last_observation->joints;
    const Evaluation before = objective->evaluate(joints, current.positions(), 0, &current);
    const Evaluation after = next_objective->evaluate(joints, next.positions(), 0, &next);
    if (before.statics().converged() && after.statics().converged())
      feedback->model_changed(before.positions(), after.positions());
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
  Positions x = current.positions();
  object->carry_gripped_nodes(current.joints(), observation.joints, current.positions(), x);
  Evaluation predicted = objective->evaluate(observation.joints, x, 0, &current);
  if (!predicted.statics().converged()) {
    // Not the optimizer's failure: the loop goes on with the next observation.
    ++observations_ignored;
    observation_problem =
        "observation ignored: no equilibrium at its joints (" + predicted.statics().reason + ")";
    return false;
  }
  const double now = std::chrono::duration<double>(Clock::now() - started).count();
  const GateVerdict gate =
      feedback->observe(observation.markers, predicted.positions(), observation.sigma, now);
  observation_problem = gate.reason.empty() ? "" : "observation gated: " + gate.reason;
  if (gate.frame_rejected) return false;
  // What the loop shows and judges by: the markers the gate let through.
  observed_markers.clear();
  for (std::size_t k = 0; k < observation.markers.size(); ++k)
    if (gate.inside[k]) observed_markers.push_back(observation.markers[k]);
  last_observation = observation;
  ++observations;
  double sum = 0;
  int count = 0;
  for (const auto& [node, y] : observed_markers)
    for (int k = 0; k < user_targets.size(); ++k)
      if (user_targets.nodes[k] == node) sum += (y - user_targets.positions[k]).norm(), ++count;
  observed_error = count ? sum / count : NAN;
  return reaim(observation.sigma);
}

bool Controller::State::reaim(double sigma) {
  // Not while the optimizer walks for the user's request: re-aims would keep resetting it, and
  // the loop (and its trust region) would never start. The walk's end catches up.
  if (!feedback_on || !loop_start || !moved_enough(feedback->corrected(user_targets), sigma))
    return false;
  aim();
  return true;
}

bool Controller::State::moved_enough(const ShapeTargets& corrected, double sigma) const {
  const ShapeTargets& aimed = objective->targets();
  if (aimed.size() != corrected.size()) return true;
  if (aimed.size() == 0) return false;
  double sum = 0;
  for (int k = 0; k < aimed.size(); ++k)
    sum += (aimed.positions[k] - corrected.positions[k]).squaredNorm();
  // The filtered estimate's own noise (3 axes) is σ·√(3g/(2−g)): twice that is noise, not news.
  const double g = options.feedback.gain;
  const double noise = sigma * std::sqrt(3 * g / (2 - g));
  return std::sqrt(sum / aimed.size()) > std::max(options.feedback.retarget_threshold, 2 * noise);
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
  // Show the applied request (targets, "optimizing", the error against them) before the step:
  // one step of a 12k-tet object can take seconds, and the GUI would show the old state till then.
  if (work && had_requests) publish();
  if (work) {
    failed = false;
    try {
      last_outcome = optimizer->step(*objective, current);
    } catch (const std::exception& e) {  // e.g. the start state is no stable equilibrium
      last_outcome = StepOutcome::Stuck;
      last_error = std::string("optimizer stopped: ") + e.what();
      failed = true;
    }
    ++iterations;
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - last_iteration).count();
    last_iteration = now;
    if (dt > 0) rate = rate == 0 ? 1 / dt : 0.8 * rate + 0.2 / dt;
    if (last_outcome != StepOutcome::Improved) {
      // The walk for the user's request ended: the loop starts here, with what the feedback
      // learnt on the way.
      const bool walked = !loop_start;
      start_loop();
      if (walked && last_observation && reaim(last_observation->sigma)) {
        objective->rescore(current);
        optimizer->reset();
      } else {
        idle = true;  // wait for the next request
        judge_stop();
      }
    }
  } else if (objective->targets().empty() || paused) {
    idle = true;
  }
  if (work || had_requests) publish();
}

void Controller::State::judge_stop() {
  shortfall = {};
  if (stopped_status(current, failed, options.tolerance) != ControllerStatus::BestEffort) return;
  try {
    shortfall = find_shortfalls(*objective, current);
  } catch (const std::exception& e) {  // the probes' statics: the reasons stay unknown
    shortfall.detail = std::string("reasons unknown: ") + e.what();
  }
  const std::string why = optimizer->why_stopped();
  if (!why.empty()) shortfall.detail += "; the optimizer stopped: " + why;
  Eigen::Index j = 0;
  if (loop_start &&
      (current.joints() - *loop_start).cwiseAbs().maxCoeff(&j) >= options.trust_region - 1e-9) {
    char held[160];
    std::snprintf(held, sizeof held,
                  "; the feedback's trust region holds %s at %.3g rad from where the loop started",
                  object->robot().active_joint_names()[j].c_str(), options.trust_region);
    shortfall.detail += held;
  }
}

ControllerStatus Controller::State::status() const {
  if (paused) return ControllerStatus::Paused;
  if (objective->targets().empty()) return ControllerStatus::Idle;
  if (!idle) return ControllerStatus::Optimizing;
  return stopped_status(current, failed, options.tolerance);
}

void Controller::State::publish() {
  auto s = std::make_shared<ControllerSnapshot>();
  const RobotModel& robot = object->robot();
  s->time = std::chrono::duration<double>(Clock::now() - started).count();
  s->joint_names = robot.active_joint_names();
  s->joints = current.joints();
  s->lower_limits = robot.lower_limits();
  s->upper_limits = robot.upper_limits();
  s->T_world_link = forward_kinematics(robot, current.joints()).T_world_link;
  s->positions = current.positions();
  s->contact_scale = current.state->contact_scale();
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
  s->gate = feedback->gate_counts();
  s->authority = feedback->authority();
  s->authority.trust_region = options.trust_region;
  if (loop_start)
    s->authority.joint_offset = (current.joints() - *loop_start).cwiseAbs().maxCoeff();
  s->status = status();
  s->tolerance = options.tolerance;
  s->jog_refused_links = jog_refused_links;
  if (s->status == ControllerStatus::BestEffort) {
    s->shortfalls = shortfall.reasons;
    s->status_reason = "error " + millimetres(current.error.max) + " above the tolerance " +
                       millimetres(options.tolerance) + "; " + shortfall.detail;
  } else if (s->status == ControllerStatus::Failed) {
    s->status_reason = last_error;
  }
  if (const auto& collisions = object->scene().robot->collisions)
    find_collisions(*collisions, current.state->kinematics(), *s);
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
  s.scene = with_linear_solver(scene, options);
  s.options = options;
  s.loaded = std::make_shared<const GrippedObject>(s.scene);
  s.object = s.loaded;
  s.objective = std::make_unique<ReducedObjective>(*s.object);
  s.optimizer = make_optimizer(options.optimizer, options.gradient);
  s.optimizer->out_of_time = [&s] { return s.stopping.load(); };
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
  state_->stopping = true;
  state_->inbox_changed.notify_all();
  if (state_->worker.joinable()) state_->worker.join();
  state_->stopping = false;
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
  post(*state_, [&](Inbox& in) {
    in.paused = paused;
    state_->pause_requested = paused;
    state_->jogged_to.reset();
  });
}

void Controller::set_joints(const Eigen::VectorXd& joints) {
  if (joints.size() != state_->loaded->joint_count())
    throw InputError("joints", "",
                     "one value per active joint (" +
                         std::to_string(state_->loaded->joint_count()) + ")");
  if (!joints.allFinite()) throw InputError("joints", "", "finite values");
  jog([&](const Eigen::VectorXd&) { return joints; });
}

void Controller::set_joint(int joint, double value) {
  const int count = state_->loaded->joint_count();
  if (joint < 0 || joint >= count)
    throw InputError("joint", "",
                     "an active joint's index (0 to " + std::to_string(count - 1) + ")", joint);
  if (!std::isfinite(value)) throw InputError("value", "", "a finite number");
  jog([&](const Eigen::VectorXd& from) {
    Eigen::VectorXd joints = from;
    joints[joint] = value;
    return joints;
  });
}

void Controller::jog(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& joints_from) {
  const RobotModel& robot = state_->loaded->robot();
  std::string refusal;
  {
    std::lock_guard lock(state_->inbox_mutex);
    const auto now = snapshot();
    if (!state_->pause_requested)
      throw InputError("joints", "", "the optimizer to be paused before jogging");
    const Eigen::VectorXd& from = state_->jogged_to ? *state_->jogged_to : now->joints;
    const Eigen::VectorXd theta =
        joints_from(from).cwiseMax(robot.lower_limits()).cwiseMin(robot.upper_limits());
    std::vector<int> links;
    refusal = state_->jog_collision(from, theta, links);
    if (refusal.empty()) {
      state_->inbox.jog = state_->jogged_to = theta;
      state_->inbox.jog_refused_links.reset();
    } else {
      state_->inbox.jog_refused_links = links;  // shown red until the next jog
    }
  }
  state_->inbox_changed.notify_all();
  if (!refusal.empty()) throw InputError(refusal);
}

void Controller::observe(ShapeObservation observation) {
  const int joints = state_->loaded->joint_count(), nodes = state_->loaded->node_count();
  if (observation.joints.size() != joints)
    throw InputError("observation", "joints",
                     "one value per active joint (" + std::to_string(joints) + ")");
  if (!observation.joints.allFinite()) throw InputError("observation", "joints", "finite values");
  if (observation.markers.empty())
    throw InputError("observation", "markers", "at least one marker");
  if (!(observation.sigma > 0 && std::isfinite(observation.sigma)))
    throw InputError("observation", "sigma", "a positive number of metres", observation.sigma);
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
  post(*state_, [&](Inbox& in) { in.model = with_linear_solver(model, state_->options); });
}

void Controller::reset() {
  post(*state_, [&](Inbox& in) {
    const std::optional<bool> paused = in.paused;  // a reset does not undo a pause
    in = Inbox{};
    in.reset = true;
    in.paused = paused;
    state_->jogged_to.reset();
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
