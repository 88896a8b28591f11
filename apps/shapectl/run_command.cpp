// shapectl run SCENE.json --targets TARGETS.json [--robot sim|egm] [--arm] [--log LOG.jsonl]
//              [--until-settled] [--timeout S] [link options]
//              [--world WORLD.json [--camera-rate HZ] [--camera-sigma M] [--no-feedback]]
// The controller and the robot link without a GUI: the optimizer's best θ goes to the link
// whenever it changes; the link's governor moves the robot (only if armed). With
// --until-settled it exits 0 once the optimizer has converged and the robot has arrived, or 2
// with the reason when that cannot happen (optimizer stuck, link disarmed, timeout).
#include <chrono>
#include <iostream>
#include <thread>

#include <nlohmann/json.hpp>

#include <shapectl/calib/live_observation.hpp>
#include <shapectl/calib/simulated_world.hpp>
#include <shapectl/control/controller.hpp>
#include <shapectl/control/targets_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/egm_link.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/link/stop_signal.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "commands.hpp"
#include "result_json.hpp"

namespace shapectl::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct RunArgs {
  std::string scene;
  std::string targets;
  std::string log;
  bool arm = false;
  bool until_settled = false;
  double timeout = 0;         // s; 0: none
  std::string robot = "sim";  // a LinkKind name
  LinkConfig link;
  double watchdog_ms = 100;
  // The simulated real object (calib/simulated_world.hpp): its camera observes markers on the
  // target nodes; with feedback on, the controller closes the loop on them.
  std::string world;
  double camera_rate = 10;       // observations per second
  double camera_sigma = 0.0003;  // m
  bool feedback = true;
};

nlohmann::json link_json(const LinkStatus& s) {
  return {{"kind", s.kind},
          {"connected", s.connected},
          {"armed", s.armed},
          {"arrived", s.arrived},
          {"reason", s.reason},
          {"commands_sent", s.commands_sent},
          {"rejected_datagrams", s.rejected_datagrams},
          {"lost_datagrams", s.lost_datagrams},
          {"stale_datagrams", s.stale_datagrams},
          {"foreign_datagrams", s.foreign_datagrams},
          {"commanded", vector_json(s.commanded)},
          {"measured", vector_json(s.measured)}};
}

// Why running on cannot settle, or empty.
std::string cannot_settle(const ControllerSnapshot& s, const LinkStatus& link, bool armed_once) {
  if (s.status == ControllerStatus::Stuck)
    return "optimizer stuck: no acceptable step (error " + std::to_string(s.error.mean) + " m)";
  if (!s.last_error.empty()) return "optimizer: " + s.last_error;
  if (armed_once && !link.armed) return "robot link disarmed: " + link.reason;
  return {};
}

void log_snapshot(SessionLog& log, const ControllerSnapshot& s) {
  log.write("optimizer", {{"sequence", s.sequence},
                          {"status", to_string(s.status)},
                          {"joints", vector_json(s.joints)},
                          {"safe", s.safe},
                          {"error_mean", s.error.mean},
                          {"error_max", s.error.max},
                          {"objective", s.objective},
                          {"iterations", s.iterations}});
}

struct RunInputs {
  Scene scene;
  TargetsInput targets;
  std::unique_ptr<SimulatedWorld> world;  // --world
};

// --world: the "real" object, observed on the target nodes (the centre-line's too).
std::unique_ptr<SimulatedWorld> make_world(const RunArgs& args, const Scene& model,
                                           const ShapeTargets& targets) {
  if (args.world.empty()) return nullptr;
  if (args.link.kind != LinkKind::Sim)
    throw InputError("run", "--world", "--robot sim (a real robot holds a real object)");
  if (!(args.camera_rate > 0 && args.camera_rate <= 1000))
    throw InputError("run", "--camera-rate", "0 < rate <= 1000 per second", args.camera_rate);
  if (!(args.camera_sigma >= 0 && args.camera_sigma <= 0.1))
    throw InputError("run", "--camera-sigma", "0 <= sigma <= 0.1 m", args.camera_sigma);
  const Scene world = load_scene(args.world);
  SimulatedCamera camera;
  camera.marker_nodes = targets.nodes;
  camera.sigma = args.camera_sigma;
  try {
    return std::make_unique<SimulatedWorld>(world, model, camera, args.camera_rate);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.world, "object", e.what());
  }
}

// The scene (with a robot) and the targets, checked; the link settings completed from them.
RunInputs load_run_inputs(RunArgs& args) {
  Scene scene = load_scene(args.scene);
  print_scene_notes(scene);
  if (!scene.robot) throw InputError(args.scene, "robot", "run needs a scene with a robot");
  TargetsInput targets = load_targets(args.targets, scene.object_mesh->node_count());
  parse(args.robot, &args.link.kind);  // checked by the option
  args.link.watchdog_timeout = args.watchdog_ms / 1000;
  args.link.sim_initial_joints = scene.robot->reference_joints;
  if (args.timeout < 0) throw InputError("run", "--timeout", "a number >= 0", args.timeout);
  std::unique_ptr<SimulatedWorld> world = make_world(args, scene, targets.targets);
  return {std::move(scene), std::move(targets), std::move(world)};
}

// The session log if --log names one, opened with a "session" event; else null.
std::shared_ptr<SessionLog> open_session_log(const RunArgs& args, const Scene& scene) {
  if (args.log.empty()) return nullptr;
  auto log = std::make_shared<SessionLog>(args.log);
  log->write("session", {{"command", "run"},
                         {"scene", std::filesystem::absolute(args.scene).string()},
                         {"targets_file", args.targets},
                         {"robot", to_string(args.link.kind)},
                         {"joint_names", scene.robot->model->active_joint_names()}});
  return log;
}

std::unique_ptr<RobotLink> make_run_link(const RunArgs& args, const Scene& scene,
                                         const std::shared_ptr<SessionLog>& log) {
  auto link = make_robot_link(args.link, *scene.robot->model, scene.robot->collisions, log);
  if (auto* egm = dynamic_cast<EgmLink*>(link.get()))
    std::cerr << "run: EGM on " << args.link.egm_address << " ports " << egm->port(0)
              << (egm->channels().size() > 1 ? " and " + std::to_string(egm->port(1)) : "") << "\n";
  return link;
}

// Hands the file's targets (nodes or a centre-line) to the controller, and to the log.
void set_run_targets(Controller& controller, const TargetsInput& targets, SessionLog* log) {
  if (targets.centerline.empty()) controller.set_targets(targets.targets);
  else controller.set_centerline(targets.centerline);
  if (log)
    log->write("targets", {{"nodes", targets.targets.nodes},
                           {"positions", points_json(targets.targets.positions)},
                           {"centerline", points_json(targets.centerline)}});
}

// Seconds since the robot link started.
struct RunClock {
  Clock::time_point start = Clock::now();
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start).count(); }
};

// Arming needs feedback: gives the robot 5 s to appear, then fails (SolverFailure).
void arm_when_ready(RobotLink& link, const RunClock& clock) {
  std::string why;
  while (!link.arm(&why)) {
    if (clock.elapsed() > 5 || stop_signal_received())
      throw SolverFailure("cannot arm the robot link: " + why);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::cerr << "run: armed\n";
}

// How following the optimizer ended.
struct RunOutcome {
  bool settled = false;
  std::string failure;                                 // why it cannot settle; empty otherwise
  std::shared_ptr<const ControllerSnapshot> snapshot;  // the last one seen
};

// The progress line's state: "converged; robot connected, arrived".
std::string progress_report(const ControllerSnapshot& s, const LinkStatus& st) {
  return std::string(to_string(s.status)) + "; robot " +
         (st.connected ? "connected" : "not connected") + ", " +
         (st.armed ? (st.arrived ? "arrived" : "moving") : "not armed: " + st.reason);
}

// --until-settled: true when following should end, settled or with outcome.failure set.
bool settle_decided(const ControllerSnapshot& s, const LinkStatus& st, bool armed,
                    RunOutcome& outcome) {
  outcome.failure = cannot_settle(s, st, armed);
  if (!outcome.failure.empty()) return true;
  if (s.status != ControllerStatus::Converged) return false;
  // Not armed, the robot is never asked to move: it cannot arrive, so say so.
  if (!armed) {
    outcome.failure =
        "the optimizer converged, but the robot is not armed (--arm), so it cannot arrive";
    return true;
  }
  outcome.settled = st.arrived;
  return st.arrived;
}

// With the loop closed, settled also means the observed object is at the targets.
bool observed_at_targets(const ControllerSnapshot& s) {
  return !s.feedback || (s.observations > 0 && s.observed_error < 1e-3);
}

// --world: the world settles at the robot's measured joints; a due observation goes to the
// controller and the log (with the world's true error, which only a simulation knows).
void observe_world(SimulatedWorld& world, Controller& controller, const ControllerSnapshot& snap,
                   const LinkStatus& st, double time, SessionLog* log) {
  if (st.measured.size() != snap.joints.size()) return;  // no feedback from the robot yet
  const std::optional<ObservationFrame> frame = world.step(time, st.measured);
  if (!frame) return;
  controller.observe(live_observation(*frame));
  if (log)
    log->write("observation", {{"time", time},
                               {"true_error", world.true_error(snap.targets)},
                               {"observed_error", snap.observed_error},
                               {"model_error", snap.model_error}});
}

// Sends each new snapshot's θ to the link (and the log) and prints progress, until settled,
// failed, timed out or stopped by a signal.
RunOutcome follow_optimizer(const RunArgs& args, Controller& controller, RobotLink& link,
                            SessionLog* log, const RunClock& clock, SimulatedWorld* world) {
  RunOutcome outcome;
  std::uint64_t seen = 0;
  std::string last_report;
  outcome.snapshot = controller.snapshot();
  while (!stop_signal_received()) {
    outcome.snapshot = controller.wait_for_snapshot(seen, 0.02);
    const ControllerSnapshot& snap = *outcome.snapshot;
    if (snap.sequence > seen) {
      seen = snap.sequence;
      link.set_target(snap.joints, snap.safe);
      if (log) log_snapshot(*log, snap);
    }
    const LinkStatus st = link.status();
    if (world) observe_world(*world, controller, snap, st, clock.elapsed(), log);
    const std::string report = progress_report(snap, st);
    if (report != last_report) {
      std::cerr << "run: " << clock.elapsed() << " s: " << report << " (error "
                << snap.error.mean * 1000 << " mm)\n";
      last_report = report;
    }
    if (args.until_settled && settle_decided(snap, st, args.arm, outcome)) {
      if (!outcome.failure.empty() || observed_at_targets(snap)) break;
      outcome.settled = false;  // arrived, but the observed object is not there yet: on
    }
    if (args.timeout > 0 && clock.elapsed() >= args.timeout) {
      if (args.until_settled)
        outcome.failure = "not settled after " + std::to_string(args.timeout) + " s: optimizer " +
                          to_string(snap.status) + ", robot " +
                          (st.arrived ? "arrived" : "not arrived");
      break;
    }
  }
  return outcome;
}

// Leaves the robot standing: disarm, give the governor time to brake, then stop. Returns the
// link's last status.
LinkStatus stop_run(RobotLink& link, Controller& controller, const std::string& failure) {
  link.disarm(failure.empty() ? "run finished" : failure);
  for (int k = 0; k < 300 && link.status().commanded != link.status().measured; ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  controller.stop();
  const LinkStatus final_status = link.status();
  link.stop();
  return final_status;
}

// What `run` prints on stdout.
nlohmann::json run_result(const RunOutcome& outcome, const LinkStatus& final_status,
                          RobotLink& link, const SimulatedWorld* world) {
  const ControllerSnapshot& snap = *outcome.snapshot;
  nlohmann::json result = {{"settled", outcome.settled},         {"status", to_string(snap.status)},
                           {"error_mean", snap.error.mean},      {"error_max", snap.error.max},
                           {"iterations", snap.iterations},      {"joint_names", snap.joint_names},
                           {"joints", vector_json(snap.joints)}, {"link", link_json(final_status)}};
  if (auto* egm = dynamic_cast<EgmLink*>(&link)) {
    const LatencyStats l = egm->latency();
    result["latency_us"] = {{"samples", l.samples},
                            {"median", l.median_us},
                            {"p99", l.p99_us},
                            {"max", l.max_us}};
  }
  if (snap.observations > 0) {
    result["observations"] = snap.observations;
    result["feedback"] = snap.feedback;
    result["model_error"] = snap.model_error;
    result["observed_error"] =
        std::isfinite(snap.observed_error) ? nlohmann::json(snap.observed_error) : nullptr;
  }
  if (world) result["true_error"] = world->true_error(snap.targets);
  if (!outcome.failure.empty()) result["reason"] = outcome.failure;
  return result;
}

void run(RunArgs args) {
  RunInputs inputs = load_run_inputs(args);
  const std::shared_ptr<SessionLog> log = open_session_log(args, inputs.scene);
  const auto link = make_run_link(args, inputs.scene, log);
  Controller controller(inputs.scene);
  set_run_targets(controller, inputs.targets, log.get());
  if (inputs.world) controller.set_feedback(args.feedback);
  install_stop_signal_handlers();
  controller.start();
  link->start();
  const RunClock clock;
  if (args.arm) arm_when_ready(*link, clock);  // throws if it cannot
  const RunOutcome outcome =
      follow_optimizer(args, controller, *link, log.get(), clock, inputs.world.get());
  const LinkStatus final_status = stop_run(*link, controller, outcome.failure);
  const nlohmann::json result = run_result(outcome, final_status, *link, inputs.world.get());
  if (log) log->write("end", {{"settled", outcome.settled}, {"reason", outcome.failure}});
  std::cout << result.dump(2) << "\n";
  if (!outcome.failure.empty()) throw SolverFailure(outcome.failure);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand("run", "Run the controller and the robot link without a GUI");
  cmd->add_option("scene", args->scene, "SCENE.json")->required();
  cmd->add_option("--targets", args->targets, "TARGETS.json")->required();
  cmd->add_option("--robot", args->robot, "robot link: sim (in-process) or egm (ABB EGM)")
      ->check(CLI::IsMember(link_kind_names()))
      ->capture_default_str();
  cmd->add_flag("--arm", args->arm, "arm the link: let the robot move (otherwise it holds)");
  cmd->add_option("--log", args->log, "session log to write (JSON lines)");
  cmd->add_flag("--until-settled", args->until_settled,
                "exit 0 once converged and arrived; exit 2 with the reason if that cannot happen");
  cmd->add_option("--timeout", args->timeout, "seconds before giving up (0: none)")
      ->capture_default_str();
  cmd->add_option("--max-velocity", args->link.max_velocity,
                  "rad/s per joint (capped by the robot's own)")
      ->capture_default_str();
  cmd->add_option("--max-acceleration", args->link.max_acceleration, "rad/s² per joint")
      ->capture_default_str();
  cmd->add_option("--limit-margin", args->link.limit_margin, "rad kept from each joint limit")
      ->capture_default_str();
  cmd->add_option("--watchdog-ms", args->watchdog_ms, "feedback gap that holds and disarms, ms")
      ->capture_default_str();
  cmd->add_option("--egm-address", args->link.egm_address, "local address for the EGM ports")
      ->capture_default_str();
  cmd->add_option("--egm-left-port", args->link.egm_left_port, "UDP port of the left arm (ROB_L)")
      ->capture_default_str();
  cmd->add_option("--egm-right-port", args->link.egm_right_port,
                  "UDP port of the right arm (ROB_R)")
      ->capture_default_str();
  cmd->add_option("--world", args->world,
                  "WORLD.json: simulate the real object (true material, grip offsets; same mesh) "
                  "with --robot sim; "
                  "a camera observes markers on the target nodes")
      ->check(CLI::ExistingFile);
  cmd->add_option("--camera-rate", args->camera_rate, "--world: observations per second")
      ->capture_default_str();
  cmd->add_option("--camera-sigma", args->camera_sigma, "--world: marker noise, m")
      ->capture_default_str();
  cmd->add_flag("--feedback,!--no-feedback", args->feedback,
                "--world: close the loop on the observations (default) or not (open loop)");
  cmd->callback([args] { run(*args); });
}

}  // namespace shapectl::cli
