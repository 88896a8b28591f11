// shapectl run SCENE.json --targets TARGETS.json [--robot sim|egm] [--arm] [--log LOG.jsonl]
//              [--until-settled] [--timeout S] [link options]
//              [--world WORLD.json [--camera-rate HZ] [--camera-sigma M] [--camera-points N]
//                                  [--camera-outliers F]]
//              [--observations-udp PORT [--observations-address ADDR]]
//              [--no-feedback] [--no-online-calibration] [--fit LIST]
// The controller and the robot link without a GUI: the optimizer's best θ goes to the link
// whenever it changes; the link's governor moves the robot (only if armed). With
// --until-settled it exits 0 once the optimizer reached the targets (within --tolerance) and
// the robot has arrived, or 2 with the reason when that cannot happen (best effort: the
// targets unreachable, with why; optimizer failed, link disarmed, timeout).
// Observed frames (the simulated world's camera, or UDP datagrams from a real one) close the
// loop: model-error feedback on their markers and, in the background, calibration of the
// --fit parameters from a sliding window of them (calib/online_calibration.hpp).
#include <chrono>
#include <iostream>
#include <thread>

#include <nlohmann/json.hpp>

#include <shapectl/calib/joint_path.hpp>
#include <shapectl/calib/observation_receiver.hpp>
#include <shapectl/calib/online_calibration.hpp>
#include <shapectl/calib/simulated_world.hpp>
#include <shapectl/control/controller.hpp>
#include <shapectl/control/reach_bound.hpp>
#include <shapectl/control/targets_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/egm_link.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/link/stop_signal.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/server/session.hpp>

#include "closed_loop_options.hpp"
#include "commands.hpp"
#include "linear_solver_option.hpp"
#include "link_options.hpp"
#include "output_option.hpp"
#include "result_json.hpp"
#include "robot_mesh_options.hpp"
#include "session_log_options.hpp"

namespace shapectl::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct RunArgs {
  std::vector<std::string> package_paths;  // --package-path: the URDF's package:// meshes
  std::string scene;
  std::string targets;
  std::string log;
  SessionLogLimits log_limits;  // --log-max-mb, --log-keep
  bool arm = false;
  bool until_settled = false;
  double timeout = 0;         // s; 0: none
  double tolerance = 1e-3;    // m: a target error at most this is reached
  std::string robot = "sim";  // a LinkKind name
  LinkArgs link_options;
  LinkConfig link;      // from link_options and the scene (load_run_inputs)
  ClosedLoopArgs loop;  // the simulated world, feedback, online calibration
  // A real camera's frames: one JSON frame per UDP datagram (calib/observation_receiver.hpp).
  int observations_udp = -1;  // port; -1: none
  std::string observations_address = "127.0.0.1";
  std::string linear_solver;
};

// Whether frames will arrive: only then do feedback and calibration matter.
bool observed(const RunArgs& args) {
  return !args.loop.world.empty() || args.observations_udp >= 0;
}

nlohmann::json link_json(const LinkStatus& s) {
  return {{"kind", s.kind},
          {"connected", s.connected},
          {"armed", s.armed},
          {"arrived", s.arrived},
          {"blocked", s.blocked},
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
  // With the loop closed, the model's best effort is judged by what is observed
  // (settle_decided).
  if (s.status == ControllerStatus::BestEffort && !s.feedback)
    return "targets not reached (best effort): " + s.status_reason;
  if (s.status == ControllerStatus::Failed) return "optimizer failed: " + s.status_reason;
  if (!s.last_error.empty()) return "optimizer: " + s.last_error;
  if (armed_once && !link.armed) return "robot link disarmed: " + link.reason;
  return {};
}

struct RunInputs {
  Scene scene;
  TargetsInput targets;
  std::unique_ptr<SimulatedWorld> world;          // --world
  std::unique_ptr<ObservationReceiver> receiver;  // --observations-udp
  OnlineCalibrationOptions calibration;
};

std::unique_ptr<ObservationReceiver> make_receiver(const RunArgs& args, const Scene& scene) {
  if (args.observations_udp < 0) return nullptr;
  auto receiver =
      std::make_unique<ObservationReceiver>(args.observations_address, args.observations_udp,
                                            ObservationContext{.node_count =
                                                                   scene.object_mesh->node_count(),
                                                               .robot = scene.robot->model.get(),
                                                               .allow_points_files = false});
  std::cerr << "run: observations on udp " << args.observations_address << ":" << receiver->port()
            << "\n";
  return receiver;
}

// --world: the "real" object, observed on the target nodes (the centre-line's too).
std::unique_ptr<SimulatedWorld> make_world(const RunArgs& args, const Scene& model,
                                           const ShapeTargets& targets) {
  if (args.loop.world.empty()) return nullptr;
  if (args.link.kind != LinkKind::Sim)
    throw InputError("run", "--world", "--robot sim (a real robot holds a real object)");
  SimulatedCamera camera = simulated_camera(args.loop, "run");
  camera.marker_nodes = targets.nodes;
  return simulated_world(args.loop, model, camera);
}

// The scene (with a robot) and the targets, checked; the link settings completed from them.
RunInputs load_run_inputs(RunArgs& args) {
  check_linear_solver_option("run", args.linear_solver);
  Scene scene = load_scene(args.scene);
  apply_linear_solver_option(args.linear_solver,
                             scene);  // the controller's, the fits', the world's
  print_scene_notes(scene, args.package_paths);
  if (!scene.robot) throw InputError(args.scene, "robot", "run needs a scene with a robot");
  TargetsInput targets = load_targets(args.targets, scene.object_mesh->node_count());
  check_in_reach(GrippedObject(scene), targets, args.targets);  // before the link starts
  LinkKind kind = LinkKind::Sim;
  parse(args.robot, &kind);  // checked by the option
  args.link = link_config(args.link_options, kind, scene.robot->reference_joints);
  if (args.timeout < 0) throw InputError("run", "--timeout", "a number >= 0", args.timeout);
  std::unique_ptr<SimulatedWorld> world = make_world(args, scene, targets.targets);
  OnlineCalibrationOptions calibration = online_calibration_options(args.loop, "run");
  std::unique_ptr<ObservationReceiver> receiver = make_receiver(args, scene);
  return {std::move(scene), std::move(targets), std::move(world), std::move(receiver), calibration};
}

// The session log if --log names one, opened with a "session" event; else null.
std::shared_ptr<SessionLog> open_session_log(const RunArgs& args, const Scene& scene) {
  if (args.log.empty()) return nullptr;
  auto log = std::make_shared<SessionLog>(args.log, args.log_limits);
  log->write_header("session", {{"command", "run"},
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
  const bool stationary = s.status == ControllerStatus::Reached ||
                          (s.feedback && s.status == ControllerStatus::BestEffort);
  if (!stationary) return false;
  // Not armed, the robot is never asked to move: it cannot arrive, so say so.
  if (!armed) {
    outcome.failure =
        "the optimizer reached the targets, but the robot is not armed (--arm), so it cannot "
        "arrive";
    return true;
  }
  // Held short of a self-collision on the way, at a standstill: it stays there.
  if (st.blocked) {
    outcome.failure = "robot cannot arrive: " + st.reason;
    return true;
  }
  outcome.settled = st.arrived;
  return st.arrived;
}

// With the loop closed, settled also means the observed object is at the targets.
bool observed_at_targets(const ControllerSnapshot& s) {
  return !s.feedback || (s.observations > 0 && s.observed_error < 1e-3);
}

// The observed frames and where they go: the simulated world's camera and/or UDP datagrams,
// into the closed loop (feedback and online calibration) and the log.
struct Observers {
  SimulatedWorld* world = nullptr;
  ObservationReceiver* receiver = nullptr;
  OnlineCalibration* calibration = nullptr;
  std::uint64_t reported_rejections = 0;
};

void log_observation(SessionLog* log, const ObservationFrame& frame, double time,
                     const ControllerSnapshot& snap, const SimulatedWorld* world) {
  if (!log) return;
  nlohmann::json event = {{"time", time},
                          {"markers", frame.markers.size()},
                          {"points", frame.points.size()},
                          {"observed_error", snap.observed_error},
                          {"model_error", snap.model_error},
                          {"gate", server::gate_json(snap.gate)},
                          {"authority", server::authority_json(snap.authority)}};
  if (world) event["true_error"] = world->true_error(snap.targets);
  log->write("observation", event);
}

// The world settles at the robot's measured joints; due frames, and every datagram waiting,
// go to the closed loop; a finished calibration goes to the controller (and the log).
void observe(Observers& o, const ControllerSnapshot& snap, const LinkStatus& st, double time,
             SessionLog* log) {
  std::vector<ObservationFrame> frames;
  if (o.world && st.measured.size() == snap.joints.size())  // feedback from the robot
    if (std::optional<ObservationFrame> frame = o.world->step(time, st.measured))
      frames.push_back(std::move(*frame));
  if (o.receiver) {
    for (ObservationFrame& f : o.receiver->receive()) frames.push_back(std::move(f));
    if (o.receiver->rejected() > o.reported_rejections) {
      std::cerr << "run: observation rejected (" << o.receiver->rejected()
                << " so far): " << o.receiver->last_rejection() << "\n";
      o.reported_rejections = o.receiver->rejected();
    }
  }
  for (const ObservationFrame& frame : frames) {
    if (frame.markers.empty() && frame.points.empty()) continue;
    o.calibration->observe(frame);
    log_observation(log, frame, time, snap, o.world);
  }
  const std::uint64_t runs = o.calibration->status().runs;
  o.calibration->poll(time);
  const OnlineCalibrationStatus c = o.calibration->status();
  if (c.runs > runs && log)
    log->write("calibration", {{"time", time},
                               {"applied", c.applied},
                               {"error", c.error},
                               {"rms_before", c.result ? c.result->rms_before : NAN},
                               {"rms_after", c.result ? c.result->rms_after : NAN}});
}

// Sends each new snapshot's θ to the link (and the log) and prints progress, until settled,
// failed, timed out or stopped by a signal.
RunOutcome follow_optimizer(const RunArgs& args, Controller& controller, RobotLink& link,
                            SessionLog* log, const RunClock& clock, Observers& observers) {
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
      if (log) server::log_snapshot(*log, snap);
    }
    const LinkStatus st = link.status();
    try {
      observe(observers, snap, st, clock.elapsed(), log);
    } catch (const NoEquilibrium& e) {  // the world's object, at the robot's measured joints
      outcome.failure = args.loop.world + ": the world's object: " + e.what();
      break;
    }
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
                          RobotLink& link, const Observers& observers, const RobotModel& robot) {
  const ControllerSnapshot& snap = *outcome.snapshot;
  nlohmann::json result = {{"settled", outcome.settled},
                           {"status", to_string(snap.status)},
                           {"status_reason", snap.status_reason},
                           {"unreachable", shortfall_names(snap.shortfalls)},
                           {"tolerance", snap.tolerance},
                           {"error_mean", snap.error.mean},
                           {"error_max", snap.error.max},
                           {"iterations", snap.iterations},
                           {"joint_names", snap.joint_names},
                           {"joints", vector_json(snap.joints)},
                           {"fixed_joints", fixed_joints_json(robot)},
                           {"link", link_json(final_status)}};
  if (auto* egm = dynamic_cast<EgmLink*>(&link)) {
    const LatencyStats l = egm->latency();
    result["latency_us"] = {{"samples", l.samples},
                            {"median", l.median_us},
                            {"p99", l.p99_us},
                            {"max", l.max_us}};
  }
  if (snap.observations > 0 || snap.gate.frames_checked > 0 || snap.observations_ignored > 0) {
    result["observations"] = snap.observations;
    result["observations_ignored"] = snap.observations_ignored;
    result["gate"] = server::gate_json(snap.gate);
    result["authority"] = server::authority_json(snap.authority);
    result["feedback"] = snap.feedback;
    result["model_error"] = snap.model_error;
    result["observed_error"] =
        std::isfinite(snap.observed_error) ? nlohmann::json(snap.observed_error) : nullptr;
  }
  if (snap.model_updates > 0 || observers.calibration->status().runs > 0) {
    const OnlineCalibrationStatus c = observers.calibration->status();
    result["calibration"] = {{"runs", c.runs},
                             {"applied", c.applied_runs},
                             {"youngs_modulus", youngs_modulus_of(snap.material)},
                             {"density", snap.material.density},
                             {"error", c.error}};
  }
  if (observers.receiver)
    result["datagrams"] = {{"received", observers.receiver->received()},
                           {"rejected", observers.receiver->rejected()}};
  if (observers.world) result["true_error"] = observers.world->true_error(snap.targets);
  if (!outcome.failure.empty()) result["reason"] = outcome.failure;
  return result;
}

void run(RunArgs args) {
  const double trust_region = feedback_trust_region(args.loop, "run");
  RunInputs inputs = load_run_inputs(args);
  const std::shared_ptr<SessionLog> log = open_session_log(args, inputs.scene);
  const auto link = make_run_link(args, inputs.scene, log);
  ControllerOptions options;
  options.tolerance = args.tolerance;
  options.trust_region = trust_region;
  Controller controller(inputs.scene, options);
  set_run_targets(controller, inputs.targets, log.get());
  if (observed(args)) controller.set_feedback(args.loop.feedback);
  OnlineCalibration calibration(controller, inputs.scene, inputs.calibration);
  Observers observers{inputs.world.get(), inputs.receiver.get(), &calibration};
  install_stop_signal_handlers();
  controller.start();
  link->start();
  const RunClock clock;
  if (args.arm) arm_when_ready(*link, clock);  // throws if it cannot
  const RunOutcome outcome = follow_optimizer(args, controller, *link, log.get(), clock, observers);
  calibration.cancel();  // a fit still running would hold both cores while the rest stops
  const LinkStatus final_status = stop_run(*link, controller, outcome.failure);
  const nlohmann::json result =
      run_result(outcome, final_status, *link, observers, *inputs.scene.robot->model);
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
  cmd->add_option("--log", args->log, "session log to write (JSON lines)")
      ->check(writable_output());
  add_session_log_options(*cmd, args->log_limits);
  cmd->add_flag("--until-settled", args->until_settled,
                "exit 0 once the targets are reached and the robot arrived; exit 2 with the "
                "reason if that cannot happen (best effort: the targets are unreachable)");
  cmd->add_option("--timeout", args->timeout, "seconds before giving up (0: none)")
      ->capture_default_str();
  add_tolerance_option(*cmd, args->tolerance);
  add_linear_solver_option(*cmd, args->linear_solver);
  add_link_options(*cmd, args->link_options);
  add_closed_loop_options(*cmd, args->loop, /*feedback_flag=*/true);
  cmd->add_option("--observations-udp", args->observations_udp,
                  "PORT: observed frames from a camera program, one JSON frame per datagram "
                  "(docs/calibration.md)");
  cmd->add_option("--observations-address", args->observations_address,
                  "local address for --observations-udp")
      ->capture_default_str();
  add_package_path_option(*cmd, args->package_paths);
  cmd->callback([args] { run(*args); });
}

}  // namespace shapectl::cli
