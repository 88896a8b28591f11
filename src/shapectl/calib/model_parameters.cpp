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

// T moved on the left about its own origin: (exp([dr]) R, t + dt).
void move(Eigen::Isometry3d& T, const Vec3& dt, const Vec3& dr) {
  T.linear() = rotation_of(dr) * T.linear();
  T.translation() += dt;
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

// Six coordinates of a rigid motion: 1 cm and 0.1 rad are changes worth noticing.
void add_motion_coordinates(std::vector<ParameterCoordinate>& out, Kind translation, Kind rotation,
                            int grip, const std::string& prefix) {
  for (int r = 0; r < 2; ++r)
    for (int axis = 0; axis < 3; ++axis)
      out.push_back(
          {r ? rotation : translation, grip, axis, prefix + axis_name(r, axis), r ? 0.1 : 0.01});
}

// Why the object's pose cannot be fitted in this scene; empty when it can.
std::string object_pose_refusal(const Scene& scene) {
  if (scene.robot && scene.fixed)
    return "object_pose: the object is held by the robot's grips as well as by fixed nodes; its "
           "pose is fitted only for scenes held by fixed nodes alone";
  if (scene.robot)
    return "object_pose: the object is held by the robot's grips alone, which tie it to the "
           "grippers: its pose follows the joints (fit grip_offsets for where they hold it)";
  if (!scene.fixed) return "object_pose: the scene has no fixed nodes to place";
  // Its force derivatives turn the weight with the object, not the loads.
  if (!scene.loads.empty()) return "object_pose: not fitted in a scene with \"loads\"";
  return "";
}

}  // namespace

const char* fit_parameter_names() {
  return "youngs_modulus, poisson_ratio, density, grip_offsets, object_pose";
}

const char* default_fit(const Scene& scene) {
  return scene.robot ? "youngs_modulus,grip_offsets" : "youngs_modulus,object_pose";
}

FitSelection parse_fit_selection(const std::string& list) {
  FitSelection s;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "youngs_modulus") s.youngs_modulus = true;
    else if (item == "poisson_ratio") s.poisson_ratio = true;
    else if (item == "density") s.density = true;
    else if (item == "grip_offsets") s.grip_offsets = true;
    else if (item == "object_pose") s.object_pose = true;
    else
      throw std::invalid_argument(
          "unknown parameter \"" + item +
          "\" (expected youngs_modulus, poisson_ratio, density, grip_offsets or object_pose)");
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
  p.object_pose = scene.T_world_object;
  return p;
}

Scene PhysicalParameters::applied_to(const Scene& scene) const {
  Scene out = scene;
  out.material = material_from_youngs(youngs_modulus, poisson_ratio, density);
  for (std::size_t k = 0; k < out.grips.size(); ++k) out.grips[k].offset = grip_offsets[k];
  out.T_world_object = object_pose;
  return out;
}

ParameterSpace::ParameterSpace(const Scene& scene, const FitSelection& selection) {
  // One material is fitted, its derivatives taken over the whole mesh.
  if ((selection.youngs_modulus || selection.poisson_ratio || selection.density) &&
      !scene.regions.empty())
    throw std::invalid_argument(
        "youngs_modulus, poisson_ratio, density: not fitted in a scene with \"regions\" "
        "(calibration fits one material for the whole object)");
  if (selection.youngs_modulus)
    coordinates_.push_back({Kind::LogYoungsModulus, -1, -1, "youngs_modulus", 1});
  if (selection.poisson_ratio)
    coordinates_.push_back({Kind::PoissonLogit, -1, -1, "poisson_ratio", 1});
  if (selection.density) coordinates_.push_back({Kind::LogDensity, -1, -1, "density", 1});
  if (selection.grip_offsets) {
    if (scene.grips.empty()) throw std::invalid_argument("grip_offsets: the scene has no grips");
    for (std::size_t g = 0; g < scene.grips.size(); ++g) {
      const std::string& hand = scene.robot->end_effectors[scene.grips[g].end_effector].name;
      add_motion_coordinates(coordinates_, Kind::GripTranslation, Kind::GripRotation, int(g),
                             "grip_offsets." + hand + ".");
    }
  }
  if (selection.object_pose) {
    const std::string refusal = object_pose_refusal(scene);
    if (!refusal.empty()) throw std::invalid_argument(refusal);
    add_motion_coordinates(coordinates_, Kind::PoseTranslation, Kind::PoseRotation, -1,
                           "object_pose.");
  }
}

PhysicalParameters ParameterSpace::advanced(const PhysicalParameters& p,
                                            const Eigen::VectorXd& dz) const {
  PhysicalParameters out = p;
  std::vector<Vec3> dt(p.grip_offsets.size(), Vec3::Zero()), dr = dt;
  Vec3 pose_dt = Vec3::Zero(), pose_dr = Vec3::Zero();
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
      case Kind::PoseTranslation: pose_dt[c.axis] = dz[k]; break;
      case Kind::PoseRotation: pose_dr[c.axis] = dz[k]; break;
    }
  }
  for (std::size_t g = 0; g < out.grip_offsets.size(); ++g) move(out.grip_offsets[g], dt[g], dr[g]);
  move(out.object_pose, pose_dt, pose_dr);
  return out;
}

double ParameterSpace::physical_per_coordinate(const ParameterCoordinate& c,
                                               const PhysicalParameters& p) const {
  switch (c.kind) {
    case Kind::LogYoungsModulus: return p.youngs_modulus;
    case Kind::LogDensity: return p.density;
    case Kind::PoissonLogit: return p.poisson_ratio * (1 - 2 * p.poisson_ratio);
    default: return 1;  // m and rad: the coordinates themselves
  }
}

Eigen::MatrixXd ParameterSpace::force_derivatives(const ObjectStatics& statics, const Scene& scene,
                                                  const Positions& x,
                                                  const PhysicalParameters& p) const {
  Eigen::MatrixXd dF = Eigen::MatrixXd::Zero(x.size(), size());
  // Elasticity is linear in (μ, κ); E scales both, so ∂F/∂ln E = −∂E_elastic/∂x.
  const double nu = p.poisson_ratio, E = p.youngs_modulus;
  const Eigen::VectorXd g_mu = unit_elastic_gradient(statics.mesh(), x, 1, 0);
  const Eigen::VectorXd g_kappa = unit_elastic_gradient(statics.mesh(), x, 0, 1);
  const Material m = scene.material;
  // dμ/dν and dκ/dν of material_from_youngs.
  const double dmu_dnu = -E / (2 * (1 + nu) * (1 + nu));
  const double dkappa_dnu = E * (1 + 2 * nu * nu) / std::pow((1 + nu) * (1 - 2 * nu), 2);
  const double dnu_ds = nu * (1 - 2 * nu);
  // Gravity's force mᵢ g: ∝ ρ, and turned by −δr when the scene turns by δr.
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(x.size());
  Gravity(statics.mesh(), m.density, scene.gravity).add_gradient(x, weight);
  weight = -weight;
  for (int k = 0; k < size(); ++k) {
    const ParameterCoordinate& c = coordinates_[k];
    switch (c.kind) {
      case Kind::LogYoungsModulus: dF.col(k) = -(m.mu * g_mu + m.kappa * g_kappa); break;
      case Kind::PoissonLogit: dF.col(k) = -(dmu_dnu * g_mu + dkappa_dnu * g_kappa) * dnu_ds; break;
      case Kind::LogDensity: dF.col(k) = weight; break;
      case Kind::PoseRotation:
        for (Eigen::Index i = 0; i < x.size() / 3; ++i)
          dF.col(k).segment<3>(3 * i) = Vec3(weight.segment<3>(3 * i)).cross(Vec3::Unit(c.axis));
        break;
      default: break;  // grip and pose translation columns: no force on the object itself
    }
  }
  return dF;
}

Eigen::MatrixXd ParameterSpace::pose_motion(const Positions& x, const PhysicalParameters& p) const {
  Eigen::MatrixXd dx = Eigen::MatrixXd::Zero(x.size(), size());
  const Vec3 origin = p.object_pose.translation();
  for (int k = 0; k < size(); ++k) {
    const ParameterCoordinate& c = coordinates_[k];
    if (c.kind != Kind::PoseTranslation && c.kind != Kind::PoseRotation) continue;
    for (Eigen::Index i = 0; i < x.size() / 3; ++i)
      dx.col(k).segment<3>(3 * i) = c.kind == Kind::PoseTranslation
                                        ? Vec3(Vec3::Unit(c.axis))
                                        : Vec3::Unit(c.axis).cross(x.segment<3>(3 * i) - origin);
  }
  return dx;
}

Eigen::MatrixXd ParameterSpace::force_derivatives(const GrippedObject& object,
                                                  const ObjectState& state,
                                                  const PhysicalParameters& p) const {
  const Scene& scene = object.scene();
  Eigen::MatrixXd dF = force_derivatives(object.statics(), scene, state.positions(), p);
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
