#include <shapectl/scene_io/scene_file.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <shapectl/fem/material.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/io/length_units.hpp>
#include <shapectl/linalg/cholesky_backend.hpp>
#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/mesh/load_mesh.hpp>
#include <shapectl/mesh/mesh_limits.hpp>
#include <shapectl/mesh/surface_mesher.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/robot_model.hpp>
#include <shapectl/scene_io/obstacle_reader.hpp>
#include <shapectl/sim/object_statics.hpp>
#include <shapectl/sim/scene_checks.hpp>

namespace shapectl {

namespace {

// Generous bounds on scene numbers: finite but absurd values (gravity 1e300) are typos.
constexpr double max_distance = max_scene_distance;  // m, positions and sizes
constexpr double max_gravity = 1e3;                  // m/s^2 (100 g)
constexpr double max_stiffness = 1e12;               // N/m, and the barrier stiffnesses
constexpr double max_weight = 1e12;                  // objective weights
constexpr double max_force = 1e9;                    // N, an applied load

// A positive number from lo to hi; "a positive number" for zero or negative values.
double positive_in(const JsonInput& j, double lo, double hi, const std::string& unit) {
  j.positive();
  return j.number_in(lo, hi, unit);
}

}  // namespace

AlignedBox read_box(const JsonInput& j) {
  j.expect_only({"min", "max"});
  AlignedBox box{j.at("min").vec3_within(max_distance, "a point", "m"),
                 j.at("max").vec3_within(max_distance, "a point", "m")};
  if ((box.max - box.min).minCoeff() < 0) j.at("max").fail("a corner not below min in any axis");
  return box;
}

namespace {
// The "box" and/or "nodes" keys of `j`, which may have others.
NodeSelection read_selection_keys(const JsonInput& j, int node_count) {
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
}  // namespace

NodeSelection read_node_selection(const JsonInput& j, int node_count) {
  j.expect_only({"box", "nodes"});
  return read_selection_keys(j, node_count);
}

Eigen::Isometry3d read_pose(const JsonInput& j) {
  j.expect_only({"position", "rpy"});
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (j.has("position"))
    T.translation() = j.at("position").vec3_within(max_distance, "a position", "m");
  if (j.has("rpy"))
    T.linear() = rotation_from_rpy(j.at("rpy").vec3_within(max_scene_angle, "angles", "rad"));
  return T;
}

double read_mesh_scale(const JsonInput& j) {
  if (j.has("units") && j.has("scale"))
    j.at("scale").fail_problem("give \"units\" or \"scale\", not both");
  if (j.has("scale")) return positive_in(j.at("scale"), 1e-9, 1e9, "");
  if (!j.has("units")) return 1;
  if (const auto scale = metres_per_unit(j.at("units").string())) return *scale;
  j.at("units").fail("\"m\", \"cm\" or \"mm\" (or give \"scale\": factor to metres)");
}

namespace {

// A generated box: sizes and cell counts bounded, cells not so flat that a tet degenerates.
std::shared_ptr<const TetMesh> read_box_mesh(const JsonInput& box) {
  box.expect_only({"size", "cells", "hole"});
  const JsonInput size_json = box.at("size");
  if (size_json.size() != 3) size_json.fail("an array of 3 numbers");
  Vec3 size;
  for (int k = 0; k < 3; ++k) size[k] = positive_in(size_json.at(k), 1e-6, max_distance, "m");
  const JsonInput cells = box.at("cells");
  if (cells.size() != 3) cells.fail("an array of 3 whole numbers");
  std::array<int, 3> n{};
  for (int k = 0; k < 3; ++k) n[k] = static_cast<int>(cells.at(k).integer_in(1, 1000));
  if (6LL * n[0] * n[1] * n[2] > max_mesh_tets)
    cells.fail("at most " + std::to_string(max_mesh_tets / 6) +
               " cells in all (6 tetrahedra each, at most " + std::to_string(max_mesh_tets) +
               " tetrahedra)");
  // Each tet of a cell h has volume hx hy hz / 6 and its diagonal as longest edge; TetMesh
  // calls a tet degenerate below 1e-9 × edge³: refuse with margin, naming the field.
  const Vec3 h = size.cwiseQuotient(Vec3(n[0], n[1], n[2]));
  if (!(h.prod() / 6 > 1e-8 * std::pow(h.norm(), 3))) {
    std::ostringstream got;
    got << "cells of " << h.x() << " x " << h.y() << " x " << h.z() << " m";
    throw InputError(box.source(), size_json.path(),
                     "a size whose cells (size / cells) are not too flat for tetrahedra",
                     got.str());
  }
  std::optional<BoxHole> hole;
  if (box.has("hole")) {
    const AlignedBox b = read_box(box.at("hole"));
    hole = BoxHole{b.min, b.max};
  }
  try {
    return std::make_shared<const TetMesh>(make_box_mesh(size, n, hole));
  } catch (const InputError& e) {
    throw InputError(box.source(), box.path(), e.what());
  }
}

// A mesh file, its coordinates scaled to metres: a surface before TetGen sees it (so
// max_tet_volume is in m^3 either way), a volume mesh node by node.
std::shared_ptr<const TetMesh> read_mesh_file(const std::filesystem::path& file, double scale,
                                              const SurfaceMeshOptions& options,
                                              const MeshOrigin& origin) {
  if (is_surface_file(file)) {
    TriangleSurface surface = read_surface(file);
    Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
    for (Vec3& v : surface.vertices) {
      v *= scale;
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    // Before TetGen: a surface in mm would otherwise fail on its volume bound, or take long.
    if (!surface.vertices.empty())
      check_object_extent(options.origin_file, origin, hi - lo, nullptr);
    return std::make_shared<const TetMesh>(tetrahedralize_surface(surface, options, file.string()));
  }
  const TetMesh mesh = load_mesh(file, options);
  if (scale == 1) return std::make_shared<const TetMesh>(mesh);
  std::vector<Vec3> nodes = mesh.rest_positions();
  for (Vec3& x : nodes) x *= scale;
  std::vector<std::array<int, 4>> tets;
  for (const TetRest& t : mesh.tets()) tets.push_back(t.nodes);
  return std::make_shared<const TetMesh>(std::move(nodes), std::move(tets), file.string());
}

std::shared_ptr<const TetMesh> read_mesh(const JsonInput& j, MeshOrigin& origin) {
  origin.field = j.path();
  if (j.is_string()) {
    const auto path = j.file_path();
    origin.kind =
        is_surface_file(path) ? MeshOrigin::Kind::SurfaceFile : MeshOrigin::Kind::VolumeFile;
    return read_mesh_file(path, 1, {.origin_file = j.source(), .origin_path = j.path()}, origin);
  }
  if (!j.is_object()) j.fail("a mesh file name or an object with \"box\" or \"file\"");
  if (j.has("box")) {
    j.expect_only({"box"});
    origin.kind = MeshOrigin::Kind::Box;
    return read_box_mesh(j.at("box"));
  }
  j.expect_only(
      {"file", "units", "scale", "max_radius_edge_ratio", "max_tet_volume", "keep_surface"});
  SurfaceMeshOptions options{.origin_file = j.source(), .origin_path = j.path()};
  if (j.has("max_radius_edge_ratio"))
    options.max_radius_edge_ratio = j.at("max_radius_edge_ratio").non_negative();
  if (j.has("max_tet_volume")) options.max_tet_volume = j.at("max_tet_volume").non_negative();
  if (j.has("keep_surface")) options.keep_surface = j.at("keep_surface").boolean();
  const double scale = read_mesh_scale(j);
  const auto path = j.at("file").file_path();
  origin.kind =
      is_surface_file(path) ? MeshOrigin::Kind::SurfaceFile : MeshOrigin::Kind::VolumeFile;
  origin.units_given = j.has("units") || j.has("scale");
  return read_mesh_file(path, scale, options, origin);
}

Material read_material(const JsonInput& j) {
  if (j.has("youngs_modulus") || j.has("poisson_ratio")) {
    j.expect_only({"youngs_modulus", "poisson_ratio", "density"});
    const double E = positive_in(j.at("youngs_modulus"), 1, 1e13, "Pa");
    const double nu = j.at("poisson_ratio").number();
    if (!(nu > 0 && nu < 0.5)) j.at("poisson_ratio").fail("a number between 0 and 0.5 (exclusive)");
    return material_from_youngs(E, nu, positive_in(j.at("density"), 1e-3, 1e5, "kg/m^3"));
  }
  j.expect_only({"mu", "kappa", "density"});
  return {.mu = positive_in(j.at("mu"), 0.1, 1e13, "Pa"),
          .kappa = positive_in(j.at("kappa"), 0.1, 1e16, "Pa"),
          .density = positive_in(j.at("density"), 1e-3, 1e5, "kg/m^3")};
}

std::string significant(double value, int digits) {
  std::ostringstream out;
  out.precision(digits);
  out << value;
  return out.str();
}

// A material whose load doubles resolve on the scene's mesh under its gravity
// (sim/object_statics.hpp, roundoff_load_ratio): otherwise the rest shape would pass as the
// equilibrium. Names the field and its largest valid value.
void check_resolvable_material(const JsonInput& j, const Scene& scene, const Material& m) {
  const double ratio = roundoff_load_ratio(scene, m);
  if (ratio <= 1) return;
  const std::string why =
      " on this mesh under this gravity (beyond, round-off in the forces would exceed 1 % of a "
      "node's load: the rest shape would pass as the equilibrium)";
  if (j.has("poisson_ratio")) {
    const double E = j.at("youngs_modulus").number(), nu = j.at("poisson_ratio").number();
    auto resolves = [&](double youngs, double poisson) {
      return roundoff_load_ratio(scene, material_from_youngs(youngs, poisson, m.density)) <= 1;
    };
    // The ratio grows with nu (mu + kappa = E/(2(1+nu)(1-2nu))): bisect on log(0.5 - nu).
    double valid = 0.49, invalid = 1e-17;
    if (resolves(E, 0.5 - valid)) {
      for (int k = 0; k < 24; ++k) {  // to a factor 1 + 3e-6 of the gap
        const double mid = std::sqrt(valid * invalid);
        (resolves(E, 0.5 - mid) ? valid : invalid) = mid;
      }
      const double gap = 1.01 * valid;  // rounded into the valid side
      j.at("poisson_ratio")
          .fail("a number from 0 to " + significant(0.5 - gap, 10) + " (0.5 - " +
                significant(gap, 2) + ")" + why);
    }
    // Too stiff even at nu = 0.01: under gravity the ratio is proportional to E.
    if (const double largest = 0.99 * E / ratio; largest >= 1 && resolves(largest, nu))
      j.at("youngs_modulus").fail("at most " + significant(largest, 3) + " Pa" + why);
  } else if (const double kappa = 0.99 * ((m.mu + m.kappa) / ratio - m.mu); kappa >= 0.1) {
    j.at("kappa").fail("at most " + significant(kappa, 3) + " Pa" + why);
  }
  j.fail_problem("a material too stiff for its weight" + why);
}

// "regions": [{"box", "material"}]: each material checked as the object's is.
std::vector<MaterialRegion> read_regions(const JsonInput& list, const Scene& scene) {
  std::vector<MaterialRegion> regions;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const JsonInput r = list.at(k);
    r.expect_only({"box", "material"});
    regions.push_back({.box = read_box(r.at("box")), .material = read_material(r.at("material"))});
    check_resolvable_material(r.at("material"), scene, regions.back().material);
  }
  return regions;
}

// A load on no node or a region of no element would silently change nothing. Checked after
// check_scene, as the grips' regions are: a mesh drawn in mm misses every box, and the object's
// size says why.
void refuse_empty_selections(const JsonInput& root, const Scene& scene) {
  if (root.has("loads")) refuse_empty_loads(root.at("loads"), scene.loads);
  const TetMesh& mesh = *scene.object_mesh;
  for (std::size_t k = 0; k < scene.regions.size(); ++k) {
    const MaterialRegion& region = scene.regions[k];
    if (std::none_of(mesh.tets().begin(), mesh.tets().end(),
                     [&](const TetRest& t) { return region.contains(mesh, t); }))
      root.at("regions").at(k).at("box").fail(
          "a box around the centroid of at least one element (rest positions, object "
          "coordinates)");
  }
}

RobotSetup read_robot(const JsonInput& j) {
  j.expect_only({"urdf", "reference_joints", "active_joints", "fixed_joints", "end_effectors",
                 "collision_spheres", "joint_limit_margin", "joint_limit_stiffness"});
  RobotSetup r;
  const auto urdf = j.at("urdf").file_path();
  r.model = std::make_shared<RobotModel>(RobotModel::load_urdf_file(urdf));
  auto read_map = [](const JsonInput& m) {
    std::map<std::string, double> values;
    for (const auto& name : m.keys()) values[name] = m.at(name).number_in(-1e3, 1e3, "rad or m");
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
    r.model->set_fixed_joint_values(read_map(j.at("fixed_joints")),
                                    j.source() + ": robot.fixed_joints");
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
    if (e.has("tcp")) ee.tcp_link = e.at("tcp").vec3_within(max_distance, "a point", "m");
    for (const auto& other : r.end_effectors)
      if (other.name == ee.name) e.at("name").fail("a name not used by another end effector");
    r.end_effectors.push_back(ee);
  }
  if (j.has("collision_spheres"))
    r.collisions = std::make_shared<const CollisionModel>(
        CollisionModel::load_json_file(*r.model, j.at("collision_spheres").file_path()));
  if (j.has("joint_limit_margin")) {
    j.at("joint_limit_margin").non_negative();
    r.joint_limit_margin = j.at("joint_limit_margin").number_in(0, 10, "rad or m");
  }
  if (j.has("joint_limit_stiffness"))
    r.joint_limit_stiffness = positive_in(j.at("joint_limit_stiffness"), 1e-12, max_stiffness, "");
  return r;
}

std::vector<Grip> read_grips(const JsonInput& list, const RobotSetup& robot, const TetMesh& mesh) {
  std::vector<Grip> grips;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const JsonInput g = list.at(k);
    g.expect_only({"end_effector", "region", "nodes", "offset"});
    Grip grip;
    // Where the gripper really holds the object (shapectl calibrate fits it): about the TCP.
    if (g.has("offset")) grip.offset = read_pose(g.at("offset"));
    const std::string name = g.at("end_effector").string();
    for (std::size_t e = 0; e < robot.end_effectors.size(); ++e)
      if (robot.end_effectors[e].name == name) grip.end_effector = static_cast<int>(e);
    if (grip.end_effector < 0) g.at("end_effector").fail("the name of one of robot.end_effectors");
    NodeSelection selection;
    if (g.has("region")) selection = read_node_selection(g.at("region"), mesh.node_count());
    if (g.has("nodes")) {
      const JsonInput nodes = g.at("nodes");
      for (std::size_t n = 0; n < nodes.size(); ++n)
        selection.nodes.push_back(
            static_cast<int>(nodes.at(n).integer_in(0, mesh.node_count() - 1)));
    }
    if (!g.has("region") && !g.has("nodes")) g.fail("a grip with \"region\" or \"nodes\"");
    grip.nodes = selection.resolve(mesh);
    // An empty region is reported by check_scene, after the object size (a mesh in mm misses it).
    grips.push_back(grip);
  }
  return grips;
}

// The object: its mesh (no node beyond max_distance of the origin), material and placement.
void read_object(const JsonInput& object, Scene& scene) {
  object.expect_only({"mesh", "material", "pose"});
  scene.object_mesh = read_mesh(object.at("mesh"), scene.mesh_origin);
  const double reach = std::max(scene.object_mesh->bounds_min().cwiseAbs().maxCoeff(),
                                scene.object_mesh->bounds_max().cwiseAbs().maxCoeff());
  if (!(reach <= max_distance))
    object.at("mesh").fail_problem(
        "node coordinates beyond " + std::to_string(int(max_distance)) +
        " m of the origin (coordinates are metres; a mesh file drawn in mm or cm "
        "needs \"units\")");
  scene.material = read_material(object.at("material"));
  if (object.has("pose")) scene.T_world_object = read_pose(object.at("pose"));
}

StaticsSettings read_statics(const JsonInput& s) {
  s.expect_only({"max_iterations", "relative_tolerance", "linear_solver"});
  StaticsSettings statics;
  if (s.has("linear_solver")) {
    const std::string name = s.at("linear_solver").string();
    CholeskyBackend backend;
    if (parse(name, &backend)) statics.backend = backend;
    else if (name != "auto") s.at("linear_solver").fail(linear_solver_choices());
  }
  if (s.has("max_iterations"))
    statics.max_iterations = static_cast<int>(s.at("max_iterations").integer_in(1, 100000));
  if (s.has("relative_tolerance"))
    statics.relative_tolerance = positive_in(s.at("relative_tolerance"), 1e-300, 1, "");
  return statics;
}

ObjectiveWeights read_objective(const JsonInput& o) {
  o.expect_only({"shape_weight", "collision_weight", "joint_limit_weight"});
  auto weight = [&](const char* key) {
    o.at(key).non_negative();
    return o.at(key).number_in(0, max_weight, "");
  };
  ObjectiveWeights weights;
  if (o.has("shape_weight"))
    weights.shape = positive_in(o.at("shape_weight"), 1e-12, max_weight, "");
  if (o.has("collision_weight")) weights.collision = weight("collision_weight");
  if (o.has("joint_limit_weight")) weights.joint_limits = weight("joint_limit_weight");
  return weights;
}

}  // namespace

std::shared_ptr<const TetMesh> load_object_mesh(const JsonInput& j) {
  MeshOrigin origin;
  return read_mesh(j, origin);
}

Scene load_scene(const std::filesystem::path& file) {
  const JsonInput root = JsonInput::load(file);
  root.expect_only({"object", "gravity", "fixed", "loads", "regions", "statics", "robot", "grips",
                    "grip_stiffness", "objective", "obstacles", "contact"});
  Scene scene;
  scene.source = file;
  read_object(root.at("object"), scene);
  if (root.has("gravity"))
    scene.gravity = root.at("gravity").vec3_within(max_gravity, "a gravity vector", "m/s^2");
  check_resolvable_material(root.at("object").at("material"), scene, scene.material);
  if (root.has("regions")) scene.regions = read_regions(root.at("regions"), scene);
  if (root.has("fixed"))
    scene.fixed = read_node_selection(root.at("fixed"), scene.object_mesh->node_count());
  if (root.has("loads")) scene.loads = read_loads(root.at("loads"), *scene.object_mesh);
  if (root.has("statics")) scene.statics = read_statics(root.at("statics"));
  if (root.has("robot")) scene.robot = read_robot(root.at("robot"));
  if (root.has("grips")) {
    if (!scene.robot) root.at("grips").fail_problem("grips need a \"robot\"");
    scene.grips = read_grips(root.at("grips"), *scene.robot, *scene.object_mesh);
  }
  if (root.has("grip_stiffness"))
    scene.grip_stiffness = positive_in(root.at("grip_stiffness"), 1e-12, max_stiffness, "N/m");
  if (root.has("objective")) scene.weights = read_objective(root.at("objective"));
  const RobotSetup* robot = scene.robot ? &*scene.robot : nullptr;
  if (root.has("obstacles")) scene.obstacles = read_obstacles(root.at("obstacles"), robot);
  if (root.has("contact")) scene.contact = read_contact(root.at("contact"), robot);
  scene.warnings = check_scene(scene);
  refuse_empty_selections(root, scene);
  return scene;
}

// "loads": [{"nodes" and/or "box", "force"}]: a force (N, world frame) shared equally by its
// nodes (rest positions, object coordinates, as "fixed").
std::vector<NodeLoad> read_loads(const JsonInput& list, const TetMesh& mesh) {
  std::vector<NodeLoad> loads;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const JsonInput l = list.at(k);
    l.expect_only({"nodes", "box", "force"});
    loads.push_back({.nodes = read_selection_keys(l, mesh.node_count()).resolve(mesh),
                     .force = l.at("force").vec3_within(max_force, "a force", "N")});
  }
  return loads;
}

void refuse_empty_loads(const JsonInput& list, const std::vector<NodeLoad>& loads) {
  for (std::size_t k = 0; k < loads.size(); ++k) {
    if (!loads[k].nodes.empty()) continue;
    const JsonInput l = list.at(k);
    if (l.has("box"))
      l.at("box").fail("a box around at least one node (rest positions, object coordinates)");
    l.at("nodes").fail("at least one node index");
  }
}

}  // namespace shapectl
