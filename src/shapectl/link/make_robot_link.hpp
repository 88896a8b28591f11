#pragma once
// Building a robot link from settings: LinkConfig (what the CLI flags and the server set) and
// make_robot_link (the factory the CLI and the server call).
//
//   LinkConfig config;                 // defaults: sim robot, conservative motion limits
//   config.kind = LinkKind::Egm;
//   auto link = make_robot_link(config, scene.robot->model, scene.robot->collisions, log);
//   link->start();
//   link->set_target(snapshot->joints, snapshot->safe);   // whenever a snapshot appears
//   link->arm(&why);  link->disarm("user");  link->status();
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include <shapectl/link/link_supervisor.hpp>
#include <shapectl/link/robot_link.hpp>

namespace shapectl {

class CollisionModel;
class RobotModel;
class SessionLog;

// Sim: the in-process robot; Egm: ABB EGM over UDP (YuMi).
enum class LinkKind { Sim, Egm };
// "sim", "egm": the names of `--robot` and of the state's "link.kind" (web/js/protocol.js).
const char* to_string(LinkKind kind);
bool parse(std::string_view name, LinkKind* kind);
std::vector<std::string> link_kind_names();

struct LinkConfig {
  LinkKind kind = LinkKind::Sim;

  // Motion governor, per joint. The velocity is capped by the robot's own limit (URDF).
  double max_velocity = 0.5;        // rad/s
  double max_acceleration = 1.0;    // rad/s²
  double limit_margin = 0.02;       // rad kept from each joint limit
  double watchdog_timeout = 0.1;    // s without feedback: hold and disarm
  double max_tracking_error = 0.2;  // rad, commanded vs measured while armed
  double arrive_tolerance = 1e-3;   // rad, measured vs target for "arrived"

  // sim
  double sim_period = 0.004;           // s between commands
  double sim_acceleration = 10;        // rad/s², the simulated robot's own limit
  Eigen::VectorXd sim_initial_joints;  // where it starts (active order); empty: 0 in limits

  // egm
  std::string egm_address = "0.0.0.0";  // local address the ports bind to
  int egm_left_port = 6511;             // ROB_L's UdpUc device sends here; 0: any free port
  int egm_right_port = 6512;            // ROB_R
  double egm_period = 0.004;            // s, the controller's \SampleRate (one step per message)
};

// InputError "link: max_velocity: expected a positive number, got -1" and similar.
void validate(const LinkConfig& config);

// The limits the link enforces for `robot`'s active joints: band = joint limits − margin,
// velocity = min(max_velocity, robot's), acceleration = max_acceleration.
GovernorLimits governor_limits(const LinkConfig& config, const RobotModel& robot);

// Self-collision check of a pose (spheres overlapping); empty when `collisions` is null.
PoseCheck collision_pose_check(const RobotModel& robot,
                               std::shared_ptr<const CollisionModel> collisions);

// The link `config.kind` names, for `robot` (copied). `collisions` and `log` may be null.
// InputError for bad settings, an unknown kind, a robot that is not YuMi-like for "egm", or a
// port that cannot be bound.
std::unique_ptr<RobotLink> make_robot_link(const LinkConfig& config, const RobotModel& robot,
                                           std::shared_ptr<const CollisionModel> collisions = {},
                                           std::shared_ptr<SessionLog> log = {});

}  // namespace shapectl
