#include <shapectl/calib/model_parameters.hpp>

#include <cmath>
#include <optional>
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

// Materials for the elements of `region` alone (owner as Scene::element_regions), the others
// none: the energy is linear in (μ, κ) and the weight in ρ, element by element.
std::vector<Material> region_only(const std::vector<int>& owner, int region, const Material& m) {
  std::vector<Material> out(owner.size());
  for (std::size_t e = 0; e < owner.size(); ++e)
    if (owner[e] == region) out[e] = m;
  return out;
}

// ∂E_elastic/∂x of the elements of `region` with moduli (μ, κ).
Eigen::VectorXd region_elastic_gradient(const TetMesh& mesh, const std::vector<int>& owner,
                                        int region, const Positions& x, double mu, double kappa) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  NeoHookean(mesh, region_only(owner, region, Material{.mu = mu, .kappa = kappa, .density = 0}))
      .add_gradient(x, g);
  return g;
}

// The weight of the elements of `region` (ρ of `m`), N per node, stacked.
Eigen::VectorXd region_weight(const TetMesh& mesh, const std::vector<int>& owner, int region,
                              const Positions& x, const Material& m, const Vec3& gravity) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  Gravity(mesh, region_only(owner, region, m), gravity).add_gradient(x, g);
  return -g;
}

const char* const kMaterialNames[] = {"youngs_modulus", "poisson_ratio", "density"};

// "regions[1].youngs_modulus" → {1, "youngs_modulus"}; nullopt for anything else.
std::optional<RegionParameter> parse_region_parameter(const std::string& item) {
  const std::string prefix = "regions[";
  if (item.rfind(prefix, 0) != 0) return std::nullopt;
  const std::size_t close = item.find("].", prefix.size());
  if (close == std::string::npos || close == prefix.size() || close - prefix.size() > 6)
    return std::nullopt;
  const std::string index = item.substr(prefix.size(), close - prefix.size());
  if (index.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  const std::string name = item.substr(close + 2);
  for (const char* known : kMaterialNames)
    if (name == known) return RegionParameter{std::stoi(index), name};
  return std::nullopt;
}

// ∂F/∂z of a material coordinate c (of region c.region) at x: elasticity is linear in (μ, κ)
// and E scales both, so ∂F/∂ln E = −∂E_elastic/∂x of the region's elements; ν moves (μ, κ)
// along (dμ/dν, dκ/dν); the weight is ∝ ρ.
Eigen::VectorXd material_force_derivative(const TetMesh& mesh, const std::vector<int>& owner,
                                          const ParameterCoordinate& c, const Positions& x,
                                          const Scene& scene, const PhysicalParameters& p) {
  const Material& m = c.region < 0 ? scene.material : scene.regions[c.region].material;
  if (c.kind == Kind::LogYoungsModulus)
    return -region_elastic_gradient(mesh, owner, c.region, x, m.mu, m.kappa);
  if (c.kind == Kind::LogDensity) return region_weight(mesh, owner, c.region, x, m, scene.gravity);
  // dμ/dν and dκ/dν of material_from_youngs, times dν/ds.
  const double nu = p.material(c.region).poisson_ratio, E = p.material(c.region).youngs_modulus;
  const double dmu_dnu = -E / (2 * (1 + nu) * (1 + nu));
  const double dkappa_dnu = E * (1 + 2 * nu * nu) / std::pow((1 + nu) * (1 - 2 * nu), 2);
  const double dnu_ds = nu * (1 - 2 * nu);
  return -region_elastic_gradient(mesh, owner, c.region, x, dmu_dnu, dkappa_dnu) * dnu_ds;
}

Kind material_kind(const std::string& name) {
  if (name == "youngs_modulus") return Kind::LogYoungsModulus;
  if (name == "poisson_ratio") return Kind::PoissonLogit;
  return Kind::LogDensity;
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
  return "";
}

}  // namespace

const char* fit_parameter_names() {
  return "youngs_modulus, poisson_ratio, density, grip_offsets, object_pose, camera_poses, "
         "regions[K].youngs_modulus, regions[K].poisson_ratio, regions[K].density";
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
    else if (item == "camera_poses") s.camera_poses = true;
    else if (const auto region = parse_region_parameter(item)) s.regions.push_back(*region);
    else
      throw std::invalid_argument("unknown parameter \"" + item + "\" (expected " +
                                  fit_parameter_names() + ")");
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
  for (const MaterialRegion& r : scene.regions)
    p.regions.push_back(
        {youngs_modulus_of(r.material), poisson_ratio_of(r.material), r.material.density});
  return p;
}

Eigen::Isometry3d PhysicalParameters::camera_pose(int k) const {
  return k < static_cast<int>(camera_poses.size()) ? camera_poses[k]
                                                   : Eigen::Isometry3d::Identity();
}

MaterialValues PhysicalParameters::material(int region) const {
  if (region >= 0) return regions[region];
  return {youngs_modulus, poisson_ratio, density};
}

void PhysicalParameters::set_material(int region, const MaterialValues& values) {
  if (region >= 0) {
    regions[region] = values;
    return;
  }
  youngs_modulus = values.youngs_modulus;
  poisson_ratio = values.poisson_ratio;
  density = values.density;
}

Scene PhysicalParameters::applied_to(const Scene& scene) const {
  Scene out = scene;
  out.material = material_from_youngs(youngs_modulus, poisson_ratio, density);
  for (std::size_t k = 0; k < out.regions.size(); ++k)
    out.regions[k].material = material_from_youngs(regions[k].youngs_modulus,
                                                   regions[k].poisson_ratio, regions[k].density);
  for (std::size_t k = 0; k < out.grips.size(); ++k) out.grips[k].offset = grip_offsets[k];
  out.T_world_object = object_pose;
  return out;
}

ParameterSpace::ParameterSpace(const Scene& scene, const FitSelection& selection, int cameras) {
  if (selection.youngs_modulus)
    coordinates_.push_back({Kind::LogYoungsModulus, -1, -1, "youngs_modulus", 1});
  if (selection.poisson_ratio)
    coordinates_.push_back({Kind::PoissonLogit, -1, -1, "poisson_ratio", 1});
  if (selection.density) coordinates_.push_back({Kind::LogDensity, -1, -1, "density", 1});
  for (const RegionParameter& r : selection.regions) {
    const std::string name = "regions[" + std::to_string(r.region) + "]." + r.name;
    if (r.region < 0 || r.region >= static_cast<int>(scene.regions.size()))
      throw std::invalid_argument(name + ": " +
                                  (scene.regions.empty()
                                       ? std::string("the scene has no \"regions\"")
                                       : "the scene has " + std::to_string(scene.regions.size()) +
                                             " region(s), regions[0] to regions[" +
                                             std::to_string(scene.regions.size() - 1) + "]"));
    for (const ParameterCoordinate& c : coordinates_)
      if (c.name == name) throw std::invalid_argument(name + ": named twice");
    coordinates_.push_back({material_kind(r.name), -1, -1, name, 1, r.region});
  }
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
  if (selection.camera_poses) {
    if (cameras <= 0)
      throw std::invalid_argument(
          "camera_poses: no frame has a depth image (a camera's pose moves its image's points)");
    for (int k = 0; k < cameras; ++k) {
      add_motion_coordinates(coordinates_, Kind::CameraTranslation, Kind::CameraRotation, -1,
                             "cameras[" + std::to_string(k) + "].pose.");
      for (auto c = coordinates_.end() - 6; c != coordinates_.end(); ++c) c->camera = k;
    }
  }
}

PhysicalParameters ParameterSpace::advanced(const PhysicalParameters& p,
                                            const Eigen::VectorXd& dz) const {
  PhysicalParameters out = p;
  std::vector<Vec3> dt(p.grip_offsets.size(), Vec3::Zero()), dr = dt;
  Vec3 pose_dt = Vec3::Zero(), pose_dr = Vec3::Zero();
  std::vector<Vec3> camera_dt, camera_dr;
  for (int k = 0; k < size(); ++k) {
    const ParameterCoordinate& c = coordinates_[k];
    switch (c.kind) {
      case Kind::LogYoungsModulus:
      case Kind::LogDensity:
      case Kind::PoissonLogit: {
        MaterialValues m = out.material(c.region);
        const double nu = p.material(c.region).poisson_ratio;
        if (c.kind == Kind::LogYoungsModulus) m.youngs_modulus *= std::exp(dz[k]);
        if (c.kind == Kind::LogDensity) m.density *= std::exp(dz[k]);
        if (c.kind == Kind::PoissonLogit)
          m.poisson_ratio = 0.5 / (1 + std::exp(-(std::log(2 * nu / (1 - 2 * nu)) + dz[k])));
        out.set_material(c.region, m);
        break;
      }
      case Kind::GripTranslation: dt[c.grip][c.axis] = dz[k]; break;
      case Kind::GripRotation: dr[c.grip][c.axis] = dz[k]; break;
      case Kind::PoseTranslation: pose_dt[c.axis] = dz[k]; break;
      case Kind::PoseRotation: pose_dr[c.axis] = dz[k]; break;
      case Kind::CameraTranslation:
      case Kind::CameraRotation: {
        const std::size_t n = static_cast<std::size_t>(c.camera) + 1;
        if (camera_dt.size() < n)
          camera_dt.resize(n, Vec3::Zero()), camera_dr.resize(n, Vec3::Zero());
        (c.kind == Kind::CameraTranslation ? camera_dt : camera_dr)[c.camera][c.axis] = dz[k];
        break;
      }
    }
  }
  for (std::size_t k = 0; k < camera_dt.size(); ++k) {
    if (out.camera_poses.size() <= k) out.camera_poses.resize(k + 1, Eigen::Isometry3d::Identity());
    move(out.camera_poses[k], camera_dt[k], camera_dr[k]);
  }
  for (std::size_t g = 0; g < out.grip_offsets.size(); ++g) move(out.grip_offsets[g], dt[g], dr[g]);
  move(out.object_pose, pose_dt, pose_dr);
  return out;
}

double ParameterSpace::physical_per_coordinate(const ParameterCoordinate& c,
                                               const PhysicalParameters& p) const {
  const MaterialValues m = p.material(c.region);
  switch (c.kind) {
    case Kind::LogYoungsModulus: return m.youngs_modulus;
    case Kind::LogDensity: return m.density;
    case Kind::PoissonLogit: return m.poisson_ratio * (1 - 2 * m.poisson_ratio);
    default: return 1;  // m and rad: the coordinates themselves
  }
}

CameraMotion ParameterSpace::camera_motion(int camera, const Vec3& camera_position,
                                           const PhysicalParameters& p) const {
  // p' = o + t_C + R_C (p − o) for camera position o and correction C.
  const Eigen::Isometry3d C = p.camera_pose(camera);
  CameraMotion m;
  m.motion.linear() = C.linear();
  m.motion.translation() = camera_position + C.translation() - C.linear() * camera_position;
  m.origin = camera_position + C.translation();
  for (int k = 0; k < size() && m.column < 0; ++k)
    if (coordinates_[k].kind == Kind::CameraTranslation && coordinates_[k].camera == camera)
      m.column = k;
  return m;
}

Eigen::MatrixXd ParameterSpace::force_derivatives(const ObjectStatics& statics, const Scene& scene,
                                                  const Positions& x,
                                                  const PhysicalParameters& p) const {
  Eigen::MatrixXd dF = Eigen::MatrixXd::Zero(x.size(), size());
  const TetMesh& mesh = statics.mesh();
  // Each element's region (all -1 without regions): a material's columns are its elements'.
  const std::vector<int> owner =
      scene.regions.empty() ? std::vector<int>(mesh.tets().size(), -1) : scene.element_regions();
  // The external forces, world frame: turned by −δr in the object's frame when the scene turns
  // by δr.
  Eigen::VectorXd weight_gradient = Eigen::VectorXd::Zero(x.size());
  Gravity(mesh, scene.element_materials(), scene.gravity).add_gradient(x, weight_gradient);
  const Eigen::VectorXd external = scene.load_forces() - weight_gradient;
  for (int k = 0; k < size(); ++k) {
    const ParameterCoordinate& c = coordinates_[k];
    if (c.kind == Kind::PoseRotation) {
      for (Eigen::Index i = 0; i < x.size() / 3; ++i)
        dF.col(k).segment<3>(3 * i) = Vec3(external.segment<3>(3 * i)).cross(Vec3::Unit(c.axis));
    } else if (c.kind == Kind::LogYoungsModulus || c.kind == Kind::PoissonLogit ||
               c.kind == Kind::LogDensity) {
      dF.col(k) = material_force_derivative(mesh, owner, c, x, scene, p);
    }  // grip and pose translation columns: no force on the object itself
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
