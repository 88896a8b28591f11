// Mesh collision geometry read from URDF (its files are found as in mesh_resource_test.cpp).
#include <gtest/gtest.h>

#include <shapectl/robot/urdf_collision.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

TEST(UrdfCollision, MeshesAreReadWithScaleAndOrigin) {
  test::TempDir dir;
  const auto urdf = dir.write(
      "r.urdf",
      "<robot name='r'><link name='base'/><joint name='j' type='revolute'><parent link='base'/>"
      "<child link='arm'/><axis xyz='0 0 1'/><limit lower='-1' upper='1' velocity='1' "
      "effort='1'/></joint>"
      "<link name='arm'><collision><origin xyz='0.1 0.2 0.3' rpy='0 0 1.5707963267948966'/>"
      "<geometry><mesh filename='package://p/m.stl' scale='0.001 0.001 "
      "0.002'/></geometry></collision>"
      "<collision><geometry><box size='1 1 1'/></geometry></collision></link></robot>");
  const RobotModel model = RobotModel::load_urdf_file(urdf);
  const auto meshes = read_mesh_collisions(model, urdf);
  ASSERT_EQ(meshes.size(), 1u);
  EXPECT_EQ(model.links()[static_cast<std::size_t>(meshes[0].link)].name, "arm");
  EXPECT_EQ(meshes[0].filename, "package://p/m.stl");
  EXPECT_NEAR((meshes[0].scale - Vec3(0.001, 0.001, 0.002)).norm(), 0, 1e-15);
  EXPECT_NEAR((meshes[0].T_link_mesh.translation() - Vec3(0.1, 0.2, 0.3)).norm(), 0, 1e-12);
  EXPECT_NEAR((meshes[0].T_link_mesh.linear() * Vec3::UnitX() - Vec3::UnitY()).norm(), 0, 1e-9);
}

}  // namespace
}  // namespace shapectl
