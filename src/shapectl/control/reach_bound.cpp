#include <shapectl/control/reach_bound.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <sstream>

#include <shapectl/io/input_error.hpp>
#include <shapectl/robot/kinematics.hpp>

namespace shapectl {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The joints from the root to `link`, root first.
std::vector<int> chain_to(const RobotModel& robot, int link) {
  std::vector<int> chain;
  for (int j = robot.links()[static_cast<std::size_t>(link)].parent_joint; j >= 0;
       j = robot
               .links()[static_cast<std::size_t>(
                   robot.joints()[static_cast<std::size_t>(j)].parent_link)]
               .parent_joint)
    chain.push_back(j);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

// The largest |value| a prismatic joint can take: its limits, its fixed value, or its master's
// travel for a mimic joint; +inf without limits.
double prismatic_travel(const RobotModel& robot, int joint) {
  const Joint& j = robot.joints()[static_cast<std::size_t>(joint)];
  if (j.mimic_master >= 0)
    return std::abs(j.mimic_multiplier) * prismatic_travel(robot, j.mimic_master) +
           std::abs(j.mimic_offset);
  return std::max({std::abs(j.lower), std::abs(j.upper), std::abs(robot.fixed_value(joint))});
}

// Rest path lengths along mesh edges from `sources` (Dijkstra), +inf where no path leads.
std::vector<double> path_lengths(const TetMesh& mesh, const std::vector<int>& sources) {
  const auto& x = mesh.rest_positions();
  std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(mesh.node_count()));
  for (const TetRest& t : mesh.tets())
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        if (a != b) neighbours[static_cast<std::size_t>(t.nodes[a])].push_back(t.nodes[b]);
  std::vector<double> d(static_cast<std::size_t>(mesh.node_count()), kInfinity);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (int s : sources) d[static_cast<std::size_t>(s)] = 0, queue.push({0.0, s});
  while (!queue.empty()) {
    const auto [dn, n] = queue.top();
    queue.pop();
    if (dn > d[static_cast<std::size_t>(n)]) continue;
    for (int m : neighbours[static_cast<std::size_t>(n)]) {
      const double dm =
          dn + (x[static_cast<std::size_t>(m)] - x[static_cast<std::size_t>(n)]).norm();
      if (dm < d[static_cast<std::size_t>(m)])
        d[static_cast<std::size_t>(m)] = dm, queue.push({dm, m});
    }
  }
  return d;
}

std::string point_text(const Vec3& p) {
  std::ostringstream out;
  out.precision(3);
  out << "[" << p.x() << ", " << p.y() << ", " << p.z() << "]";
  return out.str();
}

std::string metres(double value) {
  std::ostringstream out;
  out.precision(3);
  out << value << " m";
  return out.str();
}

// "joint 'j1'", or the gripping link when no joint moves it.
std::string base_name(const RobotModel& robot, const ArmReach& arm) {
  return arm.base_joint >= 0
             ? "joint '" + robot.joints()[static_cast<std::size_t>(arm.base_joint)].name + "'"
             : "link '" + robot.links()[static_cast<std::size_t>(arm.link)].name + "'";
}

// "target 529 m from joint 'j1' (at [..]), the base of the arm holding node 12; the robot
// reaches at most 4.2 m with that node (...)"
std::string beyond_reach(const char* what, double distance, const RobotModel& robot,
                         const ArmReach& arm, const std::string& with, double bound) {
  const std::string base = base_name(robot, arm);
  return std::string(what) + " " + metres(distance) + " from " + base + " (at " +
         point_text(arm.base) + "), where the arm gripping with link '" +
         robot.links()[static_cast<std::size_t>(arm.link)].name +
         "' starts; the robot reaches at most " + metres(bound) + " from there with " + with +
         " (coordinates are metres unless the file gives \"units\": \"mm\" or \"cm\")";
}

}  // namespace

std::vector<ArmReach> reach_bounds(const GrippedObject& object) {
  const RobotModel& robot = object.robot();
  const KinematicsState reference = forward_kinematics(robot, object.reference_joints());
  std::vector<ArmReach> arms;
  for (const GrippedNode& g : object.grips().nodes()) {
    if (std::any_of(arms.begin(), arms.end(), [&](const ArmReach& a) { return a.link == g.link; }))
      continue;
    ArmReach arm;
    arm.link = g.link;
    // The chain's length from the first movable joint on, and that joint's origin.
    const std::vector<int> chain = chain_to(robot, g.link);
    double length = 0;
    for (int j : chain) {
      const Joint& joint = robot.joints()[static_cast<std::size_t>(j)];
      if (arm.base_joint < 0) {
        if (!joint.movable()) continue;
        arm.base_joint = j;
        arm.base = reference.T_world_link[static_cast<std::size_t>(joint.parent_link)] *
                   joint.T_parent_child.translation();
      } else {
        length += joint.T_parent_child.translation().norm();
      }
      if (joint.type == JointType::Prismatic) length += prismatic_travel(robot, j);
    }
    if (arm.base_joint < 0)
      arm.base = reference.T_world_link[static_cast<std::size_t>(g.link)].translation();
    // The farthest anchor of this link's nodes from the link's origin, and their paths.
    double anchor = 0;
    std::vector<int> gripped;
    for (const GrippedNode& h : object.grips().nodes()) {
      if (h.link != g.link) continue;
      anchor = std::max(anchor, h.point_link.norm());
      gripped.push_back(h.node);
    }
    const double spring = object.statics().weight() / object.grips().stiffness();
    arm.node_bound = arm.rest_bound = path_lengths(object.mesh(), gripped);
    for (double& d : arm.node_bound) d = length + anchor + spring + max_edge_stretch * d;
    for (double& d : arm.rest_bound) d = length + anchor + spring + d;
    arms.push_back(std::move(arm));
  }
  return arms;
}

void check_targets_in_reach(const GrippedObject& object, const ShapeTargets& targets,
                            const std::string& source) {
  for (const ArmReach& arm : reach_bounds(object))
    for (int k = 0; k < targets.size(); ++k) {
      const int node = targets.nodes[static_cast<std::size_t>(k)];
      const double bound = arm.node_bound[static_cast<std::size_t>(node)];
      const double distance = (targets.positions[static_cast<std::size_t>(k)] - arm.base).norm();
      if (distance > bound)
        throw InputError(source, "targets[" + std::to_string(k) + "]",
                         beyond_reach("target", distance, object.robot(), arm,
                                      "node " + std::to_string(node), bound));
    }
}

std::string beyond_unstretched_reach(const GrippedObject& object, const ShapeTargets& targets) {
  const ArmReach* worst_arm = nullptr;
  int worst = -1;
  double excess = 0, distance = 0;
  const std::vector<ArmReach> arms = reach_bounds(object);
  for (const ArmReach& arm : arms)
    for (int k = 0; k < targets.size(); ++k) {
      const int node = targets.nodes[static_cast<std::size_t>(k)];
      const double d = (targets.positions[static_cast<std::size_t>(k)] - arm.base).norm();
      if (d - arm.rest_bound[static_cast<std::size_t>(node)] <= excess) continue;
      excess = d - arm.rest_bound[static_cast<std::size_t>(node)];
      distance = d, worst = k, worst_arm = &arm;
    }
  if (!worst_arm) return {};
  const RobotModel& robot = object.robot();
  const auto node = static_cast<std::size_t>(targets.nodes[static_cast<std::size_t>(worst)]);
  return "node " + std::to_string(node) + "'s target is " + metres(distance) + " from " +
         base_name(robot, *worst_arm) + ", where the arm gripping with link '" +
         robot.links()[static_cast<std::size_t>(worst_arm->link)].name +
         "' starts: " + metres(excess) + " beyond the " + metres(worst_arm->rest_bound[node]) +
         " it reaches with that node unstretched (" + metres(worst_arm->node_bound[node]) +
         " stretched tenfold)";
}

void check_centerline_in_reach(const GrippedObject& object, const std::vector<Vec3>& centerline,
                               const std::string& source) {
  for (const ArmReach& arm : reach_bounds(object)) {
    const double bound = *std::max_element(arm.node_bound.begin(), arm.node_bound.end());
    for (std::size_t k = 0; k < centerline.size(); ++k) {
      const double distance = (centerline[k] - arm.base).norm();
      if (distance > bound)
        throw InputError(source, "centerline[" + std::to_string(k) + "]",
                         beyond_reach("point", distance, object.robot(), arm, "any node", bound));
    }
  }
}

void check_in_reach(const GrippedObject& object, const TargetsInput& input,
                    const std::string& source) {
  if (input.centerline.empty()) check_targets_in_reach(object, input.targets, source);
  else check_centerline_in_reach(object, input.centerline, source);
}

}  // namespace shapectl
