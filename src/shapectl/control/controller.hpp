#pragma once
// The continuous controller (paper Section IV–V): owns the scene's simulation and optimizer
// state, takes requests (targets, centre-lines, pause, jog, reset) from any thread, runs
// optimizer iterations in its own thread, and publishes immutable snapshots that the GUI, the
// robot link and the logger read without ever touching the state.
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include <shapectl/control/model_error_feedback.hpp>
#include <shapectl/control/optimize.hpp>
#include <shapectl/control/shape_targets.hpp>
#include <shapectl/control/shortfall.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl {

struct ControllerOptions {
  OptimizerKind optimizer = OptimizerKind::GaussNewton;
  GradientMethod gradient = GradientMethod::Sensitivity;
  FeedbackOptions feedback;
  // The user's tolerance: stopped with every target within it is "reached", above it "best
  // effort" (with the reasons, control/shortfall.hpp). Metres.
  double tolerance = 1e-3;
  // A jog (set_joints) may move each joint at most this far from the current (or last
  // requested) joints, rad; farther is refused. A slider click must not swing an arm.
  double max_jog_step = 0.05;
  // The statics' linear solver over the scene's and every model's (`--linear-solver`): unset
  // keeps theirs; set to nullopt is "auto".
  std::optional<std::optional<CholeskyBackend>> linear_solver;
  // The feedback's trust region, rad per joint. Where the optimizer stops for the user's last
  // request (targets, centre-line, clear, reset, jog, feedback off) is the loop's start; what
  // observations then cause (the feedback re-aiming, a calibration's new model) may move no
  // joint farther than this from there, and the optimizer's walk for a user's request takes no
  // feedback re-aim before it stops. So an observation, lying or not, keeps the robot in a box
  // around the joints the open loop chose (docs/calibration.md, "Safety"); the user's own
  // requests go anywhere, as without feedback. 0.02: the honest loop on the closed-loop tests'
  // world (model 17-20 mm off) converges as fast as without it (measured, issue 32).
  double trust_region = 0.02;
};

// An observation of the real object for the closed loop: tracked markers at mesh nodes (world
// frame, m) and the joints the robot measured when they were taken.
struct ShapeObservation {
  Eigen::VectorXd joints;
  std::vector<std::pair<int, Vec3>> markers;
  double sigma = 0.001;  // m, the markers' noise (standard deviation per axis)
  double time = 0;       // s, as the observer stamped it
};

// What the controller is doing, as published. Once the optimizer stops (stationary, no
// acceptable step or out of its iteration budget) the status says whether the targets were
// met, never merely that iterating ended.
enum class ControllerStatus {
  Idle,        // no targets
  Optimizing,  // iterating
  Reached,     // stopped with every target within the tolerance
  BestEffort,  // stopped above the tolerance: unreachable from here, reasons in the snapshot
  Paused,
  Failed,  // the optimizer could not go on (no equilibrium, an error): see last_error
};
// "idle", "optimizing", "reached", "best effort", "paused", "failed" (the GUI's names too:
// web/js/protocol.js).
const char* to_string(ControllerStatus status);
bool parse(std::string_view name, ControllerStatus* status);
// How a stopped run ended at `best`: Failed (`failed`, or no converged equilibrium), Reached
// (every target error within `tolerance`, m) or BestEffort. `solve` says the same.
ControllerStatus stopped_status(const Evaluation& best, bool failed, double tolerance);

// One published state. Everything in the world frame, metres and radians.
struct ControllerSnapshot {
  std::uint64_t sequence = 0;            // increases with every publication
  double time = 0;                       // seconds since the controller started
  std::vector<std::string> joint_names;  // active joints, θ order
  Eigen::VectorXd joints;  // θ: the current best, always safe once a safe state exists
  Eigen::VectorXd lower_limits, upper_limits;
  std::vector<Eigen::Isometry3d> T_world_link;  // every link of the robot model
  Positions positions;                          // x̂(θ), 3n
  double contact_scale = 1;      // the factor on the contact stiffness at positions (ObjectState's)
  ShapeTargets targets;          // what is asked for now (the user's, not the corrected ones)
  std::vector<Vec3> centerline;  // the sketched centre-line, if the targets came from one
  ShapeError error;              // of positions against targets
  double objective = 0;
  double min_clearance = 0;  // m; +inf without a collision model
  bool within_limits = true;
  bool safe = true;
  std::uint64_t iterations = 0;  // optimizer iterations so far
  double iterations_per_second = 0;
  bool paused = false;
  ControllerStatus status = ControllerStatus::Idle;
  double tolerance = 1e-3;            // m, ControllerOptions::tolerance
  std::vector<Shortfall> shortfalls;  // BestEffort: why; empty otherwise (or a local minimum)
  std::string status_reason;          // BestEffort/Failed in words, with numbers; else empty
  std::string last_error;             // e.g. statics failure while jogging; empty when fine
  // Self-collision at θ (with a collision model): the link indices whose spheres overlap
  // another's, ascending, and the closest checked sphere pair (first < 0 without pairs).
  std::vector<int> colliding_links;
  SphereClearance closest_pair;
  // The two links a jog refused for self-collision would have made overlap (shown red until
  // the next accepted jog, resume or reset); empty otherwise.
  std::vector<int> jog_refused_links;
  // The closed loop (set_feedback, observe): the last observation, its model error (observed
  // vs predicted at its joints, RMS, m) and observed error (observed vs targets at the
  // observed target nodes, mean, m; NaN when no target node is observed).
  bool feedback = false;
  std::vector<std::pair<int, Vec3>> observed_markers;
  double model_error = 0;
  double observed_error = 0;
  std::uint64_t observations = 0;
  // Observations the model could not predict (no equilibrium at their joints), and what was
  // wrong with the newest (ignored, or markers outside the plausibility gate; empty when fine).
  // `observations` counts the frames taken: not those ignored or rejected by the gate.
  std::uint64_t observations_ignored = 0;
  std::string observation_problem;
  GateCounts gate;              // the plausibility gate's counts (control/observation_gate.hpp)
  FeedbackAuthority authority;  // the feedback's bounds and what it applies now
  // The model the optimizer works with: the scene's values until set_model replaces them.
  Material material;
  std::vector<Eigen::Isometry3d> grip_offsets;  // one per grip
  std::uint64_t model_updates = 0;
};

class Controller {
 public:
  Controller(const Scene& scene, ControllerOptions options = {});
  ~Controller();  // stops the thread
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  const Scene& scene() const;   // as loaded; the current model's values are in the snapshot
  const TetMesh& mesh() const;  // placed rest mesh (node order = file order)
  const RobotModel& robot() const;

  // Runs iterations in a background thread until stop() or destruction.
  void start();
  void stop();
  // Without the thread: apply pending requests, then one optimizer iteration (if any is due).
  void step_once();

  // Requests; safe from any thread, applied before the next iteration. Invalid input (node out
  // of range, non-finite numbers, centre-line on an object that is not bar-like) throws
  // InputError and changes nothing.
  void set_targets(ShapeTargets targets);
  void set_centerline(std::vector<Vec3> polyline);
  void clear_targets();
  void set_paused(bool paused);
  // Jog: only while paused; θ is clamped to the hard limits, statics follows. Refused
  // (InputError, nothing changed) when a joint would move more than max_jog_step from the
  // current joints (or the last jog still pending), or when it would make spheres overlap
  // that do not already (the message names the two links).
  void set_joints(const Eigen::VectorXd& joints);
  // A jog of one joint (an active joint's index): the others stay at the last jog still
  // pending, else at the current joints; judged as set_joints. Quick jogs of two joints from
  // several threads or clients do not undo each other: the jog race is guarded here alone.
  void set_joint(int joint, double value);
  void reset();  // reference joints and shape, targets cleared
  // The closed loop: each observation updates the model-error estimate (control/
  // model_error_feedback.hpp); with feedback on, the optimizer aims at the corrected targets
  // so that the observed shape reaches the user's. Markers must be nodes of the mesh and every
  // number finite (InputError otherwise, nothing changed); joints of the robot's size.
  void observe(ShapeObservation observation);
  void set_feedback(bool on);
  // A better model of the same object (a calibration's: material, density, grip offsets; same
  // mesh, robot and grips). The controller continues from the same θ: the equilibrium is
  // solved anew there and the feedback's estimate moved with the model
  // (ModelErrorFeedback::model_changed), so the robot sees no jump. Refused, with last_error
  // set, when the new model has no stable equilibrium at θ. InputError for another object.
  void set_model(const Scene& model);

  std::shared_ptr<const ControllerSnapshot> snapshot() const;
  // Blocks until a snapshot with sequence > `after` exists, or the timeout passes.
  std::shared_ptr<const ControllerSnapshot> wait_for_snapshot(std::uint64_t after,
                                                              double timeout_seconds) const;

  struct State;  // the worker's state (controller.cpp)

 private:
  // The jog to joints_from(the last jog still pending, else the current joints), judged and
  // queued under the inbox's lock (see set_joints).
  void jog(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& joints_from);

  std::unique_ptr<State> state_;
};

}  // namespace shapectl
