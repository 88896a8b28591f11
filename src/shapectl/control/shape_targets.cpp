#include <shapectl/control/shape_targets.hpp>

#include <algorithm>

namespace shapectl {

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
