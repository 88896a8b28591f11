#include "link_options.hpp"

namespace shapectl::cli {

void add_link_options(CLI::App& cmd, LinkArgs& args) {
  LinkConfig& c = args.config;
  cmd.add_option("--max-velocity", c.max_velocity, "rad/s per joint (capped by the robot's own)")
      ->capture_default_str();
  cmd.add_option("--max-acceleration", c.max_acceleration, "rad/s² per joint")
      ->capture_default_str();
  cmd.add_option("--limit-margin", c.limit_margin, "rad kept from each joint limit")
      ->capture_default_str();
  cmd.add_option("--watchdog-ms", args.watchdog_ms, "feedback gap that holds and disarms, ms")
      ->capture_default_str();
  cmd.add_option("--egm-address", c.egm_address, "local address for the EGM ports")
      ->capture_default_str();
  cmd.add_option("--egm-left-port", c.egm_left_port, "UDP port of the left arm (ROB_L)")
      ->capture_default_str();
  cmd.add_option("--egm-right-port", c.egm_right_port, "UDP port of the right arm (ROB_R)")
      ->capture_default_str();
}

LinkConfig link_config(const LinkArgs& args, LinkKind kind, const Eigen::VectorXd& initial_joints) {
  LinkConfig config = args.config;
  config.kind = kind;
  config.watchdog_timeout = args.watchdog_ms / 1000;
  config.sim_initial_joints = initial_joints;
  validate(config);
  return config;
}

}  // namespace shapectl::cli
