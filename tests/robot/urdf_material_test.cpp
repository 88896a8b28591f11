// URDF material colours on the visual shapes: inline, named at the robot level, or none.
#include <gtest/gtest.h>

#include <shapectl/robot/robot_model.hpp>

namespace shapectl {
namespace {

TEST(UrdfMaterial, VisualsCarryInlineAndNamedColoursAndNoneWithoutAMaterial) {
  const RobotModel model = RobotModel::from_urdf_string(
      "<robot name='r'><material name='steel'><color rgba='0.2 0.3 0.4 1'/></material>"
      "<link name='base'>"
      "<visual><geometry><box size='1 1 1'/></geometry>"
      "<material name='red'><color rgba='1 0 0 0.5'/></material></visual>"
      "<visual><geometry><sphere radius='0.1'/></geometry><material name='steel'/></visual>"
      "<visual><geometry><cylinder radius='0.1' length='0.2'/></geometry></visual>"
      "</link></robot>",
      "r.urdf");
  const std::vector<Shape>& visuals = model.links()[0].visual_shapes;
  ASSERT_EQ(visuals.size(), 3u);
  ASSERT_TRUE(visuals[0].rgba.has_value());
  EXPECT_EQ(*visuals[0].rgba, Eigen::Vector4d(1, 0, 0, 0.5));
  ASSERT_TRUE(visuals[1].rgba.has_value());
  EXPECT_NEAR((*visuals[1].rgba - Eigen::Vector4d(0.2, 0.3, 0.4, 1)).norm(), 0, 1e-6);
  EXPECT_FALSE(visuals[2].rgba.has_value());
}

TEST(UrdfMaterial, ATextureOnlyMaterialIsNoColour) {
  const RobotModel model = RobotModel::from_urdf_string(
      "<robot name='r'><link name='base'><visual><geometry><box size='1 1 1'/></geometry>"
      "<material name='wood'><texture filename='wood.png'/></material></visual></link></robot>",
      "r.urdf");
  ASSERT_EQ(model.links()[0].visual_shapes.size(), 1u);
  EXPECT_FALSE(model.links()[0].visual_shapes[0].rgba.has_value());
}

}  // namespace
}  // namespace shapectl
