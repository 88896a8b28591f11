// The shipped YuMi model: names, limits, known-answer poses, home pose and sphere cover.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/kinematics.hpp>

namespace shapectl {
namespace {

const std::string kYumiDir = SHAPECTL_SOURCE_DIR "/data/robots/yumi/";
constexpr double kDeg = M_PI / 180;

RobotModel yumi() { return RobotModel::load_urdf_file(kYumiDir + "yumi.urdf"); }

// Chain order 1, 2, 7, 3, 4, 5, 6 (ABB axis numbers), radians.
using ArmJoints = std::array<double, 7>;
Eigen::VectorXd arms(const RobotModel& model, const ArmJoints& right, const ArmJoints& left) {
  const std::array<const char*, 7> axes = {"1", "2", "7", "3", "4", "5", "6"};
  std::map<std::string, double> values;
  for (std::size_t i = 0; i < 7; ++i) {
    values[std::string("yumi_joint_") + axes[i] + "_r"] = right[i];
    values[std::string("yumi_joint_") + axes[i] + "_l"] = left[i];
  }
  return model.active_joints_from_map(values, "test");
}
ArmJoints degrees(ArmJoints q) {
  for (double& x : q) x *= kDeg;
  return q;
}
// The left arm mirrors the right one: axes 1, 7, 4 and 6 change sign.
ArmJoints mirrored(ArmJoints q) {
  for (std::size_t i : {0u, 2u, 4u, 6u}) q[i] = -q[i];
  return q;
}

const Eigen::Isometry3d& pose(const RobotModel& model, const KinematicsState& state,
                              const char* link) {
  return state.T_world_link[static_cast<std::size_t>(model.link_index(link))];
}

void expect_pose(const Eigen::Isometry3d& T, const Vec3& position, const Eigen::Quaterniond& q,
                 double tolerance) {
  EXPECT_LE((T.translation() - position).norm(), tolerance) << T.translation().transpose();
  EXPECT_LE(Eigen::Quaterniond(T.linear()).angularDistance(q), 2 * tolerance);
}

TEST(YumiModel, NamesFollowTheCommonDescriptionAndChainOrder) {
  const RobotModel model = yumi();
  EXPECT_EQ(model.name(), "yumi");
  EXPECT_EQ(model.active_joint_names(),
            (std::vector<std::string>{"yumi_joint_1_r", "yumi_joint_2_r", "yumi_joint_7_r",
                                      "yumi_joint_3_r", "yumi_joint_4_r", "yumi_joint_5_r",
                                      "yumi_joint_6_r", "gripper_r_joint", "yumi_joint_1_l",
                                      "yumi_joint_2_l", "yumi_joint_7_l", "yumi_joint_3_l",
                                      "yumi_joint_4_l", "yumi_joint_5_l", "yumi_joint_6_l",
                                      "gripper_l_joint"}));
  for (const char* link : {"world", "yumi_body", "yumi_link_3_l", "gripper_l_base", "gripper_l_tcp",
                           "gripper_r_tcp", "gripper_r_finger_l"})
    EXPECT_TRUE(model.find_link(link)) << link;
  // The axis-7 joint moves link 3, the axis-3 joint link 4.
  EXPECT_EQ(model
                .links()[static_cast<std::size_t>(
                    model.joints()[static_cast<std::size_t>(model.joint_index("yumi_joint_7_l"))]
                        .child_link)]
                .name,
            "yumi_link_3_l");
  EXPECT_DOUBLE_EQ(model.joints()[static_cast<std::size_t>(model.joint_index("yumi_joint_3_r"))]
                       .T_parent_child.translation()
                       .x(),
                   -0.04188);
  EXPECT_TRUE(model.warnings().empty());
}

TEST(YumiModel, LimitsAndSpeedsMatchTheControllerTable) {
  RobotModel model = yumi();
  model.set_active_joints({"yumi_joint_1_l", "yumi_joint_2_l", "yumi_joint_7_l", "yumi_joint_3_l",
                           "yumi_joint_4_l", "yumi_joint_5_l", "yumi_joint_6_l"});
  const Eigen::VectorXd lower = model.lower_limits() / kDeg;
  const Eigen::VectorXd upper = model.upper_limits() / kDeg;
  const Eigen::VectorXd speed = model.velocity_limits() / kDeg;
  const std::array<double, 7> lo = {-168.5, -143.5, -168.5, -123.5, -290, -88, -229};
  const std::array<double, 7> hi = {168.5, 43.5, 168.5, 80, 290, 138, 229};
  const std::array<double, 7> deg_per_s = {180, 180, 180, 180, 400, 400, 400};
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(lower[i], lo[static_cast<std::size_t>(i)], 1e-8);
    EXPECT_NEAR(upper[i], hi[static_cast<std::size_t>(i)], 1e-8);
    EXPECT_NEAR(speed[i], deg_per_s[static_cast<std::size_t>(i)], 1e-8);
  }
}

TEST(YumiModel, FlangesMatchKnownAnswerPoses) {
  const RobotModel model = yumi();
  // kinematics.md §6.3 (world frame, 5 decimals).
  const KinematicsState zero =
      forward_kinematics(model, Eigen::VectorXd::Zero(model.active_count()));
  expect_pose(pose(model, zero, "gripper_r_base"), {0.56846, 0.00587, 0.51462},
              {0.29767, 0.06720, 0.87438, 0.37727}, 1e-5);
  expect_pose(pose(model, zero, "gripper_l_base"), {0.56860, -0.00497, 0.51362},
              {0.29748, -0.06774, 0.87516, -0.37552}, 1e-5);
  const KinematicsState bent =
      forward_kinematics(model, arms(model, {0.3, -0.5, 0.4, 0.7, -0.4, 0.2, 0.6},
                                     {-0.3, -0.5, -0.4, 0.7, 0.4, 0.2, -0.6}));
  expect_pose(pose(model, bent, "gripper_r_base"), {0.38289, 0.03417, 0.69596},
              {0.15972, -0.13201, 0.79981, 0.56335}, 1e-5);
  expect_pose(pose(model, bent, "gripper_l_base"), {0.38333, -0.03420, 0.69513},
              {0.15942, 0.13117, 0.80097, -0.56199}, 1e-5);
}

TEST(YumiModel, TcpSits114MillimetresAlongTheFlangeNormal) {
  const RobotModel model = yumi();
  const KinematicsState zero =
      forward_kinematics(model, Eigen::VectorXd::Zero(model.active_count()));
  expect_pose(pose(model, zero, "gripper_r_tcp"), {0.633701, 0.076644, 0.453167},
              {0.297670, 0.067200, 0.874381, 0.377273}, 1e-6);
  expect_pose(pose(model, zero, "gripper_l_tcp"), {0.633871, -0.075426, 0.451840},
              {0.297479, -0.067744, 0.875157, -0.375523}, 1e-6);
  for (const char* side : {"r", "l"}) {
    const auto& base = pose(model, zero, ("gripper_" + std::string(side) + "_base").c_str());
    const auto& tcp = pose(model, zero, ("gripper_" + std::string(side) + "_tcp").c_str());
    EXPECT_LE((tcp.translation() - base.translation() - 0.1142 * base.linear().col(2)).norm(),
              1e-12);
  }
}

TEST(YumiModel, AllZeroPoseCollides) {
  const RobotModel model = yumi();
  const CollisionModel spheres =
      CollisionModel::load_json_file(model, kYumiDir + "yumi_spheres.json");
  const KinematicsState zero =
      forward_kinematics(model, Eigen::VectorXd::Zero(model.active_count()));
  EXPECT_LT(spheres.min_clearance(zero), -0.05);
}

// ABB's RAPID home [0,-130,30,0,40,0] deg, axis 7 = -135 (left) / +135 (right), read with this
// model's (upstream URDF) signs, puts each gripper on the other arm's side: the arms cross.
TEST(YumiModel, RapidHomeReadLiterallyCrossesTheArms) {
  const RobotModel model = yumi();
  const CollisionModel spheres =
      CollisionModel::load_json_file(model, kYumiDir + "yumi_spheres.json");
  const KinematicsState crossed =
      forward_kinematics(model, arms(model, degrees({0, -130, 135, 30, 0, 40, 0}),
                                     degrees({0, -130, -135, 30, 0, 40, 0})));
  expect_pose(pose(model, crossed, "gripper_r_tcp"), {0.035430, 0.198136, 0.597577},
              {0.598436, -0.653336, 0.354493, -0.298935}, 1e-6);
  expect_pose(pose(model, crossed, "gripper_l_tcp"), {0.036021, -0.198438, 0.596710},
              {0.596841, 0.654227, 0.355000, 0.299570}, 1e-6);
  EXPECT_GT(pose(model, crossed, "gripper_r_tcp").translation().y(),
            0.1);  // right gripper on the left
  const auto closest = spheres.closest_pairs(crossed, 1);
  ASSERT_EQ(closest.size(), 1u);
  EXPECT_LT(closest[0].clearance, -0.05);
  const auto link_name = [&](int sphere) {
    return model
        .links()[static_cast<std::size_t>(spheres.spheres()[static_cast<std::size_t>(sphere)].link)]
        .name;
  };
  EXPECT_NE(link_name(closest[0].first).back(), link_name(closest[0].second).back());  // _l vs _r
}

// shapectl's home (see docs/robot.md): grippers pointing down, 0.27 m either side of the centre
// plane, 0.31 m above the floor plane, every joint at least 35° inside its limits.
TEST(YumiModel, HomePoseIsCollisionFreeAndInsideLimits) {
  const RobotModel model = yumi();
  const CollisionModel spheres =
      CollisionModel::load_json_file(model, kYumiDir + "yumi_spheres.json");
  const ArmJoints right = degrees({0, -25, -50, 45, 70, -25, 0});
  const Eigen::VectorXd home = arms(model, right, mirrored(right));
  const KinematicsState state = forward_kinematics(model, home);
  expect_pose(pose(model, state, "gripper_r_tcp"), {0.348831, -0.266658, 0.308466},
              {0.073056, 0.802030, 0.588411, -0.071991}, 1e-6);
  expect_pose(pose(model, state, "gripper_l_tcp"), {0.348194, 0.267853, 0.308682},
              {-0.073891, 0.802370, -0.587644, -0.073602}, 1e-6);
  EXPECT_LT(pose(model, state, "gripper_r_tcp").linear().col(2).z(), -0.97);
  EXPECT_GT(spheres.min_clearance(state), spheres.margin() + 0.05);
  EXPECT_EQ(spheres.value(model, state), 0.0);
  for (int i = 0; i < model.active_count(); ++i) {
    if (model.active_joint_names()[static_cast<std::size_t>(i)].rfind("yumi_joint_", 0) != 0)
      continue;
    EXPECT_GE(home[i] - model.lower_limits()[i], 35 * kDeg - 1e-12);
    EXPECT_GE(model.upper_limits()[i] - home[i], 35 * kDeg - 1e-12);
  }
}

// Points on and inside every collision primitive of the URDF lie in some sphere of that link.
TEST(YumiModel, SpheresCoverEveryLinkPrimitive) {
  const RobotModel model = yumi();
  const CollisionModel spheres =
      CollisionModel::load_json_file(model, kYumiDir + "yumi_spheres.json");
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  int checked_shapes = 0;
  for (int link = 0; link < model.link_count(); ++link) {
    for (const Shape& shape : model.links()[static_cast<std::size_t>(link)].collision_shapes) {
      ++checked_shapes;
      for (int sample = 0; sample < 2000; ++sample) {
        Vec3 p(unit(rng), unit(rng), unit(rng));  // in [-1, 1]³
        if (sample % 2 == 0) {                    // push half the samples onto the surface
          if (shape.kind == Shape::Kind::Box) {
            const int axis = sample / 2 % 3;
            p[axis] = p[axis] < 0 ? -1 : 1;
          } else {
            p.normalize();
          }
        }
        Vec3 local;
        if (shape.kind == Shape::Kind::Box) {
          local = 0.5 * shape.box_size.cwiseProduct(p);
        } else if (shape.kind == Shape::Kind::Sphere) {
          local = shape.radius * (p.norm() > 1 ? p.normalized() : p);
        } else {
          const Eigen::Vector2d radial =
              p.head<2>().norm() > 1 ? p.head<2>().normalized() : p.head<2>();
          local = Vec3(shape.radius * radial.x(), shape.radius * radial.y(),
                       0.5 * shape.length * p.z());
        }
        const Vec3 point = shape.T_link_shape * local;
        bool inside = false;
        for (const CollisionSphere& s : spheres.spheres())
          inside = inside || (s.link == link && (point - s.center_link).norm() <= s.radius + 1e-9);
        ASSERT_TRUE(inside) << model.links()[static_cast<std::size_t>(link)].name << " point "
                            << point.transpose();
      }
    }
  }
  EXPECT_EQ(checked_shapes, 3 + 2 * (2 + 3 + 2 + 3 + 2 + 1 + 1) + 2 * 3);
}

}  // namespace
}  // namespace shapectl
