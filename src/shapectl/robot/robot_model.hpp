#pragma once
// A robot's kinematic tree read from URDF: links, joints, limits and primitive geometry,
// plus the choice of which joints are optimised (the active joints θ).
#include <Eigen/Geometry>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <shapectl/robot/xacro_expander.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

enum class JointType { Fixed, Revolute, Continuous, Prismatic };

// A primitive or (visuals only) a mesh attached to a link. Cylinders run along z of their own
// frame (URDF convention).
struct Shape {
  enum class Kind { Sphere, Box, Cylinder, Mesh };
  Kind kind = Kind::Sphere;
  Eigen::Isometry3d T_link_shape = Eigen::Isometry3d::Identity();
  Vec3 box_size = Vec3::Zero();  // full edge lengths along x, y, z (box), metres
  double radius = 0;             // sphere, cylinder; metres
  double length = 0;             // cylinder; metres
  // Mesh: the file name as the URDF writes it ("package://pkg/meshes/a.stl"; visual_meshes.hpp
  // finds the file) and the URDF's per-axis scale, applied before T_link_shape.
  std::string mesh_filename;
  Vec3 mesh_scale = Vec3::Ones();
  // The URDF material's colour (visuals only): red, green, blue, alpha in [0, 1]; none when the
  // URDF gives no colour (the GUI then picks one per link).
  std::optional<Eigen::Vector4d> rgba;
};

struct Link {
  std::string name;
  int parent_joint = -1;  // index into joints(); -1 for the root
  // Collision meshes are not loaded: the collision spheres are the collision model (one warning
  // says so); `shapectl author` covers them with spheres (urdf_collision.hpp).
  std::vector<Shape> collision_shapes;
  std::vector<Shape> visual_shapes;  // primitives and meshes
};

struct Joint {
  std::string name;
  JointType type = JointType::Fixed;
  int parent_link = -1;
  int child_link = -1;
  // Pose of the child link frame in the parent link frame at joint value 0.
  Eigen::Isometry3d T_parent_child = Eigen::Isometry3d::Identity();
  Vec3 axis = Vec3::UnitZ();  // unit; in the child frame (= joint frame)
  // Position limits (rad or m); -inf/+inf for continuous joints. Velocity (rad/s or m/s); +inf
  // when the URDF gives none.
  double lower = 0;
  double upper = 0;
  double velocity = 0;
  // A mimic joint's value is multiplier · master + offset; chains are resolved to the final
  // master (a joint that mimics nothing).
  int mimic_master = -1;
  double mimic_multiplier = 1;
  double mimic_offset = 0;
  bool movable() const { return type != JointType::Fixed; }
};

class RobotModel {
 public:
  // Errors (missing file, URDF syntax, kinematic loops, non-finite numbers, bad limits) throw
  // InputError naming the file and the element, e.g. "arm.urdf:12: joint 'j2': ...".
  // ROBOT.urdf.xacro is expanded first (read_robot_description); line numbers of errors found
  // after the expansion are lines of the expanded text.
  static RobotModel load_urdf_file(const std::filesystem::path& file,
                                   const XacroOptions& xacro = {});
  static RobotModel from_urdf_string(const std::string& xml, const std::string& source_name);

  const std::string& name() const { return name_; }
  const std::string& source() const { return source_; }
  // Links root first; joints in tree order (depth first, siblings in file order), so a joint's
  // parent link always comes before its child. links()[joints()[j].child_link] is unique.
  const std::vector<Link>& links() const { return links_; }
  const std::vector<Joint>& joints() const { return joints_; }
  int link_count() const { return static_cast<int>(links_.size()); }
  int joint_count() const { return static_cast<int>(joints_.size()); }
  // Skipped geometry and similar, one line each, for the user to see.
  const std::vector<std::string>& warnings() const { return warnings_; }

  std::optional<int> find_link(std::string_view name) const;
  std::optional<int> find_joint(std::string_view name) const;
  // InputError "<source>: link 'x': unknown link" when absent.
  int link_index(std::string_view name) const;
  int joint_index(std::string_view name) const;

  // The optimisation variables θ. Default: every movable joint that mimics nothing, in tree
  // order. Fixed and mimic joints cannot be active.
  void set_active_joints(const std::vector<std::string>& names);
  const std::vector<int>& active_joints() const { return active_joints_; }  // joint indices
  std::vector<std::string> active_joint_names() const;
  int active_count() const { return static_cast<int>(active_joints_.size()); }
  int active_index(int joint) const { return active_index_[static_cast<std::size_t>(joint)]; }
  Eigen::VectorXd lower_limits() const;  // size active_count()
  Eigen::VectorXd upper_limits() const;
  Eigen::VectorXd velocity_limits() const;

  // Values of the movable joints that are not active (default 0), e.g. gripper fingers.
  // Each name must be an inactive, movable, non-mimic joint; `source` names the input in errors.
  void set_fixed_joint_values(const std::map<std::string, double>& values,
                              const std::string& source);
  // θ from named values; missing joints are 0. Each name must be an active joint.
  Eigen::VectorXd active_joints_from_map(const std::map<std::string, double>& values,
                                         const std::string& source) const;
  // Every joint's value (size joint_count(), 0 for fixed joints) from θ and the fixed values;
  // mimic joints follow their master.
  Eigen::VectorXd full_joints(const Eigen::VectorXd& active) const;
  // The value an inactive joint keeps (0 for fixed and mimic joints).
  double fixed_value(int joint) const { return fixed_values_[joint]; }

  // Jacobian structure: the joints whose motion moves `link`, with the column of θ they feed
  // and the factor (mimic multiplier, 1 otherwise). Root to link order.
  struct JacobianEntry {
    int joint;
    int column;
    double scale;
  };
  const std::vector<JacobianEntry>& jacobian_entries(int link) const {
    return jacobian_entries_[static_cast<std::size_t>(link)];
  }

 private:
  friend class UrdfReader;
  void rebuild_jacobian_entries();

  std::string name_;
  std::string source_;
  std::vector<Link> links_;
  std::vector<Joint> joints_;
  std::vector<std::string> warnings_;
  std::map<std::string, int, std::less<>> link_by_name_;
  std::map<std::string, int, std::less<>> joint_by_name_;
  std::vector<int> active_joints_;
  std::vector<int> active_index_;  // per joint; -1 when not active
  Eigen::VectorXd fixed_values_;   // per joint; used for inactive movable joints
  std::vector<std::vector<JacobianEntry>> jacobian_entries_;  // per link
};

}  // namespace shapectl
