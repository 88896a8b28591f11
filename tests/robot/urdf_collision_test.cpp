// Mesh collision geometry read from URDF and its file names resolved the ROS way.
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

TEST(UrdfCollision, MeshFilesResolveRelativeToTheUrdfAndThroughPackagePaths) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "share" / "pkg" / "meshes");
  std::filesystem::create_directories(dir.path() / "urdf");
  const auto in_package = dir.write("share/pkg/meshes/a.stl", "solid a\nendsolid a\n");
  const auto beside = dir.write("urdf/b.obj", "");
  const auto urdf_dir = dir.path() / "urdf";
  EXPECT_EQ(resolve_mesh_file("package://pkg/meshes/a.stl", urdf_dir, {dir.path() / "share"}),
            in_package);
  // A package path may also name the package folder itself.
  EXPECT_EQ(resolve_mesh_file("package://pkg/meshes/a.stl", urdf_dir,
                              {dir.path() / "share" / "pkg"}),
            in_package);
  EXPECT_EQ(resolve_mesh_file("b.obj", urdf_dir, {}), beside);
  EXPECT_EQ(resolve_mesh_file("file://" + beside.string(), urdf_dir, {}), beside);
  EXPECT_FALSE(resolve_mesh_file("package://pkg/meshes/a.stl", urdf_dir, {}));
  EXPECT_FALSE(
      resolve_mesh_file("package://other/meshes/a.stl", urdf_dir, {dir.path() / "nowhere"}));
  EXPECT_FALSE(resolve_mesh_file("missing.obj", urdf_dir, {}));
}

}  // namespace
}  // namespace shapectl
