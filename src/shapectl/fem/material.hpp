#pragma once
// Compressible neo-Hookean material parameters.

namespace shapectl {

struct Material {
  double mu = 0;       // shear modulus, Pa
  double kappa = 0;    // the κ of Ψ = μ/2 (tr FᵀF − 3) − μ ln J + κ/2 (ln J)², Pa
  double density = 0;  // kg/m^3
};

// μ = E/(2(1+ν)), κ = Eν/((1+ν)(1−2ν)): small strains then reproduce linear elasticity
// (κ plays the role of Lamé's λ).
Material material_from_youngs(double youngs_modulus, double poisson_ratio, double density);
// The inverse: E = μ(3κ + 2μ)/(κ + μ), ν = κ/(2(κ + μ)).
double youngs_modulus_of(const Material& m);
double poisson_ratio_of(const Material& m);

}  // namespace shapectl
