// shapectl author ROBOT.urdf (--mesh MESH | --box LX,LY,LZ) --end-effectors NAME=LINK,... --out
// SCENE.json Proposes a scene from a robot and an object: collision spheres from the URDF's
// collision geometry, grip regions at the nodes nearest the tools, the object pose, and reference
// joints by inverse kinematics that put the tools at the grip regions. Writes the scene, its sphere
// file and a report; refuses (exit 1) what it cannot make plausible.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <sstream>

#include <shapectl/io/atomic_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/io/json_output.hpp>
#include <shapectl/io/length_units.hpp>
#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/mesh/load_mesh.hpp>
#include <shapectl/mesh/surface_mesher.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/inverse_kinematics.hpp>
#include <shapectl/robot/joint_limits.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/sphere_cover.hpp>
#include <shapectl/robot/urdf_collision.hpp>
#include <shapectl/robot/visual_meshes.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "commands.hpp"
#include "grasp_axes.hpp"
#include "output_option.hpp"
#include "robot_mesh_options.hpp"

namespace shapectl::cli {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct AuthorOptions {
  std::string urdf;
  std::string mesh;
  std::string box;
  std::string cells;
  std::string end_effectors;
  std::vector<std::string> tool_offsets;
  std::vector<std::string> grip_regions;
  double grip_radius = 0;  // 0: from the object's size (see add_author_command)
  std::string object_pose;
  double youngs_modulus = 2e5;
  double poisson_ratio = 0.3;
  double density = 40;
  std::vector<std::string> package_paths;
  bool allow_missing_meshes = false;
  std::string units;                     // of --mesh: "m", "cm" or "mm"; empty: metres
  std::string active_joints;             // NAME,...: exactly these; empty: those that move a tool
  std::optional<double> finger_opening;  // value of the joints that move no tool
  std::vector<std::string> approaches;   // NAME=X,Y,Z: world approach direction (grasp_axes.hpp)
  std::vector<std::string> grip_axes;    // NAME=X,Y,Z: world closing direction
  std::vector<std::string> tool_axes;    // NAME=A,C: the tool's approach and closing axes
  double sphere_margin = 0.005;
  unsigned seed = 1;
  std::string out;
  std::string spheres_out;
  std::string report;
};

constexpr double joint_limit_margin = 0.05;  // rad, as written into the scene
constexpr double tool_tolerance = 1e-3;      // m, tool ↔ grip region centre after IK
constexpr int collision_samples = 200;       // random poses to find always-colliding pairs
constexpr double always_fraction = 0.95;
constexpr std::size_t max_generated_spheres = 1000;  // IK's dense pair Jacobian stays small

// "a,b,c" as `count` (or one of `counts`) finite numbers; `option` names the option in errors.
std::vector<double> numbers(const std::string& text, const std::string& option,
                            const std::string& expected,
                            std::initializer_list<std::size_t> counts) {
  std::vector<double> values;
  std::size_t begin = 0;
  while (begin <= text.size() && values.size() <= 16) {
    const std::size_t end = std::min(text.find(',', begin), text.size());
    double v = 0;
    const auto [ptr, ec] = std::from_chars(text.data() + begin, text.data() + end, v);
    if (ec != std::errc() || ptr != text.data() + end || !std::isfinite(v))
      throw InputError("command line", option, expected, bounded_preview(text));
    values.push_back(v);
    begin = end + 1;
  }
  for (std::size_t c : counts)
    if (values.size() == c) return values;
  throw InputError("command line", option, expected, bounded_preview(text));
}

// "name=value" → {name, value}.
std::pair<std::string, std::string> named(const std::string& text, const std::string& option,
                                          const std::string& expected) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("command line", option, expected, bounded_preview(text));
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::vector<EndEffector> read_end_effectors(const AuthorOptions& o, const RobotModel& model) {
  std::vector<EndEffector> ees;
  std::stringstream list(o.end_effectors);
  for (std::string item; std::getline(list, item, ',');) {
    const auto eq = item.find('=');
    EndEffector ee{.name = eq == std::string::npos ? item : item.substr(0, eq)};
    const std::string link = eq == std::string::npos ? item : item.substr(eq + 1);
    const auto index = model.find_link(link);
    if (!index || ee.name.empty())
      throw InputError("command line", "--end-effectors",
                       "NAME=LINK or LINK with a link of " + fs::path(o.urdf).filename().string(),
                       bounded_preview(item));
    for (const auto& other : ees)
      if (other.name == ee.name)
        throw InputError("command line", "--end-effectors", "distinct names",
                         bounded_preview(ee.name));
    ee.link = *index;
    ees.push_back(ee);
  }
  if (ees.empty() || ees.size() > 16)
    throw InputError("command line", "--end-effectors", "1 to 16 end effectors",
                     bounded_preview(o.end_effectors));
  for (const auto& text : o.tool_offsets) {
    const auto [name, value] = named(text, "--tool-offset", "NAME=X,Y,Z (metres, link frame)");
    const auto xyz = numbers(value, "--tool-offset", "NAME=X,Y,Z (metres, link frame)", {3});
    bool found = false;
    for (auto& ee : ees)
      if (ee.name == name) {
        ee.tcp_link = Vec3(xyz[0], xyz[1], xyz[2]);
        found = true;
      }
    if (!found)
      throw InputError("command line", "--tool-offset", "the name of one of --end-effectors",
                       bounded_preview(name));
  }
  return ees;
}

// The index of end effector `name` in `ees`; `option` names the option in errors.
std::size_t end_effector_index(const std::vector<EndEffector>& ees, const std::string& name,
                               const std::string& option) {
  for (std::size_t e = 0; e < ees.size(); ++e)
    if (ees[e].name == name) return e;
  throw InputError("command line", option, "the name of one of --end-effectors",
                   bounded_preview(name));
}

// "x", "-y", "+z" → a unit axis.
Vec3 axis_named(const std::string& text, const std::string& option, const std::string& expected) {
  const bool negative = !text.empty() && text[0] == '-';
  const std::string axis =
      (!text.empty() && (text[0] == '-' || text[0] == '+')) ? text.substr(1) : text;
  if (axis.size() != 1 || axis[0] < 'x' || axis[0] > 'z')
    throw InputError("command line", option, expected, bounded_preview(text));
  const Vec3 unit = Vec3::Unit(axis[0] - 'x');
  return negative ? Vec3(-unit) : unit;
}

// --approach, --grip-axis and --tool-axes, one GraspAxes per end effector.
std::vector<GraspAxes> read_grasp_axes(const AuthorOptions& o,
                                       const std::vector<EndEffector>& ees) {
  std::vector<GraspAxes> axes(ees.size());
  for (auto [list, option, field] :
       {std::tuple{&o.approaches, "--approach", &GraspAxes::approach_world},
        std::tuple{&o.grip_axes, "--grip-axis", &GraspAxes::closing_world}}) {
    const std::string expected = std::string("NAME=X,Y,Z: a non-zero world direction");
    for (const auto& text : *list) {
      const auto [name, value] = named(text, option, expected);
      const auto xyz = numbers(value, option, expected, {3});
      const Vec3 direction(xyz[0], xyz[1], xyz[2]);
      if (!(direction.norm() > 1e-9))
        throw InputError("command line", option, expected, bounded_preview(text));
      axes[end_effector_index(ees, name, option)].*field = direction.normalized();
    }
  }
  const std::string expected =
      "NAME=A,C: the tool's approach and closing axes in its link frame, each x, y or z with an "
      "optional sign (e.g. z,x)";
  for (const auto& text : o.tool_axes) {
    const auto [name, value] = named(text, "--tool-axes", expected);
    const auto comma = value.find(',');
    if (comma == std::string::npos)
      throw InputError("command line", "--tool-axes", expected, bounded_preview(text));
    GraspAxes& a = axes[end_effector_index(ees, name, "--tool-axes")];
    a.approach_link = axis_named(value.substr(0, comma), "--tool-axes", expected);
    a.closing_link = axis_named(value.substr(comma + 1), "--tool-axes", expected);
    if (std::abs(a.approach_link.dot(*a.closing_link)) > 0.5)
      throw InputError("command line", "--tool-axes", expected + ", two different axes",
                       bounded_preview(text));
  }
  return axes;
}

struct ObjectMesh {
  std::shared_ptr<const TetMesh> mesh;
  Json json;  // the scene's "object.mesh"
};

ObjectMesh read_object_mesh(const AuthorOptions& o, const fs::path& scene_dir) {
  if (o.mesh.empty() == o.box.empty())
    throw InputError("command line", "--mesh", "either --mesh FILE or --box LX,LY,LZ",
                     o.mesh.empty() ? "neither" : "both");
  const std::optional<double> unit = metres_per_unit(o.units.empty() ? "m" : o.units);
  if (!unit) throw InputError("command line", "--units", "m, cm or mm", bounded_preview(o.units));
  if (!o.box.empty()) {
    // In --units like a mesh (a box typed in cm with --units cm is what the user meant).
    const auto s =
        numbers(o.box, "--box", "LX,LY,LZ: three edge lengths (--units, default m)", {3});
    const Vec3 size = *unit * Vec3(s[0], s[1], s[2]);
    if (!(size.minCoeff() >= 1e-4 && size.maxCoeff() <= 100))
      throw InputError("command line", "--box", "edge lengths from 1e-4 to 100 m",
                       bounded_preview(o.box));
    std::array<int, 3> cells{};
    if (o.cells.empty()) {
      // About four cells across the thinnest edge, at most 40 along any edge.
      for (int a = 0; a < 3; ++a)
        cells[a] =
            static_cast<int>(std::clamp(std::round(4 * size[a] / size.minCoeff()), 1.0, 40.0));
    } else {
      const auto c = numbers(o.cells, "--cells", "NX,NY,NZ: cell counts from 1 to 200", {3});
      for (int a = 0; a < 3; ++a) {
        if (!(c[a] >= 1 && c[a] <= 200 && c[a] == std::floor(c[a])))
          throw InputError("command line", "--cells", "NX,NY,NZ: cell counts from 1 to 200",
                           bounded_preview(o.cells));
        cells[a] = static_cast<int>(c[a]);
      }
    }
    return {std::make_shared<const TetMesh>(make_box_mesh(size, cells)),
            Json{{"box", {{"size", vec3_json(size)}, {"cells", cells}}}}};
  }
  const fs::path file = fs::absolute(o.mesh);
  std::error_code error;
  fs::path relative = fs::relative(file, fs::absolute(scene_dir), error);
  if (error || relative.empty()) relative = file;
  if (o.units.empty() || o.units == "m")
    return {std::make_shared<const TetMesh>(load_mesh(file)), Json(relative.generic_string())};
  // Read as the scene will read it (scaled before TetGen meshes a surface), so the grips'
  // node numbers are the scene's.
  const JsonInput read({{"file", file.string()}, {"units", o.units}}, "command line", "--mesh");
  return {load_object_mesh(read), Json{{"file", relative.generic_string()}, {"units", o.units}}};
}

struct Spheres {
  std::vector<CollisionSphere> spheres;
  std::vector<std::pair<int, int>> adjacent;  // link pairs
  std::vector<std::pair<int, int>> always;    // link pairs overlapping in (almost) every pose
};

void add_cover(std::vector<CollisionSphere>& out, int link, const std::vector<CoverSphere>& cover) {
  for (const auto& s : cover) out.push_back({link, s.center, s.radius});
}

std::vector<CollisionSphere> cover_meshes(const AuthorOptions& o, const RobotModel& model,
                                          std::vector<std::string>& warnings) {
  const std::vector<fs::path> paths = package_paths(o.package_paths);
  std::vector<CollisionSphere> spheres;
  for (const auto& m : read_mesh_collisions(model, o.urdf, xacro_options(o.package_paths))) {
    const std::string& link = model.links()[static_cast<std::size_t>(m.link)].name;
    const auto file = resolve_mesh_file(m.filename, fs::path(o.urdf).parent_path(), paths);
    if (!file || !is_surface_file(*file)) {
      warnings.push_back(o.urdf + ": link '" + link + "': collision mesh '" +
                         bounded_preview(m.filename) +
                         (file ? "' is not OBJ, STL or OFF" : "' not found (give --package-path)") +
                         ": skipped, the link has no spheres for it");
      continue;
    }
    TriangleSurface surface = read_surface(*file);
    for (auto& v : surface.vertices) v = m.T_link_mesh * v.cwiseProduct(m.scale);
    add_cover(spheres, m.link, cover_triangle_mesh(surface.vertices, surface.triangles));
  }
  return spheres;
}

// The mesh files the URDF names (collision meshes, covered with spheres; visual ones, drawn)
// that cannot be found, as written: a scene authored without them would have a robot with
// holes in its collision model.
std::vector<std::string> missing_meshes(const AuthorOptions& o, const RobotModel& model) {
  const std::vector<fs::path> paths = package_paths(o.package_paths);
  std::set<std::string> missing;
  for (const auto& m : read_mesh_collisions(model, o.urdf, xacro_options(o.package_paths)))
    if (!resolve_mesh_file(m.filename, fs::path(o.urdf).parent_path(), paths))
      missing.insert(bounded_preview(m.filename));
  for (const auto& m : find_visual_meshes(model, paths))
    if (!m.file && m.problem.rfind("not found", 0) == 0)
      missing.insert(bounded_preview(model.links()[static_cast<std::size_t>(m.link)]
                                         .visual_shapes[static_cast<std::size_t>(m.shape)]
                                         .mesh_filename));
  return {missing.begin(), missing.end()};
}

void check_meshes_found(const AuthorOptions& o, const RobotModel& model) {
  if (o.allow_missing_meshes) return;
  const std::vector<std::string> missing = missing_meshes(o, model);
  if (missing.empty()) return;
  std::string list;
  for (std::size_t k = 0; k < missing.size() && k < 5; ++k)
    list += (k ? ", '" : "'") + missing[k] + "'";
  if (missing.size() > 5) list += " and " + std::to_string(missing.size() - 5) + " more";
  throw InputError(o.urdf + ": " + std::to_string(missing.size()) + " mesh file" +
                   (missing.size() == 1 ? "" : "s") + " not found: " + list +
                   "; give --package-path DIR (the folder holding the ROS package) or set "
                   "ROS_PACKAGE_PATH, or --allow-missing-meshes to author without them");
}

// The joints θ of the scene: --active-joints if given, else every joint that moves an end
// effector. The others that could move (gripper fingers, a head) are fixed: at
// --finger-opening, else at the value nearest 0 within their limits. Returns the fixed values.
std::map<std::string, double> choose_active_joints(const AuthorOptions& o,
                                                   const std::vector<EndEffector>& ees,
                                                   RobotModel& model) {
  std::vector<std::string> active;
  if (!o.active_joints.empty()) {
    std::stringstream list(o.active_joints);
    for (std::string name; std::getline(list, name, ',');) active.push_back(name);
  } else {
    std::set<int> moving;
    for (const auto& ee : ees)
      for (const auto& entry : model.jacobian_entries(ee.link)) moving.insert(entry.joint);
    for (int j : model.active_joints())
      if (moving.count(j)) active.push_back(model.joints()[static_cast<std::size_t>(j)].name);
  }
  try {
    model.set_active_joints(active);
  } catch (const InputError& e) {
    throw InputError("command line", "--active-joints", e.what());
  }
  std::map<std::string, double> fixed;
  for (int j = 0; j < model.joint_count(); ++j) {
    const Joint& joint = model.joints()[static_cast<std::size_t>(j)];
    if (!joint.movable() || joint.mimic_master >= 0 || model.active_index(j) >= 0) continue;
    const double value = o.finger_opening.value_or(0);
    if (o.finger_opening && !(value >= joint.lower && value <= joint.upper))
      throw InputError("command line", "--finger-opening",
                       "a value within the limits of joint '" + joint.name + "' (" +
                           std::to_string(joint.lower) + " to " + std::to_string(joint.upper) + ")",
                       value);
    fixed[joint.name] = std::clamp(value, joint.lower, joint.upper);
  }
  model.set_fixed_joint_values(fixed, "command line");
  return fixed;
}

// Link pairs whose spheres overlap: from the centres at one pose.
std::set<std::pair<int, int>> overlapping_links(const CollisionModel& collision,
                                                const KinematicsState& state) {
  std::vector<Vec3> centers;
  collision.sphere_centers(state, centers);
  std::set<std::pair<int, int>> links;
  for (const auto& [a, b] : collision.pairs()) {
    const auto& sa = collision.spheres()[static_cast<std::size_t>(a)];
    const auto& sb = collision.spheres()[static_cast<std::size_t>(b)];
    if ((centers[static_cast<std::size_t>(a)] - centers[static_cast<std::size_t>(b)]).norm() <
        sa.radius + sb.radius)
      links.insert(std::minmax(sa.link, sb.link));
  }
  return links;
}

Spheres generate_spheres(const AuthorOptions& o, const RobotModel& model,
                         std::vector<std::string>& warnings) {
  Spheres s;
  for (int l = 0; l < model.link_count(); ++l)
    for (const auto& shape : model.links()[static_cast<std::size_t>(l)].collision_shapes)
      add_cover(s.spheres, l, cover_shape(shape));
  const auto meshes = cover_meshes(o, model, warnings);
  s.spheres.insert(s.spheres.end(), meshes.begin(), meshes.end());
  if (s.spheres.size() > max_generated_spheres)
    throw InputError(o.urdf, "collision geometry",
                     std::to_string(s.spheres.size()) +
                         " spheres generated, more than the limit of " +
                         std::to_string(max_generated_spheres) +
                         "; simplify the collision geometry");
  std::set<int> with_spheres;
  for (const auto& sphere : s.spheres) with_spheres.insert(sphere.link);
  for (const auto& joint : model.joints())
    if (with_spheres.count(joint.parent_link) && with_spheres.count(joint.child_link))
      s.adjacent.push_back(std::minmax(joint.parent_link, joint.child_link));
  // Pairs that overlap in nearly every pose cannot be told apart from the geometry around a
  // joint: ignore them, as MoveIt's setup assistant does.
  const CollisionModel all(model, s.spheres, 0, CollisionModel::default_stiffness, s.adjacent);
  std::mt19937 rng(o.seed);
  const Eigen::VectorXd lower = model.lower_limits(), upper = model.upper_limits();
  std::map<std::pair<int, int>, int> counts;
  for (int k = 0; k < collision_samples; ++k) {
    Eigen::VectorXd q(model.active_count());
    for (int i = 0; i < q.size(); ++i)
      q[i] = std::uniform_real_distribution<double>(std::isfinite(lower[i]) ? lower[i] : -M_PI,
                                                    std::isfinite(upper[i]) ? upper[i] : M_PI)(rng);
    for (const auto& pair : overlapping_links(all, forward_kinematics(model, q))) ++counts[pair];
  }
  for (const auto& [pair, count] : counts)
    if (count >= always_fraction * collision_samples) s.always.push_back(pair);
  return s;
}

Eigen::Isometry3d pose_from(const std::vector<double>& v) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Vec3(v[0], v[1], v[2]);
  if (v.size() == 6) T.linear() = rotation_from_rpy(Vec3(v[3], v[4], v[5]));
  return T;
}

// --object-pose X,Y,Z[,ROLL,PITCH,YAW] within the bounds a scene file's pose has.
Eigen::Isometry3d object_pose_from(const std::string& text) {
  const std::string expected = "X,Y,Z or X,Y,Z,ROLL,PITCH,YAW (m, rad)";
  const std::vector<double> v = numbers(text, "--object-pose", expected, {3, 6});
  const bool angles_in_range =
      std::all_of(v.begin() + 3, v.end(), [](double a) { return std::abs(a) <= max_scene_angle; });
  if (!(Vec3(v[0], v[1], v[2]).norm() <= max_scene_distance) || !angles_in_range) {
    std::ostringstream range;
    range << expected << " with the position within " << max_scene_distance
          << " m of the origin and each angle within ±" << max_scene_angle << " rad";
    throw InputError("command line", "--object-pose", range.str(), bounded_preview(text));
  }
  return pose_from(v);
}

// Default placement: the object's longest bounding-box axis along the line between the first
// two tools, its box centre midway between them, pulled a fifth of the way towards the robot's
// root in the horizontal plane: tools at full stretch (a zero pose often is) cannot reach further.
Eigen::Isometry3d default_object_pose(const TetMesh& mesh, const Vec3& first_tool,
                                      const Vec3& second_tool) {
  const Vec3 lo = mesh.bounds_min(), hi = mesh.bounds_max();
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::Unit(axis), first_tool - second_tool)
                   .toRotationMatrix();
  Vec3 centre = 0.5 * (first_tool + second_tool);
  centre.head<2>() *= 0.8;
  T.translation() = centre - T.linear() * (0.5 * (lo + hi));
  return T;
}

struct ProposedGrip {
  std::vector<int> nodes;
  Vec3 centre_world = Vec3::Zero();
  double nearest_distance = 0;  // tool at the start pose ↔ nearest node, m (nearest-node grips)
};

std::vector<ProposedGrip> propose_grips(const AuthorOptions& o, const std::vector<EndEffector>& ees,
                                        const TetMesh& mesh,
                                        const Eigen::Isometry3d& T_world_object,
                                        const std::vector<Vec3>& tools) {
  std::map<std::string, std::string> given;
  for (const auto& text : o.grip_regions) {
    const auto [name, value] =
        named(text, "--grip-region", "NAME=X0,Y0,Z0,X1,Y1,Z1 (box) or NAME=X,Y,Z,R (sphere)");
    bool known = false;
    for (const auto& ee : ees) known = known || ee.name == name;
    if (!known)
      throw InputError("command line", "--grip-region", "the name of one of --end-effectors",
                       bounded_preview(name));
    given[name] = value;
  }
  const auto& X = mesh.rest_positions();
  std::vector<char> taken(X.size(), 0);
  std::vector<ProposedGrip> grips;
  for (std::size_t e = 0; e < ees.size(); ++e) {
    ProposedGrip g;
    const std::string where = given.count(ees[e].name) ? "--grip-region" : "--grip-radius";
    if (given.count(ees[e].name)) {
      const auto v =
          numbers(given[ees[e].name], "--grip-region",
                  "NAME=X0,Y0,Z0,X1,Y1,Z1 (box) or NAME=X,Y,Z,R (sphere), object coordinates",
                  {4, 6});
      for (std::size_t i = 0; i < X.size(); ++i) {
        const Vec3& p = X[i];
        const bool inside = v.size() == 4 ? (p - Vec3(v[0], v[1], v[2])).norm() <= v[3]
                                          : (p - Vec3(v[0], v[1], v[2])).minCoeff() >= 0 &&
                                                (Vec3(v[3], v[4], v[5]) - p).minCoeff() >= 0;
        if (inside && !taken[i]) g.nodes.push_back(static_cast<int>(i));
      }
    } else {
      // The nodes within the grip radius of the node nearest the tool.
      const Vec3 tool_object = T_world_object.inverse() * tools[e];
      std::size_t nearest = 0;
      for (std::size_t i = 1; i < X.size(); ++i)
        if ((X[i] - tool_object).squaredNorm() < (X[nearest] - tool_object).squaredNorm())
          nearest = i;
      g.nearest_distance = (X[nearest] - tool_object).norm();
      // Default radius: reach through the thinnest extent, so a grip holds the whole section.
      const double radius =
          o.grip_radius > 0
              ? o.grip_radius
              : std::clamp(1.1 * (mesh.bounds_max() - mesh.bounds_min()).minCoeff(), 0.02, 0.05);
      for (std::size_t i = 0; i < X.size(); ++i)
        if ((X[i] - X[nearest]).norm() <= radius && !taken[i])
          g.nodes.push_back(static_cast<int>(i));
    }
    if (g.nodes.empty())
      throw InputError("command line", where,
                       "a grip region for end effector '" + ees[e].name +
                           "' that catches at least one node not gripped by another end effector",
                       "none");
    Vec3 sum = Vec3::Zero();
    for (int i : g.nodes) {
      taken[static_cast<std::size_t>(i)] = 1;
      sum += X[static_cast<std::size_t>(i)];
    }
    g.centre_world = T_world_object * (sum / static_cast<double>(g.nodes.size()));
    grips.push_back(g);
  }
  return grips;
}

Json spheres_json(const RobotModel& model, const Spheres& s, double margin,
                  const std::string& urdf) {
  Json by_link = Json::object();
  for (const auto& sphere : s.spheres)
    by_link[model.links()[static_cast<std::size_t>(sphere.link)].name].push_back(
        {{"center", vec3_json(sphere.center_link)}, {"radius", sphere.radius}});
  Json ignore = Json::array();
  std::set<std::pair<int, int>> seen;
  for (const auto* list : {&s.adjacent, &s.always})
    for (const auto& [a, b] : *list)
      if (seen.insert({a, b}).second)
        ignore.push_back({model.links()[static_cast<std::size_t>(a)].name,
                          model.links()[static_cast<std::size_t>(b)].name});
  return {{"description",
           "generated by shapectl author from " + fs::path(urdf).filename().string() +
               ": covers of the collision geometry; ignore_pairs are adjacent links and links "
               "overlapping in nearly every pose"},
          {"margin", margin},
          {"stiffness", CollisionModel::default_stiffness},
          {"spheres", by_link},
          {"ignore_pairs", ignore}};
}

fs::path relative_to(const fs::path& file, const fs::path& dir) {
  std::error_code error;
  fs::path r = fs::relative(fs::absolute(file), fs::absolute(dir), error);
  return error || r.empty() ? fs::absolute(file) : r;
}

void run(const AuthorOptions& o) {
  const fs::path out = o.out;
  const fs::path scene_dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  const fs::path spheres_out = o.spheres_out.empty()
                                   ? scene_dir / (out.stem().string() + "_spheres.json")
                                   : fs::path(o.spheres_out);
  if (!(o.youngs_modulus >= 1 && o.youngs_modulus <= 1e13))
    throw InputError("command line", "--youngs-modulus", "a number from 1 to 1e13 Pa",
                     o.youngs_modulus);
  if (!(o.poisson_ratio > 0 && o.poisson_ratio < 0.5))
    throw InputError("command line", "--poisson-ratio", "a number between 0 and 0.5 (exclusive)",
                     o.poisson_ratio);
  if (!(o.density >= 1e-3 && o.density <= 1e5))
    throw InputError("command line", "--density", "a number from 1e-3 to 1e5 kg/m^3", o.density);
  if (!(o.grip_radius >= 0 && o.grip_radius <= 10))
    throw InputError("command line", "--grip-radius", "a distance from 0 to 10 m", o.grip_radius);
  if (!(o.sphere_margin >= 0 && o.sphere_margin <= 0.1))
    throw InputError("command line", "--sphere-margin", "a distance from 0 to 0.1 m",
                     o.sphere_margin);

  RobotModel model = RobotModel::load_urdf_file(o.urdf, xacro_options(o.package_paths));
  // The loader's note that collision meshes are ignored does not apply here: they are covered
  // with spheres below.
  std::vector<std::string> warnings;
  for (const auto& w : robot_notes(model, o.package_paths))
    if (w.find("collision meshes ignored") == std::string::npos) warnings.push_back(w);
  check_meshes_found(o, model);
  const std::vector<EndEffector> ees = read_end_effectors(o, model);
  const std::vector<GraspAxes> grasp_axes = read_grasp_axes(o, ees);
  const std::map<std::string, double> fixed_joints = choose_active_joints(o, ees, model);
  const ObjectMesh object = read_object_mesh(o, scene_dir);
  const Spheres spheres = generate_spheres(o, model, warnings);
  for (const auto& w : warnings) std::cerr << "warning: " << w << "\n";
  std::vector<std::pair<int, int>> ignore = spheres.adjacent;
  ignore.insert(ignore.end(), spheres.always.begin(), spheres.always.end());
  const CollisionModel collision(model, spheres.spheres, o.sphere_margin,
                                 CollisionModel::default_stiffness, ignore);

  // Start: every joint at 0, moved inside its limits.
  const Eigen::VectorXd start =
      Eigen::VectorXd::Zero(model.active_count())
          .cwiseMax((model.lower_limits().array() + joint_limit_margin).matrix())
          .cwiseMin((model.upper_limits().array() - joint_limit_margin).matrix());
  const KinematicsState start_state = forward_kinematics(model, start);
  std::vector<Vec3> tools;
  for (const auto& ee : ees)
    tools.push_back(start_state.T_world_link[static_cast<std::size_t>(ee.link)] * ee.tcp_link);

  Eigen::Isometry3d T_world_object;
  if (!o.object_pose.empty()) {
    T_world_object = object_pose_from(o.object_pose);
  } else {
    if (ees.size() < 2 || (tools[0] - tools[1]).norm() < 1e-3)
      throw InputError(
          "command line", "--object-pose",
          "an object pose (it is proposed only between two end effectors that are apart)", "none");
    T_world_object = default_object_pose(*object.mesh, tools[0], tools[1]);
  }
  const auto grips = propose_grips(o, ees, *object.mesh, T_world_object, tools);

  std::vector<IkGoal> goals;
  for (std::size_t e = 0; e < ees.size(); ++e) {
    IkGoal goal;  // position, and the orientation asked for
    goal.link = ees[e].link;
    goal.point_link = ees[e].tcp_link;
    goal.position_world = grips[e].centre_world;
    orient_goal(grasp_axes[e], model,
                start_state.T_world_link[static_cast<std::size_t>(ees[e].link)].linear(),
                o.approaches.empty() ? "--grip-axis" : "--approach", goal);
    goals.push_back(goal);
  }
  IkOptions ik_options{.collisions = &collision,
                       .joint_limit_margin = joint_limit_margin,
                       .position_tolerance = 1e-4,
                       .seed = o.seed};
  const IkResult ik = solve_inverse_kinematics(model, goals, start, ik_options);
  if (ik.status != IkStatus::Converged)
    throw InputError(
        "command line", o.object_pose.empty() ? "--end-effectors" : "--object-pose",
        "grip regions the tools can reach without self-collision (inverse kinematics: " +
            ik.reason + "); place the object elsewhere or choose other grips");
  const KinematicsState reference = forward_kinematics(model, ik.joints);
  const auto violations = limit_violations(model, reference.joints);
  const double clearance = collision.min_clearance(reference);
  Json grip_report = Json::array();
  for (std::size_t e = 0; e < ees.size(); ++e) {
    const double distance =
        (reference.T_world_link[static_cast<std::size_t>(ees[e].link)] * ees[e].tcp_link -
         grips[e].centre_world)
            .norm();
    if (!(distance <= tool_tolerance))
      throw SolverFailure("tool '" + ees[e].name + "' ends " + std::to_string(distance) +
                          " m from its grip region");
    const Eigen::Matrix3d R =
        reference.T_world_link[static_cast<std::size_t>(ees[e].link)].linear();
    const GraspAxes& axes = grasp_axes[e];
    const Vec3 closing_link = closing_axis_link(axes, model, ees[e].link);
    grip_report.push_back({{"end_effector", ees[e].name},
                           {"link", model.links()[static_cast<std::size_t>(ees[e].link)].name},
                           {"node_count", grips[e].nodes.size()},
                           {"region_centre", vec3_json(grips[e].centre_world)},
                           {"tool_distance", distance},
                           {"approach_axis", vec3_json(R * axes.approach_link)},
                           {"closing_axis", vec3_json(R * closing_link)}});
  }
  if (!violations.empty() || !(clearance > 0))
    throw SolverFailure("inverse kinematics returned joints outside their limits or in collision");

  Json reference_joints = Json::object();
  const auto names = model.active_joint_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    reference_joints[names[i]] = ik.joints[static_cast<Eigen::Index>(i)];
  Json end_effectors = Json::array();
  for (const auto& ee : ees)
    end_effectors.push_back({{"name", ee.name},
                             {"link", model.links()[static_cast<std::size_t>(ee.link)].name},
                             {"tcp", vec3_json(ee.tcp_link)}});
  Json grip_list = Json::array();
  for (std::size_t e = 0; e < ees.size(); ++e)
    grip_list.push_back({{"end_effector", ees[e].name}, {"nodes", grips[e].nodes}});
  const auto scene_text = [&](const fs::path& spheres_file) {
    const Json scene = {{"object",
                         {{"mesh", object.json},
                          {"material",
                           {{"youngs_modulus", o.youngs_modulus},
                            {"poisson_ratio", o.poisson_ratio},
                            {"density", o.density}}},
                          {"pose", scene_pose_json(T_world_object)}}},
                        {"gravity", {0, 0, -9.81}},
                        {"robot",
                         {{"urdf", relative_to(o.urdf, scene_dir).generic_string()},
                          {"collision_spheres",
                           relative_to(spheres_file, scene_dir).generic_string()},
                          {"active_joints", names},
                          {"fixed_joints", fixed_joints},
                          {"reference_joints", reference_joints},
                          {"end_effectors", end_effectors},
                          {"joint_limit_margin", joint_limit_margin}}},
                        {"grips", grip_list},
                        {"grip_stiffness", 1e4}};
    return to_pretty_json(scene);  // names that are not valid UTF-8 written with U+FFFD
  };
  const std::string spheres_text =
      to_pretty_json(spheres_json(model, spheres, o.sphere_margin, o.urdf));

  // The scene is loaded (and so checked) as it will be written before anything is replaced: a
  // scene every command would refuse never overwrites a good one. It and its spheres go to
  // temporary names beside the results first.
  const std::string check_prefix = ".author-check-" + std::to_string(::getpid()) + "-";
  const fs::path check_spheres =
      spheres_out.parent_path() / (check_prefix + spheres_out.filename().string());
  const fs::path check_scene = out.parent_path() / (check_prefix + out.filename().string());
  const Scene loaded = [&] {
    struct Remove {
      std::vector<fs::path> files;
      ~Remove() {
        std::error_code ignored;
        for (const auto& f : files) fs::remove(f, ignored);
      }
    } remove{{check_spheres, check_scene}};
    write_files_atomically(
        {{check_spheres, spheres_text}, {check_scene, scene_text(check_spheres)}});
    try {
      return load_scene(check_scene);
    } catch (const InputError& e) {
      throw InputError("the proposed scene would be refused, so nothing was written (" +
                       std::string(e.what()) + "); change the option that sets that field");
    }
  }();
  for (const auto& w : loaded.warnings) {
    std::cerr << "warning: " << w << "\n";
    warnings.push_back(w);
  }

  std::map<std::string, int> per_link;
  for (const auto& s : spheres.spheres)
    ++per_link[model.links()[static_cast<std::size_t>(s.link)].name];
  Json report = {{"scene", out.string()},
                 {"spheres_file", spheres_out.string()},
                 {"grips", grip_report},
                 {"inverse_kinematics",
                  {{"status", to_string(ik.status)},
                   {"reason", ik.reason},
                   {"residual", ik.position_error},
                   {"iterations", ik.iterations},
                   {"starts", ik.starts}}},
                 {"min_clearance", std::isfinite(clearance) ? Json(clearance) : Json(nullptr)},
                 {"joints_within_limits", violations.empty()},
                 {"spheres",
                  {{"count", spheres.spheres.size()},
                   {"per_link", per_link},
                   {"ignored_adjacent", spheres.adjacent.size()},
                   {"ignored_always_overlapping", spheres.always.size()}}},
                 {"object",
                  {{"node_count", loaded.object_mesh->node_count()},
                   {"tet_count", loaded.object_mesh->tet_count()}}},
                 {"warnings", warnings}};
  // Every file or none.
  std::vector<FileContent> files = {{spheres_out, spheres_text}, {out, scene_text(spheres_out)}};
  if (!o.report.empty()) files.push_back({o.report, to_pretty_json(report)});
  write_files_atomically(files);

  std::cout << "wrote " << out.string() << " and " << spheres_out.string() << " ("
            << spheres.spheres.size() << " spheres)\n";
  for (const auto& g : grip_report)
    std::cout << "grip '" << g["end_effector"].get<std::string>()
              << "': " << g["node_count"].get<std::size_t>() << " nodes, tool "
              << g["tool_distance"].get<double>() * 1e3 << " mm from the region centre\n";
  std::cout << "reference joints within limits, min clearance "
            << (std::isfinite(clearance) ? std::to_string(clearance * 1e3) + " mm"
                                         : std::string("n/a (no checked pairs)"))
            << "; inverse kinematics: " << ik.reason << "\n";
}

}  // namespace

void add_author_command(CLI::App& app) {
  auto o = std::make_shared<AuthorOptions>();
  CLI::App* c =
      app.add_subcommand("author", "Propose a scene from a URDF robot and an object mesh");
  c->add_option("robot", o->urdf, "Robot description (URDF, or URDF xacro)")->required();
  c->add_option("--mesh", o->mesh,
                "Object mesh: .msh, .node/.ele, or a closed surface .obj/.stl/.off (metres)");
  c->add_option("--box", o->box, "Instead of --mesh: a box LX,LY,LZ (metres)");
  c->add_option("--cells", o->cells,
                "Cells NX,NY,NZ of --box (default: about 4 across the thinnest edge)");
  c->add_option("--end-effectors", o->end_effectors,
                "NAME=LINK,... (or LINK,...): the tools that grip")
      ->required();
  c->add_option("--tool-offset", o->tool_offsets,
                "NAME=X,Y,Z: tool point in the link frame (m); repeatable");
  c->add_option("--grip-region", o->grip_regions,
                "NAME=X0,Y0,Z0,X1,Y1,Z1 (box) or NAME=X,Y,Z,R (sphere) in object coordinates; "
                "default: nodes near the tool; repeatable");
  c->add_option(
      "--grip-radius", o->grip_radius,
      "Default grips: nodes this close to the node nearest the tool (m); default 1.1 x the "
      "object's thinnest extent, clamped to 0.02..0.05");
  c->add_option(
      "--object-pose", o->object_pose,
      "X,Y,Z[,ROLL,PITCH,YAW] (m, rad); default: between the first two tools at the start pose");
  c->add_option("--youngs-modulus", o->youngs_modulus, "Pa")->capture_default_str();
  c->add_option("--poisson-ratio", o->poisson_ratio, "")->capture_default_str();
  c->add_option("--density", o->density, "kg/m^3")->capture_default_str();
  add_package_path_option(*c, o->package_paths);
  c->add_flag("--allow-missing-meshes", o->allow_missing_meshes,
              "Author even when mesh files the URDF names are not found (links lose them)");
  c->add_option("--units", o->units,
                "Units of --mesh's coordinates and --box's sizes: m (default), cm or mm");
  c->add_option("--active-joints", o->active_joints,
                "NAME,...: the joints to optimise (default: every joint that moves a tool)");
  c->add_option("--finger-opening", o->finger_opening,
                "Value (m or rad) of the joints that move no tool, e.g. gripper fingers "
                "(default: nearest 0 within their limits)");
  c->add_option("--approach", o->approaches,
                "NAME=X,Y,Z: world direction the tool approaches the object along (its approach "
                "axis, see --tool-axes, points this way), e.g. left=0,0,-1 from above; repeatable");
  c->add_option("--grip-axis", o->grip_axes,
                "NAME=X,Y,Z: world direction the fingers close along (e.g. across the object's "
                "thin side); with --approach the grasp is fully set; repeatable");
  c->add_option("--tool-axes", o->tool_axes,
                "NAME=A,C: the tool's approach and closing axes in its link frame, e.g. z,x "
                "(default: z, and the fingers' joint axis, else y); repeatable");
  c->add_option("--sphere-margin", o->sphere_margin,
                "Collision margin written to the sphere file (m)")
      ->capture_default_str();
  c->add_option("--seed", o->seed, "Seed of the random poses (ignore pairs, IK restarts)")
      ->capture_default_str();
  c->add_option("--out", o->out, "Scene JSON to write")->required()->check(writable_output());
  c->add_option("--spheres-out", o->spheres_out,
                "Sphere JSON to write (default: beside the scene, <name>_spheres.json)")
      ->check(writable_output());
  c->add_option("--report", o->report,
                "Report JSON: grips, IK, clearance, limits, spheres, warnings")
      ->check(writable_output());
  c->callback([o] { run(*o); });
}

}  // namespace shapectl::cli
