#pragma once
// The immutable description of a scene: the object (mesh, material, placement), gravity, what
// holds it (fixed nodes, a robot's grips) and the objective's weights. Read from SCENE.json by
// scene_io/scene_file.hpp, or built in code.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <shapectl/contact/obstacle.hpp>
#include <shapectl/fem/material.hpp>
#include <shapectl/linalg/cholesky_backend.hpp>
#include <shapectl/mesh/tet_mesh.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

struct AlignedBox {
  Vec3 min, max;
  bool contains(const Vec3& p) const {
    return (p - min).minCoeff() >= 0 && (max - p).minCoeff() >= 0;
  }
};

// A set of mesh nodes chosen by an object-space box and/or explicit indices.
struct NodeSelection {
  // `{}`: a designated initializer may name one of the two without a warning.
  std::optional<AlignedBox> box{};
  std::vector<int> nodes{};
  // Indices of the selected nodes of `mesh` (rest positions in object coordinates).
  std::vector<int> resolve(const TetMesh& mesh) const;
};

// A constant force shared equally by some nodes of the object: a hanging weight, a tip force.
struct NodeLoad {
  std::vector<int> nodes;     // at least one, each once
  Vec3 force = Vec3::Zero();  // the total, N, world frame
};

// Part of the object of its own material: the elements whose rest centroid (object
// coordinates) lies in `box`.
struct MaterialRegion {
  AlignedBox box;
  Material material;
  // Whether `tet` of `mesh` (rest positions) is in the region.
  bool contains(const TetMesh& mesh, const TetRest& tet) const;
};

struct StaticsSettings {
  int max_iterations = 100;
  double relative_tolerance = 1e-6;        // force tolerance as a fraction of the object's weight
  std::optional<CholeskyBackend> backend;  // linear_solver_choices(); default: from the matrix
  // Newton steps by conjugate gradients preconditioned with a nearby state's factorization
  // (StaticsOptions::krylov_steps and cold_krylov_steps); off only to measure what they save
  // (`bench --no-krylov`).
  bool krylov_steps = true;
  bool chord_steps = true;   // off: Krylov steps only (tests force that path with it)
  bool rotate_chord = true;  // StaticsOptions::rotate_chord; off only to measure what it saves
  bool single_precision_chord = true;  // StaticsOptions::single_precision_chord; likewise
};

struct EndEffector {
  std::string name;
  int link = -1;
  Vec3 tcp_link = Vec3::Zero();  // tool centre point in the link frame, metres
};

// The robot part of a scene: model, reference configuration θ⁰ and what it grips with.
struct RobotSetup {
  std::shared_ptr<RobotModel> model;
  Eigen::VectorXd reference_joints;  // θ⁰, active joints, rad
  std::vector<EndEffector> end_effectors;
  std::shared_ptr<const CollisionModel> collisions;  // may be null: no self-collision term
  double joint_limit_margin = 0.05;                  // rad (m for prismatic)
  double joint_limit_stiffness = 1e3;                // k of the cubic barrier
};

struct Grip {
  int end_effector = -1;  // index into RobotSetup::end_effectors
  std::vector<int> nodes;
  // Where the gripper really holds the object relative to where the scene places it: a rigid
  // motion of the gripped nodes in the end effector's TCP frame, about the TCP. Identity
  // unless given ("offset" in the scene file) or fitted by `shapectl calibrate`.
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
};

struct ObjectiveWeights {
  double shape = 1.0;         // × ½ Σ |pᵢ − p'ᵢ|²  (m²)
  double collision = 1.0;     // × collision barrier
  double joint_limits = 1.0;  // × joint-limit barrier
};

// Where the object's mesh came from: the scene checks tailor their advice to it.
struct MeshOrigin {
  enum class Kind { InCode, Box, VolumeFile, SurfaceFile };
  Kind kind = Kind::InCode;
  std::string field = "object.mesh";  // JSON path of the mesh in the scene file
  bool units_given = false;           // "units" or "scale" was set (file meshes only)
};

struct Scene {
  std::filesystem::path source;                // the scene file
  std::shared_ptr<const TetMesh> object_mesh;  // rest mesh in object coordinates
  Material material;
  // Later regions override earlier ones; elements in none are of `material`.
  std::vector<MaterialRegion> regions;
  Eigen::Isometry3d T_world_object = Eigen::Isometry3d::Identity();
  Vec3 gravity{0, 0, -9.81};
  std::optional<NodeSelection> fixed;
  std::vector<NodeLoad> loads;
  StaticsSettings statics;
  std::optional<RobotSetup> robot;
  std::vector<Grip> grips;
  double grip_stiffness = 1e4;  // K, N/m
  ObjectiveWeights weights;
  // Static obstacles the object rests on or touches (world frame), and how contact acts; none:
  // no contact term at all.
  std::vector<Obstacle> obstacles;
  ContactSettings contact;
  MeshOrigin mesh_origin;
  // Findings of check_scene where results might be wrong, one line each, "file: field: what";
  // for the commands to print. (Where they would be wrong, load_scene throws instead.)
  std::vector<std::string> warnings;

  // Rest positions placed in the world, stacked (3n).
  Positions world_rest_positions() const;
  // Each element's material (mesh.tets() order), or {material} alone when there are no regions.
  std::vector<Material> element_materials() const;
  // Each element's region (mesh.tets() order): the index of the last region containing it, or
  // -1 for the object's own material.
  std::vector<int> element_regions() const;
  // The loads' nodal forces, stacked (3n), N, world frame.
  Eigen::VectorXd load_forces() const;
  // The sum of the loads' forces, N, world frame.
  Vec3 loads_total() const;
};

}  // namespace shapectl
