// shapectl egm-sim [--address A] [--left-port P] [--right-port P] [--scene SCENE.json]
//                  [--duration S] [--acceleration A]
// Stands in for a YuMi controller's EGM side: sends feedback at 250 Hz to the sensor's ports and
// moves simulated arms by the commands it gets back. Prints what it received as JSON at the end.
#include <chrono>
#include <iostream>
#include <thread>

#include <nlohmann/json.hpp>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/link/egm_simulator.hpp>
#include <shapectl/link/stop_signal.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "commands.hpp"

namespace shapectl::cli {

namespace {

struct EgmSimArgs {
  std::string address = "127.0.0.1";
  int left_port = 6511;
  int right_port = 6512;
  std::string scene;
  double duration = 0;  // 0: until Ctrl-C
  double acceleration = 10;
};

// The scene's reference joints of one arm, chain order; zeros when it names none.
ArmJoints arm_from_scene(const Scene& scene, const char* suffix) {
  ArmJoints q = ArmJoints::Zero();
  if (!scene.robot) return q;
  const RobotModel& robot = *scene.robot->model;
  const int axes[7] = {1, 2, 7, 3, 4, 5, 6};
  for (int i = 0; i < 7; ++i) {
    const auto joint = robot.find_joint("yumi_joint_" + std::to_string(axes[i]) + "_" + suffix);
    if (joint && robot.active_index(*joint) >= 0)
      q[i] = scene.robot->reference_joints[robot.active_index(*joint)];
  }
  return q;
}

nlohmann::json arm_json(const EgmSimArmStats& s) {
  return {{"feedback_sent", s.feedback_sent},
          {"commands", s.commands},
          {"rejected", s.rejected},
          {"max_speed", s.max_speed},
          {"max_acceleration", s.max_acceleration},
          {"outside_limits", s.outside_limits},
          {"position", vector_json(s.position)}};
}

void run_egm_sim(const EgmSimArgs& args) {
  if (args.duration < 0) throw InputError("egm-sim", "--duration", "a number >= 0", args.duration);
  if (!(args.acceleration > 0))
    throw InputError("egm-sim", "--acceleration", "a positive number", args.acceleration);
  EgmSimulatorConfig config;
  config.sensor_address = args.address;
  config.left_port = args.left_port;
  config.right_port = args.right_port;
  config.acceleration = args.acceleration;
  if (!args.scene.empty()) {
    const Scene scene = load_scene(args.scene);
    config.left_initial = arm_from_scene(scene, "l");
    config.right_initial = arm_from_scene(scene, "r");
  }
  EgmSimulator sim(config);
  install_stop_signal_handlers();
  sim.start();
  std::cerr << "egm-sim: sending EGM feedback to " << args.address << " ports " << args.left_port
            << " (left), " << args.right_port << " (right) at 250 Hz\n";
  const auto start = std::chrono::steady_clock::now();
  while (!stop_signal_received()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (args.duration > 0 && elapsed >= args.duration) break;
  }
  sim.stop();
  nlohmann::json out = nlohmann::json::object();
  if (args.left_port > 0) out["left"] = arm_json(sim.stats(0));
  if (args.right_port > 0) out["right"] = arm_json(sim.stats(1));
  std::cout << out.dump(2) << "\n";
}

}  // namespace

void add_egm_sim_command(CLI::App& app) {
  auto args = std::make_shared<EgmSimArgs>();
  auto* cmd =
      app.add_subcommand("egm-sim", "Stand-in for the YuMi controller's EGM side (testing)");
  cmd->add_option("--address", args->address,
                  "IPv4 address the sensor (shapectl run/serve) listens on")
      ->capture_default_str();
  cmd->add_option("--left-port", args->left_port, "left arm's sensor port (0: no left arm)")
      ->capture_default_str();
  cmd->add_option("--right-port", args->right_port, "right arm's sensor port (0: no right arm)")
      ->capture_default_str();
  cmd->add_option("--scene", args->scene, "start the arms at this scene's reference joints");
  cmd->add_option("--duration", args->duration, "seconds to run (0: until Ctrl-C)")
      ->capture_default_str();
  cmd->add_option("--acceleration", args->acceleration,
                  "simulated arms' acceleration limit, rad/s²")
      ->capture_default_str();
  cmd->callback([args] { run_egm_sim(*args); });
}

}  // namespace shapectl::cli
