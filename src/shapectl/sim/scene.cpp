#include <shapectl/sim/scene.hpp>

#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/mesh/load_mesh.hpp>

namespace shapectl {

std::vector<int> NodeSelection::resolve(const TetMesh& mesh) const {
  std::vector<char> chosen(mesh.node_count(), 0);
  for (int i : nodes) chosen[i] = 1;
  if (box)
    for (int i = 0; i < mesh.node_count(); ++i)
      if (box->contains(mesh.rest_positions()[i])) chosen[i] = 1;
  std::vector<int> out;
  for (int i = 0; i < mesh.node_count(); ++i)
    if (chosen[i]) out.push_back(i);
  return out;
}

Positions Scene::world_rest_positions() const {
  Positions x(3 * object_mesh->node_count());
  for (int i = 0; i < object_mesh->node_count(); ++i)
    x.segment<3>(3 * i) = T_world_object * object_mesh->rest_positions()[i];
  return x;
}

AlignedBox read_box(const JsonInput& j) {
  j.expect_only({"min", "max"});
  AlignedBox box{j.at("min").vec3(), j.at("max").vec3()};
  if ((box.max - box.min).minCoeff() < 0) j.at("max").fail("a corner not below min in any axis");
  return box;
}

NodeSelection read_node_selection(const JsonInput& j, int node_count) {
  j.expect_only({"box", "nodes"});
  if (!j.has("box") && !j.has("nodes")) j.fail("an object with \"box\" or \"nodes\"");
  NodeSelection s;
  if (j.has("box")) s.box = read_box(j.at("box"));
  if (j.has("nodes")) {
    const JsonInput list = j.at("nodes");
    for (std::size_t k = 0; k < list.size(); ++k)
      s.nodes.push_back(static_cast<int>(list.at(k).integer_in(0, node_count - 1)));
  }
  return s;
}

Eigen::Isometry3d read_pose(const JsonInput& j) {
  j.expect_only({"position", "rpy"});
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (j.has("position")) T.translation() = j.at("position").vec3();
  if (j.has("rpy")) {
    // URDF convention: fixed-axis roll about x, then pitch about y, then yaw about z.
    const Vec3 rpy = j.at("rpy").vec3();
    T.linear() = (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                  Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
                     .toRotationMatrix();
  }
  return T;
}

namespace {

std::shared_ptr<const TetMesh> read_mesh(const JsonInput& j) {
  if (j.is_string()) {
    const auto path = j.directory() / j.string();
    return std::make_shared<const TetMesh>(load_mesh(path, {}));
  }
  if (!j.is_object()) j.fail("a mesh file name or an object with \"box\" or \"file\"");
  if (j.has("box")) {
    j.expect_only({"box"});
    const JsonInput box = j.at("box");
    box.expect_only({"size", "cells", "hole"});
    const Vec3 size = box.at("size").vec3();
    for (int k = 0; k < 3; ++k)
      if (!(size[k] > 0)) box.at("size").at(k).fail("a positive number");
    const JsonInput cells = box.at("cells");
    if (cells.size() != 3) cells.fail("an array of 3 whole numbers");
    std::array<int, 3> n{};
    for (int k = 0; k < 3; ++k) n[k] = static_cast<int>(cells.at(k).integer_in(1, 1000));
    std::optional<BoxHole> hole;
    if (box.has("hole")) {
      const AlignedBox b = read_box(box.at("hole"));
      hole = BoxHole{b.min, b.max};
    }
    return std::make_shared<const TetMesh>(make_box_mesh(size, n, hole));
  }
  j.expect_only({"file", "max_radius_edge_ratio", "max_tet_volume", "keep_surface"});
  SurfaceMeshOptions options;
  if (j.has("max_radius_edge_ratio"))
    options.max_radius_edge_ratio = j.at("max_radius_edge_ratio").non_negative();
  if (j.has("max_tet_volume")) options.max_tet_volume = j.at("max_tet_volume").non_negative();
  if (j.has("keep_surface")) options.keep_surface = j.at("keep_surface").boolean();
  return std::make_shared<const TetMesh>(load_mesh(j.directory() / j.at("file").string(), options));
}

Material read_material(const JsonInput& j) {
  if (j.has("youngs_modulus") || j.has("poisson_ratio")) {
    j.expect_only({"youngs_modulus", "poisson_ratio", "density"});
    const double E = j.at("youngs_modulus").positive();
    const double nu = j.at("poisson_ratio").number();
    if (!(nu > 0 && nu < 0.5)) j.at("poisson_ratio").fail("a number between 0 and 0.5 (exclusive)");
    return material_from_youngs(E, nu, j.at("density").non_negative());
  }
  j.expect_only({"mu", "kappa", "density"});
  return {.mu = j.at("mu").positive(), .kappa = j.at("kappa").positive(),
          .density = j.at("density").non_negative()};
}

RobotSetup read_robot(const JsonInput& j) {
  j.expect_only({"urdf", "reference_joints", "active_joints", "fixed_joints", "end_effectors",
                 "collision_spheres", "joint_limit_margin", "joint_limit_stiffness"});
  RobotSetup r;
  const auto urdf = j.directory() / j.at("urdf").string();
  r.model = std::make_shared<RobotModel>(RobotModel::load_urdf_file(urdf));
  auto read_map = [](const JsonInput& m) {
    std::map<std::string, double> values;
    for (const auto& name : m.keys()) values[name] = m.at(name).number();
    return values;
  };
  if (j.has("active_joints")) {
    const JsonInput list = j.at("active_joints");
    std::vector<std::string> names;
    for (std::size_t k = 0; k < list.size(); ++k) names.push_back(list.at(k).string());
    try {
      r.model->set_active_joints(names);
    } catch (const InputError& e) {
      list.fail_problem(e.what());
    }
  }
  if (j.has("fixed_joints"))
    r.model->set_fixed_joint_values(read_map(j.at("fixed_joints")), j.source() + ": robot.fixed_joints");
  r.reference_joints = Eigen::VectorXd::Zero(r.model->active_count());
  if (j.has("reference_joints"))
    r.reference_joints = r.model->active_joints_from_map(read_map(j.at("reference_joints")),
                                                         j.source() + ": robot.reference_joints");
  const JsonInput ees = j.at("end_effectors");
  for (std::size_t k = 0; k < ees.size(); ++k) {
    const JsonInput e = ees.at(k);
    e.expect_only({"name", "link", "tcp"});
    EndEffector ee{.name = e.at("name").string()};
    const std::string link = e.at("link").string();
    const auto index = r.model->find_link(link);
    if (!index) e.at("link").fail("a link of " + urdf.filename().string());
    ee.link = *index;
    if (e.has("tcp")) ee.tcp_link = e.at("tcp").vec3();
    for (const auto& other : r.end_effectors)
      if (other.name == ee.name) e.at("name").fail("a name not used by another end effector");
    r.end_effectors.push_back(ee);
  }
  if (j.has("collision_spheres"))
    r.collisions = std::make_shared<const CollisionModel>(
        CollisionModel::load_json_file(*r.model, j.directory() / j.at("collision_spheres").string()));
  if (j.has("joint_limit_margin")) r.joint_limit_margin = j.at("joint_limit_margin").non_negative();
  if (j.has("joint_limit_stiffness")) r.joint_limit_stiffness = j.at("joint_limit_stiffness").positive();
  return r;
}

std::vector<Grip> read_grips(const JsonInput& list, const RobotSetup& robot, const TetMesh& mesh) {
  std::vector<Grip> grips;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const JsonInput g = list.at(k);
    g.expect_only({"end_effector", "region", "nodes"});
    Grip grip;
    const std::string name = g.at("end_effector").string();
    for (std::size_t e = 0; e < robot.end_effectors.size(); ++e)
      if (robot.end_effectors[e].name == name) grip.end_effector = static_cast<int>(e);
    if (grip.end_effector < 0) g.at("end_effector").fail("the name of one of robot.end_effectors");
    NodeSelection selection;
    if (g.has("region")) selection = read_node_selection(g.at("region"), mesh.node_count());
    if (g.has("nodes")) {
      const JsonInput nodes = g.at("nodes");
      for (std::size_t n = 0; n < nodes.size(); ++n)
        selection.nodes.push_back(static_cast<int>(nodes.at(n).integer_in(0, mesh.node_count() - 1)));
    }
    if (!g.has("region") && !g.has("nodes")) g.fail("a grip with \"region\" or \"nodes\"");
    grip.nodes = selection.resolve(mesh);
    if (grip.nodes.empty()) g.fail_problem("the grip region contains no node of the mesh");
    grips.push_back(grip);
  }
  return grips;
}

}  // namespace

Scene load_scene(const std::filesystem::path& file) {
  const JsonInput root = JsonInput::load(file);
  root.expect_only({"object", "gravity", "fixed", "statics", "robot", "grips", "grip_stiffness",
                    "objective"});
  Scene scene;
  scene.source = file;
  const JsonInput object = root.at("object");
  object.expect_only({"mesh", "material", "pose"});
  scene.object_mesh = read_mesh(object.at("mesh"));
  scene.material = read_material(object.at("material"));
  if (object.has("pose")) scene.T_world_object = read_pose(object.at("pose"));
  if (root.has("gravity")) scene.gravity = root.at("gravity").vec3();
  if (root.has("fixed")) scene.fixed = read_node_selection(root.at("fixed"), scene.object_mesh->node_count());
  if (root.has("statics")) {
    const JsonInput s = root.at("statics");
    s.expect_only({"max_iterations", "relative_tolerance", "linear_solver"});
    if (s.has("linear_solver")) {
      const std::string name = s.at("linear_solver").string();
      if (name == "ldlt") scene.statics.backend = SparseCholesky::Backend::SimplicialLDLT;
      else if (name == "band") scene.statics.backend = SparseCholesky::Backend::Band;
      else if (name == "cholmod") scene.statics.backend = SparseCholesky::Backend::CholmodSupernodal;
      else if (name != "auto") s.at("linear_solver").fail("\"auto\", \"ldlt\", \"band\" or \"cholmod\"");
    }
    if (s.has("max_iterations")) scene.statics.max_iterations = static_cast<int>(s.at("max_iterations").integer_in(1, 100000));
    if (s.has("relative_tolerance")) scene.statics.relative_tolerance = s.at("relative_tolerance").positive();
  }
  if (root.has("robot")) scene.robot = read_robot(root.at("robot"));
  if (root.has("grips")) {
    if (!scene.robot) root.at("grips").fail_problem("grips need a \"robot\"");
    scene.grips = read_grips(root.at("grips"), *scene.robot, *scene.object_mesh);
  }
  if (root.has("grip_stiffness")) scene.grip_stiffness = root.at("grip_stiffness").positive();
  if (root.has("objective")) {
    const JsonInput o = root.at("objective");
    o.expect_only({"shape_weight", "collision_weight", "joint_limit_weight"});
    if (o.has("shape_weight")) scene.weights.shape = o.at("shape_weight").positive();
    if (o.has("collision_weight")) scene.weights.collision = o.at("collision_weight").non_negative();
    if (o.has("joint_limit_weight")) scene.weights.joint_limits = o.at("joint_limit_weight").non_negative();
  }
  return scene;
}

}  // namespace shapectl
