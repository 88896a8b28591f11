// URDF mesh file names resolved the ROS way: package:// through package paths, file://, relative.
#include <gtest/gtest.h>

#include <cstdlib>

#include <shapectl/robot/mesh_resource.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

TEST(MeshResource, FilesResolveRelativeToTheUrdfAndThroughPackagePaths) {
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
  EXPECT_FALSE(resolve_mesh_file("package://", urdf_dir, {dir.path() / "share"}));
}

TEST(MeshResource, AFolderIsAnotherPackageOnlyWhenItsPackageXmlSaysSo) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "checkout" / "meshes");
  const auto mesh = dir.write("checkout/meshes/a.stl", "solid a\nendsolid a\n");
  const auto checkout = dir.path() / "checkout";
  // "checkout" is not named like the package and declares nothing: not the package.
  EXPECT_FALSE(resolve_mesh_file("package://arm_description/meshes/a.stl", dir.path(), {checkout}));
  dir.write("checkout/package.xml",
            "<?xml version='1.0'?>\n<package format='2'>\n  <name> arm_description </name>\n"
            "  <version>1.0.0</version>\n</package>\n");
  EXPECT_EQ(resolve_mesh_file("package://arm_description/meshes/a.stl", dir.path(), {checkout}),
            mesh);
  EXPECT_FALSE(resolve_mesh_file("package://other/meshes/a.stl", dir.path(), {checkout}));
}

TEST(MeshResource, RosPackagePathEntriesFollowTheGivenOnes) {
  const char* old = std::getenv("ROS_PACKAGE_PATH");
  const std::string saved = old ? old : "";
  ::setenv("ROS_PACKAGE_PATH", "/opt/a::/opt/b", 1);
  const auto paths = with_ros_package_path({"/given"});
  if (old) ::setenv("ROS_PACKAGE_PATH", saved.c_str(), 1);
  else ::unsetenv("ROS_PACKAGE_PATH");
  EXPECT_EQ(paths, (std::vector<std::filesystem::path>{"/given", "/opt/a", "/opt/b"}));
}

}  // namespace
}  // namespace shapectl
