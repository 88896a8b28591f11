#include "grasp_axes.hpp"

#include <cmath>

#include <shapectl/io/input_error.hpp>
#include <shapectl/robot/kinematics.hpp>

namespace shapectl::cli {

namespace {
const double min_axis_angle = std::sin(10 * M_PI / 180);  // |a × c| below this: too parallel

// Whether `link` is `ancestor` or below it.
bool in_subtree(const RobotModel& model, int link, int ancestor) {
  for (int l = link; l >= 0;) {
    if (l == ancestor) return true;
    const int parent_joint = model.links()[static_cast<std::size_t>(l)].parent_joint;
    if (parent_joint < 0) return false;
    l = model.joints()[static_cast<std::size_t>(parent_joint)].parent_link;
  }
  return false;
}
}  // namespace

std::optional<Vec3> finger_axis(const RobotModel& model, int tool_link) {
  const KinematicsState zero =
      forward_kinematics(model, Eigen::VectorXd::Zero(model.active_count()));
  const Eigen::Matrix3d R_link_world =
      zero.T_world_link[static_cast<std::size_t>(tool_link)].linear().transpose();
  // The tool link and the links it is fixed to, up to the first movable joint.
  for (int hand = tool_link; hand >= 0;) {
    for (const Joint& joint : model.joints())
      if (joint.parent_link == hand && joint.type == JointType::Prismatic &&
          !in_subtree(model, tool_link, joint.child_link))
        return (R_link_world *
                zero.T_world_link[static_cast<std::size_t>(joint.child_link)].linear() * joint.axis)
            .normalized();
    const int parent_joint = model.links()[static_cast<std::size_t>(hand)].parent_joint;
    if (parent_joint < 0 || model.joints()[static_cast<std::size_t>(parent_joint)].movable()) break;
    hand = model.joints()[static_cast<std::size_t>(parent_joint)].parent_link;
  }
  return std::nullopt;
}

Vec3 closing_axis_link(const GraspAxes& axes, const RobotModel& model, int tool_link) {
  return axes.closing_link ? *axes.closing_link
                           : finger_axis(model, tool_link).value_or(Vec3(Vec3::UnitY()));
}

void orient_goal(const GraspAxes& axes, const RobotModel& model,
                 const Eigen::Matrix3d& R_world_link, const std::string& option, IkGoal& goal) {
  if (!axes.approach_world && !axes.closing_world) return;
  const Vec3 closing_link = closing_axis_link(axes, model, goal.link);
  if (!axes.closing_world) {
    goal.axis_link = axes.approach_link;
    goal.axis_world = *axes.approach_world;
    return;
  }
  // The fingers close symmetrically: the closing direction nearer the start's.
  Vec3 closing = *axes.closing_world;
  if (closing.dot(R_world_link * closing_link) < 0) closing = -closing;
  if (!axes.approach_world) {
    goal.axis_link = closing_link;
    goal.axis_world = closing;
    return;
  }
  const Vec3 approach = *axes.approach_world;
  if (approach.cross(closing).norm() < min_axis_angle)
    throw InputError("command line", option,
                     "a closing direction (--grip-axis) at least 10 degrees from the approach "
                     "direction (--approach)",
                     "two nearly parallel directions");
  if (std::abs(axes.approach_link.dot(closing_link)) > 1e-6)
    throw InputError("command line", "--tool-axes",
                     "perpendicular approach and closing axes of the tool",
                     "axes that are not perpendicular");
  const Vec3 c = (closing - closing.dot(approach) * approach).normalized();
  Eigen::Matrix3d world, link;
  world << approach, c, approach.cross(c);
  link << axes.approach_link, closing_link, axes.approach_link.cross(closing_link);
  goal.rotation_world = world * link.transpose();
}

}  // namespace shapectl::cli
