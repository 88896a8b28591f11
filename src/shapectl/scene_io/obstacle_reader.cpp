#include <shapectl/scene_io/obstacle_reader.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>

#include <shapectl/io/json_input.hpp>
#include <shapectl/mesh/surface_reader.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl {

namespace {

constexpr double max_obstacle_distance = max_scene_distance;  // m: points, sizes, radii
constexpr double max_contact_distance = 1.0;                  // m: d̂ beyond is a typo
constexpr double max_contact_stiffness = 1e12;                // N/m, as the scene's stiffnesses

// A length from 1e-9 m to max_obstacle_distance; "a positive number" for zero or less.
double length_of(const JsonInput& j) {
  j.positive();
  return j.number_in(1e-9, max_obstacle_distance, "m");
}

Vec3 point_of(const JsonInput& j) { return j.vec3_within(max_obstacle_distance, "a point", "m"); }

Obstacle read_plane(const std::string& name, const JsonInput& j) {
  j.expect_only({"point", "normal"});
  const Vec3 normal = j.at("normal").vec3();
  if (!(normal.norm() > 1e-12)) j.at("normal").fail("a non-zero normal vector");
  return make_plane(name, point_of(j.at("point")), normal);
}

Obstacle read_box_obstacle(const std::string& name, const JsonInput& j) {
  j.expect_only({"size", "pose"});
  const JsonInput size_json = j.at("size");
  if (size_json.size() != 3) size_json.fail("an array of 3 numbers");
  Vec3 size;
  for (int k = 0; k < 3; ++k) size[k] = length_of(size_json.at(k));
  const Eigen::Isometry3d pose =
      j.has("pose") ? read_pose(j.at("pose")) : Eigen::Isometry3d::Identity();
  return make_box(name, size, pose);
}

Obstacle read_sphere(const std::string& name, const JsonInput& j) {
  j.expect_only({"center", "radius"});
  return make_sphere(name, point_of(j.at("center")), length_of(j.at("radius")));
}

Obstacle read_capsule(const std::string& name, const JsonInput& j) {
  j.expect_only({"a", "b", "radius"});
  const Vec3 a = point_of(j.at("a")), b = point_of(j.at("b"));
  if (!((a - b).norm() > 1e-9)) j.at("b").fail("a point other than \"a\" (else use a sphere)");
  return make_capsule(name, a, b, length_of(j.at("radius")));
}

// A closed triangle surface file, scaled to metres ("units" or "scale"), placed by "pose".
Obstacle read_mesh_obstacle(const std::string& name, const JsonInput& j) {
  j.expect_only({"file", "units", "scale", "pose"});
  const auto file = j.at("file").file_path();
  if (!is_surface_file(file))
    j.at("file").fail("a closed triangle surface file (.obj, .stl or .off)");
  const double scale = read_mesh_scale(j);
  const Eigen::Isometry3d pose =
      j.has("pose") ? read_pose(j.at("pose")) : Eigen::Isometry3d::Identity();
  TriangleSurface surface = read_surface(file);
  for (Vec3& v : surface.vertices) {
    v = pose * (scale * v);
    if (!(v.norm() <= max_obstacle_distance))
      j.at("file").fail_problem("a vertex lies beyond " +
                                std::to_string(int(max_obstacle_distance)) +
                                " m of the origin (coordinates are metres unless \"units\" or "
                                "\"scale\" say otherwise)");
  }
  try {
    return make_mesh_obstacle(name, std::move(surface.vertices), std::move(surface.triangles));
  } catch (const std::invalid_argument& e) {
    j.at("file").fail_problem(std::string("not a closed surface: ") + e.what());
  }
}

// "link": the index of the robot link it names.
int read_link(const JsonInput& j, const RobotSetup* robot) {
  if (!robot) j.fail_problem("an obstacle on a link needs a \"robot\"");
  const RobotModel& model = *robot->model;
  const std::string name = j.string();
  if (const auto link = model.find_link(name)) return *link;
  std::string links;
  for (const Link& l : model.links()) links += (links.empty() ? "" : ", ") + l.name;
  j.fail("a link of the robot " + std::filesystem::path(model.source()).filename().string() + " (" +
         links + ")");
}

// The obstacle's name and shape; in its link's frame if it has a "link".
Obstacle read_shape(const JsonInput& j, std::size_t index) {
  const std::string name =
      j.has("name") ? j.at("name").string() : "obstacle " + std::to_string(index + 1);
  if (name.empty()) j.at("name").fail("a non-empty name");
  const char* shapes[] = {"plane", "box", "sphere", "capsule", "mesh"};
  int given = 0;
  for (const char* s : shapes) given += j.has(s);
  if (given != 1)
    j.fail("an object with exactly one of \"plane\", \"box\", \"sphere\", \"capsule\", \"mesh\"");
  if (j.has("plane")) return read_plane(name, j.at("plane"));
  if (j.has("box")) return read_box_obstacle(name, j.at("box"));
  if (j.has("sphere")) return read_sphere(name, j.at("sphere"));
  if (j.has("capsule")) return read_capsule(name, j.at("capsule"));
  return read_mesh_obstacle(name, j.at("mesh"));
}

Obstacle read_obstacle(const JsonInput& j, std::size_t index, const RobotSetup* robot) {
  j.expect_only({"name", "plane", "box", "sphere", "capsule", "mesh", "link"});
  const int link = j.has("link") ? read_link(j.at("link"), robot) : -1;
  if (link >= 0 && j.has("plane"))
    j.at("plane").fail_problem(
        "a plane cannot move with a link (it is a whole half-space): give a box on the link");
  Obstacle o = read_shape(j, index);
  o.link = link;
  return o;
}

}  // namespace

std::vector<Obstacle> read_obstacles(const JsonInput& list, const RobotSetup* robot) {
  std::vector<Obstacle> obstacles;
  for (std::size_t k = 0; k < list.size(); ++k) {
    Obstacle o = read_obstacle(list.at(k), k, robot);
    for (const Obstacle& other : obstacles)
      if (other.name == o.name)
        (list.at(k).has("name") ? list.at(k).at("name") : list.at(k))
            .fail("a name no other obstacle has ('" + o.name + "' is taken)");
    obstacles.push_back(std::move(o));
  }
  return obstacles;
}

ContactSettings read_contact(const JsonInput& j, const RobotSetup* robot) {
  j.expect_only({"distance", "self", "robot", "friction", "stiffness", "sweep_steps"});
  ContactSettings c;
  if (j.has("distance")) {
    j.at("distance").positive();
    c.distance = j.at("distance").number_in(1e-9, max_contact_distance, "m");
  }
  if (j.has("self")) c.self = j.at("self").boolean();
  if (j.has("robot") && j.at("robot").boolean()) {
    if (!robot) j.at("robot").fail_problem("contact with the robot needs a \"robot\" in the scene");
    if (!robot->collisions || robot->collisions->spheres().empty())
      j.at("robot").fail_problem(
          "contact with the robot uses its collision spheres: give robot.collision_spheres");
    c.robot = true;
  }
  if (j.has("friction")) c.friction = j.at("friction").non_negative();
  if (j.has("sweep_steps"))
    c.sweep_steps = static_cast<int>(j.at("sweep_steps").integer_in(1, 10000));
  if (j.has("stiffness")) {
    j.at("stiffness").positive();
    c.stiffness = j.at("stiffness").number_in(1e-12, max_contact_stiffness, "N/m");
  }
  return c;
}

}  // namespace shapectl
