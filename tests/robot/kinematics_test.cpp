#include <shapectl/robot/kinematics.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <shapectl/io/input_error.hpp>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

// Every joint type: revolute z, prismatic x, continuous y (with an rpy origin), fixed, a
// revolute about a general axis on a second branch, and a mimic joint.
const char* const kTestUrdf = R"(<?xml version="1.0"?>
<robot name="every_joint">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="1.5" effort="1"/>
  </joint>
  <link name="a"><visual><geometry><mesh filename="package://missing/a.stl"/></geometry></visual></link>
  <joint name="j2" type="prismatic">
    <parent link="a"/><child link="b"/>
    <origin xyz="0.3 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.4" velocity="0.2" effort="1"/>
  </joint>
  <link name="b"/>
  <joint name="j3" type="continuous">
    <parent link="b"/><child link="c"/>
    <origin xyz="0 0 0.2" rpy="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
  <link name="c"/>
  <joint name="tool_joint" type="fixed">
    <parent link="c"/><child link="tool"/>
    <origin xyz="0 0 0.1"/>
  </joint>
  <link name="tool"/>
  <joint name="m1" type="revolute">
    <parent link="a"/><child link="e"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-9" upper="9" velocity="1" effort="1"/>
    <mimic joint="j1" multiplier="2" offset="0.1"/>
  </joint>
  <link name="e"/>
  <joint name="e_tip_joint" type="fixed">
    <parent link="e"/><child link="e_tip"/>
    <origin xyz="0.1 0 0"/>
  </joint>
  <link name="e_tip"/>
  <joint name="k1" type="revolute">
    <parent link="base"/><child link="d"/>
    <origin xyz="0 0 0" rpy="0.3 -0.2 0.1"/><axis xyz="1 1 0"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/>
  </joint>
  <link name="d"/>
  <joint name="d_tip_joint" type="fixed">
    <parent link="d"/><child link="d_tip"/>
    <origin xyz="0 0 0.4" rpy="0 0 0"/>
  </joint>
  <link name="d_tip"/>
</robot>)";

RobotModel test_robot() { return RobotModel::from_urdf_string(kTestUrdf, "every_joint.urdf"); }

Vec3 position(const RobotModel& model, const KinematicsState& state, const char* link) {
  return state.T_world_link[static_cast<std::size_t>(model.link_index(link))].translation();
}

TEST(RobotModel, ActiveJointsDefaultToMovableNonMimicJointsInTreeOrder) {
  const RobotModel model = test_robot();
  EXPECT_EQ(model.active_joint_names(), (std::vector<std::string>{"j1", "j2", "j3", "k1"}));
  EXPECT_EQ(model.link_count(), 9);
  EXPECT_EQ(model.links()[0].name, "base");
  EXPECT_DOUBLE_EQ(model.lower_limits()[1], 0.0);
  EXPECT_DOUBLE_EQ(model.upper_limits()[1], 0.4);
  EXPECT_DOUBLE_EQ(model.velocity_limits()[0], 1.5);
  EXPECT_TRUE(std::isinf(model.lower_limits()[2]));  // continuous
  EXPECT_TRUE(std::isinf(model.velocity_limits()[2]));
  const Joint& mimic = model.joints()[static_cast<std::size_t>(model.joint_index("m1"))];
  EXPECT_EQ(mimic.mimic_master, model.joint_index("j1"));
  EXPECT_DOUBLE_EQ(mimic.mimic_multiplier, 2.0);
}

TEST(RobotModel, AVisualMeshIsKeptWithItsFileName) {
  // Whether the file exists is for find_visual_meshes (visual_meshes_test.cpp) to say.
  const RobotModel model = test_robot();
  EXPECT_TRUE(model.warnings().empty());
  const auto& visuals =
      model.links()[static_cast<std::size_t>(model.link_index("a"))].visual_shapes;
  ASSERT_EQ(visuals.size(), 1u);
  EXPECT_EQ(visuals[0].kind, Shape::Kind::Mesh);
  EXPECT_EQ(visuals[0].mesh_filename, "package://missing/a.stl");
}

TEST(RobotModel, UnknownNamesAndInvalidActiveJointsAreInputErrors) {
  RobotModel model = test_robot();
  EXPECT_THROW(model.link_index("nope"), InputError);
  EXPECT_THROW(model.set_active_joints({"m1"}), InputError);
  EXPECT_THROW(model.set_active_joints({"tool_joint"}), InputError);
  EXPECT_THROW(model.set_active_joints({"j1", "j1"}), InputError);
  try {
    model.active_joints_from_map({{"j9", 1.0}}, "joints.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "joints.json: joint 'j9': unknown joint in every_joint.urdf");
  }
}

TEST(Kinematics, EveryJointTypeMatchesHandComputedPoses) {
  const RobotModel model = test_robot();
  const double half_pi = M_PI / 2;
  // θ = (j1, j2, j3, k1)
  const KinematicsState state =
      forward_kinematics(model, Eigen::Vector4d(half_pi, 0.2, half_pi, 0));
  // a = Trans(0,0,0.5)·Rz(90°); b = a·Trans(0.3+0.2,0,0); c = b·Trans(0,0,0.2)·Ry(90°).
  EXPECT_TRUE(position(model, state, "b").isApprox(Vec3(0, 0.5, 0.5), 1e-12));
  EXPECT_TRUE(position(model, state, "c").isApprox(Vec3(0, 0.5, 0.7), 1e-12));
  // Ry(90°) turns the tool's z offset into +x, Rz(90°) that into +y.
  EXPECT_TRUE(position(model, state, "tool").isApprox(Vec3(0, 0.6, 0.7), 1e-12));
  Mat3 R_world_tool;
  R_world_tool << 0, -1, 0, 0, 0, 1, -1, 0, 0;
  EXPECT_TRUE(
      state.T_world_link[static_cast<std::size_t>(model.link_index("tool"))].linear().isApprox(
          R_world_tool, 1e-12));
  // Mimic: e turns by 2·j1 + 0.1 about a's z, on top of a's own 90°.
  EXPECT_TRUE(position(model, state, "e_tip")
                  .isApprox(Vec3(0.1 * std::sin(0.1), -0.1 * std::cos(0.1), 0.6), 1e-12));
  EXPECT_NEAR(state.joints[model.joint_index("m1")], M_PI + 0.1, 1e-15);
}

TEST(Kinematics, GeneralAxisRotatesAboutThatAxis) {
  const RobotModel model = test_robot();
  const Mat3 R_origin =
      (Eigen::AngleAxisd(0.1, Vec3::UnitZ()) * Eigen::AngleAxisd(-0.2, Vec3::UnitY()) *
       Eigen::AngleAxisd(0.3, Vec3::UnitX()))
          .toRotationMatrix();
  // Half a turn about (1,1,0)/√2 maps (0,0,0.4) to (0,0,-0.4) in the joint frame.
  const KinematicsState state = forward_kinematics(model, Eigen::Vector4d(0, 0, 0, M_PI));
  EXPECT_TRUE(position(model, state, "d_tip").isApprox(R_origin * Vec3(0, 0, -0.4), 1e-12));
  // A quarter turn maps it to (0.4/√2)(1,-1,0).
  const KinematicsState quarter = forward_kinematics(model, Eigen::Vector4d(0, 0, 0, M_PI / 2));
  EXPECT_TRUE(
      position(model, quarter, "d_tip")
          .isApprox(R_origin * Vec3(0.4 / std::sqrt(2.0), -0.4 / std::sqrt(2.0), 0), 1e-12));
}

TEST(Kinematics, InactiveJointsKeepTheirFixedValues) {
  RobotModel model = test_robot();
  model.set_active_joints({"j1", "j3"});
  model.set_fixed_joint_values({{"j2", 0.25}}, "test");
  const KinematicsState state = forward_kinematics(model, Eigen::Vector2d(0, 0));
  EXPECT_TRUE(position(model, state, "b").isApprox(Vec3(0.55, 0, 0.5), 1e-12));
  EXPECT_THROW(model.set_fixed_joint_values({{"j1", 0.1}}, "test"), InputError);  // active
}

// Central differences of a link point's world position against the analytic Jacobian.
void expect_point_jacobians_match(const RobotModel& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-1.5, 1.5);
  Eigen::VectorXd theta(model.active_count());
  for (int i = 0; i < theta.size(); ++i)
    theta[i] = std::clamp(angle(rng), model.lower_limits()[i], model.upper_limits()[i]);
  const KinematicsState state = forward_kinematics(model, theta);
  for (int link = 0; link < model.link_count(); ++link) {
    const std::string& name = model.links()[static_cast<std::size_t>(link)].name;
    const Vec3 point(angle(rng) * 0.1, angle(rng) * 0.1, angle(rng) * 0.1);
    const auto point_world = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
      return forward_kinematics(model, t).T_world_link[static_cast<std::size_t>(link)] * point;
    };
    const Eigen::Matrix3Xd jacobian = point_jacobian(model, state, link, point);
    const Eigen::MatrixXd numeric = test::central_difference_jacobian(point_world, theta, 1e-6);
    if (!model.jacobian_entries(link).empty()) {  // links that some joint moves
      EXPECT_TRUE(
          test::derivative_matches(jacobian, numeric, 1e-6, "point Jacobian of " + name, 1e-3));
    } else {  // no joint moves the link: both Jacobians are zero
      EXPECT_EQ(jacobian.cwiseAbs().maxCoeff(), 0.0) << name;
      EXPECT_EQ(numeric.cwiseAbs().maxCoeff(), 0.0) << name;
    }

    // Jᵀf without forming J agrees with the matrix.
    const Vec3 force(angle(rng), angle(rng), angle(rng));
    Eigen::VectorXd transpose = Eigen::VectorXd::Zero(model.active_count());
    add_point_jacobian_transpose(model, state, link,
                                 state.T_world_link[static_cast<std::size_t>(link)] * point, force,
                                 transpose);
    EXPECT_LE((transpose - jacobian.transpose() * force).norm(), 1e-12);
  }
}

TEST(Kinematics, PointJacobiansMatchCentralDifferences) {
  const RobotModel model = test_robot();
  std::mt19937 rng(42);
  for (int trial = 0; trial < 5; ++trial) expect_point_jacobians_match(model, rng);
}

TEST(Kinematics, YumiPointJacobiansMatchCentralDifferences) {
  RobotModel model = RobotModel::load_urdf_file(SHAPECTL_SOURCE_DIR "/data/robots/yumi/yumi.urdf");
  std::mt19937 rng(7);
  for (int trial = 0; trial < 3; ++trial) expect_point_jacobians_match(model, rng);
}

}  // namespace
}  // namespace shapectl
