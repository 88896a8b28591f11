#include <shapectl/sim/scene_checks.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/contact/self_contact.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/robot/joint_limits.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/sim/contact_obstacles.hpp>

namespace shapectl {

namespace {

std::string show(double value, int precision = 3) {
  std::ostringstream out;
  out.precision(precision);
  out << value;
  return out.str();
}

std::string millimetres(double metres) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << metres * 1e3 << " mm";
  return out.str();
}

std::string grip_field(const Scene& scene, std::size_t g) {
  return "grips[" + std::to_string(g) + "] ('" +
         scene.robot->end_effectors[static_cast<std::size_t>(scene.grips[g].end_effector)].name +
         "')";
}

// Bounding-box diagonal of the robot's link origins at the reference joints.
double robot_extent(const RobotSetup& robot) {
  const KinematicsState state = forward_kinematics(*robot.model, robot.reference_joints);
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const auto& T : state.T_world_link) {
    lo = lo.cwiseMin(T.translation());
    hi = hi.cwiseMax(T.translation());
  }
  return (hi - lo).norm();
}

void check_object_size(const Scene& scene) {
  const MeshOrigin& origin = scene.mesh_origin;
  const bool from_file =
      origin.kind == MeshOrigin::Kind::VolumeFile || origin.kind == MeshOrigin::Kind::SurfaceFile;
  if (!scene.robot && !from_file) return;  // a box's size is explicit metres
  check_object_extent(scene.source.string(), origin,
                      scene.object_mesh->bounds_max() - scene.object_mesh->bounds_min(),
                      scene.robot ? &*scene.robot : nullptr);
}

std::string tet_count_warning(const Scene& scene) {
  const int tets = scene.object_mesh->tet_count();
  if (tets <= tet_warning_count) return "";
  std::string coarsen;
  switch (scene.mesh_origin.kind) {
    case MeshOrigin::Kind::Box:
      coarsen = "use fewer cells (" + scene.mesh_origin.field + ".box.cells)";
      break;
    case MeshOrigin::Kind::SurfaceFile:
      coarsen = "give a larger " + scene.mesh_origin.field +
                ".max_tet_volume (m^3) or a larger "
                "max_radius_edge_ratio (e.g. 2: fewer added points), or simplify the surface";
      break;
    default: coarsen = "coarsen the mesh where it was made"; break;
  }
  return scene.source.string() + ": " + scene.mesh_origin.field + ": " + std::to_string(tets) +
         " tetrahedra: expect about " + show(expected_seconds_per_target_change(tets), 2) +
         " s per target change on 2 cores (1,536 tets take ~" +
         show(1e3 * expected_seconds_per_target_change(1536), 2) + " ms, 12,288 ~" +
         show(expected_seconds_per_target_change(12288), 2) + " s, 51,714 ~" +
         show(expected_seconds_per_target_change(51714), 2) + " s); to coarsen, " + coarsen;
}

// The scene field that sets a joint's reference value.
std::string joint_field(const RobotModel& model, const std::string& name) {
  const Joint& joint = model.joints()[static_cast<std::size_t>(model.joint_index(name))];
  if (joint.mimic_master >= 0)
    return "robot.reference_joints." +
           model.joints()[static_cast<std::size_t>(joint.mimic_master)].name +
           " (through the mimic joint '" + name + "')";
  if (model.active_index(model.joint_index(name)) >= 0) return "robot.reference_joints." + name;
  return "robot.fixed_joints." + name;
}

std::string unit_of(const RobotModel& model, const std::string& name) {
  return model.joints()[static_cast<std::size_t>(model.joint_index(name))].type ==
                 JointType::Prismatic
             ? "m"
             : "rad";
}

void check_joint_limits(const Scene& scene, std::vector<std::string>& warnings) {
  const RobotSetup& robot = *scene.robot;
  const RobotModel& model = *robot.model;
  const auto violations = limit_violations(model, model.full_joints(robot.reference_joints));
  if (!violations.empty()) {
    const LimitViolation& v = violations.front();
    std::string expected = "a value within the joint's limits [" + show(v.lower, 4) + ", " +
                           show(v.upper, 4) + "] " + unit_of(model, v.joint) +
                           " (a joint without a value is 0)";
    if (violations.size() > 1) {
      expected += "; also outside:";
      for (std::size_t k = 1; k < violations.size(); ++k)
        expected += " " + violations[k].joint + " = " + show(violations[k].value, 4);
    }
    throw InputError(scene.source.string(), joint_field(model, v.joint), expected,
                     show(v.value, 6));
  }
  // Inside the margin the barrier already pushes at the reference: allowed, but it moves the robot.
  const Eigen::VectorXd lower = model.lower_limits(), upper = model.upper_limits();
  const auto names = model.active_joint_names();
  for (int k = 0; k < model.active_count(); ++k) {
    const double q = robot.reference_joints[k];
    const double gap = std::min(q - lower[k], upper[k] - q);
    if (gap < joint_margin(lower[k], upper[k], robot.joint_limit_margin))
      warnings.push_back(scene.source.string() + ": robot.reference_joints." +
                         names[static_cast<std::size_t>(k)] + ": " + show(q, 4) +
                         " is within robot.joint_limit_margin (" + show(robot.joint_limit_margin) +
                         ") of its limits [" + show(lower[k], 4) + ", " + show(upper[k], 4) +
                         "]: the limit barrier pushes the robot away from the reference pose");
  }
}

void check_collisions(const Scene& scene, std::vector<std::string>& warnings) {
  const RobotSetup& robot = *scene.robot;
  if (!robot.collisions || robot.collisions->pair_count() == 0) return;
  const CollisionModel& collisions = *robot.collisions;
  const KinematicsState state = forward_kinematics(*robot.model, robot.reference_joints);
  const SphereClearance closest = collisions.closest_pairs(state, 1).front();
  auto link_of = [&](int sphere) {
    return robot.model
        ->links()[static_cast<std::size_t>(
            collisions.spheres()[static_cast<std::size_t>(sphere)].link)]
        .name;
  };
  const std::string pair = "the closest pair is a sphere of '" + link_of(closest.first) +
                           "' and one of '" + link_of(closest.second) + "', clearance " +
                           millimetres(closest.clearance);
  if (closest.clearance < 0)
    throw InputError(
        scene.source.string(), "robot.reference_joints",
        "the robot collides with itself at the reference joints (robot.collision_spheres): " +
            pair + "; choose reference joints where every checked pair is clear");
  if (closest.clearance < collisions.margin())
    warnings.push_back(scene.source.string() + ": robot.reference_joints: " + pair +
                       ", inside the spheres' margin (" + millimetres(collisions.margin()) +
                       "): the collision barrier pushes the robot away from the reference pose");
}

void check_grips(const Scene& scene, std::vector<std::string>& warnings) {
  const auto placements = grip_placements(scene);
  for (std::size_t g = 0; g < placements.size(); ++g) {
    const GripPlacement& p = placements[g];
    const std::string field = grip_field(scene, g);
    if (p.node_count == 0) {
      // Regions are in object coordinates; a region typed in world coordinates misses.
      const Vec3 lo = scene.object_mesh->bounds_min(), hi = scene.object_mesh->bounds_max();
      throw InputError(scene.source.string(), "grips[" + std::to_string(g) + "]",
                       "the grip region contains no node of the mesh (its nodes span [" +
                           show(lo.x()) + ", " + show(lo.y()) + ", " + show(lo.z()) + "] to [" +
                           show(hi.x()) + ", " + show(hi.y()) + ", " + show(hi.z()) +
                           "] m in object coordinates, before object.pose)");
    }
    const std::string distance = "its centre (the mean of its " + std::to_string(p.node_count) +
                                 " nodes) is " + millimetres(p.tool_distance) +
                                 " from the end effector's tool point at the reference joints";
    if (p.tool_distance > grip_error_distance)
      throw InputError(
          scene.source.string(), field,
          distance + ", expected at most " + millimetres(grip_error_distance) +
              ": grip springs would hold the object where no gripper is; move the region, "
              "object.pose or robot.reference_joints so the tool reaches it");
    if (p.tool_distance > grip_warning_distance)
      warnings.push_back(scene.source.string() + ": " + field + ": " + distance + " (more than " +
                         millimetres(grip_warning_distance) +
                         "): is that where the gripper closes?");
    if (p.node_count < grip_warning_node_count)
      warnings.push_back(scene.source.string() + ": " + field + ": catches only " +
                         std::to_string(p.node_count) +
                         " node(s): the object may turn about them; use a larger region");
  }
}

// The winding number of the closed surface (triangles of `points`) about p: 1 inside, 0 outside
// (the sum of the triangles' solid angles, Van Oosterom and Strackee 1983, over 4π).
double winding_number(const std::vector<Vec3>& points,
                      const std::vector<std::array<int, 3>>& triangles, const Vec3& p) {
  double sum = 0;
  for (const auto& t : triangles) {
    const Vec3 a = points[t[0]] - p, b = points[t[1]] - p, c = points[t[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2 * std::atan2(a.dot(b.cross(c)),
                          la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return sum / (4 * M_PI);
}

// Whether one of two surfaces that do not meet holds the other: the obstacle's first point
// inside the object, or the object's first node inside the obstacle.
bool one_inside_the_other(const Obstacle& o, const std::vector<Vec3>& nodes,
                          const std::vector<std::array<int, 3>>& surface) {
  if (o.plane) return false;  // a half-space: first_intersection sees every node's side
  if (!o.points.empty() && winding_number(nodes, surface, o.points.front()) > 0.5) return true;
  const Vec3& node = nodes[static_cast<std::size_t>(surface.front()[0])];
  if (o.triangles.empty()) {  // a sphere or capsule: within its radius of its point or segment
    const Vec3 a = o.points.front(), b = o.points.back(), ab = b - a;
    const double s =
        ab.squaredNorm() > 0 ? std::clamp((node - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    return (a + s * ab - node).norm() <= o.radius;
  }
  return winding_number(o.points, o.triangles, node) > 0.5;
}

// The rest shape placed in the world must be clear of every obstacle: the contact barrier is
// infinite at a gap of zero, so no solve could start there.
// d̂ is the gap at which contact forces start; one near the object's size (a distance meant in
// mm written as metres) makes the barrier act across the whole object and Newton fail.
void check_contact_distance(const Scene& scene) {
  const double size = (scene.object_mesh->bounds_max() - scene.object_mesh->bounds_min()).norm();
  const double limit = max_contact_distance_fraction * size;
  if (scene.contact.distance <= limit) return;
  throw InputError(scene.source.string(), "contact.distance",
                   "at most " + show(limit) + " m (a tenth of the object's " + show(size) +
                       " m bounding-box diagonal); got " + show(scene.contact.distance) +
                       " m: the barrier acts on gaps below this distance (typically 1e-3 of the "
                       "object's size, e.g. 0.001): was it meant in mm?");
}

// Distance between the object's rest bounding box and an obstacle (0 when they overlap).
double obstacle_distance(const Obstacle& obstacle, const Vec3& lo, const Vec3& hi) {
  if (obstacle.plane) {
    double nearest = INFINITY;
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                   (corner & 4) ? hi.z() : lo.z());
      nearest =
          std::min(nearest, std::abs((p - obstacle.plane->point).dot(obstacle.plane->normal)));
    }
    return nearest;
  }
  Vec3 olo = Vec3::Constant(INFINITY), ohi = Vec3::Constant(-INFINITY);
  for (const Vec3& p : obstacle.points) {
    olo = olo.cwiseMin(p);
    ohi = ohi.cwiseMax(p);
  }
  const Vec3 gap = (olo - hi).cwiseMax(lo - ohi).cwiseMax(0.0);
  return std::max(0.0, gap.norm() - obstacle.radius);
}

// An obstacle far beyond anything the object could reach is nearly always given in mm or cm.
void warn_distant_obstacles(const Scene& scene, std::vector<std::string>& warnings) {
  const Positions x = scene.world_rest_positions();
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) {
    lo = lo.cwiseMin(x.segment<3>(3 * i));
    hi = hi.cwiseMax(x.segment<3>(3 * i));
  }
  double reach = (hi - lo).norm();
  if (scene.robot) reach += robot_extent(*scene.robot);
  const double limit = std::max(distant_obstacle_floor, distant_obstacle_factor * reach);
  for (std::size_t k = 0; k < scene.obstacles.size(); ++k) {
    if (scene.obstacles[k].link >= 0) continue;  // it moves with the robot, near the object
    const double d = obstacle_distance(scene.obstacles[k], lo, hi);
    if (d > limit)
      warnings.push_back(scene.source.string() + ": obstacles[" + std::to_string(k) + "] ('" +
                         scene.obstacles[k].name + "'): " + show(d) +
                         " m from the object, which can never reach it (limit " + show(limit) +
                         " m); scene lengths are metres: were its coordinates given in mm?");
  }
}

// The contact's obstacles (the robot's spheres too) in the world, those on links where the
// reference joints put them.
std::vector<Obstacle> obstacles_at_reference(const Scene& scene) {
  std::vector<Obstacle> obstacles = contact_obstacles(scene);
  if (!scene.robot) return obstacles;
  const KinematicsState reference =
      forward_kinematics(*scene.robot->model, scene.robot->reference_joints);
  for (Obstacle& o : obstacles)
    if (o.link >= 0) {
      o = moved(o, reference.T_world_link[o.link]);
      o.link = -1;
    }
  return obstacles;
}

void check_obstacle_gaps(const Scene& scene) {
  const std::vector<Obstacle> obstacles = obstacles_at_reference(scene);
  if (obstacles.empty()) return;
  const ObstacleContact contact(*scene.object_mesh, obstacles, scene.contact.distance, 1.0);
  const Positions x = scene.world_rest_positions();
  auto field = [&](std::size_t k) {
    if (k >= scene.obstacles.size()) return "contact.robot (sphere '" + obstacles[k].name + "')";
    return "obstacles[" + std::to_string(k) + "] ('" + scene.obstacles[k].name + "')";
  };
  auto on_link = [&](std::size_t k) {
    return k >= scene.obstacles.size() || scene.obstacles[k].link >= 0;
  };
  const auto [obstacle, triangle] = contact.first_intersection(x);
  if (obstacle >= 0) {
    const auto nodes = scene.object_mesh->surface_triangles()[static_cast<std::size_t>(triangle)];
    throw InputError(scene.source.string(), field(static_cast<std::size_t>(obstacle)),
                     "the object's rest shape (placed by object.pose) touches or intersects this " +
                         obstacles[static_cast<std::size_t>(obstacle)].shape +
                         (on_link(static_cast<std::size_t>(obstacle)) ? " (at the reference joints)"
                                                                      : "") +
                         " at surface triangle " + std::to_string(triangle) + " (nodes " +
                         std::to_string(nodes[0]) + ", " + std::to_string(nodes[1]) + ", " +
                         std::to_string(nodes[2]) +
                         "); move the object or the obstacle so that every gap is positive");
  }
  std::vector<Vec3> nodes(x.size() / 3);
  for (std::size_t i = 0; i < nodes.size(); ++i) nodes[i] = x.segment<3>(3 * i);
  const auto surface = scene.object_mesh->surface_triangles();
  // (An obstacle of a gripper, which ignores the gripped nodes, may hold the object.)
  for (std::size_t k = 0; k < obstacles.size(); ++k)
    if (!surface.empty() && obstacles[k].ignored_nodes.empty() &&
        one_inside_the_other(obstacles[k], nodes, surface))
      throw InputError(scene.source.string(), field(k),
                       "the object's rest shape (placed by object.pose) and this " +
                           obstacles[k].shape +
                           " overlap, one wholly inside the other; move the object or the "
                           "obstacle so that they are apart");
}

// With self-contact on, the rest shape must not meet itself: the barrier keeps the surface from
// passing through itself, so one that starts through itself would stay so.
void check_self_intersection(const Scene& scene) {
  if (!scene.contact.self) return;
  const SelfContact self(*scene.object_mesh, scene.contact.distance, 1.0);
  const auto [a, b] = self.first_intersection(scene.world_rest_positions());
  if (a < 0) return;
  const auto surface = scene.object_mesh->surface_triangles();
  const auto show_triangle = [&](int t) {
    const auto& n = surface[static_cast<std::size_t>(t)];
    return "surface triangle " + std::to_string(t) + " (nodes " + std::to_string(n[0]) + ", " +
           std::to_string(n[1]) + ", " + std::to_string(n[2]) + ")";
  };
  throw InputError(scene.source.string(), "contact.self",
                   "the object's rest shape intersects itself: " + show_triangle(a) + " meets " +
                       show_triangle(b) +
                       "; self-contact needs a mesh whose surface does not meet itself (give "
                       "false, or mend the mesh)");
}

}  // namespace

// A mesh far larger than anything the robot could hold (or than any object, without one) is
// nearly always a mesh drawn in mm or cm read as metres.
void check_object_extent(const std::string& source, const MeshOrigin& origin, const Vec3& size,
                         const RobotSetup* robot) {
  const bool from_file =
      origin.kind == MeshOrigin::Kind::VolumeFile || origin.kind == MeshOrigin::Kind::SurfaceFile;
  const double extent = size.norm();
  double limit = max_object_extent;
  std::string why =
      "larger than any object shapectl is meant for (limit " + show(max_object_extent) + " m)";
  if (robot) {
    const double reach = robot_extent(*robot);
    if (object_reach_factor * reach < limit) {
      limit = std::max(1.0, object_reach_factor * reach);
      why = "far larger than the robot could hold (limit " + show(limit) +
            " m: " + show(object_reach_factor) + " x the " + show(reach) +
            " m its link origins span)";
    }
  }
  if (!(extent > limit)) return;
  std::string hint;
  if (!from_file) hint = "the box size is in metres";
  else if (origin.units_given) hint = "check its \"units\" or \"scale\"";
  else
    hint =
        "mesh coordinates are read as metres: for a mesh drawn in millimetres give {\"file\": ..., "
        "\"units\": "
        "\"mm\"} (or \"cm\", or \"scale\": factor)";
  throw InputError(source, origin.field,
                   "the object is " + show(extent) + " m across (bounding box " + show(size.x()) +
                       " x " + show(size.y()) + " x " + show(size.z()) + " m), " + why + "; " +
                       hint);
}

std::vector<GripPlacement> grip_placements(const Scene& scene) {
  std::vector<GripPlacement> out;
  if (scene.grips.empty()) return out;
  const RobotSetup& robot = *scene.robot;
  const KinematicsState state = forward_kinematics(*robot.model, robot.reference_joints);
  for (const Grip& grip : scene.grips) {
    const EndEffector& ee = robot.end_effectors[static_cast<std::size_t>(grip.end_effector)];
    GripPlacement p{.node_count = static_cast<int>(grip.nodes.size())};
    if (!grip.nodes.empty()) {
      Vec3 centre = Vec3::Zero();
      for (int i : grip.nodes)
        centre +=
            scene.T_world_object * scene.object_mesh->rest_positions()[static_cast<std::size_t>(i)];
      centre /= static_cast<double>(grip.nodes.size());
      p.tool_distance =
          (state.T_world_link[static_cast<std::size_t>(ee.link)] * ee.tcp_link - centre).norm();
    }
    out.push_back(p);
  }
  return out;
}

std::vector<std::string> describe_grips(const Scene& scene) {
  std::vector<std::string> out;
  const auto placements = grip_placements(scene);
  for (std::size_t g = 0; g < placements.size(); ++g)
    out.push_back(grip_field(scene, g) + ": " + std::to_string(placements[g].node_count) +
                  " nodes, centre " + millimetres(placements[g].tool_distance) +
                  " from the tool point");
  return out;
}

double expected_seconds_per_target_change(int tet_count) {
  // Log-log interpolation between `shapectl bench --sizes` medians (2-core VM, 2026-11-24,
  // docs/benchmarks.md), extrapolated with the nearest segment's slope.
  constexpr double tets[] = {1536, 12288, 51714}, seconds[] = {0.015, 0.21, 1.4};
  const double n = std::max(tet_count, 1);
  const int k = n < tets[1] ? 0 : 1;
  const double p = std::log(seconds[k + 1] / seconds[k]) / std::log(tets[k + 1] / tets[k]);
  return seconds[k] * std::pow(n / tets[k], p);
}

std::vector<std::string> check_scene(const Scene& scene) {
  std::vector<std::string> warnings;
  check_object_size(scene);
  if (const std::string w = tet_count_warning(scene); !w.empty()) warnings.push_back(w);
  check_contact_distance(scene);
  check_obstacle_gaps(scene);
  check_self_intersection(scene);
  warn_distant_obstacles(scene, warnings);
  if (scene.robot) {
    check_joint_limits(scene, warnings);
    check_collisions(scene, warnings);
    check_grips(scene, warnings);
  }
  return warnings;
}

}  // namespace shapectl
