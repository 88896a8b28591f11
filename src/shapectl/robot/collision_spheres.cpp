#include <shapectl/robot/collision_spheres.hpp>

#include <shapectl/io/input_file.hpp>
#include <shapectl/io/json_input.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

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
        fixed ? group[static_cast<std::size_t>(
                    robot.joints()[static_cast<std::size_t>(j)].parent_link)]
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
  std::stable_sort(spheres_.begin(), spheres_.end(),
                   [](const auto& a, const auto& b) { return a.link < b.link; });
  for (const auto& s : spheres_) radii_.push_back(s.radius);
  // Sphere range of every link.
  std::vector<std::pair<int, int>> range(static_cast<std::size_t>(robot.link_count()), {0, 0});
  for (int s = static_cast<int>(spheres_.size()) - 1; s >= 0; --s) {
    auto& r = range[static_cast<std::size_t>(spheres_[static_cast<std::size_t>(s)].link)];
    if (r.second == 0) r.second = s + 1;
    r.first = s;
  }
  const auto checked = checked_link_pairs(robot, ignore_pairs);
  for (std::size_t link_a = 0; link_a < range.size(); ++link_a) {
    for (std::size_t link_b = link_a + 1; link_b < range.size(); ++link_b) {
      auto outer = range[link_a];
      auto inner = range[link_b];
      if (outer.first == outer.second || inner.first == inner.second || !checked[link_a][link_b])
        continue;
      // The link with more spheres forms the inner loop, which is the one that vectorises.
      if (outer.second - outer.first > inner.second - inner.first) std::swap(outer, inner);
      for (int a = outer.first; a < outer.second; ++a) {
        blocks_.push_back({a, inner.first, inner.second});
        for (int b = inner.first; b < inner.second; ++b) {
          pairs_.emplace_back(a, b);
          reach_.push_back(radii_[static_cast<std::size_t>(a)] +
                           radii_[static_cast<std::size_t>(b)] + margin_);
        }
      }
    }
  }
}

void CollisionModel::sphere_centers(const KinematicsState& state,
                                    std::vector<Vec3>& centers) const {
  centers.resize(spheres_.size());
  for (std::size_t s = 0; s < spheres_.size(); ++s)
    centers[s] =
        state.T_world_link[static_cast<std::size_t>(spheres_[s].link)] * spheres_[s].center_link;
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
    const double distance =
        (centers[static_cast<std::size_t>(a)] - centers[static_cast<std::size_t>(b)]).norm();
    all.push_back({a, b,
                   distance - spheres_[static_cast<std::size_t>(a)].radius -
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
  const std::size_t n = spheres_.size();
  std::vector<double> xyz(3 * n);  // all x, then all y, then all z
  double* x = xyz.data();
  double* y = x + n;
  double* z = y + n;
  for (std::size_t s = 0; s < n; ++s) {
    const Vec3 c =
        state.T_world_link[static_cast<std::size_t>(spheres_[s].link)] * spheres_[s].center_link;
    x[s] = c.x();
    y[s] = c.y();
    z[s] = c.z();
  }
  // dB/ds per sphere, accumulated over its violated pairs, then mapped to θ once per sphere.
  std::vector<Vec3> forces;
  if (gradient) forces.assign(n, Vec3::Zero());
  const double* radius = radii_.data();
  double total = 0;
  for (const Block& block : blocks_) {
    const auto a = static_cast<std::size_t>(block.sphere);
    const double reach_a = radius[a] + margin_;
    // Most blocks are clear: a branch-free pass finds out (and vectorises).
    int overlapping = 0;
    for (int b = block.begin; b < block.end; ++b) {
      const double dx = x[a] - x[b], dy = y[a] - y[b], dz = z[a] - z[b];
      const double reach = reach_a + radius[b];
      overlapping += dx * dx + dy * dy + dz * dz < reach * reach;
    }
    if (overlapping == 0) continue;
    for (int b = block.begin; b < block.end; ++b) {
      const Vec3 diff(x[a] - x[b], y[a] - y[b], z[a] - z[b]);
      const double distance = diff.norm();
      const double v = reach_a + radius[b] - distance;
      if (v <= 0) continue;
      total += barrier_.value(v);
      if (!gradient) continue;
      // dv/ds_a = −u with u the unit vector from b to a (any direction if the centres coincide).
      const Vec3 u = distance > 1e-12 ? Vec3(diff / distance) : Vec3::UnitX();
      const Vec3 force = -barrier_.derivative(v) * u;
      forces[a] += force;
      forces[static_cast<std::size_t>(b)] -= force;
    }
  }
  if (gradient) {
    gradient->setZero(robot.active_count());
    for (std::size_t s = 0; s < n; ++s)
      if (!forces[s].isZero(0))
        add_point_jacobian_transpose(robot, state, spheres_[s].link, Vec3(x[s], y[s], z[s]),
                                     forces[s], *gradient);
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
  const double stiffness =
      json.has("stiffness") ? json.at("stiffness").positive() : default_stiffness;
  auto link_named = [&](const JsonInput& where, const std::string& name) {
    const auto link = robot.find_link(name);
    if (!link)
      where.fail_problem("unknown link '" + bounded_preview(name) + "' (not in " + robot.source() +
                         ")");
    return *link;
  };

  // Pairs grow with the square of the sphere count: bound it (YuMi has 155).
  constexpr std::size_t max_spheres = 2000;
  std::vector<CollisionSphere> spheres;
  const JsonInput all = json.at("spheres");
  for (const auto& name : all.keys()) {
    const JsonInput list = all.at(name);
    const int link = link_named(list, name);
    if (spheres.size() + list.size() > max_spheres)
      list.fail_problem("more than " + std::to_string(max_spheres) + " spheres in all (the limit)");
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
