// Visual meshes in URDF: read as Shape::Kind::Mesh with file name, scale, origin and colour; their
// files found (or a warning naming URDF, link and file); collision meshes ignored with one line.
#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>
#include <shapectl/robot/visual_meshes.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

// base carries a box and an STL (scaled, rotated, coloured); arm an OBJ, a DAE, a missing
// mesh, a texture image and two collision meshes.
std::string two_link_urdf() {
  return "<robot name='r'>"
         "<material name='white'><color rgba='1 1 1 1'/></material>"
         "<link name='base'>"
         "<visual><geometry><box size='0.1 0.1 0.1'/></geometry></visual>"
         "<visual><origin xyz='0.1 0.2 0.3' rpy='0 0 1.5707963267948966'/>"
         "<geometry><mesh filename='package://bot/meshes/base.stl' scale='0.001 0.001 0.002'/>"
         "</geometry><material name='white'/></visual></link>"
         "<joint name='j' type='revolute'><parent link='base'/><child link='arm'/>"
         "<axis xyz='0 0 1'/><limit lower='-1' upper='1' velocity='1' effort='1'/></joint>"
         "<link name='arm'>"
         "<visual><geometry><mesh filename='meshes/arm.obj'/></geometry></visual>"
         "<visual><geometry><mesh filename='package://bot/meshes/hand.DAE'/></geometry></visual>"
         "<visual><geometry><mesh filename='package://bot/meshes/gone.stl'/></geometry></visual>"
         "<visual><geometry><mesh filename='package://bot/meshes/skin.png'/></geometry></visual>"
         "<collision><geometry><mesh filename='package://bot/meshes/arm.stl'/></geometry>"
         "</collision><collision><geometry><mesh filename='package://bot/meshes/b.stl'/>"
         "</geometry></collision></link></robot>";
}

TEST(VisualMeshes, UrdfMeshVisualsAreReadWithFileScaleOriginAndColour) {
  const RobotModel model = RobotModel::from_urdf_string(two_link_urdf(), "r.urdf");
  const auto& base = model.links()[0].visual_shapes;
  ASSERT_EQ(base.size(), 2u);
  EXPECT_EQ(base[0].kind, Shape::Kind::Box);
  const Shape& stl = base[1];
  EXPECT_EQ(stl.kind, Shape::Kind::Mesh);
  EXPECT_EQ(stl.mesh_filename, "package://bot/meshes/base.stl");
  EXPECT_NEAR((stl.mesh_scale - Vec3(0.001, 0.001, 0.002)).norm(), 0, 1e-15);
  EXPECT_NEAR((stl.T_link_shape.translation() - Vec3(0.1, 0.2, 0.3)).norm(), 0, 1e-12);
  EXPECT_NEAR((stl.T_link_shape.linear() * Vec3::UnitX() - Vec3::UnitY()).norm(), 0, 1e-9);
  ASSERT_TRUE(stl.rgba);
  EXPECT_EQ(*stl.rgba, Eigen::Vector4d(1, 1, 1, 1));
  const auto& arm = model.links()[1].visual_shapes;
  ASSERT_EQ(arm.size(), 4u);
  EXPECT_EQ(arm[0].mesh_filename, "meshes/arm.obj");
  EXPECT_EQ(arm[0].mesh_scale, Vec3::Ones());
  EXPECT_FALSE(arm[0].rgba);
  EXPECT_TRUE(model.links()[1].collision_shapes.empty());
  // Collision meshes: one warning for all of them, not one per mesh.
  ASSERT_EQ(model.warnings().size(), 1u);
  EXPECT_NE(model.warnings()[0].find("2 collision meshes ignored for the collision model"),
            std::string::npos)
      << model.warnings()[0];
  EXPECT_NE(model.warnings()[0].find("package://bot/meshes/arm.stl"), std::string::npos);
}

TEST(VisualMeshes, AZeroOrNonFiniteScaleNamesTheLink) {
  const std::string urdf =
      "<robot name='r'><link name='base'><visual><geometry>"
      "<mesh filename='a.stl' scale='1 0 1'/></geometry></visual></link></robot>";
  try {
    RobotModel::from_urdf_string(urdf, "r.urdf");
    FAIL() << "accepted a zero scale";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("link 'base': visual mesh scale"), std::string::npos)
        << e.what();
  }
}

TEST(VisualMeshes, FilesAreFoundThroughPackagePathsAndTheUrdfFolderOrExplained) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "share" / "bot" / "meshes");
  std::filesystem::create_directories(dir.path() / "robot" / "meshes");
  const auto stl = dir.write("share/bot/meshes/base.stl", "solid a\nendsolid a\n");
  const auto dae = dir.write("share/bot/meshes/hand.DAE", "<COLLADA/>");
  dir.write("share/bot/meshes/skin.png", "png");
  const auto obj = dir.write("robot/meshes/arm.obj", "v 0 0 0\n");
  const auto urdf = dir.write("robot/r.urdf", two_link_urdf());
  const RobotModel model = RobotModel::load_urdf_file(urdf);
  const auto meshes = find_visual_meshes(model, {dir.path() / "share"});
  ASSERT_EQ(meshes.size(), 5u);
  EXPECT_EQ(meshes[0].link, 0);
  EXPECT_EQ(meshes[0].shape, 1);
  EXPECT_EQ(meshes[0].file, std::filesystem::absolute(stl));
  EXPECT_EQ(meshes[0].format, MeshFormat::Stl);
  EXPECT_EQ(meshes[1].file, std::filesystem::absolute(obj));
  EXPECT_EQ(meshes[1].format, MeshFormat::Obj);
  EXPECT_EQ(meshes[2].file, std::filesystem::absolute(dae));
  EXPECT_EQ(meshes[2].format, MeshFormat::Dae);
  EXPECT_STREQ(to_string(meshes[2].format), "dae");
  for (int k : {0, 1, 2}) EXPECT_TRUE(meshes[static_cast<std::size_t>(k)].problem.empty());

  EXPECT_FALSE(meshes[3].file);
  const std::string missing = visual_mesh_warning(model, meshes[3]);
  EXPECT_NE(missing.find(urdf.string() + ": link 'arm': visual mesh "
                                         "'package://bot/meshes/gone.stl' not found"),
            std::string::npos)
      << missing;
  EXPECT_NE(missing.find("--package-path"), std::string::npos);
  EXPECT_FALSE(meshes[4].file);
  EXPECT_NE(visual_mesh_warning(model, meshes[4]).find("skin.png' is not STL, DAE or OBJ"),
            std::string::npos);

  // Without the package path only the mesh beside the URDF is found.
  const auto alone = find_visual_meshes(model, {});
  ASSERT_EQ(alone.size(), 5u);
  EXPECT_FALSE(alone[0].file);
  EXPECT_TRUE(alone[1].file);
  EXPECT_FALSE(alone[2].file);
}

}  // namespace
}  // namespace shapectl
