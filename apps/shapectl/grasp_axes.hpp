#pragma once
// The grasp orientation `author` asks inverse kinematics for (--approach, --grip-axis,
// --tool-axes). A tool has two axes in its link frame: the approach axis (default +z, the
// usual tool-frame convention) and the closing axis, along which its fingers move (default: the
// axis of the fingers' prismatic joint, else +y). The user gives world directions for either or
// both: one makes a 5-DOF goal (free to turn about it), both a full orientation.
#include <optional>

#include <shapectl/robot/inverse_kinematics.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl::cli {

struct GraspAxes {
  std::optional<Vec3> approach_world;  // unit; none: not asked for
  std::optional<Vec3> closing_world;   // unit, sign free (the fingers close symmetrically)
  Vec3 approach_link = Vec3::UnitZ();  // unit, tool link frame
  std::optional<Vec3> closing_link;    // unit; none: finger_axis, else +y
};

// The axis along which the end effector's fingers move, in the frame of `tool_link`: the first
// prismatic joint hanging off the tool link or a link it is rigidly fixed to, not on the way to
// the tool. None without one.
std::optional<Vec3> finger_axis(const RobotModel& model, int tool_link);

// The tool's closing axis in its link frame: the one --tool-axes named, else the fingers' axis,
// else +y.
Vec3 closing_axis_link(const GraspAxes& axes, const RobotModel& model, int tool_link);

// Adds the orientation `axes` ask for to `goal` (a position goal for `goal.link`).
// `R_world_link` (the link's orientation at the start pose) picks the closing axis's sign.
// Throws InputError naming `option` when the approach and closing directions are within 10° of
// parallel, or the tool axes are not perpendicular.
void orient_goal(const GraspAxes& axes, const RobotModel& model,
                 const Eigen::Matrix3d& R_world_link, const std::string& option, IkGoal& goal);

}  // namespace shapectl::cli
