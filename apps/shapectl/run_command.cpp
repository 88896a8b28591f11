// shapectl run SCENE.json --targets TARGETS.json [--robot sim|egm] [--arm] [--log LOG.jsonl]
//              [--until-settled] [--timeout S] [link options]
// The controller and the robot link without a GUI: the optimizer's best θ goes to the link
// whenever it changes; the link's governor moves the robot (only if armed). With
// --until-settled it exits 0 once the optimizer has converged and the robot has arrived, or 2
// with the reason when that cannot happen (optimizer stuck, link disarmed, timeout).
#include <chrono>
#include <iostream>
#include <thread>

#include <nlohmann/json.hpp>

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
  double timeout = 0;  // s; 0: none
  std::string robot = "sim";  // a LinkKind name
  LinkConfig link;
  double watchdog_ms = 100;
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
  if (s.status == ControllerStatus::Stuck) return "optimizer stuck: no acceptable step (error " + std::to_string(s.error.mean) + " m)";
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

void run(RunArgs args) {
  const Scene scene = load_scene(args.scene);
  print_scene_notes(scene);
  if (!scene.robot) throw InputError(args.scene, "robot", "run needs a scene with a robot");
  const TargetsInput targets = load_targets(args.targets, scene.object_mesh->node_count());
  parse(args.robot, &args.link.kind);  // checked by the option
  args.link.watchdog_timeout = args.watchdog_ms / 1000;
  args.link.sim_initial_joints = scene.robot->reference_joints;
  if (args.timeout < 0) throw InputError("run", "--timeout", "a number >= 0", args.timeout);

  std::shared_ptr<SessionLog> log;
  if (!args.log.empty()) {
    log = std::make_shared<SessionLog>(args.log);
    log->write("session", {{"command", "run"},
                           {"scene", std::filesystem::absolute(args.scene).string()},
                           {"targets_file", args.targets},
                           {"robot", to_string(args.link.kind)},
                           {"joint_names", scene.robot->model->active_joint_names()}});
  }
  auto link = make_robot_link(args.link, *scene.robot->model, scene.robot->collisions, log);
  if (auto* egm = dynamic_cast<EgmLink*>(link.get()))
    std::cerr << "run: EGM on " << args.link.egm_address << " ports " << egm->port(0)
              << (egm->channels().size() > 1 ? " and " + std::to_string(egm->port(1)) : "") << "\n";

  Controller controller(scene);
  if (targets.centerline.empty()) controller.set_targets(targets.targets);
  else controller.set_centerline(targets.centerline);
  if (log) {
    log->write("targets", {{"nodes", targets.targets.nodes},
                           {"positions", points_json(targets.targets.positions)},
                           {"centerline", points_json(targets.centerline)}});
  }
  install_stop_signal_handlers();
  controller.start();
  link->start();

  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  bool armed_once = false;
  if (args.arm) {
    // Arming needs feedback; give the robot a moment to appear.
    std::string why;
    while (!link->arm(&why)) {
      if (elapsed() > 5 || stop_signal_received()) throw SolverFailure("cannot arm the robot link: " + why);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    armed_once = true;
    std::cerr << "run: armed\n";
  }

  std::uint64_t seen = 0;
  std::string last_report;
  std::string failure;
  bool settled = false;
  std::shared_ptr<const ControllerSnapshot> snap = controller.snapshot();
  while (!stop_signal_received()) {
    snap = controller.wait_for_snapshot(seen, 0.02);
    if (snap->sequence > seen) {
      seen = snap->sequence;
      link->set_target(snap->joints, snap->safe);
      if (log) log_snapshot(*log, *snap);
    }
    const LinkStatus st = link->status();
    // A progress line whenever the state changes.
    const std::string report = std::string(to_string(snap->status)) + "; robot " +
                               (st.connected ? "connected" : "not connected") + ", " +
                               (st.armed ? (st.arrived ? "arrived" : "moving") : "not armed: " + st.reason);
    if (report != last_report) {
      std::cerr << "run: " << elapsed() << " s: " << report << " (error " << snap->error.mean * 1000 << " mm)\n";
      last_report = report;
    }
    if (args.until_settled) {
      failure = cannot_settle(*snap, st, armed_once);
      if (!failure.empty()) break;
      if (snap->status == ControllerStatus::Converged) {
        // Not armed, the robot is never asked to move: it cannot arrive, so say so.
        if (!armed_once) {
          failure = "the optimizer converged, but the robot is not armed (--arm), so it cannot arrive";
          break;
        }
        if (st.arrived) {
          settled = true;
          break;
        }
      }
    }
    if (args.timeout > 0 && elapsed() >= args.timeout) {
      if (args.until_settled)
        failure = "not settled after " + std::to_string(args.timeout) + " s: optimizer " +
                  to_string(snap->status) + ", robot " + (st.arrived ? "arrived" : "not arrived");
      break;
    }
  }
  // Leave the robot standing: disarm, give the governor time to brake, then stop.
  link->disarm(failure.empty() ? "run finished" : failure);
  for (int k = 0; k < 300 && link->status().commanded != link->status().measured; ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  controller.stop();
  const LinkStatus final_status = link->status();
  link->stop();

  nlohmann::json result = {{"settled", settled},
                           {"status", to_string(snap->status)},
                           {"error_mean", snap->error.mean},
                           {"error_max", snap->error.max},
                           {"iterations", snap->iterations},
                           {"joint_names", snap->joint_names},
                           {"joints", vector_json(snap->joints)},
                           {"link", link_json(final_status)}};
  if (auto* egm = dynamic_cast<EgmLink*>(link.get())) {
    const LatencyStats l = egm->latency();
    result["latency_us"] = {{"samples", l.samples}, {"median", l.median_us}, {"p99", l.p99_us}, {"max", l.max_us}};
  }
  if (!failure.empty()) result["reason"] = failure;
  if (log) log->write("end", {{"settled", settled}, {"reason", failure}});
  std::cout << result.dump(2) << "\n";
  if (!failure.empty()) throw SolverFailure(failure);
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
  cmd->add_option("--timeout", args->timeout, "seconds before giving up (0: none)")->capture_default_str();
  cmd->add_option("--max-velocity", args->link.max_velocity, "rad/s per joint (capped by the robot's own)")
      ->capture_default_str();
  cmd->add_option("--max-acceleration", args->link.max_acceleration, "rad/s² per joint")->capture_default_str();
  cmd->add_option("--limit-margin", args->link.limit_margin, "rad kept from each joint limit")->capture_default_str();
  cmd->add_option("--watchdog-ms", args->watchdog_ms, "feedback gap that holds and disarms, ms")->capture_default_str();
  cmd->add_option("--egm-address", args->link.egm_address, "local address for the EGM ports")->capture_default_str();
  cmd->add_option("--egm-left-port", args->link.egm_left_port, "UDP port of the left arm (ROB_L)")->capture_default_str();
  cmd->add_option("--egm-right-port", args->link.egm_right_port, "UDP port of the right arm (ROB_R)")->capture_default_str();
  cmd->callback([args] { run(*args); });
}

}  // namespace shapectl::cli
