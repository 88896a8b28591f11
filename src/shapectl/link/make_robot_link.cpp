#include <shapectl/link/make_robot_link.hpp>

#include <cmath>

#include <shapectl/enum_names.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/link/egm_link.hpp>
#include <shapectl/link/sim_link.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

namespace {

void expect_positive(const char* name, double value) {
  if (!(value > 0 && std::isfinite(value)))
    throw InputError("link", name, "a positive number", value);
}

}  // namespace

namespace {
constexpr auto kLinkKinds =
    enum_names<LinkKind>(std::pair{LinkKind::Sim, "sim"}, std::pair{LinkKind::Egm, "egm"});
}  // namespace

const char* to_string(LinkKind kind) { return kLinkKinds.name(kind); }

bool parse(std::string_view name, LinkKind* kind) { return kLinkKinds.parse(name, kind); }

std::vector<std::string> link_kind_names() { return kLinkKinds.names(); }

void validate(const LinkConfig& c) {
  expect_positive("max_velocity", c.max_velocity);
  expect_positive("max_acceleration", c.max_acceleration);
  if (!(c.limit_margin >= 0 && std::isfinite(c.limit_margin)))
    throw InputError("link", "limit_margin", "a number >= 0", c.limit_margin);
  expect_positive("watchdog_timeout", c.watchdog_timeout);
  expect_positive("max_tracking_error", c.max_tracking_error);
  expect_positive("arrive_tolerance", c.arrive_tolerance);
  expect_positive("sim_period", c.sim_period);
  expect_positive("sim_acceleration", c.sim_acceleration);
  expect_positive("egm_period", c.egm_period);
  for (const auto& [name, port] :
       {std::pair{"egm_left_port", c.egm_left_port}, std::pair{"egm_right_port", c.egm_right_port}})
    if (port < 0 || port > 65535) throw InputError("link", name, "a port 0..65535", port);
}

GovernorLimits governor_limits(const LinkConfig& config, const RobotModel& robot) {
  const int n = robot.active_count();
  GovernorLimits g;
  g.lower = robot.lower_limits().array() + config.limit_margin;
  g.upper = robot.upper_limits().array() - config.limit_margin;
  // A range narrower than two margins: hold its middle.
  const Eigen::VectorXd middle = 0.5 * (robot.lower_limits() + robot.upper_limits());
  for (int i = 0; i < n; ++i)
    if (g.lower[i] > g.upper[i]) g.lower[i] = g.upper[i] = middle[i];
  // Never faster than the robot allows; a joint without a URDF speed gets the configured one.
  const Eigen::VectorXd robot_velocity = robot.velocity_limits();
  g.velocity = Eigen::VectorXd::Constant(n, config.max_velocity);
  for (int i = 0; i < n; ++i)
    if (std::isfinite(robot_velocity[i]) && robot_velocity[i] > 0)
      g.velocity[i] = std::min(g.velocity[i], robot_velocity[i]);
  g.acceleration = Eigen::VectorXd::Constant(n, config.max_acceleration);
  return g;
}

PoseCheck collision_pose_check(const RobotModel& robot,
                               std::shared_ptr<const CollisionModel> collisions) {
  if (!collisions) return {};
  auto model = std::make_shared<const RobotModel>(robot);
  return [model, collisions](const Eigen::VectorXd& joints, std::string* why) {
    // A fresh state per call: callers on several threads may check at once.
    const KinematicsState state = forward_kinematics(*model, joints);
    const double clearance = collisions->min_clearance(state);
    if (clearance >= 0) return true;
    if (why)
      *why = "self-collision (spheres overlap by " + std::to_string(-clearance * 1000) + " mm)";
    return false;
  };
}

std::unique_ptr<RobotLink> make_robot_link(const LinkConfig& config, const RobotModel& robot,
                                           std::shared_ptr<const CollisionModel> collisions,
                                           std::shared_ptr<SessionLog> log) {
  validate(config);
  PoseCheck check = collision_pose_check(robot, std::move(collisions));
  if (config.kind == LinkKind::Egm)
    return std::make_unique<EgmLink>(config, robot, std::move(check), std::move(log));
  return std::make_unique<SimLink>(config, robot, std::move(check), std::move(log));
}

}  // namespace shapectl
