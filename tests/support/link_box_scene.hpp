#pragma once
// The two arms' bar (two_arm_scene) with a box attached to a robot link: under the bar's middle
// at the reference joints, its top `gap` below the bar's bottom face, turned by `turn` (bar
// frame) about its centre. The box moves with its link as θ changes.
#include <shapectl/contact/obstacle.hpp>

#include "support/obstacle_clearance.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl::test {

struct LinkBox {
  Scene scene;
  int link = -1;
  Vec3 size = Vec3::Zero();
  Eigen::Isometry3d T_link_box = Eigen::Isometry3d::Identity();

  // The box in the world with the robot at `state`, for tests/support's own clearance check.
  ObstacleShape shape(const KinematicsState& state) const {
    ObstacleShape s;
    s.kind = ObstacleShape::Kind::Box;
    s.size = size;
    s.pose = state.T_world_link[link] * T_link_box;
    return s;
  }
};

// size: the box's edges along the bar, across it and up (m).
inline LinkBox two_arm_scene_with_link_box(
    const std::array<int, 3>& cells, const std::string& link, const Vec3& size, double gap,
    const Eigen::Matrix3d& turn = Eigen::Matrix3d::Identity()) {
  LinkBox b;
  b.scene = two_arm_scene(cells);
  b.size = size;
  const RobotModel& robot = *b.scene.robot->model;
  b.link = robot.link_index(link);
  // The box in the bar's frame, its highest corner `gap` under the bottom face (z = −0.015).
  Eigen::Isometry3d T_bar_box = Eigen::Isometry3d::Identity();
  T_bar_box.linear() = turn;
  double top = -1;
  for (int i = 0; i < 8; ++i) {
    const Vec3 s((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
    top = std::max(top, (turn * s.cwiseProduct(size)).z());
  }
  T_bar_box.translation() = Vec3(0, 0, -0.015 - gap - top);
  const KinematicsState reference = forward_kinematics(robot, b.scene.robot->reference_joints);
  b.T_link_box = reference.T_world_link[b.link].inverse() * b.scene.T_world_object * T_bar_box;
  Obstacle box = make_box("link box", size, b.T_link_box);
  box.link = b.link;
  b.scene.obstacles.push_back(box);
  return b;
}

// The unit step of joint `joint` (±1 in that joint, 0 in the others) that lifts the box at the
// reference joints.
inline Eigen::VectorXd lifting_step(const LinkBox& b, int joint) {
  const RobotModel& robot = *b.scene.robot->model;
  Eigen::VectorXd theta = b.scene.robot->reference_joints;
  const double z0 = b.shape(forward_kinematics(robot, theta)).pose.translation().z();
  theta[joint] += 1e-3;
  const double z1 = b.shape(forward_kinematics(robot, theta)).pose.translation().z();
  Eigen::VectorXd up = Eigen::VectorXd::Zero(theta.size());
  up[joint] = z1 > z0 ? 1 : -1;
  return up;
}

}  // namespace shapectl::test
