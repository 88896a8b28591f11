// The xacro expander on two public robot descriptions, a UR5 and a Panda, against URDF that
// ROS's xacro generated from them (data/robots/xacro/README.md says where each file is from and
// which differences between the versions the sources and the references come from are known).
#include <gtest/gtest.h>

#include <random>
#include <set>

#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/robot_description.hpp>
#include <shapectl/robot/robot_model.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

struct Description {
  std::string xacro;                     // under data/robots/xacro/
  std::string reference;                 // the URDF xacro produced
  double tolerance;                      // on origins and link poses
  std::set<std::string> only_ours;       // joints of the source version the reference lacks
  std::set<std::string> only_reference;  // and the other way round
  std::set<std::string> other_limits;    // joints whose limits the two versions set differently
};

// UR5: the sources are the version after the reference's; both print pi as 3.14159265.
const Description kUr5 = {"ur5/ur_description/urdf/ur5_robot.urdf.xacro",
                          "ur5/ur5_robot.urdf",
                          1e-12,
                          {"base_link-base_fixed_joint", "wrist_3_link-tool0_fixed_joint"},
                          {},
                          {"elbow_joint"}};
// Panda: the reference's xacro printed 12 significant digits (pi/2 as 1.57079632679), so its
// origins differ from full precision by up to 5e-12 rad.
const Description kPanda = {"panda/franka_description/robots/panda_arm_hand.urdf.xacro",
                            "panda/panda_arm_hand.urdf",
                            1e-10,
                            {},
                            {"panda_camera_joint"},
                            {}};

std::filesystem::path data(const std::string& relative) {
  return test::source_path("data/robots/xacro/" + relative);
}

std::string link_name(const RobotModel& model, int link) {
  return link < 0 ? "" : model.links()[static_cast<std::size_t>(link)].name;
}

void expect_same_joints(const Description& d, const RobotModel& ours, const RobotModel& ref) {
  int compared = 0;
  for (const Joint& j : ref.joints()) {
    const auto ours_index = ours.find_joint(j.name);
    if (d.only_reference.count(j.name)) {
      EXPECT_FALSE(ours_index) << j.name << " is listed as missing from our expansion";
      continue;
    }
    ASSERT_TRUE(ours_index) << "joint " << j.name << " missing from the expansion";
    const Joint& o = ours.joints()[static_cast<std::size_t>(*ours_index)];
    SCOPED_TRACE("joint " + j.name);
    EXPECT_EQ(o.type, j.type);
    EXPECT_EQ(link_name(ours, o.parent_link), link_name(ref, j.parent_link));
    EXPECT_EQ(link_name(ours, o.child_link), link_name(ref, j.child_link));
    EXPECT_EQ(o.axis, j.axis);
    EXPECT_LE((o.T_parent_child.matrix() - j.T_parent_child.matrix()).cwiseAbs().maxCoeff(),
              d.tolerance);
    if (d.other_limits.count(j.name)) {
      EXPECT_NE(o.lower, j.lower) << "listed as a known difference, but the limits agree";
    } else {
      EXPECT_EQ(o.lower, j.lower);
      EXPECT_EQ(o.upper, j.upper);
      EXPECT_EQ(o.velocity, j.velocity);
    }
    EXPECT_EQ(o.mimic_master < 0 ? ""
                                 : ours.joints()[static_cast<std::size_t>(o.mimic_master)].name,
              j.mimic_master < 0 ? ""
                                 : ref.joints()[static_cast<std::size_t>(j.mimic_master)].name);
    EXPECT_EQ(o.mimic_multiplier, j.mimic_multiplier);
    EXPECT_EQ(o.mimic_offset, j.mimic_offset);
    ++compared;
  }
  for (const Joint& o : ours.joints()) {
    if (!ref.find_joint(o.name)) {
      EXPECT_TRUE(d.only_ours.count(o.name)) << "joint " << o.name << " not in the reference";
    }
  }
  EXPECT_EQ(compared + static_cast<int>(d.only_ours.size()), ours.joint_count());
  EXPECT_GT(compared, 6);
}

// Link poses at random joint vectors (the same values by joint name in both models).
void expect_same_forward_kinematics(const Description& d, const RobotModel& ours,
                                    const RobotModel& ref) {
  ASSERT_EQ(ours.active_joint_names(), ref.active_joint_names());
  std::mt19937 rng(36);
  for (int trial = 0; trial < 8; ++trial) {
    std::map<std::string, double> values;
    for (const std::string& name : ours.active_joint_names()) {
      const Joint& j = ours.joints()[static_cast<std::size_t>(ours.joint_index(name))];
      const double lo = std::max(j.lower, -3.0), hi = std::min(j.upper, 3.0);
      values[name] = std::uniform_real_distribution<double>(lo, std::max(lo, hi))(rng);
    }
    const KinematicsState a = forward_kinematics(ours, ours.active_joints_from_map(values, "test"));
    const KinematicsState b = forward_kinematics(ref, ref.active_joints_from_map(values, "test"));
    int links = 0;
    for (int l = 0; l < ref.link_count(); ++l) {
      const std::string& name = ref.links()[static_cast<std::size_t>(l)].name;
      const auto mine = ours.find_link(name);
      if (!mine) continue;  // a link of a joint listed in only_reference
      const double error = (a.T_world_link[static_cast<std::size_t>(*mine)].matrix() -
                            b.T_world_link[static_cast<std::size_t>(l)].matrix())
                               .cwiseAbs()
                               .maxCoeff();
      EXPECT_LE(error, d.tolerance) << "link " << name << ", trial " << trial;
      ++links;
    }
    EXPECT_EQ(links + static_cast<int>(d.only_reference.size()), ref.link_count());
  }
}

void check(const Description& d) {
  const RobotModel ours = RobotModel::load_urdf_file(data(d.xacro));
  const RobotModel ref = RobotModel::load_urdf_file(data(d.reference));
  expect_same_joints(d, ours, ref);
  expect_same_forward_kinematics(d, ours, ref);
}

TEST(XacroReference, Ur5MatchesTheUrdfXacroGenerated) { check(kUr5); }

TEST(XacroReference, PandaMatchesTheUrdfXacroGenerated) { check(kPanda); }

TEST(XacroReference, ArgsChangeTheExpansion) {
  XacroOptions options;
  options.args["arm_id"] = "left";
  const RobotModel left = RobotModel::load_urdf_file(data(kPanda.xacro), options);
  EXPECT_TRUE(left.find_joint("left_joint4"));
  EXPECT_TRUE(left.find_link("left_rightfinger"));
  EXPECT_FALSE(left.find_link("panda_link0"));
}

}  // namespace
}  // namespace shapectl
