#pragma once
// The closed-loop tests' "real" object: the bundled YuMi bar 1.5× stiffer, 0.8× as dense and
// held 4 mm / 3° off at each grip, and the mean distance of target nodes from their targets.
#include <cmath>

#include <shapectl/control/shape_targets.hpp>
#include <shapectl/fem/material.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl::test {

inline Scene different_world(const Scene& model) {
  Scene world = model;
  world.material =
      material_from_youngs(1.5 * youngs_modulus_of(model.material),
                           poisson_ratio_of(model.material), 0.8 * model.material.density);
  world.grips[0].offset = Eigen::Translation3d(0.004 * Vec3(0, 1, -1).normalized()) *
                          Eigen::AngleAxisd(3 * M_PI / 180, Vec3(0, 0, 1));
  world.grips[1].offset = Eigen::Translation3d(0.004 * Vec3(1, 0, 1).normalized()) *
                          Eigen::AngleAxisd(3 * M_PI / 180, Vec3(0, 1, 0));
  return world;
}

inline double true_error(const ShapeTargets& targets, const Positions& world) {
  double sum = 0;
  for (int k = 0; k < targets.size(); ++k)
    sum += (world.segment<3>(3 * targets.nodes[k]) - targets.positions[k]).norm();
  return sum / targets.size();
}

}  // namespace shapectl::test
