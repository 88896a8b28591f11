#include <shapectl/robot/robot_model.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>

namespace shapectl {

namespace {

std::string quoted(std::string_view kind, std::string_view name) {
  return std::string(kind) + " '" + bounded_preview(name) + "'";  // names come from input
}

}  // namespace

std::optional<int> RobotModel::find_link(std::string_view name) const {
  const auto it = link_by_name_.find(name);
  if (it == link_by_name_.end()) return std::nullopt;
  return it->second;
}

std::optional<int> RobotModel::find_joint(std::string_view name) const {
  const auto it = joint_by_name_.find(name);
  if (it == joint_by_name_.end()) return std::nullopt;
  return it->second;
}

int RobotModel::link_index(std::string_view name) const {
  if (const auto i = find_link(name)) return *i;
  throw InputError(source_, quoted("link", name), "unknown link");
}

int RobotModel::joint_index(std::string_view name) const {
  if (const auto j = find_joint(name)) return *j;
  throw InputError(source_, quoted("joint", name), "unknown joint");
}

void RobotModel::set_active_joints(const std::vector<std::string>& names) {
  std::vector<int> active;
  for (const auto& name : names) {
    const int j = joint_index(name);
    const Joint& joint = joints_[static_cast<std::size_t>(j)];
    if (!joint.movable())
      throw InputError(source_, quoted("joint", name), "a fixed joint cannot be active");
    if (joint.mimic_master >= 0)
      throw InputError(source_, quoted("joint", name),
                       "mimics '" + joints_[static_cast<std::size_t>(joint.mimic_master)].name +
                           "'; make that joint active instead");
    if (std::find(active.begin(), active.end(), j) != active.end())
      throw InputError(source_, quoted("joint", name), "listed twice as active");
    active.push_back(j);
  }
  active_joints_ = std::move(active);
  active_index_.assign(joints_.size(), -1);
  for (std::size_t i = 0; i < active_joints_.size(); ++i)
    active_index_[static_cast<std::size_t>(active_joints_[i])] = static_cast<int>(i);
  rebuild_jacobian_entries();
}

std::vector<std::string> RobotModel::active_joint_names() const {
  std::vector<std::string> names;
  for (const int j : active_joints_) names.push_back(joints_[static_cast<std::size_t>(j)].name);
  return names;
}

Eigen::VectorXd RobotModel::lower_limits() const {
  Eigen::VectorXd v(active_count());
  for (int i = 0; i < active_count(); ++i)
    v[i] = joints_[static_cast<std::size_t>(active_joints_[static_cast<std::size_t>(i)])].lower;
  return v;
}

Eigen::VectorXd RobotModel::upper_limits() const {
  Eigen::VectorXd v(active_count());
  for (int i = 0; i < active_count(); ++i)
    v[i] = joints_[static_cast<std::size_t>(active_joints_[static_cast<std::size_t>(i)])].upper;
  return v;
}

Eigen::VectorXd RobotModel::velocity_limits() const {
  Eigen::VectorXd v(active_count());
  for (int i = 0; i < active_count(); ++i)
    v[i] = joints_[static_cast<std::size_t>(active_joints_[static_cast<std::size_t>(i)])].velocity;
  return v;
}

void RobotModel::set_fixed_joint_values(const std::map<std::string, double>& values,
                                        const std::string& source) {
  for (const auto& [name, value] : values) {
    const auto j = find_joint(name);
    if (!j) throw InputError(source, quoted("joint", name), "unknown joint in " + source_);
    const Joint& joint = joints_[static_cast<std::size_t>(*j)];
    if (!joint.movable() || joint.mimic_master >= 0 || active_index(*j) >= 0)
      throw InputError(source, quoted("joint", name),
                       "only inactive, movable, non-mimic joints take fixed values");
    if (!std::isfinite(value))
      throw InputError(source, quoted("joint", name), "a finite value", value);
    fixed_values_[*j] = value;
  }
}

Eigen::VectorXd RobotModel::active_joints_from_map(const std::map<std::string, double>& values,
                                                   const std::string& source) const {
  Eigen::VectorXd active = Eigen::VectorXd::Zero(active_count());
  for (const auto& [name, value] : values) {
    const auto j = find_joint(name);
    if (!j) throw InputError(source, quoted("joint", name), "unknown joint in " + source_);
    const Joint& joint = joints_[static_cast<std::size_t>(*j)];
    if (joint.mimic_master >= 0)
      throw InputError(source, quoted("joint", name),
                       "mimics '" + joints_[static_cast<std::size_t>(joint.mimic_master)].name +
                           "'; give that joint's value instead");
    if (active_index(*j) < 0)
      throw InputError(source, quoted("joint", name),
                       joint.movable() ? "not an active joint" : "a fixed joint has no value");
    if (!std::isfinite(value))
      throw InputError(source, quoted("joint", name), "a finite value", value);
    active[active_index(*j)] = value;
  }
  return active;
}

Eigen::VectorXd RobotModel::full_joints(const Eigen::VectorXd& active) const {
  assert(active.size() == active_count());
  Eigen::VectorXd q = Eigen::VectorXd::Zero(joint_count());
  for (int j = 0; j < joint_count(); ++j) {
    const Joint& joint = joints_[static_cast<std::size_t>(j)];
    if (!joint.movable() || joint.mimic_master >= 0) continue;
    q[j] = active_index(j) >= 0 ? active[active_index(j)] : fixed_values_[j];
  }
  // Masters are resolved to non-mimic joints at load, so one pass suffices.
  for (int j = 0; j < joint_count(); ++j) {
    const Joint& joint = joints_[static_cast<std::size_t>(j)];
    if (joint.mimic_master >= 0)
      q[j] = joint.mimic_multiplier * q[joint.mimic_master] + joint.mimic_offset;
  }
  return q;
}

void RobotModel::rebuild_jacobian_entries() {
  jacobian_entries_.assign(links_.size(), {});
  for (int link = 0; link < link_count(); ++link) {
    std::vector<JacobianEntry> entries;
    for (int j = links_[static_cast<std::size_t>(link)].parent_joint; j >= 0;
         j = links_[static_cast<std::size_t>(joints_[static_cast<std::size_t>(j)].parent_link)]
                 .parent_joint) {
      const Joint& joint = joints_[static_cast<std::size_t>(j)];
      if (!joint.movable()) continue;
      if (active_index(j) >= 0) {
        entries.push_back({j, active_index(j), 1.0});
      } else if (joint.mimic_master >= 0 && active_index(joint.mimic_master) >= 0) {
        entries.push_back({j, active_index(joint.mimic_master), joint.mimic_multiplier});
      }
    }
    std::reverse(entries.begin(), entries.end());
    jacobian_entries_[static_cast<std::size_t>(link)] = std::move(entries);
  }
}

}  // namespace shapectl
