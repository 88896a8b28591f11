#include <shapectl/fem/material.hpp>

namespace shapectl {

Material material_from_youngs(double youngs_modulus, double poisson_ratio, double density) {
  const double E = youngs_modulus, nu = poisson_ratio;
  return {.mu = E / (2 * (1 + nu)),
          .kappa = E * nu / ((1 + nu) * (1 - 2 * nu)),
          .density = density};
}

double youngs_modulus_of(const Material& m) {
  return m.mu * (3 * m.kappa + 2 * m.mu) / (m.kappa + m.mu);
}

double poisson_ratio_of(const Material& m) { return m.kappa / (2 * (m.kappa + m.mu)); }

}  // namespace shapectl
