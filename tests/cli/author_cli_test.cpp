// `shapectl author`: from a two-arm URDF written here and a generated surface mesh, a scene that
// `statics` and `solve` accept, with the robot within limits, collision-free and holding its grips.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using Json = nlohmann::json;
using test::run_cli;
using test::TempDir;

// One collision primitive of the test robot, in its link frame (as written into the URDF).
struct Primitive {
  std::string link;
  std::string kind;  // box (size), cylinder (radius, length along z), sphere (radius)
  Eigen::Vector3d xyz;
  Eigen::Vector3d rpy;
  Eigen::Vector3d size;
  double radius = 0;
  double length = 0;
};

std::vector<Primitive> primitives() {
  std::vector<Primitive> p{{"base", "box", {0, 0, -0.05}, {0, 0, 0}, {0.2, 0.5, 0.05}}};
  for (const std::string s : {"l", "r"}) {
    p.push_back({s + "_link1", "cylinder", {0, 0, 0.05}, {0, 0, 0}, {}, 0.04, 0.1});
    p.push_back({s + "_link2", "box", {0.125, 0, 0}, {0, 0, 0}, {0.25, 0.05, 0.05}});
    p.push_back({s + "_link3", "cylinder", {0.08, 0, 0}, {0, M_PI / 2, 0}, {}, 0.025, 0.16});
    p.push_back({s + "_tool", "sphere", {0, 0, 0}, {0, 0, 0}, {}, 0.01});
  }
  // The left hand as a mesh in a ROS package (hand.obj, a 40 × 30 × 20 mm box).
  p.push_back({"l_link3", "mesh", {0.17, 0, 0}, {0, 0, 0}, {0.04, 0.03, 0.02}});
  return p;
}

Eigen::Isometry3d pose(const Primitive& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = p.xyz;
  T.linear() = (Eigen::AngleAxisd(p.rpy.z(), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(p.rpy.y(), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(p.rpy.x(), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

std::string geometry(const Primitive& p) {
  std::ostringstream g;
  g.precision(17);
  g << "<collision><origin xyz='" << p.xyz.transpose() << "' rpy='" << p.rpy.transpose()
    << "'/><geometry>";
  if (p.kind == "box") g << "<box size='" << p.size.transpose() << "'/>";
  if (p.kind == "cylinder")
    g << "<cylinder radius='" << p.radius << "' length='" << p.length << "'/>";
  if (p.kind == "sphere") g << "<sphere radius='" << p.radius << "'/>";
  if (p.kind == "mesh") g << "<mesh filename='package://two_arms/meshes/hand.obj'/>";
  g << "</geometry></collision>";
  return g.str();
}

// Two 3-joint arms on a base; the right hand's mesh is missing on purpose. With `finger`, the
// left tool carries a part on a prismatic joint (±10 cm) that moves no tool, like a gripper's
// finger or a camera slide. (A real 25 mm finger named active keeps a quarter of its stroke
// from each limit, not the 0.05 margin: robot/joint_limits.hpp, joint_margin.)
std::string urdf(bool finger = false) {
  std::map<std::string, std::string> links;
  for (const auto& p : primitives()) links[p.link] += geometry(p);
  links["r_link3"] +=
      "<collision><origin xyz='0.17 0 0'/><geometry><mesh "
      "filename='package://two_arms/meshes/missing.stl'/></geometry></collision>";
  auto link = [&](const std::string& name) {
    return "<link name='" + name + "'>" + links[name] + "</link>";
  };
  auto joint = [](const std::string& name, const std::string& parent, const std::string& child,
                  const std::string& xyz, const std::string& axis, const std::string& limit) {
    return "<joint name='" + name + "' type='revolute'><parent link='" + parent +
           "'/><child link='" + child + "'/><origin xyz='" + xyz + "'/><axis xyz='" + axis +
           "'/><limit lower='-" + limit + "' upper='" + limit +
           "' velocity='2' effort='1'/></joint>";
  };
  std::string xml = "<robot name='two_arms'>" + link("base");
  for (const std::string s : {"l", "r"}) {
    xml += joint(s + "1", "base", s + "_link1", s == "l" ? "0 0.15 0" : "0 -0.15 0", "0 0 1", "2") +
           link(s + "_link1");
    xml += joint(s + "2", s + "_link1", s + "_link2", "0 0 0.1", "0 1 0", "2") + link(s + "_link2");
    xml +=
        joint(s + "3", s + "_link2", s + "_link3", "0.25 0 0", "0 1 0", "2.5") + link(s + "_link3");
    xml += "<joint name='" + s + "_tool_joint' type='fixed'><parent link='" + s +
           "_link3'/><child link='" + s + "_tool'/><origin xyz='0.2 0 0'/></joint>" +
           link(s + "_tool");
  }
  if (finger)
    xml +=
        "<joint name='l_finger_joint' type='prismatic'><parent link='l_tool'/><child "
        "link='l_finger'/><axis xyz='0 1 0'/><limit lower='-0.1' upper='0.1' velocity='0.1' "
        "effort='1'/></joint><link name='l_finger'/>";
  return xml + "</robot>";
}

// A closed box surface centred at the origin, each face a grid of quads.
std::string box_obj(const Eigen::Vector3d& size, const std::array<int, 3>& n) {
  std::map<std::array<double, 3>, int> index;
  std::ostringstream v, f;
  v.precision(17);
  auto vertex = [&](const std::array<double, 3>& p) {
    auto [it, added] = index.emplace(p, static_cast<int>(index.size()) + 1);
    if (added) v << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
    return it->second;
  };
  auto coordinate = [&](int axis, int i) { return -size[axis] / 2 + size[axis] * i / n[axis]; };
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int side : {0, n[a]})
      for (int i = 0; i < n[b]; ++i)
        for (int j = 0; j < n[c]; ++j) {
          std::vector<int> quad;
          for (auto [di, dj] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
            std::array<double, 3> p{};
            p[a] = coordinate(a, side);
            p[b] = coordinate(b, i + di);
            p[c] = coordinate(c, j + dj);
            quad.push_back(vertex(p));
          }
          if (side == 0) std::reverse(quad.begin(), quad.end());
          f << "f " << quad[0] << " " << quad[1] << " " << quad[2] << " " << quad[3] << "\n";
        }
  }
  return v.str() + f.str();
}

struct Authored {
  TempDir dir;
  std::filesystem::path urdf, mesh, scene, spheres, report;
  test::CliRun run;
};

std::vector<std::string> author_args(const Authored& a) {
  return {"author",
          a.urdf.string(),
          "--mesh",
          a.mesh.string(),
          "--end-effectors",
          "left=l_tool,right=r_tool",
          "--package-path",
          (a.dir.path() / "pkg").string(),
          "--out",
          a.scene.string(),
          "--report",
          a.report.string(),
          "--allow-missing-meshes"};
}

void write_inputs(Authored& a) {
  std::filesystem::create_directories(a.dir.path() / "pkg" / "two_arms" / "meshes");
  std::filesystem::create_directories(a.dir.path() / "out");
  a.urdf = a.dir.write("arms.urdf", urdf());
  a.dir.write("pkg/two_arms/meshes/hand.obj", box_obj({0.04, 0.03, 0.02}, {1, 1, 1}));
  a.mesh = a.dir.write("bar.obj", box_obj({0.34, 0.03, 0.03}, {17, 2, 2}));
  a.scene = a.dir.path() / "out" / "scene.json";
  a.spheres = a.dir.path() / "out" / "scene_spheres.json";
  a.report = a.dir.path() / "out" / "report.json";
}

Json read_json(const std::filesystem::path& file) { return Json::parse(test::read_text(file)); }

TEST(AuthorCli, ProposedSceneHoldsTheObjectAndSolvesWithinLimitsAndCollisionFree) {
  Authored a;
  write_inputs(a);
  a.run = run_cli(author_args(a));
  ASSERT_EQ(a.run.exit_code, 0) << a.run.err;
  const Json report = read_json(a.report);
  EXPECT_TRUE(report["joints_within_limits"].get<bool>());
  EXPECT_GT(report["min_clearance"].get<double>(), 0);
  EXPECT_EQ(report["inverse_kinematics"]["status"], "converged");
  ASSERT_EQ(report["grips"].size(), 2u);
  for (const auto& g : report["grips"]) {
    EXPECT_GE(g["node_count"].get<int>(), 4) << g;
    EXPECT_LT(g["tool_distance"].get<double>(), 1e-3) << g;
  }

  // Checked independently: kinematics at the reference joints with the written spheres ...
  const Json scene = read_json(a.scene);
  const auto joints_file =
      a.dir.write("ref.json", Json{{"joints", scene["robot"]["reference_joints"]}}.dump());
  const auto kinematics_out = a.dir.path() / "kin.json";
  const auto kin = run_cli({"kinematics", a.urdf.string(), "--joints", joints_file.string(),
                            "--spheres", a.spheres.string(), "--out", kinematics_out.string()});
  ASSERT_EQ(kin.exit_code, 0) << kin.err;
  const Json kinematics = read_json(kinematics_out);
  EXPECT_TRUE(kinematics["limit_violations"].empty());
  EXPECT_GT(kinematics["min_clearance"].get<double>(), 0);

  // ... statics at the reference: converged, each tool within a few mm of its gripped nodes'
  // centre.
  const auto statics_out = a.dir.path() / "statics.json";
  const auto statics = run_cli({"statics", a.scene.string(), "--out", statics_out.string()});
  ASSERT_EQ(statics.exit_code, 0) << statics.err;
  const Json equilibrium = read_json(statics_out);
  ASSERT_TRUE(equilibrium["converged"].get<bool>());
  for (const auto& grip : scene["grips"]) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int node : grip["nodes"]) {
      const auto p = equilibrium["positions"][static_cast<std::size_t>(node)];
      centre += Eigen::Vector3d(p[0], p[1], p[2]) / static_cast<double>(grip["nodes"].size());
    }
    const auto tool = equilibrium["tools"][grip["end_effector"].get<std::string>()]["position"];
    EXPECT_LT((centre - Eigen::Vector3d(tool[0], tool[1], tool[2])).norm(), 5e-3)
        << grip["end_effector"];
  }

  // ... and solve reaches targets taken from the shape at other joints.
  Json moved = scene["robot"]["reference_joints"];
  moved["l1"] = moved["l1"].get<double>() + 0.05;
  moved["r2"] = moved["r2"].get<double>() - 0.04;
  moved["l3"] = moved["l3"].get<double>() + 0.05;
  const auto moved_file = a.dir.write("moved.json", Json{{"joints", moved}}.dump());
  const auto goal_out = a.dir.path() / "goal.json";
  ASSERT_EQ(run_cli({"statics", a.scene.string(), "--joints", moved_file.string(), "--out",
                     goal_out.string()})
                .exit_code,
            0);
  const Json goal = read_json(goal_out);
  Json targets = Json::array();
  for (std::size_t i = 0; i < goal["positions"].size(); i += 7)
    targets.push_back({{"node", i}, {"position", goal["positions"][i]}});
  const auto targets_file = a.dir.write("targets.json", Json{{"targets", targets}}.dump());
  const auto solve_out = a.dir.path() / "solve.json";
  const auto solve = run_cli(
      {"solve", a.scene.string(), "--targets", targets_file.string(), "--out", solve_out.string()});
  ASSERT_EQ(solve.exit_code, 0) << solve.err;
  const Json solved = read_json(solve_out);
  EXPECT_LT(solved["error_mean"].get<double>(), 1e-3);
  EXPECT_GT(solved["min_clearance"].get<double>(), 0);
  EXPECT_TRUE(solved["limit_violations"].empty());
}

TEST(AuthorCli, GeneratedSpheresCoverSampledPointsOfEveryCollisionPrimitive) {
  Authored a;
  write_inputs(a);
  a.run = run_cli(author_args(a));
  ASSERT_EQ(a.run.exit_code, 0) << a.run.err;
  const Json spheres = read_json(a.spheres);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (const auto& p : primitives()) {
    ASSERT_TRUE(spheres["spheres"].contains(p.link)) << p.link;
    const auto& list = spheres["spheres"][p.link];
    for (int k = 0; k < 500; ++k) {
      Eigen::Vector3d local;
      if (p.kind == "box" || p.kind == "mesh")
        local = Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseProduct(p.size);
      if (p.kind == "cylinder") {
        const double angle = 2 * M_PI * u(rng), r = p.radius * std::sqrt(u(rng) + 0.5);
        local = Eigen::Vector3d(r * std::cos(angle), r * std::sin(angle), p.length * u(rng));
      }
      if (p.kind == "sphere") {
        Eigen::Vector3d d(u(rng), u(rng), u(rng));
        local = p.radius * std::cbrt(u(rng) + 0.5) * d.normalized();
      }
      const Eigen::Vector3d point = pose(p) * local;
      bool covered = false;
      for (const auto& s : list) {
        const Eigen::Vector3d c(s["center"][0], s["center"][1], s["center"][2]);
        covered = covered || (point - c).norm() <= s["radius"].get<double>();
      }
      EXPECT_TRUE(covered) << p.link << " " << p.kind << " point " << point.transpose();
    }
  }
  // Adjacent links are ignored pairs.
  bool shoulder = false;
  for (const auto& pair : spheres["ignore_pairs"])
    shoulder = shoulder || (pair[0] == "l_link1" && pair[1] == "l_link2") ||
               (pair[0] == "l_link2" && pair[1] == "l_link1");
  EXPECT_TRUE(shoulder) << spheres["ignore_pairs"];
}

TEST(AuthorCli, AMissingCollisionMeshIsAWarningNamingIt) {
  Authored a;
  write_inputs(a);
  a.run = run_cli(author_args(a));
  ASSERT_EQ(a.run.exit_code, 0) << a.run.err;
  EXPECT_NE(a.run.err.find("warning: "), std::string::npos) << a.run.err;
  EXPECT_NE(a.run.err.find("r_link3"), std::string::npos) << a.run.err;
  EXPECT_NE(a.run.err.find("missing.stl' not found"), std::string::npos) << a.run.err;
  EXPECT_EQ(read_json(a.report)["warnings"].size(), 1u);
}

// Without --allow-missing-meshes a mesh the URDF names and nobody finds stops the authoring,
// naming it and how to point at it; nothing is written.
TEST(AuthorCli, MissingMeshesAreExitOneNamingThemAndThePackagePath) {
  Authored a;
  write_inputs(a);
  std::vector<std::string> args = author_args(a);
  args.pop_back();  // --allow-missing-meshes
  const auto run = run_cli(args);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("arms.urdf: 1 mesh file not found: "
                         "'package://two_arms/meshes/missing.stl'"),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("--package-path"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--allow-missing-meshes"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(a.scene));
}

// A joint that moves no tool (a finger) is no optimisation variable: fixed at the opening asked
// for (or the value nearest 0), unless --active-joints names it.
TEST(AuthorCli, JointsThatMoveNoToolAreFixedAtTheFingerOpening) {
  Authored a;
  write_inputs(a);
  a.urdf = a.dir.write("arms.urdf", urdf(true));
  const std::vector<std::string> arms = {"l1", "l2", "l3", "r1", "r2", "r3"};
  a.run = run_cli(author_args(a));
  ASSERT_EQ(a.run.exit_code, 0) << a.run.err;
  Json robot = read_json(a.scene)["robot"];
  EXPECT_EQ(robot["active_joints"].get<std::vector<std::string>>(), arms);
  EXPECT_EQ(robot["fixed_joints"], Json({{"l_finger_joint", 0.0}}));
  EXPECT_FALSE(robot["reference_joints"].contains("l_finger_joint"));

  auto args = author_args(a);
  args.insert(args.end(), {"--finger-opening", "0.01"});
  const auto opened = run_cli(args);
  ASSERT_EQ(opened.exit_code, 0) << opened.err;
  robot = read_json(a.scene)["robot"];
  EXPECT_EQ(robot["fixed_joints"]["l_finger_joint"].get<double>(), 0.01);
  // The written scene is one every command takes.
  EXPECT_EQ(
      run_cli({"statics", a.scene.string(), "--out", (a.dir.path() / "s.json").string()}).exit_code,
      0);

  // Named explicitly, the same joints; a joint left out is fixed (at the opening asked for).
  args = author_args(a);
  args.insert(args.end(), {"--active-joints", "l1,l2,l3,r1,r2,r3"});
  const auto named = run_cli(args);
  ASSERT_EQ(named.exit_code, 0) << named.err;
  robot = read_json(a.scene)["robot"];
  EXPECT_EQ(robot["active_joints"].get<std::vector<std::string>>(), arms);
  EXPECT_EQ(robot["fixed_joints"], Json({{"l_finger_joint", 0.0}}));

  // Named active, the finger is a joint of θ like the arms' (the IK leaves it where it starts).
  args = author_args(a);
  args.insert(args.end(), {"--active-joints", "l1,l2,l3,r1,r2,r3,l_finger_joint"});
  const auto finger = run_cli(args);
  ASSERT_EQ(finger.exit_code, 0) << finger.err;
  robot = read_json(a.scene)["robot"];
  EXPECT_EQ(robot["active_joints"].size(), 7u);
  EXPECT_TRUE(robot["reference_joints"].contains("l_finger_joint"));
  EXPECT_EQ(robot["fixed_joints"], Json::object());

  for (const auto& [option, value] :
       {std::pair<std::string, std::string>{"--finger-opening", "0.5"},
        {"--active-joints", "l1,l2,nothing"}}) {
    args = author_args(a);
    args.insert(args.end(), {option, value});
    const auto run = run_cli(args);
    EXPECT_EQ(run.exit_code, 1) << option << ": " << run.err;
    EXPECT_NE(run.err.find(option), std::string::npos) << run.err;
  }
}

// --units: a mesh in millimetres gives the scene the metres version's nodes, the file scaled
// as the scene reads it.
TEST(AuthorCli, UnitsScaleTheMeshAsTheSceneReadsIt) {
  Authored a;
  write_inputs(a);
  ASSERT_EQ(run_cli(author_args(a)).exit_code, 0);
  const Json in_metres = read_json(a.report);
  a.mesh = a.dir.write("bar_mm.obj", box_obj({340, 30, 30}, {17, 2, 2}));
  auto args = author_args(a);
  args.insert(args.end(), {"--units", "mm"});
  a.run = run_cli(args);
  ASSERT_EQ(a.run.exit_code, 0) << a.run.err;
  EXPECT_EQ(read_json(a.scene)["object"]["mesh"]["units"], "mm");
  const Json in_millimetres = read_json(a.report);
  EXPECT_EQ(in_millimetres["object"]["node_count"], in_metres["object"]["node_count"]);
  for (int g = 0; g < 2; ++g)
    EXPECT_EQ(in_millimetres["grips"][g]["node_count"], in_metres["grips"][g]["node_count"]);

  // --box in the same units: 34 × 3 × 3 cm is the 0.34 × 0.03 × 0.03 m box.
  args = author_args(a);
  args[2] = "--box";
  args[3] = "34,3,3";
  args.insert(args.end(), {"--units", "cm"});
  const auto box = run_cli(args);
  ASSERT_EQ(box.exit_code, 0) << box.err;
  const Json size = read_json(a.scene)["object"]["mesh"]["box"]["size"];
  const std::array<double, 3> metres = {0.34, 0.03, 0.03};
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(size[k].get<double>(), metres[k], 1e-12);

  args = author_args(a);
  args.insert(args.end(), {"--units", "furlong"});
  const auto run = run_cli(args);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--units: expected m, cm or mm, got furlong"), std::string::npos)
      << run.err;
}

TEST(AuthorCli, BadInputIsExitOneNamingTheFieldAndLeavesAnExistingSceneAlone) {
  Authored a;
  write_inputs(a);
  const std::string before = "{\"keep\": true}\n";
  a.dir.write("out/scene.json", before);
  struct Case {
    std::vector<std::string> change;  // option, value
    std::string expected;
  };
  const std::vector<Case> cases{
      {{"--end-effectors", "left=l_tool,right=nothing"},
       "--end-effectors: expected NAME=LINK or LINK with a link of arms.urdf, got right=nothing"},
      {{"--mesh", (a.dir.path() / "absent.obj").string()}, "absent.obj"},
      {{"--object-pose", "2,0,0.1"}, "--object-pose: "},
      {{"--object-pose", "0.3,0,zero"}, "--object-pose: expected X,Y,Z or X,Y,Z,ROLL,PITCH,YAW"},
      // Finite but absurd: the option and its range are named (once blamed --grip-radius).
      {{"--object-pose", "1e300,0,0"},
       "--object-pose: expected X,Y,Z or X,Y,Z,ROLL,PITCH,YAW (m, rad) with the position within "
       "1000 m of the origin and each angle within ±1000 rad, got 1e300,0,0"},
      {{"--object-pose", "0.3,0,0.1,0,0,-1e5"}, "--object-pose: expected X,Y,Z or X,Y,Z,ROLL,"},
      {{"--grip-region", "left=1,1,1,2,2,2"},
       "--grip-region: expected a grip region for end effector 'left'"},
      {{"--tool-offset", "middle=0,0,0"},
       "--tool-offset: expected the name of one of --end-effectors"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = author_args(a);
    const auto at = std::find(args.begin(), args.end(), c.change[0]);
    if (at == args.end()) {
      args.push_back(c.change[0]);
      args.push_back(c.change[1]);
    } else {
      *(at + 1) = c.change[1];
    }
    const auto run = run_cli(args);
    EXPECT_EQ(run.exit_code, 1) << c.change[0] << " " << run.err;
    EXPECT_NE(run.err.find(c.expected), std::string::npos) << run.err;
    EXPECT_EQ(test::read_text(a.scene), before);
    for (const auto& f : std::filesystem::directory_iterator(a.scene.parent_path()))
      EXPECT_EQ(f.path().filename().string().find(".author-check-"), std::string::npos) << f.path();
  }
  // The unreachable grip says why.
  auto args = author_args(a);
  args.insert(args.end(), {"--object-pose", "2,0,0.1"});
  EXPECT_NE(run_cli(args).err.find("inverse kinematics: goals not reached"), std::string::npos);
}

TEST(AuthorCli, Utf16UrdfIsExitOneNamingTheEncodingAndTheFile) {
  Authored a;
  write_inputs(a);
  std::string utf16 = "\xFF\xFE";
  for (const char c : urdf()) utf16 += std::string{c, '\0'};
  a.dir.write("arms.urdf", utf16);
  const auto run = run_cli(author_args(a));
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find(a.urdf.string() +
                         ": URDF must be UTF-8 text; found UTF-16 (little-endian)"),
            std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(a.scene));
}

}  // namespace
}  // namespace shapectl
