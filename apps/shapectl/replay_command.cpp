// shapectl replay LOG.jsonl [--robot sim|egm] [--arm] [--speed X] [--scene SCENE.json] [...]
// Reads a session log, checks every logged command against the limits the log states and
// prints a summary; with --robot it replays the session: the logged optimizer results go to a
// robot link at their logged times (its governor enforces the limits again). Exit 2 when the
// log shows a violated limit or the replayed link disarms.
#include <chrono>
#include <iostream>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/command_log.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/link/stop_signal.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "commands.hpp"

namespace shapectl::cli {

namespace {

struct ReplayArgs {
  std::string log;
  std::string robot;  // empty: check only
  std::string scene;  // default: the one the log names
  bool arm = false;
  double speed = 1;
  LinkConfig link;
};

// Re-streams the logged optimizer results; returns why the link disarmed, or empty.
std::string restream(const ReplayArgs& args, const CommandLogCheck& check) {
  const std::string scene_file = args.scene.empty() ? check.scene : args.scene;
  if (scene_file.empty())
    throw InputError(args.log, "", "names no scene (no \"session\" event); pass --scene");
  const Scene scene = load_scene(scene_file);
  if (!scene.robot) throw InputError(scene_file, "robot", "replay needs a scene with a robot");
  LinkConfig config = args.link;
  parse(args.robot, &config.kind);  // checked by the option
  config.sim_initial_joints = scene.robot->reference_joints;
  auto link = make_robot_link(config, *scene.robot->model, scene.robot->collisions);
  install_stop_signal_handlers();
  link->start();
  const auto start = std::chrono::steady_clock::now();
  if (args.arm) {
    std::string why;
    while (!link->arm(&why)) {
      if (std::chrono::steady_clock::now() - start > std::chrono::seconds(5) ||
          stop_signal_received())
        throw SolverFailure("cannot arm the robot link: " + why);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  const int n = scene.robot->model->active_count();
  int sent = 0;
  for (const auto& r : check.optimizer_results) {
    if (stop_signal_received()) break;
    if (r.joints.size() != n)
      throw InputError(args.log + ":" + std::to_string(r.line), "joints",
                       std::to_string(n) + " values for " + scene_file, r.joints.size());
    std::this_thread::sleep_until(start +
                                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(r.t / args.speed)));
    link->set_target(r.joints, r.safe);
    ++sent;
  }
  // Let the robot finish the last target.
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (args.arm && link->status().armed && !link->status().arrived &&
         std::chrono::steady_clock::now() < end && !stop_signal_received())
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const LinkStatus s = link->status();
  std::cerr << "replay: " << sent << " optimizer results streamed to the " << s.kind << " robot; "
            << (s.armed ? (s.arrived ? "arrived" : "armed, not arrived") : "not armed: " + s.reason)
            << "\n";
  const std::string failure = args.arm && !s.armed ? s.reason : "";
  link->disarm("replay finished");
  link->stop();
  return failure;
}

void replay(const ReplayArgs& args) {
  // Bounded: a logged time (at most 1e9 s) over the speed stays a duration we can sleep until.
  if (!(args.speed >= 1e-3 && args.speed <= 1e3))
    throw InputError("replay", "--speed", "a number from 0.001 to 1000", args.speed);
  int truncated = 0;
  const auto events = read_session_log(args.log, &truncated);
  if (events.empty())
    throw InputError(args.log, "", "an empty log: expected JSON lines with \"t\" and \"event\"");
  const CommandLogCheck check = check_command_log(events, args.log);
  if (check.commands == 0 && check.optimizer_results.empty() && check.ok())
    throw InputError(args.log, "",
                     "nothing to check: expected \"command\" or \"optimizer\" events, got " +
                         std::to_string(events.size()) + " other events");
  std::map<std::string, int> counts;
  for (const auto& e : events) ++counts[e.event];
  nlohmann::json summary = {{"events", events.size()},
                            {"truncated_lines", truncated},
                            {"duration", events.empty() ? 0.0 : events.back().t},
                            {"counts", counts},
                            {"commands_checked", check.commands},
                            {"velocity_ratio", check.velocity_ratio},
                            {"acceleration_ratio", check.acceleration_ratio},
                            {"violations", check.violations}};
  std::string failure;
  if (!args.robot.empty()) failure = restream(args, check);
  if (!failure.empty()) summary["replay_failure"] = failure;
  std::cout << summary.dump(2) << "\n";
  if (!check.ok()) throw SolverFailure(check.violations.front());
  if (!failure.empty()) throw SolverFailure("replayed link disarmed: " + failure);
}

}  // namespace

void add_replay_command(CLI::App& app) {
  auto args = std::make_shared<ReplayArgs>();
  auto* cmd = app.add_subcommand("replay", "Check a session log and replay it to a robot link");
  cmd->add_option("log", args->log, "LOG.jsonl written by run --log")->required();
  cmd->add_option("--robot", args->robot, "replay to this link: sim or egm (default: check only)")
      ->check(CLI::IsMember(link_kind_names()));
  cmd->add_flag("--arm", args->arm, "arm the link so the robot moves");
  cmd->add_option("--speed", args->speed, "time scale (2: twice as fast)")->capture_default_str();
  cmd->add_option("--scene", args->scene, "SCENE.json (default: the one the log names)");
  cmd->add_option("--max-velocity", args->link.max_velocity, "rad/s per joint")
      ->capture_default_str();
  cmd->add_option("--max-acceleration", args->link.max_acceleration, "rad/s² per joint")
      ->capture_default_str();
  cmd->add_option("--egm-address", args->link.egm_address, "local address for the EGM ports")
      ->capture_default_str();
  cmd->add_option("--egm-left-port", args->link.egm_left_port, "UDP port of the left arm")
      ->capture_default_str();
  cmd->add_option("--egm-right-port", args->link.egm_right_port, "UDP port of the right arm")
      ->capture_default_str();
  cmd->callback([args] { replay(*args); });
}

}  // namespace shapectl::cli
