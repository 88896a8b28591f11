// Mutated URDF (YuMi and a small three-joint arm) and JOINTS.json: each loads or throws
// InputError; a model that loads gives forward kinematics without a crash.
#include <gtest/gtest.h>

#include <shapectl/robot/joints_file.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/robot_model.hpp>

#include "io/text_mutator.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

const char* const kArmUrdf = R"(<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/>
  </joint>
  <link name="upper"><visual><geometry><cylinder radius="0.02" length="0.3"/></geometry></visual></link>
  <joint name="elbow" type="prismatic">
    <parent link="upper"/><child link="fore"/><origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.1" velocity="1" effort="1"/>
  </joint>
  <link name="fore"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
  <joint name="finger" type="revolute">
    <parent link="fore"/><child link="tip"/><axis xyz="1 0 0"/>
    <limit lower="-0.5" upper="0.5" velocity="1" effort="1"/><mimic joint="shoulder" multiplier="2" offset="0.1"/>
  </joint>
  <link name="tip"/>
</robot>
)";

const test::TextMutator kUrdfMutator({"<",
                                      ">",
                                      "/>",
                                      "</link>",
                                      "</joint>",
                                      "<link name=\"x\"/>",
                                      "<joint name=\"j\" type=\"revolute\">",
                                      "\"",
                                      "'",
                                      "=",
                                      "nan",
                                      "inf",
                                      "-inf",
                                      "1e999",
                                      "-1e308",
                                      "1e-400",
                                      "0 0 0",
                                      "<a>",
                                      "<!--",
                                      "-->",
                                      "<![CDATA[",
                                      "]]>",
                                      "&amp;",
                                      "&#0;",
                                      "<?xml?>",
                                      "type=\"floating\"",
                                      "<mimic joint=\"elbow\"/>",
                                      "<parent link=\"tip\"/>",
                                      "\xff\xfe"});

void load_and_move(const std::string& text) {
  const RobotModel model = RobotModel::from_urdf_string(text, "fuzz.urdf");
  forward_kinematics(model, Eigen::VectorXd::Constant(model.active_count(), 0.1));
}

TEST(UrdfFuzz, MutatedUrdfLoadsOrIsAnInputError) {
  const std::string yumi = test::read_text(test::source_path("data/robots/yumi/yumi.urdf"));
  ASSERT_NO_THROW(load_and_move(yumi));
  ASSERT_NO_THROW(load_and_move(kArmUrdf));
  const test::FuzzCounts counts =
      test::fuzz_parser({kArmUrdf, kArmUrdf, yumi}, kUrdfMutator, 2400, 5, load_and_move);
  EXPECT_GT(counts.refused, 300);
  EXPECT_GT(counts.parsed, 300);
}

TEST(UrdfFuzz, MutatedJointsFilesLoadOrAreInputErrors) {
  const RobotModel model = RobotModel::from_urdf_string(kArmUrdf, "arm.urdf");
  const Eigen::VectorXd defaults = Eigen::VectorXd::Zero(model.active_count());
  const test::TempDir dir;
  const test::TextMutator mutator({"{", "[", "]", "}", ",", ":", "\"", "1e999", "NaN", "null",
                                   "true", "\"shoulder\"", "\"finger\": 1",
                                   "\"elbow\": 1, \"elbow\": 2", "[]", "{}"});
  const std::string seed = R"({"joints": {"shoulder": 0.5, "elbow": 0.05}})";
  const test::FuzzCounts counts =
      test::fuzz_parser({seed}, mutator, 1500, 9, [&](const std::string& text) {
        const Eigen::VectorXd theta =
            load_joints_file(dir.write("joints.json", text), model, defaults);
        ASSERT_TRUE(theta.allFinite());
      });
  EXPECT_GT(counts.refused, 300);
  EXPECT_GT(counts.parsed, 0);  // a tiny seed: most mutations break it
}

}  // namespace
}  // namespace shapectl
