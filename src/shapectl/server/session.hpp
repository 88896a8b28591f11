#pragma once
// One interactive session shared by every connected page: the controller of the current scene,
// the bundled scenes to switch between, the error history for the convergence plot and,
// optionally, a robot link. Commands come in as protocol text; what goes out (scene
// descriptions, states, position frames) is encoded here once and broadcast by the server.
//
// Not thread-safe: the server calls it from its one network thread. The controller it owns
// runs its optimizer in a thread of its own.
#include <chrono>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <shapectl/calib/online_calibration.hpp>
#include <shapectl/calib/simulated_world.hpp>
#include <shapectl/control/controller.hpp>
#include <shapectl/robot/visual_meshes.hpp>
#include <shapectl/server/protocol.hpp>

namespace shapectl {
class ObjectStatics;
class RobotLink;
class SessionLog;
}  // namespace shapectl

namespace shapectl::server {

// Appends `s` as an "optimizer" event: what the robot link was sent (`run`, `serve --log`).
void log_snapshot(SessionLog& log, const ControllerSnapshot& s);
// The plausibility gate's counts and the feedback's authority: the states' "gate" and
// "authority" (docs/gui.md).
nlohmann::json gate_json(const GateCounts& g);
nlohmann::json authority_json(const FeedbackAuthority& a);
// Appends a "gate" event (counts, authority, the newest problem) when the gate rejected a marker
// or a frame since `logged`, which then takes the snapshot's counts.
void log_gate(SessionLog& log, const ControllerSnapshot& s, GateCounts& logged);

struct SceneEntry {
  std::string name;  // what clients ask for, e.g. "yumi_bar.json"
  std::filesystem::path path;
};

// The scenes (*.json with a "robot") in `directory`, sorted by name; unreadable files skipped.
std::vector<SceneEntry> find_bundled_scenes(const std::filesystem::path& directory);

struct HistorySample {
  double time = 0;        // s since the scene was loaded
  double error_mean = 0;  // m
  bool editing = false;   // a target edit arrived within the last `editing_window` s
};

class Session {
 public:
  // Loads `scene` (an InputError if it is bad) and starts its controller. `scenes` are what
  // load_scene may switch to; `scene` is added to them if absent. `link` may be null; with a
  // link, only the scenes with its robot's active joints are offered.
  // Observed frames (`observe`, the simulated world) go through an OnlineCalibration made
  // with `calibration`. The URDF's package:// meshes are searched in `package_paths`.
  Session(const std::filesystem::path& scene, std::vector<SceneEntry> scenes,
          RobotLink* link = nullptr, ControllerOptions options = {},
          OnlineCalibrationOptions calibration = {},
          std::vector<std::filesystem::path> package_paths = {});
  ~Session();

  struct Reply {
    std::string text;  // "ok" or "error" message for the sender
    bool ok = false;
    std::string log;             // a line for the server log when the message was bad
    bool scene_changed = false;  // broadcast scene_message() to everyone
  };
  // Validates and applies one client message; never throws for bad input.
  Reply handle(std::string_view text);

  // Called at the streaming rate: samples the history, forwards θ to the link, with a
  // simulated world settles it at the link's measured joints and sends its camera's
  // observations (markers on the current target nodes) to the closed loop, and hands a
  // finished calibration to the controller.
  void tick();
  // `serve --world`: the simulated real object; needs a link (its measured joints) and holds
  // only for the scene it was made for (the session then offers no other).
  void set_world(std::unique_ptr<SimulatedWorld> world);
  // `serve --log`: each new snapshot tick() sends to the link also goes to `log` as an
  // "optimizer" event, each scene switch as a "scene" event. `log` must outlive the session;
  // null stops logging.
  void set_log(SessionLog* log) { log_ = log; }
  // JSON "scene" message: static description (robot geometry, mesh triangles, grips, scene
  // list, limits, history). Sent on connect and after a scene switch.
  std::string scene_message() const;
  // The file of the scene robot's visual mesh `index` (its "url" in the scene message) if it was
  // found, has that extension and is still within max_visual_mesh_bytes; else nullopt.
  std::optional<std::filesystem::path> robot_mesh_file(std::size_t index,
                                                       std::string_view extension) const;
  // JSON "state" message for the latest snapshot (at most as old as the last tick()).
  std::string state_message(int clients) const;
  std::shared_ptr<const ControllerSnapshot> snapshot() const { return snapshot_; }
  // True while the optimizer works (streaming at full rate matters then).
  bool busy() const;

  Controller& controller() { return *controller_; }
  const OnlineCalibration& calibration() const { return *calibration_; }
  const std::string& scene_name() const { return scene_name_; }

  static constexpr double editing_window = 0.3;  // s
  static constexpr std::size_t history_capacity = 6000;

 private:
  void load(const SceneEntry& entry);
  void apply(const Command& command);
  ProtocolContext context() const;
  nlohmann::json describe_scene() const;
  double now() const;
  void observe_world(double time);
  void update_contacts();

  std::vector<SceneEntry> scenes_;
  std::string scene_name_;
  RobotLink* link_;
  ControllerOptions options_;
  OnlineCalibrationOptions calibration_options_;
  std::unique_ptr<Controller> controller_;
  std::unique_ptr<OnlineCalibration> calibration_;  // of controller_: destroyed before it
  std::shared_ptr<const ControllerSnapshot> snapshot_;
  nlohmann::json scene_description_;  // the static part of scene_message()
  std::vector<std::filesystem::path> package_paths_;
  std::vector<VisualMesh> robot_meshes_;  // of the current scene's robot, found or not
  // The scene object's energy, for its contact terms (null without obstacles and self-contact):
  // the same obstacles, d̂ and κ as the controller's statics. The states' "contacts", of the
  // snapshot contacts_sequence_.
  std::unique_ptr<ObjectStatics> statics_;
  nlohmann::json contacts_;
  std::uint64_t contacts_sequence_ = 0;
  ShapeTargets targets_;  // node targets as the clients set them (a centre-line clears them)
  std::chrono::steady_clock::time_point started_;
  double last_edit_time_ = -1e9;
  std::deque<HistorySample> history_;
  std::unique_ptr<SimulatedWorld> world_;
  double true_error_ = NAN;  // the world's, at the last tick (NaN without a world or targets)
  SessionLog* log_ = nullptr;
  std::uint64_t logged_sequence_ = 0;  // of the last snapshot written to log_
  GateCounts logged_gate_;             // the gate's counts last written to log_
  // `observe` messages refused (bad frame: joints outside their limits, unknown nodes, ...)
  // and why the newest was; in the state message.
  std::uint64_t observations_rejected_ = 0;
  std::string observation_rejection_;
};

}  // namespace shapectl::server
