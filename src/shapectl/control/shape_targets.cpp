#include <shapectl/control/shape_targets.hpp>

#include <algorithm>
#include <sstream>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

void check_target_point(const Vec3& p, const std::string& source, const std::string& where) {
  if (p.allFinite() && p.cwiseAbs().maxCoeff() <= max_target_distance) return;
  std::ostringstream found;
  found << "[" << p.x() << ", " << p.y() << ", " << p.z() << "]";
  throw InputError(source, where, "a finite point within 1000 m of the origin", found.str());
}

void check_targets(const ShapeTargets& targets, int node_count, const std::string& source) {
  if (targets.nodes.size() != targets.positions.size())
    throw InputError(source, "", "as many positions as nodes",
                     std::to_string(targets.positions.size()) + " positions for " +
                         std::to_string(targets.nodes.size()) + " nodes");
  for (std::size_t k = 0; k < targets.nodes.size(); ++k) {
    const std::string where = "targets[" + std::to_string(k) + "]";
    if (targets.nodes[k] < 0 || targets.nodes[k] >= node_count)
      throw InputError(source, where + ".node",
                       "a node from 0 to " + std::to_string(node_count - 1), targets.nodes[k]);
    check_target_point(targets.positions[k], source, where + ".position");
  }
}

ShapeError shape_error(const ShapeTargets& targets, const Positions& x) {
  ShapeError e;
  if (targets.empty()) return e;
  for (int k = 0; k < targets.size(); ++k) {
    const double d = (x.segment<3>(3 * targets.nodes[k]) - targets.positions[k]).norm();
    e.mean += d;
    e.max = std::max(e.max, d);
  }
  e.mean /= targets.size();
  return e;
}

}  // namespace shapectl
