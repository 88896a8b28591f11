#pragma once
// A small two-arm robot (3 revolute joints per arm) holding a foam bar by its ends: fast enough
// for finite-difference checks of every derivative. Built in code, no files.
#include <cmath>

#include <shapectl/contact/obstacle.hpp>
#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl::test {

inline std::string two_arm_urdf() {
  auto arm = [](const std::string& s, const std::string& y) {
    return "<joint name='" + s + "1' type='revolute'><parent link='base'/><child link='" + s +
           "_link1'/><origin xyz='0 " + y +
           " 0'/><axis xyz='0 0 1'/>"
           "<limit lower='-2' upper='2' velocity='2' effort='1'/></joint><link name='" +
           s +
           "_link1'/>"
           "<joint name='" +
           s + "2' type='revolute'><parent link='" + s + "_link1'/><child link='" + s +
           "_link2'/><origin xyz='0 0 0.1'/><axis xyz='0 1 0'/>"
           "<limit lower='-2' upper='2' velocity='2' effort='1'/></joint><link name='" +
           s +
           "_link2'/>"
           "<joint name='" +
           s + "3' type='revolute'><parent link='" + s + "_link2'/><child link='" + s +
           "_link3'/><origin xyz='0.25 0 0'/><axis xyz='0 1 0'/>"
           "<limit lower='-2.5' upper='2.5' velocity='2' effort='1'/></joint><link name='" +
           s +
           "_link3'/>"
           "<joint name='" +
           s + "_tool_joint' type='fixed'><parent link='" + s + "_link3'/><child link='" + s +
           "_tool'/><origin xyz='0.2 0 0'/></joint><link name='" + s + "_tool'/>";
  };
  return "<robot name='two_arms'><link name='base'/>" + arm("l", "0.15") + arm("r", "-0.15") +
         "</robot>";
}

// The bar lies between the two tools at the reference joints, gripped 20 mm at each end.
inline Scene two_arm_scene(const std::array<int, 3>& cells = {12, 1, 1}) {
  Scene s;
  s.source = "two_arm_scene";
  auto model =
      std::make_shared<RobotModel>(RobotModel::from_urdf_string(two_arm_urdf(), "two_arms.urdf"));
  RobotSetup robot;
  robot.model = model;
  robot.reference_joints = Eigen::VectorXd(6);
  robot.reference_joints << 0.0, -0.3, 0.9, 0.0, -0.3, 0.9;
  robot.end_effectors = {{"left", model->link_index("l_tool"), Vec3::Zero()},
                         {"right", model->link_index("r_tool"), Vec3::Zero()}};
  std::vector<CollisionSphere> spheres;
  for (const char* link : {"l_link3", "r_link3"})
    for (double x : {0.05, 0.1, 0.15})
      spheres.push_back({model->link_index(link), Vec3(x, 0, 0), 0.03});
  robot.collisions = std::make_shared<const CollisionModel>(*model, spheres, 0.005, 1e6);
  robot.joint_limit_margin = 0.05;
  robot.joint_limit_stiffness = 1e3;
  const KinematicsState ref = forward_kinematics(*model, robot.reference_joints);
  const Vec3 left = ref.T_world_link[model->link_index("l_tool")].translation();
  const Vec3 right = ref.T_world_link[model->link_index("r_tool")].translation();
  const double length = (left - right).norm() + 0.04;
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh({length, 0.03, 0.03}, cells));
  s.material = material_from_youngs(5e4, 0.3, 40);
  s.T_world_object.translation() = 0.5 * (left + right);
  s.T_world_object.linear() =
      Eigen::Quaterniond::FromTwoVectors(Vec3::UnitX(), left - right).toRotationMatrix();
  s.robot = robot;
  const double end = length / 2 - 0.02 - 1e-9;
  for (int e = 0; e < 2; ++e) {
    Grip g;
    g.end_effector = e;
    for (int i = 0; i < s.object_mesh->node_count(); ++i) {
      const double x = s.object_mesh->rest_positions()[i].x();
      if (e == 0 ? x > end : x < -end) g.nodes.push_back(i);
    }
    s.grips.push_back(g);
  }
  s.grip_stiffness = 1e4;
  return s;
}

// Both arms swung about z by `a` towards each other (their third links close in).
inline Eigen::VectorXd arms_swung_in(double a) {
  Eigen::VectorXd theta(6);
  theta << -a, -0.3, 0.9, a, -0.3, 0.9;
  return theta;
}

// two_arm_scene with the third links' collision spheres grown so that their clearance at the
// reference joints is `clearance` (m; negative: they overlap).
inline Scene two_arm_scene_with_clearance(double clearance) {
  Scene s = two_arm_scene();
  const CollisionModel& old = *s.robot->collisions;
  const double now =
      old.min_clearance(forward_kinematics(*s.robot->model, s.robot->reference_joints));
  std::vector<CollisionSphere> spheres = old.spheres();
  for (CollisionSphere& sphere : spheres) sphere.radius += (now - clearance) / 2;
  s.robot->collisions = std::make_shared<const CollisionModel>(*s.robot->model, spheres,
                                                               old.margin(), old.stiffness());
  return s;
}

// A table, the plane obstacle "table", `gap` under the lowest node of the scene's rest shape;
// returns its height.
inline double add_table_under(Scene& s, double gap) {
  const Positions rest = s.world_rest_positions();
  double bottom = INFINITY;
  for (Eigen::Index i = 0; i < rest.size() / 3; ++i) bottom = std::min(bottom, rest[3 * i + 2]);
  s.obstacles.push_back(make_plane("table", Vec3(0, 0, bottom - gap), Vec3::UnitZ()));
  return bottom - gap;
}

}  // namespace shapectl::test
