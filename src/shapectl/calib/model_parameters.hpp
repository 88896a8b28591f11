#pragma once
// The physical parameters calibration can fit, and their coordinates z: Young's modulus and
// density as logarithms (positive), Poisson's ratio as s with ν = ½·logistic(s) (inside
// (0, ½)), each grip's offset as 3 translations (m) and 3 rotations (rad) applied on the left,
// O ← (exp([δr]) R, t + δt), about the TCP in the end effector's frame; the object's pose
// T_world_object (scenes held by fixed nodes alone) the same way, in world axes about the
// object frame's origin o: the whole scene, clamp included, moved by δ. A scene with "regions"
// has one material per region besides its own (the elements in no region): each region's
// Young's modulus, Poisson's ratio and density are coordinates of their own
// ("regions[1].youngs_modulus"), their derivatives taken over that region's elements alone.
// A depth camera's pose (observations' "depth_image", "camera": K) is corrected the same way:
// 3 translations and 3 rotations ("cameras[K].pose.x" ... ".rz"), applied on the left in world
// axes about the camera's origin o, so its points move rigidly, p' = o + δt + R_δ (p − o); the
// model's x̂ does not move, the residuals do (calib/observation_residuals.hpp).
//
// For equilibria x̂ the forces' derivatives ∂F/∂z (F = −∂E/∂x) give the parameter sensitivity
// dx̂/dz = H⁻¹ ∂F/∂z (GrippedObject::force_response), exactly as dx̂/dθ. The object's pose
// adds a rigid part: moving the scene by δ moves its equilibrium by δ, under gravity turned
// by R_δᵀ in the object's frame, so x̂(δ) = δ ∘ y(R_δᵀ g) and at δ = 0
//   dx̂ᵢ/dδt = I,   dx̂ᵢ/dδr = −[x̂ᵢ − o]× + H⁻¹ ∂F/∂δr,   ∂Fᵢ/∂δr = [Fᵢ_gravity + Fᵢ_loads]×
// (the loads are world-frame forces too: they turn with gravity in the object's frame).
#include <string>
#include <vector>

#include <shapectl/sim/gripped_object.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl {

// One material parameter of a region: "regions[1].youngs_modulus".
struct RegionParameter {
  int region = 0;    // index into Scene::regions
  std::string name;  // "youngs_modulus", "poisson_ratio" or "density"
};

// What a calibration fits. With "regions", youngs_modulus etc. are the object's own material's
// (the elements in no region).
struct FitSelection {
  bool youngs_modulus = false;
  bool poisson_ratio = false;
  bool density = false;
  bool grip_offsets = false;
  bool object_pose = false;
  std::vector<RegionParameter> regions = {};
  bool camera_poses = false;  // every depth camera's pose correction
  bool empty() const {
    return !(youngs_modulus || poisson_ratio || density || grip_offsets || object_pose ||
             camera_poses) &&
           regions.empty();
  }
};
// Parsed from "youngs_modulus,poisson_ratio,density,grip_offsets,object_pose,camera_poses,
// regions[1].youngs_modulus". Throws std::invalid_argument naming the unknown entry and the
// known ones.
FitSelection parse_fit_selection(const std::string& list);
// "youngs_modulus, poisson_ratio, density, grip_offsets, object_pose, camera_poses,
// regions[K].youngs_modulus, ...": for messages.
const char* fit_parameter_names();
// What to fit when nobody says: a robot's grips are where the real object is held off; a
// clamp is where the scene puts it.
const char* default_fit(const Scene& scene);

// One material's fittable values.
struct MaterialValues {
  double youngs_modulus = 0;  // Pa
  double poisson_ratio = 0;
  double density = 0;  // kg/m^3
};

struct PhysicalParameters {
  double youngs_modulus = 0;  // Pa
  double poisson_ratio = 0;
  double density = 0;                                             // kg/m^3
  std::vector<Eigen::Isometry3d> grip_offsets;                    // one per scene grip
  Eigen::Isometry3d object_pose = Eigen::Isometry3d::Identity();  // T_world_object
  std::vector<MaterialValues> regions;                            // one per scene region
  // Depth camera K's pose correction C (T_world_camera ← (R_C R, t + t_C)); missing: identity.
  std::vector<Eigen::Isometry3d> camera_poses;

  // Camera k's correction (identity when not fitted).
  Eigen::Isometry3d camera_pose(int k) const;
  // Region r's material, or the object's own for r = -1.
  MaterialValues material(int region) const;
  void set_material(int region, const MaterialValues& values);

  static PhysicalParameters of(const Scene& scene);
  // The scene with these values (material, grip offsets, pose); everything else unchanged.
  Scene applied_to(const Scene& scene) const;
};

// One coordinate of z.
struct ParameterCoordinate {
  enum class Kind {
    LogYoungsModulus,
    PoissonLogit,
    LogDensity,
    GripTranslation,
    GripRotation,
    PoseTranslation,
    PoseRotation,
    CameraTranslation,
    CameraRotation
  };
  Kind kind;
  int grip = -1;  // for grip coordinates
  int axis =
      -1;  // 0..2 for grip, pose and camera coordinates (the TCP frame's or the world's x, y, z)
  // "youngs_modulus", "grip_offsets.left.x", "grip_offsets.left.rx", "object_pose.rz",
  // "regions[1].youngs_modulus"
  std::string name;
  // Typical size of a change worth noticing: 1 (a factor e) for the logarithms, 1 cm, 0.1 rad.
  double scale = 1;
  int region = -1;  // material coordinates: the region's (-1: the object's own material)
  int camera = -1;  // camera coordinates: the camera's index
};

// How a frame's points move with their camera's pose correction: p' = motion p, rotations
// turning about `origin` (the corrected camera's), and where the camera's six coordinates are.
struct CameraMotion {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  Vec3 origin = Vec3::Zero();
  int column = -1;  // index of its "x" coordinate (then y, z, rx, ry, rz); -1: not fitted
};

class ParameterSpace {
 public:
  // Throws std::invalid_argument when the scene has nothing a selected parameter moves: no
  // grips for grip_offsets; for object_pose, an object the robot's grips hold (they tie it to
  // the grippers, which are where the joints put them); a region the scene does not have;
  // camera_poses without cameras. cameras: how many depth cameras the observations have
  // (camera_count).
  ParameterSpace(const Scene& scene, const FitSelection& selection, int cameras = 0);
  const std::vector<ParameterCoordinate>& coordinates() const { return coordinates_; }
  int size() const { return static_cast<int>(coordinates_.size()); }

  // p moved by dz (size(): one entry per coordinate).
  PhysicalParameters advanced(const PhysicalParameters& p, const Eigen::VectorXd& dz) const;
  // ∂F/∂z at the equilibrium `state` of `object` (built from p.applied_to(scene)): 3n × size().
  Eigen::MatrixXd force_derivatives(const GrippedObject& object, const ObjectState& state,
                                    const PhysicalParameters& p) const;
  // ∂F/∂z of the object's own forces (elasticity, gravity, loads) at x, for `statics` built
  // from `scene` = p.applied_to(original) (with a frame's loads): 3n × size(), grip columns
  // zero.
  Eigen::MatrixXd force_derivatives(const ObjectStatics& statics, const Scene& scene,
                                    const Positions& x, const PhysicalParameters& p) const;
  // The rigid part of dx̂/dz at the equilibrium x: −[xᵢ − o]× for pose rotations, I for pose
  // translations, zero for the other coordinates (3n × size()).
  Eigen::MatrixXd pose_motion(const Positions& x, const PhysicalParameters& p) const;
  // dν/ds etc.: the derivative of the physical value a coordinate moves (Pa, 1, kg/m^3, m,
  // rad) with respect to the coordinate, for reporting standard deviations in physical units.
  double physical_per_coordinate(const ParameterCoordinate& c, const PhysicalParameters& p) const;
  // How the points of a depth camera at `camera_position` (world) with index `camera` move at p.
  CameraMotion camera_motion(int camera, const Vec3& camera_position,
                             const PhysicalParameters& p) const;

 private:
  std::vector<ParameterCoordinate> coordinates_;
};

}  // namespace shapectl
