// shapectl serve [SCENE.json] [--host 127.0.0.1] [--port 8080] [--robot none|sim|egm]
//                [link options] [--log LOG.jsonl] [--web-root DIR] [--package-path DIR]...
// The browser GUI: serves web/ over HTTP and the session over a WebSocket at /ws
// (docs/gui.md).
#include <iostream>

#include <shapectl/calib/simulated_world.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/server/server.hpp>
#include <shapectl/server/web_paths.hpp>

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

struct ServeArgs {
  std::string scene;
  std::string host = "127.0.0.1";
  int port = 8080;
  std::string robot = "none";
  LinkArgs link;
  std::string log;
  SessionLogLimits log_limits;  // --log-max-mb, --log-keep
  std::string web_root;
  std::string scenes_dir;
  double rate = 30;
  double tolerance = 1e-3;  // m
  ClosedLoopArgs loop;      // the simulated real object, the online calibration
  // --package-path: the URDF's package:// meshes
  std::vector<std::string> package_paths;
  std::string linear_solver;
};

// The session log if --log names one, opened with a "session" event; else null.
std::shared_ptr<SessionLog> open_serve_log(const ServeArgs& args,
                                           const std::filesystem::path& scene,
                                           const Scene& description) {
  if (args.log.empty()) return nullptr;
  auto log = std::make_shared<SessionLog>(args.log, args.log_limits);
  log->write_header("session", {{"command", "serve"},
                                {"scene", std::filesystem::absolute(scene).string()},
                                {"robot", args.robot},
                                {"joint_names", description.robot->model->active_joint_names()}});
  return log;
}

void run_serve(const ServeArgs& args) {
  check_linear_solver_option("serve", args.linear_solver);
  server::ServerOptions options;
  options.host = args.host;
  options.port = static_cast<unsigned short>(args.port);
  options.state_rate = args.rate;
  options.web_root =
      args.web_root.empty() ? server::default_web_root() : std::filesystem::path(args.web_root);
  if (!std::filesystem::is_regular_file(options.web_root / "index.html"))
    throw InputError("serve", "--web-root", "a directory with index.html",
                     options.web_root.string());
  ControllerOptions controller_options;
  controller_options.trust_region = feedback_trust_region(args.loop, "serve");
  const std::filesystem::path scenes_dir = args.scenes_dir.empty()
                                               ? server::default_scenes_dir()
                                               : std::filesystem::path(args.scenes_dir);
  const std::filesystem::path scene =
      args.scene.empty() ? scenes_dir / "yumi_bar.json" : std::filesystem::path(args.scene);

  // The robot link follows the optimizer's θ; it starts disarmed (arm from the page).
  std::unique_ptr<RobotLink> link;
  std::shared_ptr<SessionLog> log;
  if (args.robot != "none" || !args.log.empty()) {
    const Scene description = load_scene(scene);
    if (!description.robot)
      throw InputError(scene.string(), "robot",
                       "a robot for " + (args.robot == "none" ? "--log" : "--robot " + args.robot));
    LinkKind kind = LinkKind::Sim;
    parse(args.robot, &kind);  // checked by the option; "none" leaves it
    const LinkConfig config = link_config(args.link, kind, description.robot->reference_joints);
    log = open_serve_log(args, scene, description);
    if (args.robot != "none") {
      link = make_robot_link(config, *description.robot->model, description.robot->collisions, log);
      link->start();
    }
  }
  controller_options.tolerance = args.tolerance;
  controller_options.linear_solver = linear_solver_override(args.linear_solver);
  server::Session session(scene, server::find_bundled_scenes(scenes_dir), link.get(),
                          controller_options, online_calibration_options(args.loop, "serve"),
                          package_paths(args.package_paths));
  print_robot_notes(session.controller().robot(), args.package_paths);
  session.set_log(log.get());
  if (!args.loop.world.empty()) {
    if (args.robot != "sim")
      throw InputError("serve", "--world", "--robot sim (a real robot holds a real object)");
    // Markers on the target nodes, set at every tick.
    const SimulatedCamera camera = simulated_camera(args.loop, "serve");
    Scene world = load_scene(scene);
    apply_linear_solver_option(args.linear_solver, world);
    session.set_world(simulated_world(args.loop, world, camera));
  }
  server::Server server(session, options);
  std::cout << "shapectl serve: open " << server.url() << " (scene " << session.scene_name()
            << "; Ctrl-C stops)" << std::endl;
  if (args.host != "127.0.0.1" && args.host != "::1")
    std::cerr << "serve: warning: listening on " << args.host
              << ": anyone who can reach this port can move the robot (see docs/gui.md)\n";
  server.run();
  session.set_log(nullptr);
  if (link) link->stop();
  if (log) log->write("end", {{"reason", "serve stopped"}});
  std::cout << "shapectl serve: stopped" << std::endl;
}

}  // namespace

void add_serve_command(CLI::App& app) {
  auto args = std::make_shared<ServeArgs>();
  CLI::App* cmd =
      app.add_subcommand("serve",
                         "Browser GUI: drag targets, sketch centre-lines, watch the robot follow");
  cmd->add_option("scene", args->scene, "Scene JSON (default: scenes/yumi_bar.json)");
  cmd->add_option("--host", args->host,
                  "Address to listen on; anything but loopback exposes the robot")
      ->capture_default_str();
  cmd->add_option("--port", args->port, "TCP port; 0 picks a free one")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  cmd->add_option("--robot", args->robot, "Robot link following the optimizer (starts disarmed)")
      ->check(CLI::IsMember({"none", "sim", "egm"}))
      ->capture_default_str();
  add_link_options(*cmd, args->link);
  cmd->add_option("--log", args->log,
                  "session log to write (JSON lines, as `run --log`; `shapectl replay` reads it)")
      ->check(writable_output());
  add_session_log_options(*cmd, args->log_limits);
  cmd->add_option("--web-root", args->web_root,
                  "Directory with index.html (default: the repository's web/)");
  cmd->add_option("--scenes-dir", args->scenes_dir,
                  "Scenes offered for switching (default: scenes/)");
  add_closed_loop_options(*cmd, args->loop, /*feedback_flag=*/false);
  cmd->add_option("--rate", args->rate, "State messages per second to each page")
      ->check(CLI::Range(1.0, 120.0))
      ->capture_default_str();
  add_package_path_option(*cmd, args->package_paths);
  add_tolerance_option(*cmd, args->tolerance);
  add_linear_solver_option(*cmd, args->linear_solver);
  cmd->callback([args] { run_serve(*args); });
}

}  // namespace shapectl::cli
