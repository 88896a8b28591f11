#include <shapectl/fem/material.hpp>

namespace shapectl {

Material material_from_youngs(double youngs_modulus, double poisson_ratio, double density) {
  const double E = youngs_modulus, nu = poisson_ratio;
  return {.mu = E / (2 * (1 + nu)), .kappa = E * nu / ((1 + nu) * (1 - 2 * nu)), .density = density};
}

}  // namespace shapectl
