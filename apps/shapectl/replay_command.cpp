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
#include <shapectl/io/json_eigen.hpp>
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
std::string restream(const ReplayArgs& args, const std::vector<LoggedEvent>& events) {
  std::string scene_file = args.scene;
  for (const auto& e : events)
    if (scene_file.empty() && e.event == "session" && e.fields.contains("scene"))
      scene_file = e.fields["scene"].get<std::string>();
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
  for (const auto& e : events) {
    if (e.event != "optimizer" || stop_signal_received()) continue;
    const Eigen::VectorXd joints = vector_from_json(e.fields.at("joints"));
    if (joints.size() != n)
      throw InputError(args.log + ":" + std::to_string(e.line), "joints",
                       std::to_string(n) + " values for " + scene_file, joints.size());
    std::this_thread::sleep_until(start +
                                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(e.t / args.speed)));
    link->set_target(joints, e.fields.value("safe", false));
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
  if (!(args.speed > 0)) throw InputError("replay", "--speed", "a positive number", args.speed);
  int truncated = 0;
  const auto events = read_session_log(args.log, &truncated);
  const CommandLogCheck check = check_command_log(events, args.log);
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
  if (!args.robot.empty()) failure = restream(args, events);
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
