#include <shapectl/robot/collision_spheres.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

namespace shapectl {

namespace {

// Rigid group of every link: links joined by fixed joints never move relative to each other.
std::vector<int> rigid_groups(const RobotModel& robot) {
  std::vector<int> group(static_cast<std::size_t>(robot.link_count()));
  for (int link = 0; link < robot.link_count(); ++link) {
    const int j = robot.links()[static_cast<std::size_t>(link)].parent_joint;
    const bool fixed = j >= 0 && !robot.joints()[static_cast<std::size_t>(j)].movable();
    // Parents come before children, so the parent's group is known.
    group[static_cast<std::size_t>(link)] =
        fixed ? group[static_cast<std::size_t>(robot.joints()[static_cast<std::size_t>(j)].parent_link)]
              : link;
  }
  return group;
}

// Whether spheres on links a and b are checked against each other.
std::vector<std::vector<bool>> checked_link_pairs(const RobotModel& robot,
                                                  const std::vector<std::pair<int, int>>& ignore) {
  const auto n = static_cast<std::size_t>(robot.link_count());
  const std::vector<int> group = rigid_groups(robot);
  std::vector<std::vector<bool>> checked(n, std::vector<bool>(n, true));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b)
      if (group[a] == group[b]) checked[a][b] = false;
  // Groups joined by one movable joint are adjacent.
  for (const Joint& joint : robot.joints()) {
    if (!joint.movable()) continue;
    const int parent_group = group[static_cast<std::size_t>(joint.parent_link)];
    const int child_group = group[static_cast<std::size_t>(joint.child_link)];
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = 0; b < n; ++b)
        if (group[a] == parent_group && group[b] == child_group)
          checked[a][b] = checked[b][a] = false;
  }
  for (const auto& [a, b] : ignore)
    checked[static_cast<std::size_t>(a)][static_cast<std::size_t>(b)] =
        checked[static_cast<std::size_t>(b)][static_cast<std::size_t>(a)] = false;
  return checked;
}

}  // namespace

CollisionModel::CollisionModel(const RobotModel& robot, std::vector<CollisionSphere> spheres,
                               double margin, double stiffness,
                               const std::vector<std::pair<int, int>>& ignore_pairs)
    : spheres_(std::move(spheres)), margin_(margin), barrier_{stiffness} {
  assert(margin >= 0 && stiffness >= 0);
  const auto checked = checked_link_pairs(robot, ignore_pairs);
  for (std::size_t a = 0; a < spheres_.size(); ++a)
    for (std::size_t b = a + 1; b < spheres_.size(); ++b)
      if (checked[static_cast<std::size_t>(spheres_[a].link)][static_cast<std::size_t>(spheres_[b].link)]) {
        pairs_.emplace_back(static_cast<int>(a), static_cast<int>(b));
        reach_.push_back(spheres_[a].radius + spheres_[b].radius + margin_);
      }
}

void CollisionModel::sphere_centers(const KinematicsState& state, std::vector<Vec3>& centers) const {
  centers.resize(spheres_.size());
  for (std::size_t s = 0; s < spheres_.size(); ++s)
    centers[s] = state.T_world_link[static_cast<std::size_t>(spheres_[s].link)] * spheres_[s].center_link;
}

double CollisionModel::min_clearance(const KinematicsState& state) const {
  const auto closest = closest_pairs(state, 1);
  return closest.empty() ? std::numeric_limits<double>::infinity() : closest[0].clearance;
}

std::vector<SphereClearance> CollisionModel::closest_pairs(const KinematicsState& state,
                                                           std::size_t count) const {
  std::vector<Vec3> centers;
  sphere_centers(state, centers);
  std::vector<SphereClearance> all;
  all.reserve(pairs_.size());
  for (const auto& [a, b] : pairs_) {
    const double distance = (centers[static_cast<std::size_t>(a)] - centers[static_cast<std::size_t>(b)]).norm();
    all.push_back({a, b, distance - spheres_[static_cast<std::size_t>(a)].radius -
                             spheres_[static_cast<std::size_t>(b)].radius});
  }
  count = std::min(count, all.size());
  std::partial_sort(all.begin(), all.begin() + static_cast<long>(count), all.end(),
                    [](const auto& x, const auto& y) { return x.clearance < y.clearance; });
  all.resize(count);
  return all;
}

double CollisionModel::value(const RobotModel& robot, const KinematicsState& state,
                             Eigen::VectorXd* gradient) const {
  std::vector<Vec3> centers;
  sphere_centers(state, centers);
  // dB/ds per sphere, accumulated over its violated pairs, then mapped to θ once per sphere.
  std::vector<Vec3> forces;
  if (gradient) forces.assign(spheres_.size(), Vec3::Zero());
  double total = 0;
  for (std::size_t p = 0; p < pairs_.size(); ++p) {
    const auto a = static_cast<std::size_t>(pairs_[p].first);
    const auto b = static_cast<std::size_t>(pairs_[p].second);
    const Vec3 diff = centers[a] - centers[b];
    const double distance2 = diff.squaredNorm();
    if (distance2 >= reach_[p] * reach_[p]) continue;
    const double distance = std::sqrt(distance2);
    const double v = reach_[p] - distance;
    total += barrier_.value(v);
    if (!gradient) continue;
    // dv/ds_a = −u with u the unit vector from b to a (any direction if the centres coincide).
    const Vec3 u = distance > 1e-12 ? Vec3(diff / distance) : Vec3::UnitX();
    const Vec3 force = -barrier_.derivative(v) * u;
    forces[a] += force;
    forces[b] -= force;
  }
  if (gradient) {
    gradient->setZero(robot.active_count());
    for (std::size_t s = 0; s < spheres_.size(); ++s)
      if (!forces[s].isZero(0))
        add_point_jacobian_transpose(robot, state, spheres_[s].link, centers[s], forces[s], *gradient);
  }
  return total;
}

void CollisionModel::residuals(const RobotModel& robot, const KinematicsState& state,
                               Eigen::VectorXd& r, Eigen::MatrixXd* jacobian) const {
  std::vector<Vec3> centers;
  sphere_centers(state, centers);
  r.setZero(pair_count());
  if (jacobian) jacobian->setZero(pair_count(), robot.active_count());
  Eigen::Matrix3Xd jacobian_a(3, robot.active_count());
  Eigen::Matrix3Xd jacobian_b(3, robot.active_count());
  for (std::size_t p = 0; p < pairs_.size(); ++p) {
    const auto a = static_cast<std::size_t>(pairs_[p].first);
    const auto b = static_cast<std::size_t>(pairs_[p].second);
    const Vec3 diff = centers[a] - centers[b];
    const double distance = diff.norm();
    const double v = reach_[p] - distance;
    if (v <= 0) continue;
    r[static_cast<long>(p)] = barrier_.residual(v);
    if (!jacobian) continue;
    const Vec3 u = distance > 1e-12 ? Vec3(diff / distance) : Vec3::UnitX();
    point_jacobian_world(robot, state, spheres_[a].link, centers[a], jacobian_a);
    point_jacobian_world(robot, state, spheres_[b].link, centers[b], jacobian_b);
    // dr/dθ = r'(v) · dv/dθ,  dv/dθ = −uᵀ (J_a − J_b).
    jacobian->row(static_cast<long>(p)) =
        -barrier_.residual_derivative(v) * (u.transpose() * (jacobian_a - jacobian_b));
  }
}

CollisionModel CollisionModel::load_json_file(const RobotModel& robot,
                                              const std::filesystem::path& file) {
  return from_json(robot, JsonInput::load(file));
}

CollisionModel CollisionModel::from_json(const RobotModel& robot, const JsonInput& json) {
  json.expect_only({"description", "margin", "stiffness", "spheres", "ignore_pairs"});
  if (json.has("description")) json.at("description").string();
  const double margin = json.has("margin") ? json.at("margin").non_negative() : 0.0;
  const double stiffness = json.has("stiffness") ? json.at("stiffness").positive() : default_stiffness;
  auto link_named = [&](const JsonInput& where, const std::string& name) {
    const auto link = robot.find_link(name);
    if (!link) where.fail_problem("unknown link '" + name + "' (not in " + robot.source() + ")");
    return *link;
  };

  std::vector<CollisionSphere> spheres;
  const JsonInput all = json.at("spheres");
  for (const auto& name : all.keys()) {
    const JsonInput list = all.at(name);
    const int link = link_named(list, name);
    for (std::size_t i = 0; i < list.size(); ++i) {
      const JsonInput sphere = list.at(i);
      sphere.expect_only({"center", "radius"});
      spheres.push_back({link, sphere.at("center").vec3(), sphere.at("radius").positive()});
    }
  }

  std::vector<std::pair<int, int>> ignore;
  if (json.has("ignore_pairs")) {
    const JsonInput pairs = json.at("ignore_pairs");
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const JsonInput pair = pairs.at(i);
      if (pair.size() != 2) pair.fail("a pair of link names");
      ignore.emplace_back(link_named(pair.at(std::size_t{0}), pair.at(std::size_t{0}).string()),
                          link_named(pair.at(1), pair.at(1).string()));
    }
  }
  return CollisionModel(robot, std::move(spheres), margin, stiffness, ignore);
}

}  // namespace shapectl
