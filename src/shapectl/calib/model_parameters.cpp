#include <shapectl/calib/model_parameters.hpp>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <shapectl/fem/gravity.hpp>
#include <shapectl/fem/neo_hookean.hpp>

namespace shapectl {

namespace {

using Kind = ParameterCoordinate::Kind;

Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Eigen::Matrix3d rotation_of(const Vec3& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle == 0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

// ∂E_elastic/∂x for a material with only μ = 1 (or only κ = 1): the energy is linear in both.
Eigen::VectorXd unit_elastic_gradient(const TetMesh& mesh, const Positions& x, double mu,
                                      double kappa) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  NeoHookean(mesh, Material{.mu = mu, .kappa = kappa, .density = 0}).add_gradient(x, g);
  return g;
}

const char* axis_name(bool rotation, int axis) {
  static const char* names[2][3] = {{"x", "y", "z"}, {"rx", "ry", "rz"}};
  return names[rotation][axis];
}

}  // namespace

FitSelection parse_fit_selection(const std::string& list) {
  FitSelection s;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "youngs_modulus") s.youngs_modulus = true;
    else if (item == "poisson_ratio") s.poisson_ratio = true;
    else if (item == "density") s.density = true;
    else if (item == "grip_offsets") s.grip_offsets = true;
    else
      throw std::invalid_argument(
          "unknown parameter \"" + item +
          "\" (expected youngs_modulus, poisson_ratio, density or grip_offsets)");
  }
  if (s.empty())
    throw std::invalid_argument("no parameter to fit (expected a comma-separated list)");
  return s;
}

PhysicalParameters PhysicalParameters::of(const Scene& scene) {
  PhysicalParameters p;
  p.youngs_modulus = youngs_modulus_of(scene.material);
  p.poisson_ratio = poisson_ratio_of(scene.material);
  p.density = scene.material.density;
  for (const Grip& g : scene.grips) p.grip_offsets.push_back(g.offset);
  return p;
}

Scene PhysicalParameters::applied_to(const Scene& scene) const {
  Scene out = scene;
  out.material = material_from_youngs(youngs_modulus, poisson_ratio, density);
  for (std::size_t k = 0; k < out.grips.size(); ++k) out.grips[k].offset = grip_offsets[k];
  return out;
}

ParameterSpace::ParameterSpace(const Scene& scene, const FitSelection& selection) {
  if (selection.youngs_modulus)
    coordinates_.push_back({Kind::LogYoungsModulus, -1, -1, "youngs_modulus", 1});
  if (selection.poisson_ratio)
    coordinates_.push_back({Kind::PoissonLogit, -1, -1, "poisson_ratio", 1});
  if (selection.density) coordinates_.push_back({Kind::LogDensity, -1, -1, "density", 1});
  if (selection.grip_offsets) {
    if (scene.grips.empty()) throw std::invalid_argument("grip_offsets: the scene has no grips");
    for (std::size_t g = 0; g < scene.grips.size(); ++g) {
      const std::string prefix =
          "grip_offsets." + scene.robot->end_effectors[scene.grips[g].end_effector].name + ".";
      for (int rotation = 0; rotation < 2; ++rotation)
        for (int axis = 0; axis < 3; ++axis)
          coordinates_.push_back({rotation ? Kind::GripRotation : Kind::GripTranslation, int(g),
                                  axis, prefix + axis_name(rotation, axis), rotation ? 0.1 : 0.01});
    }
  }
}

PhysicalParameters ParameterSpace::advanced(const PhysicalParameters& p,
                                            const Eigen::VectorXd& dz) const {
  PhysicalParameters out = p;
  std::vector<Vec3> dt(p.grip_offsets.size(), Vec3::Zero()), dr = dt;
  for (int k = 0; k < size(); ++k) {
    const ParameterCoordinate& c = coordinates_[k];
    switch (c.kind) {
      case Kind::LogYoungsModulus: out.youngs_modulus *= std::exp(dz[k]); break;
      case Kind::LogDensity: out.density *= std::exp(dz[k]); break;
      case Kind::PoissonLogit: {
        const double s = std::log(2 * p.poisson_ratio / (1 - 2 * p.poisson_ratio)) + dz[k];
        out.poisson_ratio = 0.5 / (1 + std::exp(-s));
        break;
      }
      case Kind::GripTranslation: dt[c.grip][c.axis] = dz[k]; break;
      case Kind::GripRotation: dr[c.grip][c.axis] = dz[k]; break;
    }
  }
  for (std::size_t g = 0; g < out.grip_offsets.size(); ++g) {
    Eigen::Isometry3d& O = out.grip_offsets[g];
    O.linear() = rotation_of(dr[g]) * O.linear();
    O.translation() += dt[g];
  }
  return out;
}

double ParameterSpace::physical_per_coordinate(const ParameterCoordinate& c,
                                               const PhysicalParameters& p) const {
  switch (c.kind) {
    case Kind::LogYoungsModulus: return p.youngs_modulus;
    case Kind::LogDensity: return p.density;
    case Kind::PoissonLogit: return p.poisson_ratio * (1 - 2 * p.poisson_ratio);
    case Kind::GripTranslation:
    case Kind::GripRotation: return 1;
  }
  return 1;
}

Eigen::MatrixXd ParameterSpace::force_derivatives(const GrippedObject& object,
                                                  const ObjectState& state,
                                                  const PhysicalParameters& p) const {
  const Positions& x = state.positions();
  const Scene& scene = object.scene();
  Eigen::MatrixXd dF = Eigen::MatrixXd::Zero(x.size(), size());
  // Elasticity is linear in (μ, κ); E scales both, so ∂F/∂ln E = −∂E_elastic/∂x.
  const double nu = p.poisson_ratio, E = p.youngs_modulus;
  const Eigen::VectorXd g_mu = unit_elastic_gradient(object.mesh(), x, 1, 0);
  const Eigen::VectorXd g_kappa = unit_elastic_gradient(object.mesh(), x, 0, 1);
  const Material m = scene.material;
  // dμ/dν and dκ/dν of material_from_youngs.
  const double dmu_dnu = -E / (2 * (1 + nu) * (1 + nu));
  const double dkappa_dnu = E * (1 + 2 * nu * nu) / std::pow((1 + nu) * (1 - 2 * nu), 2);
  const double dnu_ds = nu * (1 - 2 * nu);
  for (int k = 0; k < size(); ++k) {
    const ParameterCoordinate& c = coordinates_[k];
    switch (c.kind) {
      case Kind::LogYoungsModulus: dF.col(k) = -(m.mu * g_mu + m.kappa * g_kappa); break;
      case Kind::PoissonLogit: dF.col(k) = -(dmu_dnu * g_mu + dkappa_dnu * g_kappa) * dnu_ds; break;
      case Kind::LogDensity: {
        Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
        Gravity(object.mesh(), m.density, scene.gravity).add_gradient(x, g);
        dF.col(k) = -g;
        break;
      }
      case Kind::GripTranslation:
      case Kind::GripRotation: break;  // below
    }
  }
  // Grip springs: Fᵢ = −K (xᵢ − aᵢ), aᵢ = T_link(θ) pᵢ with pᵢ = tcp + t + R uᵢ in the link
  // frame. Moving the offset: ∂aᵢ/∂δt = R_link, ∂aᵢ/∂δr = −R_link [pᵢ − tcp − t]×.
  const std::vector<GrippedNode>& gripped = object.grips().nodes();
  const double K = object.grips().stiffness();
  std::size_t n = 0;  // gripped nodes are in grip order (GrippedObject)
  for (std::size_t g = 0; g < scene.grips.size(); ++g) {
    const Vec3 tcp = scene.robot->end_effectors[scene.grips[g].end_effector].tcp_link;
    const Vec3 t = p.grip_offsets[g].translation();
    for (std::size_t i = 0; i < scene.grips[g].nodes.size(); ++i, ++n) {
      const GrippedNode& node = gripped[n];
      const Mat3 R_link = state.kinematics().T_world_link[node.link].linear();
      const Mat3 d_rotation = -R_link * skew(node.point_link - tcp - t);
      for (int k = 0; k < size(); ++k) {
        const ParameterCoordinate& c = coordinates_[k];
        if (c.grip != int(g)) continue;
        const Vec3 da = c.kind == Kind::GripTranslation ? Vec3(R_link.col(c.axis))
                                                        : Vec3(d_rotation.col(c.axis));
        dF.col(k).segment<3>(3 * node.node) += K * da;
      }
    }
  }
  return dF;
}

}  // namespace shapectl
